"""One position, lean: `position(engine, phi, omega, epsilon)` → `Position`, the kinematics of a single
input value without the batch machinery of `analyse` (for the `solve` command, an API caller's loop,
the inner loop of a synthesis).

The answer is `analyse`'s for a batch of one: the same atlas predicts the position (its quintic Hermite
interpolant), the same block Newton corrects it to the engine's `Tolerances`, and the rates come from
the same factorised Jacobians. What differs is the cost of a call. Everything a call needs is made once
per engine and kept there (``engine.prepare("position", ...)``): the layout of the answer, and on the
compiled backend a kernel with its tables and work arrays, so that a call is a few attribute lookups, one
kernel call and one small allocation (the answer's own buffer, so that an answer is never overwritten
by the next call).

A backend offers the lean path with a method ``single(engine)`` that returns a solver (a callable
``(phi, omega, epsilon) → Position``) or None; numpy, the reference, packs one row of `analyse`. Where a
compiled solver cannot vouch for a position (a change point's bracket, a step the corrector would have
to repair, several inputs) it hands it to the reference, so the answer is always `analyse`'s.

A position past a motion limit, or one the drawn branch does not reach, raises `MotionError`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError, MotionError
from ._motion import MAX_EPSILON, MAX_OMEGA, _checked_rate, _tables, analyse

__all__ = ["Position", "position", "Layout", "layout_of", "made", "FIELDS", "ANALOGUES", "ReferenceSolver",
           "PendingSolver"]

#: what a `Position` holds, in the order of its record: (name, per input / link / point / joint, components)
FIELDS = (("phi", "I", 1), ("omega", "I", 1), ("epsilon", "I", 1),
          ("angle", "L", 1), ("w", "L", 1), ("e", "L", 1), ("ic", "L", 2),
          ("xy", "P", 2), ("v", "P", 2), ("a", "P", 2),
          ("value", "J", 1), ("rate", "J", 1), ("accel", "J", 1),
          ("wq", "L", 1), ("eq", "L", 1), ("vq", "P", 2), ("aq", "P", 2), ("rate_q", "J", 1), ("accel_q", "J", 1))
#: the analogues (d/dφ, d²/dφ²): one input only; None with several
ANALOGUES = ("wq", "eq", "vq", "aq", "rate_q", "accel_q")


@dataclass(frozen=True)
class Layout:
    """What the positions of one engine look like: the names (the indices of `Motion`), the record's dtype
    (`FIELDS`) and each field's offset in float64 units (for a kernel that writes the flat buffer)."""

    engine: object
    link_names: list
    point_names: list
    joint_names: list
    dtype: np.dtype
    offsets: dict
    analogues: bool

    @property
    def size(self) -> int:
        """float64 numbers in one record."""
        return self.dtype.itemsize // 8


def layout_of(engine) -> Layout:
    """The engine's `Layout`, made on first use and kept."""
    return engine.prepare("position layout", lambda: _make_layout(engine))


def _make_layout(engine) -> Layout:
    (point_names, _, _), _ = _tables(engine)
    count = {"I": len(engine.inputs), "L": len(engine.links), "P": len(point_names), "J": len(engine.mech.joints)}
    dtype = np.dtype([(name, float, (count[kind], comp) if comp > 1 else (count[kind],))
                      for name, kind, comp in FIELDS])
    return Layout(engine, list(engine.links), list(point_names), list(engine.mech.joints), dtype,
                  {name: dtype.fields[name][1] // 8 for name, _, _ in FIELDS}, len(engine.inputs) == 1)


def _field(name: str, analogue: bool):
    def get(self):
        if analogue and not self.layout.analogues:
            return None
        return self.record[name]
    return property(get)


@dataclass(frozen=True, repr=False)
class Position:
    """Kinematics of one position (SI), with the names and indices of `Motion` but no batch axis.

    Inputs: phi, omega, epsilon (n_in,): input value, speed and acceleration. Links: angle, w, e (L,);
    ic (L, 2) instantaneous centres (NaN for a link that does not turn). Points: xy, v, a (P, 2).
    Joints: value, rate, accel (J,). Analogues (one input; None with several): wq, eq (L,), vq, aq
    (P, 2), rate_q, accel_q (J,). Every array is a view of `record`, this position's own buffer.

    Examples
    --------
    >>> import numpy as np
    >>> import mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> p = mbplanar.position(engine, np.radians(90.0))
    >>> p.xy[p.point("A")].round(6)                    # the crank's end, m
    array([0. , 0.1])
    """

    record: np.ndarray  # 0-d structured array (`FIELDS`)
    layout: Layout

    success = True       # as `Motion.success`: a position that cannot be solved raises MotionError instead
    message = "solved"

    phi = _field("phi", False)
    omega = _field("omega", False)
    epsilon = _field("epsilon", False)
    angle = _field("angle", False)
    w = _field("w", False)
    e = _field("e", False)
    ic = _field("ic", False)
    xy = _field("xy", False)
    v = _field("v", False)
    a = _field("a", False)
    value = _field("value", False)
    rate = _field("rate", False)
    accel = _field("accel", False)
    wq = _field("wq", True)
    eq = _field("eq", True)
    vq = _field("vq", True)
    aq = _field("aq", True)
    rate_q = _field("rate_q", True)
    accel_q = _field("accel_q", True)

    @property
    def engine(self):
        return self.layout.engine

    @property
    def link_names(self) -> list:
        return self.layout.link_names

    @property
    def point_names(self) -> list:
        return self.layout.point_names

    @property
    def joint_names(self) -> list:
        return self.layout.joint_names

    def point(self, name: str) -> int:
        return self.layout.point_names.index(name)

    def __repr__(self) -> str:
        return (f"Position(phi={self.phi.tolist()}, omega={self.omega.tolist()}, epsilon={self.epsilon.tolist()}, "
                f"{len(self.link_names)} links, {len(self.point_names)} points)")

    def link(self, name: str) -> int:
        return self.layout.link_names.index(name)

    def joint(self, name: str) -> int:
        return self.layout.joint_names.index(name)


_new = object.__new__


def made(record: np.ndarray, layout: Layout) -> Position:
    """``Position(record, layout)`` without the frozen dataclass' ``__init__`` (two ``object.__setattr__``
    calls, half the cost of a compiled position's Python side): what a lean solver returns."""
    answer = _new(Position)
    state = answer.__dict__
    state["record"], state["layout"] = record, layout
    return answer


def position(engine, phi, omega=None, epsilon=None) -> Position:
    """The kinematics of one position, without the batch machinery.

    Equal to ``analyse(engine, [phi], omega, epsilon)`` (its only row) to rounding, and much cheaper per
    call on the compiled backend (``Engine(mech, backend="numba")``): no batch is built, the prediction
    comes from the engine's atlas and the work arrays are the engine's, so one engine serves one caller
    at a time.

    Parameters
    ----------
    engine : Engine
        The mechanism, compiled once.
    phi : float or sequence of float
        The input value (SI): a number for one input, one value per input for several.
    omega, epsilon : float or sequence of float, optional
        Speed and acceleration of the input(s) (default: the model's).

    Returns
    -------
    Position
        Positions, velocities, accelerations of every point (P, 2) and link (L,), for this position.

    Raises
    ------
    MotionError
        The position lies past a motion limit, or the drawn branch does not reach it.
    ModelError
        A value that is not finite, or a speed or acceleration out of range (as `analyse`).

    Examples
    --------
    >>> import numpy as np
    >>> import mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> p = mbplanar.position(engine, np.radians(30.0), omega=10.0)
    >>> p.xy[p.point("B")].round(4), p.w.round(4)      # B (m); the links' ω (rad/s)
    (array([0.3104, 0.2498]), array([ 0.    , 10.    , -3.9224, -1.1355]))
    """
    solver = engine.prepared.get("position")
    if solver is None:
        solver = engine.prepare("position", lambda: _make_solver(engine))
    return solver(phi, omega, epsilon)


def _make_solver(engine):
    """The compiled backend's lean solver where it offers one, else numpy's (`ReferenceSolver`)."""
    single = getattr(engine.compiled, "single", None)
    solver = single(engine) if single is not None else None
    return solver if solver is not None else ReferenceSolver(engine)


class PendingSolver:
    """A solver not made yet: what an engine's solver becomes when the engine is pickled (sent to another
    process), made again there on its first call (not while the engine is being unpickled, when its
    state may not be there yet)."""

    def __init__(self, engine):
        self.engine = engine

    def __call__(self, phi, omega=None, epsilon=None) -> Position:
        solver = self.engine.prepared["position"] = _make_solver(self.engine)
        return solver(phi, omega, epsilon)


class ReferenceSolver:
    """numpy's lean solver: one row of `analyse`, packed as a `Position`."""

    def __init__(self, engine):
        self.engine, self.layout = engine, layout_of(engine)

    def __reduce__(self):
        return PendingSolver, (self.engine,)

    def __call__(self, phi, omega=None, epsilon=None) -> Position:
        engine = self.engine
        return reference(engine, self.layout, _inputs(engine, phi, len(engine.inputs)), omega, epsilon)


def _inputs(engine, phi, n_in: int) -> np.ndarray:
    """phi as (1, n_in), or ModelError naming what is expected."""
    try:
        x = np.asarray(phi, float)
    except (TypeError, ValueError):
        x = None
    if x is None or x.size != n_in:
        names = ", ".join(i.name for i in engine.inputs)
        raise ModelError(f"position needs {n_in} input value(s) ({names}), got {phi!r}", source=engine.mech.source,
                         where="position")
    if not np.all(np.isfinite(x)):
        raise ModelError("the input values phi must be finite", source=engine.mech.source, where="position")
    return x.reshape(1, n_in)


def reference(engine, layout: Layout, phi: np.ndarray, omega, epsilon) -> Position:
    """The position phi (1, n_in) by `analyse`, as a `Position`; MotionError where it is not reached."""
    motion = analyse(engine, phi, omega, epsilon)
    if not motion.success:
        raise unreachable(engine, phi[0], motion)
    record = np.empty((), layout.dtype)
    for name, _, _ in FIELDS:
        if name in ANALOGUES and not layout.analogues:
            record[name] = np.nan
        else:
            record[name] = getattr(motion, name)[0]
    return made(record, layout)


def unreachable(engine, phi: np.ndarray, motion) -> MotionError:
    """The error of a position the drawn branch does not reach: where, why (`Motion.message`) and, for one
    input stopped by a motion limit, the range it moves through."""
    where = ", ".join(f"{i.name} = {i.from_si(float(p)):.10g} {i.unit}" for i, p in zip(engine.inputs, phi))
    reach = ""
    if len(engine.inputs) == 1 and motion.limits:
        inp = engine.inputs[0]
        lo, hi = engine.reach()
        from ._motion import reach_text
        reach = f" (the input moves within {reach_text(inp, lo, hi)})"
    return MotionError(f"cannot reach {where} on the drawn branch: {motion.message}{reach}", source=engine.mech.source)


def checked_speeds(engine, omega, epsilon) -> tuple[float, float]:
    """ω and ε of a one-input position as floats (default: the model's), or ModelError as `analyse`."""
    inp = engine.inputs[0]
    om = _number(engine, "omega", inp.omega if omega is None else omega)
    ep = _number(engine, "epsilon", inp.epsilon if epsilon is None else epsilon)
    if not (abs(om) <= MAX_OMEGA and abs(ep) <= MAX_EPSILON):  # (also NaN)
        _checked_rate("omega", om, MAX_OMEGA, engine)
        _checked_rate("epsilon", ep, MAX_EPSILON, engine)
    return om, ep


def finite_input(engine, phi) -> float:
    """A one-input phi as a float, or ModelError."""
    x = _number(engine, "phi", phi)
    if not math.isfinite(x):
        raise ModelError("the input values phi must be finite", source=engine.mech.source, where="position")
    return x


def _number(engine, name: str, value) -> float:
    """A number, or an array holding one, as a float; ModelError otherwise."""
    try:
        return float(value)
    except (TypeError, ValueError):
        pass
    try:
        arr = np.asarray(value, float)
    except (TypeError, ValueError):
        arr = None
    if arr is None or arr.size != 1:
        raise ModelError(f"{name} of one position must be one number, got {value!r}", source=engine.mech.source,
                         where="position")
    return float(arr.reshape(()))
