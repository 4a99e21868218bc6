"""The engine: loop-closure equations solved by block Newton–Raphson, rates, branch continuation (the
atlas) and singular positions.

`Engine(mechanism)` compiles a mechanism once; `solve_positions`, `Engine.solve_limits`, `Engine.rates` and
`Engine.atlas` answer for batches of input values (the layers above use them; users call `analyse`).
The layers above also build on the parts exported here: the joint laws (`Revolute`, `Prismatic`, `Rates`,
`perp`, `dot`, `world_frames`), the block solver (`BlockSolver`, `factor`), the continuation's rules
(`step_verdict`, `rate_jump`, the quintic Hermite interpolant `hermite_coefficients`, `hermite_value`),
the atlas (`Atlas`, `met_along`, `far_span`), the backend seam (`dispatch`, `Backend`, `load`, `planned`),
the kernels' tables (`sweep_tables`, `StepTables`, ..., and `higher_layout`, the column layout of the higher
pairs' tables), the higher pairs' laws of a mechanism (`higher_laws`), the command line's engine cache
(`load_engine`) and the design batch's dimensions (`with_dimensions`, `same_structure`).

    >>> import numpy as np
    >>> from mbplanar.engine import Engine, solve_positions
    >>> from mbplanar.model import read_model
    >>> engine = Engine(read_model("models/fourbar.toml"))
    >>> solution = solve_positions(engine, np.radians([60.0]))
    >>> bool(solution.valid[0]), solution.phi.shape                     # (B, n_in)
    (True, (1, 1))
"""

from .._lazy import lazy_attributes
from . import _higher_tables as higher_layout
from ._atlas import FAR_TURNS, LOST_PRECISION, Atlas, far_span, met_along
from ._backend import BACKENDS, Backend, dispatch, load, planned
from ._blocks import BlockSolver
from ._constraints import Prismatic, Rates, Revolute, dot, perp, world_frames
from ._continuation import (ACCEPT, CROSS, HERMITE5, hermite_coefficients, hermite_slope, hermite_value, rate_jump,
                            step_verdict)
from ._linalg import factor
from ._nodes import Node
from ._singular import limit_after
from ._solver import Crossing, Engine, Limit, Solution, higher_laws, solve_positions
from ._tables import (DESIGN_STATUS, BlockTables, CutTables, DesignJob, DesignResult, DesignTables, JointTables,
                      StepTables, SweepIn, SweepJob, SweepOut, SweepWork, atlas_tables,
                      record_layout, sweep_tables, work_sizes)
from ._tolerances import Tolerances

__all__ = ["Engine", "Tolerances", "Solution", "Limit", "Crossing", "solve_positions", "FAR_TURNS", "LOST_PRECISION",
           "Atlas", "met_along", "far_span", "limit_after", "Node", "BlockSolver", "factor", "Revolute", "Prismatic",
           "Rates", "perp", "dot", "world_frames", "HERMITE5", "ACCEPT", "CROSS", "step_verdict", "rate_jump",
           "hermite_coefficients", "hermite_value", "hermite_slope", "Backend", "BACKENDS", "load", "dispatch",
           "planned", "StepTables", "CutTables", "BlockTables", "JointTables", "SweepIn", "SweepOut", "SweepWork",
           "SweepJob", "DesignTables", "DesignJob", "DesignResult", "DESIGN_STATUS", "sweep_tables",
           "atlas_tables", "record_layout", "work_sizes", "higher_layout", "load_engine",
           "with_dimensions", "same_structure", "higher_laws"]

#: public name → the private module defining it, imported on first use (PEP 562): the command line's
#: engine cache and the design batch's dimensions are not needed to solve a model
_LAZY = {"load_engine": "_cache", "with_dimensions": "_dimensions", "same_structure": "_dimensions"}


__getattr__, __dir__ = lazy_attributes(__name__, _LAZY)
