"""The backend seam: the one place that picks who computes a job, and says why.

numpy is the reference: every job (``"kinematics"``, ``"kinetostatics"``, ``"design"``,
``"simulation"``) has a numpy implementation, and a backend may take a request instead. As in networkx's
backend dispatch, a backend declares for each request whether it can take it (`Backend.can_run`: the
kind of problem) and whether it should (`Backend.should_run`: the size, what loading it costs), each
answering True or the reason why not; `dispatch` asks, runs the first backend that answers True to both,
and logs every answer at debug level on the ``mbplanar.backends`` logger::

    import logging; logging.basicConfig(); logging.getLogger("mbplanar.backends").setLevel(logging.DEBUG)

A backend is handed the request's tables and arrays (`engine._tables`, `forces._program`), never the engine; what a backend
writes becomes the result in the layer that made the request (its `finish`). A backend that finds a
position it cannot vouch for while it runs hands the whole request back (its `run` returns the reason),
and numpy computes it.

Which backends an engine asks: its own (`Engine(mech, backend="numba")`, loaded by name from `BACKENDS`)
and then the kernels run as plain Python (``"python"``, needs nothing: one position costs less there
than numpy's batch machinery). This module sits in the engine layer because the functions that
dispatch (kinematics, forces, study) sit below `backends`; the implementations are loaded by name, as
networkx loads its backends from entry points.
"""

from __future__ import annotations

import importlib
import importlib.util
import logging
from typing import TYPE_CHECKING, Callable, Protocol

from ..errors import MbplanarError

if TYPE_CHECKING:
    from ._solver import Engine

__all__ = ["Backend", "BACKENDS", "JOBS", "check", "load", "dispatch", "candidates", "planned"]

log = logging.getLogger("mbplanar.backends")

#: the jobs a backend may take
JOBS = ("kinematics", "kinetostatics", "design", "simulation")


class Backend(Protocol):
    """An implementation of some jobs. Tables a backend keeps for an engine live in the request's
    ``store`` (the engine's `Engine.prepared`), never on the backend."""

    name: str

    def can_run(self, job: str, request) -> bool | str:
        """True when the backend can compute `request` (a job's request record), else why not; a str
        request is the reason its layer could not write one for the kernels (several inputs, higher
        pairs, ...), which a backend of kernels answers as its own."""

    def should_run(self, job: str, size: int) -> bool | str:
        """True when computing a request of `size` (positions, or designs × positions) here beats the
        next choice, else why not."""

    def run(self, job: str, request):
        """The answer to `request` (what the job's `finish` turns into the result), or a str: why the
        backend handed it back while it ran."""


#: name → (where the backend is: "module:attribute", as an entry point names an object, or a module
#: defining ``BACKEND``; the package it needs or None; the extra that installs it); an engine's `backend`
#: names one of them ("numpy": the kernels as plain Python, besides the reference). mbplanar's own are
#: public names of `mbplanar.backends`, loaded on first access.
BACKENDS: dict[str, tuple[str, str | None, str | None]] = {
    "numpy": ("mbplanar.backends:PYTHON", None, None),
    "numba": ("mbplanar.backends:NUMBA", "numba", "fast"),
}


def check(name: str) -> None:
    """Refuse what `load` would refuse, without importing the backend's package (numba takes ~0.4 s):
    ValueError for an unknown name, `MbplanarError` naming the extra to install when the package is not
    installed."""
    if name not in BACKENDS:
        raise ValueError(f"backend must be one of {', '.join(BACKENDS)}, not {name!r}")
    spec = BACKENDS[name]
    if spec[1] is not None and importlib.util.find_spec(spec[1]) is None:
        raise _missing(name, spec)


def load(name: str) -> Backend:
    """The backend called `name`. ValueError for an unknown name, `MbplanarError` naming the extra to
    install when its package is missing."""
    check(name)
    module, _, attribute = BACKENDS[name][0].partition(":")
    return getattr(importlib.import_module(module), attribute or "BACKEND")  # (numba: imported when first used)


def _missing(name: str, spec) -> MbplanarError:
    _, package, extra = spec
    return MbplanarError(f"backend {name!r} needs {package}: pip install 'mbplanar[{extra}]'")


def candidates(engine: Engine) -> list:
    """The backends `dispatch` asks for an engine, in order: the engine's own (`Engine.backend`), then
    the kernels as plain Python (``"python"``) where the engine's is another."""
    found = engine.prepared.get("backends")
    if found is None:
        own = load(engine.backend)
        found = engine.prepared["backends"] = [own] if own.name == "python" else [own, load("numpy")]
    return found


def dispatch(engine: Engine, job: str, size: int, reference: Callable, request: Callable | None = None,
             finish: Callable | None = None):
    """`job` for a request of `size` computed by the first of the engine's backends (`candidates`) that
    can and should run it, else by `reference()` (numpy). `request()` makes the request the backends are
    handed (made once, when a backend is willing; a str: why the kernels cannot take it, for the backends'
    `can_run` to answer); ``finish(request, answer)`` makes the result of a
    backend's answer. Every backend's verdict is logged at debug level."""
    made = None
    for backend in candidates(engine):
        verdict = backend.should_run(job, size)
        if verdict is True:
            if made is None:
                made = request() if request is not None else None
            verdict = backend.can_run(job, made)
        if verdict is True:
            answer = backend.run(job, made)
            if not isinstance(answer, str):
                log.debug("%s of %d: %s", job, size, backend.name)
                return finish(made, answer) if finish is not None else answer
            verdict = answer
        _declined(job, size, backend.name, verdict)
    log.debug("%s of %d: numpy", job, size)
    return reference()


def _declined(job: str, size: int, name: str, why: str) -> None:
    if log.isEnabledFor(logging.DEBUG):
        log.debug("%s of %d: %s declines: %s", job, size, name, why)


class planned:
    """``with planned(positions):`` the work a process plans (the command line: one command per process),
    for a backend's `should_run` to weigh what loading it costs against what it saves (numba's own start
    is ~0.8 s of CPU); outside, a long-lived process is assumed (None: loading pays)."""

    positions: int | None = None

    def __init__(self, positions: int | None):
        self.value = None if positions is None else int(positions)

    def __enter__(self):
        self.before, planned.positions = planned.positions, self.value
        return self

    def __exit__(self, *exc):
        planned.positions = self.before
