"""Backends: compiled implementations of the batch computations behind one seam.

numpy (in `mbplanar.kinematics` and `mbplanar.forces`) is the reference. A backend (`Backend`) answers
``kinematics`` and ``kinetostatics`` for the batches it can vouch for and returns None for the others,
which numpy then computes (`mbplanar.engine.dispatch`, the one place of that fallback).
`Engine(mech, backend="numba")` loads one by name (`BACKENDS`, `load`): the numba backend (extra
``mbplanar[fast]``, `NUMBA`) runs one-input sweeps through compiled per-position loops split over threads;
numba is imported only then. `PYTHON` runs the same kernels as plain Python (one position costs less
there than numpy's batch machinery). `build` (``mbplanar compile``) fills numba's cache with every kernel.

    >>> from mbplanar.backends import BACKENDS, load
    >>> sorted(BACKENDS), load("numpy").name
    (['numba', 'numpy'], 'python')
"""

from .._lazy import lazy_attributes
from ..engine import BACKENDS, Backend, load

__all__ = ["Backend", "BACKENDS", "load", "PYTHON", "NUMBA", "build"]

#: public name → the private module (and its name there), imported on first access (PEP 562): a backend is
#: loaded when an engine first asks for it, the ahead-of-time build by ``mbplanar compile`` only
_LAZY = {"PYTHON": "_python:BACKEND", "NUMBA": "_numba:BACKEND", "build": "_aot"}


__getattr__, __dir__ = lazy_attributes(__name__, _LAZY)
