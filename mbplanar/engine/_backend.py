"""The backend seam: one place where a compiled implementation may take a batch, and numpy (the
reference) takes whatever it declines.

`analyse` and `kinetostatics` each read as one path: ``dispatch(engine, job, reference, *args)`` asks the
engine's compiled backend for the job and falls back to the numpy reference when there is none or when
it answers None (it cannot vouch for that batch: several inputs, a change point's bracket, loads given
by the caller, ...), as networkx's backends answer ``can_run``. The implementations live in
`mbplanar.backends` and are loaded by name when an engine asks for them (`load`); this module sits in
the engine layer because the functions that dispatch (kinematics, forces) sit below `backends`.
"""

from __future__ import annotations

import importlib
import importlib.util
from typing import TYPE_CHECKING, Callable, Protocol

from ..errors import MbplanarError

if TYPE_CHECKING:
    import numpy as np

    from ..forces import Kinetostatics
    from ..kinematics import Motion

__all__ = ["Backend", "BACKENDS", "check", "load", "dispatch"]


class Backend(Protocol):
    """A compiled implementation of the batch computations. Each method returns None where it cannot
    vouch for the batch; the numpy reference then computes all of it. Tables a backend builds for an
    engine are kept in ``engine.prepared`` (`Engine.prepare`)."""

    name: str

    def kinematics(self, engine, phi: np.ndarray, omega, epsilon, points, rates: bool) -> Motion | None:
        """`analyse` of input values phi (as given, float), of the points `points` (a
        `kinematics.PointSelection`), with or without the rates."""

    def kinetostatics(self, engine, motion: Motion, input_inertia, loads, inertia: bool) -> Kinetostatics | None:
        """`kinetostatics` of a motion."""

    # optional: ``single(engine)`` → a solver ``(phi, omega, epsilon) → Position`` of one position, made
    # once per engine (`mbplanar.kinematics.position`), or None; numpy's is used where there is none


#: name → (module defining ``BACKEND``, the package it needs, the extra that installs it);
#: None for numpy, the reference, which needs no module
BACKENDS: dict[str, tuple[str, str, str] | None] = {
    "numpy": None,
    "numba": ("mbplanar.backends._numba", "numba", "fast"),
}


def check(name: str) -> None:
    """Refuse what `load` would refuse, without importing the backend's package (numba takes ~0.4 s):
    ValueError for an unknown name, `MbplanarError` naming the extra to install when the package is not
    installed."""
    if name not in BACKENDS:
        raise ValueError(f"backend must be one of {', '.join(BACKENDS)}, not {name!r}")
    spec = BACKENDS[name]
    if spec is not None and importlib.util.find_spec(spec[1]) is None:
        raise _missing(name, spec)


def load(name: str) -> Backend | None:
    """The backend called `name` (None for numpy). ValueError for an unknown name, `MbplanarError`
    naming the extra to install when its package is missing."""
    check(name)
    spec = BACKENDS[name]
    if spec is None:
        return None
    return importlib.import_module(spec[0]).BACKEND  # (numba itself is imported when first used)


def _missing(name: str, spec: tuple[str, str, str]) -> MbplanarError:
    _, package, extra = spec
    return MbplanarError(f"backend {name!r} needs {package}: pip install 'mbplanar[{extra}]'")


def dispatch(engine, job: str, reference: Callable, *args):
    """`job` ("kinematics", "kinetostatics") of the engine's compiled backend, or `reference` (the numpy
    implementation, same arguments) where there is none or it declines the batch."""
    compiled = engine.compiled
    if compiled is not None:
        answer = getattr(compiled, job)(engine, *args)
        if answer is not None:
            return answer
    return reference(engine, *args)
