"""Results as data for people and files: JSON documents and CSV tables (`document`, `table`), shared by
the command line and the report."""

from ._export import (document, dynamics_document, dynamics_table, forces_document, forces_table, info_document,
                      plain, solve_document, sweep_table, table, write_csv)

__all__ = ["document", "table", "plain", "write_csv", "info_document", "solve_document", "forces_document",
           "dynamics_document", "sweep_table", "forces_table", "dynamics_table"]
