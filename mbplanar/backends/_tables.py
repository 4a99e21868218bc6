"""The kinetostatics kernel's load tables: the loads a kernel adds at every position as a named tuple of
arrays, each field documented with its shape (the kinematics tables are the engine's,
`mbplanar.engine._tables`).

Codes. `LOAD_FIXED`, `LOAD_GUIDE`, `LOAD_INERTIA` name the kinds of load; a table stores a load's `guide`
row (or −1) and the boolean `inertia` rather than the code, so that no kernel compares against a
constant of another file (numba would freeze it into its cache).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

# numba's on-disk cache indexes written before the kinematics tables moved to the engine name them here:
# importable, they unpickle, and the cache sees its stamp is old and compiles again (else it fails)
from ..engine._tables import BlockTables, CutTables, JointTables, StepTables  # noqa: F401

__all__ = ["LOAD_FIXED", "LOAD_GUIDE", "LOAD_INERTIA", "LoadTables", "load_tables"]

LOAD_FIXED, LOAD_GUIDE, LOAD_INERTIA = "fixed", "guide", "inertia"   # the three kinds of load a kernel adds


class LoadTables(NamedTuple):
    """The N loads the kinetostatics kernel adds at every position, in numpy's order."""

    link: np.ndarray               # (N,) int: the link loaded
    guide: np.ndarray              # (N,) int: a force along a guide: its row of guide-force sizes; else −1
    inertia: np.ndarray            # (N,) bool: a d'Alembert load (−m·a at the centre, −I·ε)
    carrier: np.ndarray            # (N,) int: the guide's carrier (guide loads; else 0)
    at: np.ndarray                 # (N, 2) float: the point of application, drawn
    force: np.ndarray              # (N, 2) float: a fixed force (else 0)
    moment: np.ndarray             # (N,) float: a fixed moment
    u0: np.ndarray                 # (N, 2) float: the guide's direction, drawn (guide loads; else 0)
    mass: np.ndarray               # (N,) float: inertia loads: the link's mass (else 0)
    moment_of_inertia: np.ndarray  # (N,) float: inertia loads: the link's I_S (else 0)


def load_tables(rows: list) -> LoadTables:
    """`LoadTables` from rows (kind, link, guide row, carrier, at, force or (mass, I_S), moment, u0), kind
    `LOAD_FIXED`, `LOAD_GUIDE` or `LOAD_INERTIA`."""
    n = len(rows)
    out = LoadTables(np.zeros(n, np.int64), np.full(n, -1, np.int64), np.zeros(n, np.bool_), np.zeros(n, np.int64),
                     np.zeros((n, 2)), np.zeros((n, 2)), np.zeros(n), np.zeros((n, 2)), np.zeros(n), np.zeros(n))
    for i, (kind, link, guide, carrier, at, force, moment, u0) in enumerate(rows):
        out.link[i], out.carrier[i], out.at[i], out.moment[i] = link, carrier, at, moment
        if kind == LOAD_INERTIA:
            out.inertia[i], out.mass[i], out.moment_of_inertia[i] = True, force[0], force[1]
        elif kind == LOAD_GUIDE:
            out.guide[i], out.u0[i] = guide, u0
        else:
            out.force[i] = force
    return out
