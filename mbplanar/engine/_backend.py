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
    ``store`` (the engine's `Engine.prepared`), never on the backend.

    A backend has a `name` and answers three questions (each verdict True or the reason why not):
    `should_run` (does a request of this size pay here?), `can_run` (can it vouch for this request?),
    and `run` (the answer, or the reason it handed the request back while running). mbplanar's own are
    loaded by name (`BACKENDS`, `load`); any object with these members is one.

    Examples
    --------
    >>> from mbplanar.engine import load
    >>> python = load("numpy")                   # the kernels as plain Python, beside numpy's batch
    >>> python.name, python.should_run("kinematics", 1)
    ('python', True)
    >>> python.should_run("kinematics", 100)
    "100 positions: numpy's vectorised batch is faster from 2 on"
    >>> python.can_run("design", "the model has higher pairs")   # a layer's reason is answered as its own
    'the model has higher pairs'
    """

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
    """The backend called `name`, loaded on first use (numba itself is imported when first used).

    Parameters
    ----------
    name : str
        A key of `BACKENDS`: "numpy" (the kernels as plain Python, beside numpy's batch) or "numba".

    Returns
    -------
    Backend

    Raises
    ------
    ValueError
        An unknown name.
    MbplanarError
        Its package is not installed: the message names the extra to install.

    Examples
    --------
    >>> from mbplanar.engine import load
    >>> load("numpy").name
    'python'
    >>> load("cobol")
    Traceback (most recent call last):
    ValueError: backend must be one of numpy, numba, not 'cobol'
    """
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
    """Compute a job by the first of the engine's backends that can and should run it, else by numpy.

    Every backend's verdict is logged at debug level on the ``mbplanar.backends`` logger.

    Parameters
    ----------
    engine : Engine
        The engine whose backends are asked (`candidates`: its own, then the kernels as plain Python).
    job : str
        One of `JOBS`: "kinematics", "kinetostatics", "design", "simulation".
    size : int
        The request's size (positions, or designs × positions), for `Backend.should_run`.
    reference : callable
        ``reference()``: numpy's answer, the result itself.
    request : callable, optional
        ``request()``: the request the backends are handed, made once, when a backend is willing; a str
        says why the kernels cannot take it, for the backends' `can_run` to answer.
    finish : callable, optional
        ``finish(request, answer)``: the result of a backend's answer (default: the answer itself).

    Returns
    -------
    object
        The result, the same whoever computed it.

    Raises
    ------
    Whatever `reference`, `request` or `finish` raise; a backend's `MbplanarError` when its package is
    missing (`load`).

    Examples
    --------
    >>> import logging, sys
    >>> from mbplanar.engine import Engine, dispatch
    >>> from mbplanar.model import read_model
    >>> engine = Engine(read_model("models/fourbar.toml"))
    >>> log = logging.getLogger("mbplanar.backends")
    >>> handler = logging.StreamHandler(sys.stdout)
    >>> log.addHandler(handler); log.setLevel(logging.DEBUG)
    >>> dispatch(engine, "kinematics", 1, lambda: "numpy's answer", lambda: "no request in this example")
    kinematics of 1: python declines: no request in this example
    kinematics of 1: numpy
    "numpy's answer"
    >>> log.removeHandler(handler); log.setLevel(logging.NOTSET)
    """
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
    is ~0.8 s of CPU); outside, a long-lived process is assumed (None: loading pays).

    `planned.positions` is the number planned (None outside); the blocks nest, each restoring the one
    before it on exit.

    Examples
    --------
    >>> from mbplanar.engine import planned
    >>> with planned(3600):
    ...     planned.positions
    3600
    >>> planned.positions is None
    True
    """

    positions: int | None = None

    def __init__(self, positions: int | None):
        self.value = None if positions is None else int(positions)

    def __enter__(self):
        self.before, planned.positions = planned.positions, self.value
        return self

    def __exit__(self, *exc):
        planned.positions = self.before
