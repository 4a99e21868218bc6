"""One position: `position(engine, phi, omega, epsilon)` → `Position`, the kinematics of a single input
value without a batch axis (for the `solve` command, an API caller's loop, the inner loop of a synthesis).

It is `analyse` of a batch of one, its only row: the same seam picks who solves it (the compiled kernel
on an engine with ``backend="numba"``, the same kernel as plain Python on numpy, numpy's batch for what
a kernel cannot vouch for), and the answer is that row's, bit for bit. What it adds: the batch axis taken
off, and a `MotionError` where the position is not reached.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from ..errors import ModelError, MotionError
from ._motion import MAX_EPSILON, MAX_OMEGA, analyse, one_position

__all__ = ["Position", "position", "ANALOGUES"]

#: the analogues (d/dφ, d²/dφ²): one input only; None with several
ANALOGUES = ("wq", "eq", "vq", "aq", "rate_q", "accel_q")


@dataclass(frozen=True, eq=False, repr=False)
class Position:
    """Kinematics of one position (SI), with the names and indices of `Motion` but no batch axis.

    Attributes
    ----------
    phi, omega, epsilon : ndarray (n_in,)
        Input value, speed and acceleration.
    angle, w, e : ndarray (L,)
        Each link's angle (rad), angular velocity and acceleration.
    ic : ndarray (L, 2)
        Instantaneous centres (m; NaN for a link that does not turn).
    xy, v, a : ndarray (P, 2)
        Each point's position, velocity and acceleration.
    value, rate, accel : ndarray (J,)
        Each joint's value, rate and acceleration.
    wq, eq : ndarray (L,) or None
        Angular velocity and acceleration analogues (one input; None with several).
    vq, aq : ndarray (P, 2) or None
        The points' velocity and acceleration analogues (one input).
    rate_q, accel_q : ndarray (J,) or None
        The joints' rate and acceleration analogues (one input).
    link_names, point_names, joint_names : list of str
        The order of the arrays' axes.
    success : bool
        Always True: a position that cannot be reached raises `MotionError` instead.
    message : str
        "solved".
    model : Mechanism
        The (assembled) model this is a position of (`Motion.model`).

    Examples
    --------
    >>> import numpy as np
    >>> import mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> p = mbplanar.position(engine, np.radians(90.0))
    >>> p.xy[p.point("A")].round(6)                    # the crank's end, m
    array([0. , 0.1])
    """

    phi: np.ndarray
    omega: np.ndarray
    epsilon: np.ndarray
    angle: np.ndarray
    w: np.ndarray
    e: np.ndarray
    ic: np.ndarray
    xy: np.ndarray
    v: np.ndarray
    a: np.ndarray
    value: np.ndarray
    rate: np.ndarray
    accel: np.ndarray
    wq: np.ndarray | None
    eq: np.ndarray | None
    vq: np.ndarray | None
    aq: np.ndarray | None
    rate_q: np.ndarray | None
    accel_q: np.ndarray | None
    link_names: list
    point_names: list
    joint_names: list
    success: bool = True
    message: str = "solved"
    model: object = None

    def point(self, name: str) -> int:
        return self.point_names.index(name)

    def link(self, name: str) -> int:
        return self.link_names.index(name)

    def joint(self, name: str) -> int:
        return self.joint_names.index(name)

    def __repr__(self) -> str:
        return (f"Position(phi={self.phi.tolist()}, omega={self.omega.tolist()}, epsilon={self.epsilon.tolist()}, "
                f"{len(self.link_names)} links, {len(self.point_names)} points)")


_ROWS = tuple(f.name for f in fields(Position) if f.name not in ("link_names", "point_names", "joint_names",
                                                                   "success", "message", "model"))
_new = object.__new__


def position(engine, phi, omega=None, epsilon=None) -> Position:
    """The kinematics of one position: `analyse` of a batch of one, without the batch axis.

    Equal to ``analyse(engine, [phi], omega, epsilon)`` (its only row), bit for bit.

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
    n_in = len(engine.inputs)
    if phi.__class__ is float and n_in == 1:
        x = phi
    else:
        x = _inputs(engine, phi, n_in)
        if n_in == 1:
            x = float(x[0, 0])
    if n_in == 1 and x - x == 0.0 and (omega is None or omega.__class__ is float and abs(omega) <= MAX_OMEGA) \
            and (epsilon is None or epsilon.__class__ is float and abs(epsilon) <= MAX_EPSILON):
        got = one_position(engine, x, omega, epsilon, lambda: _reference(engine, x, omega, epsilon))
    else:
        got = _reference(engine, x, omega, epsilon)
    if got.__class__ is Position:
        return got
    out = _new(Position)
    state = out.__dict__
    for name in _RECORD:
        state[name] = got[name]
    named = engine.prepared.get("position names")
    if named is None:
        names = engine.prepared["sweep tables"].names
        named = engine.prepared["position names"] = dict(
            link_names=names["link_names"], point_names=list(engine.prepared["every point"].names),
            joint_names=names["joint_names"], success=True, message="solved", model=engine.mech)
    state.update(named)
    return out


#: the fields of `Position` that are fields of the kernel's one-position record (`one_position`)
_RECORD = ("phi", "omega", "epsilon", "angle", "w", "e", "ic", "xy", "v", "a", "value", "rate", "accel", "wq", "eq",
           "vq", "aq", "rate_q", "accel_q")


def _reference(engine, x, omega, epsilon) -> Position:
    """`position` of the row of `analyse` of a batch of one (where no kernel takes it)."""
    motion = analyse(engine, x, omega, epsilon)
    if not motion.success:
        raise unreachable(engine, np.atleast_1d(np.asarray(x, float)).reshape(-1), motion)
    get = motion.__dict__
    out = _new(Position)
    state = out.__dict__
    for name in _ROWS:
        value = get[name]
        state[name] = None if value is None else value[0]
    state.update(link_names=motion.link_names, point_names=motion.point_names, joint_names=motion.joint_names,
                 success=True, message="solved", model=motion.model)
    return out


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
