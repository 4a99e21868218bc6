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
from ._motion import analyse

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
    """The kinematics of one position: input value(s) `phi` (SI: a number for one input, one value per
    input for several), speed `omega` and acceleration `epsilon` of the input(s) (default: the model's).

    Equal to ``analyse(engine, [phi], omega, epsilon)`` (its only row), bit for bit.

    Raises
    ------
    MotionError
        The position lies past a motion limit, or the drawn branch does not reach it.
    ModelError
        A value that is not finite, or a speed or acceleration out of range (as `analyse`).
    """
    n_in = len(engine.inputs)
    if phi.__class__ is float and n_in == 1:
        x = phi
    else:
        x = _inputs(engine, phi, n_in)
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
        reach = f" (the input moves within {inp.from_si(lo):.10g} … {inp.from_si(hi):.10g} {inp.unit})"
    return MotionError(f"cannot reach {where} on the drawn branch: {motion.message}{reach}", source=engine.mech.source)
