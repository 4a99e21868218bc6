"""Results as data for people and files: JSON documents (`document`) and CSV tables (`table`), in SI or
in the model's units, shared by the command line, the report and `to_frame()`; CAD drawings (`Sheet` of
`Layer`s, written by `write_dxf` and `write_svg`), shared by the cam's profile, the gears and the
linkage's drawing."""

from .._lazy import lazy_attributes
from ._documents import balance_document, simulate_document, simulate_table
from ._export import (document, dynamics_document, engine_for, forces_document, info_document, partials_document,
                      plain, solve_document, table, write_csv)
from ._tables import dynamics_table, forces_columns, forces_table, sweep_table

#: the CAD names, imported from `_cad` on first use (PEP 562): a command that writes no drawing does not
#: load it
__getattr__, __dir__ = lazy_attributes(__name__, dict.fromkeys(("Layer", "Sheet", "require_ezdxf", "write_dxf",
                                                                   "write_svg"), "_cad"))

__all__ = ["document", "table", "engine_for", "plain", "write_csv", "info_document", "solve_document",
           "partials_document",
           "forces_document", "dynamics_document", "sweep_table", "forces_table", "forces_columns", "dynamics_table",
           "simulate_document", "simulate_table", "balance_document", "Sheet", "Layer", "write_dxf", "write_svg",
           "require_ezdxf"]
