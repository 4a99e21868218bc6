"""Backends: compiled implementations of the batch computations behind one seam.

numpy (in `mbplanar.kinematics` and `mbplanar.forces`) is the reference. A backend (`Backend`) answers
``kinematics`` and ``kinetostatics`` for the batches it can vouch for and returns None for the others,
which numpy then computes (`mbplanar.engine._backend.dispatch`, the one place of that fallback).
`Engine(mech, backend="numba")` loads one by name (`BACKENDS`, `load`): the numba backend (extra
``mbplanar[fast]``) runs one-input sweeps through compiled per-position loops split over threads
(`_numba`, `_numba_kinematics`, `_numba_kinetostatics`, `_threads`); numba is imported only then.
"""

from ..engine._backend import BACKENDS, Backend, load

__all__ = ["Backend", "BACKENDS", "load"]
