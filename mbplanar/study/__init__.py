"""Design studies: a model's dimensions as named parameters, variant tables, per-design summaries,
and the same study on every core or on a Dask cluster.

    >>> from mbplanar.study import run_study
    >>> study = run_study("models/crank_slider_rocker.toml", "models/crank_slider_rocker_variants.csv")
    >>> [d.full_turn for d in study.designs][:8]
    [False, False, False, True, False, True, True, True]
"""

from ..model import Parameter, Template
from .batch import DesignBatch, DesignLimit, DesignMotion, design_batch
from .dimensions import with_dimensions
from .forces import DesignForces, design_kinetostatics
from .run import Study, join_motions, load_template, run_study, solve_designs
from .summary import DesignSummary, summarise
from .variants import Variants, read_variants, variants_from

__all__ = ["Parameter", "Template", "with_dimensions", "DesignForces", "design_kinetostatics", "DesignBatch", "DesignMotion", "DesignLimit", "design_batch", "Study", "run_study", "solve_designs", "join_motions", "load_template",
           "DesignSummary", "summarise", "Variants", "read_variants", "variants_from"]
