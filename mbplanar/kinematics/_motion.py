"""Kinematic results for every link, joint and point: positions, analogues (d/dφ, d²/dφ²) and real
velocities and accelerations, instantaneous centres of velocity.

`analyse(engine, phi, omega, epsilon)` solves a batch and returns a `Motion`: a frozen record of arrays
with the batch first, in SI units (m, rad, s). Real values follow the analogues: v = v_q·ω,
a = a_q·ω² + v_q·ε. ``points=[...]`` asks for some points only, ``rates=False`` for positions only, and
``outputs=[...]`` for some arrays only; what a call did not compute is None.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass, field, fields, replace

import numpy as np

from ..errors import ModelError, did_you_mean
from ..engine import (Crossing, Engine, Limit, SweepIn, SweepJob, SweepOut, atlas_tables, dispatch, dot, far_span,
                      met_along, perp, record_layout, solve_positions, sweep_tables, world_frames)

__all__ = ["Motion", "Frames", "analyse", "positions_at_limits", "point_selection", "material_points", "point_table",
           "describe_limit", "describe_crossing", "range_text", "reach_text", "OUTPUTS"]

#: the arrays of a `Motion` a call may leave out (`analyse(..., outputs=)`); the others are always there
OUTPUTS = ("w", "e", "v", "a", "wq", "eq", "vq", "aq", "value", "rate", "accel", "rate_q", "accel_q", "ic", "frames")
#: the velocities and accelerations among them (``rates=False`` leaves them out)
RATE_OUTPUTS = ("w", "e", "v", "a", "wq", "eq", "vq", "aq", "rate", "accel", "rate_q", "accel_q", "ic")
#: the analogues (one input only: with several they are None)
ANALOGUE_OUTPUTS = ("wq", "eq", "vq", "aq", "rate_q", "accel_q")


@dataclass(frozen=True, eq=False, repr=False)
class Frames:
    """The link frames of a batch (B positions, L links in `Motion.link_names` order), SI.

    Attributes
    ----------
    th : ndarray (B, L)
        Each frame's angle (rad; the link's angle less its reference angle in the drawn pose).
    r : ndarray (B, L, 2)
        Each frame's origin (m).
    w, e : ndarray (B, L) or None
        Angular velocity and acceleration of each frame; None without rates.
    v, a : ndarray (B, L, 2) or None
        Velocity and acceleration of each frame's origin; None without rates.
    analogues : bool
        True: w, v, e, a are analogues (per unit input: rad/rad, m/rad, ...; one input); False: real
        (rad/s, m/s, ...; several inputs).
    contact : ndarray (B, H) or None
        The contact parameter of every higher pair (the model's `higher` order): where on its curve a
        cam's or a slot's contact is (0 for gears and racks, which have none); None without higher pairs.

    Examples
    --------
    The four-bar's crank (link 1) turns with the input: its frame's angle is the input less the drawn
    60°, its angular velocity analogue 1 rad/rad.

    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> frames = mbplanar.analyse(engine, np.radians([0.0, 90.0])).frames
    >>> frames.th.shape, frames.r.shape, frames.analogues
    ((2, 4), (2, 4, 2), True)
    >>> np.degrees(frames.th[:, 1]).round(6), frames.w[:, 1]
    (array([-60.,  30.]), array([1., 1.]))
    """

    th: np.ndarray
    r: np.ndarray
    w: np.ndarray | None = None
    v: np.ndarray | None = None
    e: np.ndarray | None = None
    a: np.ndarray | None = None
    analogues: bool = True
    contact: np.ndarray | None = None

    def __repr__(self) -> str:
        return "Frames(" + ", ".join(f"{f.name}={_shape(getattr(self, f.name))}" for f in fields(self)) + ")"


@dataclass(frozen=True, eq=False, repr=False)
class Motion:
    """Kinematics of a batch of B positions (only those reached on the drawn branch), SI, batch first.

    Made by `analyse`; nothing is computed when a field is read. An array a call did not compute is
    None: the velocities and accelerations without ``rates=True``, the analogues with several inputs,
    and whatever ``outputs=`` leaves out (default: every array).

    Attributes
    ----------
    phi, omega, epsilon : ndarray (B, n_in)
        Input values, speeds and accelerations (rad or m, /s, /s²).
    link_names, point_names, joint_names : list of str
        The links (L), the points asked for (P; `analyse(..., points=)`, default every joint and point)
        and the joints (J): the order of the arrays' axes.
    angle : ndarray (B, L)
        Each link's angle (rad, the direction of its reference line).
    xy : ndarray (B, P, 2)
        Each point's position (m).
    w, e : ndarray (B, L) or None
        Angular velocity and acceleration (rad/s, rad/s²); ``rates=True``, output "w" or "e".
    v, a : ndarray (B, P, 2) or None
        Velocity and acceleration of each point (m/s, m/s²); ``rates=True``, output "v" or "a".
    wq, eq : ndarray (B, L) or None
        Angular velocity and acceleration analogues (rad/rad, rad/rad²); one input, ``rates=True``.
    vq, aq : ndarray (B, P, 2) or None
        Velocity and acceleration analogues of each point (m/rad, m/rad²); one input, ``rates=True``.
    value : ndarray (B, J) or None
        Each joint's value: relative angle of a revolute joint (rad), displacement along the guide of
        a prismatic one (m); output "value".
    rate, accel : ndarray (B, J) or None
        Their rates and accelerations (rad/s or m/s, /s²); ``rates=True``.
    rate_q, accel_q : ndarray (B, J) or None
        Their analogues; one input, ``rates=True``.
    ic : ndarray (B, L, 2) or None
        Each link's instantaneous centre of velocity (m; NaN where the link does not turn);
        ``rates=True``, output "ic".
    frames : Frames or None
        The link frames (what the forces are computed from); output "frames".
    limits : list of Limit
        The motion limits the batch ran into (its rows past them are left out).
    crossings : list of Crossing
        The change points passed within the range asked.
    requested : int
        Positions asked for (B ≤ requested).
    success : bool
        Every position asked for was reached.
    message : str
        "solved", or why some were not.
    records : ndarray (B,) or None
        The compiled backend's per-position records (structured: the frames and joints), of which
        `frames`, `value`, `wq`, `eq`, `rate_q`, `accel_q` are views; None from numpy.
    model : Mechanism
        The (assembled) model these are positions of: its names and units, for documents and pictures
        (`mbplanar.io.document`, `to_frame`).

    Examples
    --------
    >>> import numpy as np
    >>> import mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians([30.0, 120.0]), omega=10.0)
    >>> motion.point_names, motion.v[:, motion.point("A")].round(4)     # A on the crank: 0.1 m · 10 rad/s
    (['O', 'A', 'B', 'C', 'M'], array([[-0.5  ,  0.866],
           [-0.866, -0.5  ]]))
    """

    phi: np.ndarray
    omega: np.ndarray
    epsilon: np.ndarray
    link_names: list
    point_names: list
    joint_names: list
    angle: np.ndarray
    xy: np.ndarray
    w: np.ndarray | None = None
    e: np.ndarray | None = None
    v: np.ndarray | None = None
    a: np.ndarray | None = None
    wq: np.ndarray | None = None
    eq: np.ndarray | None = None
    vq: np.ndarray | None = None
    aq: np.ndarray | None = None
    value: np.ndarray | None = None
    rate: np.ndarray | None = None
    accel: np.ndarray | None = None
    rate_q: np.ndarray | None = None
    accel_q: np.ndarray | None = None
    ic: np.ndarray | None = None
    frames: Frames | None = None
    limits: list = field(default_factory=list)
    crossings: list = field(default_factory=list)
    requested: int = 0
    success: bool = True
    message: str = "solved"
    records: np.ndarray | None = None
    model: object = None

    def __repr__(self) -> str:
        shown = ", ".join(f"{f.name}={_shape(getattr(self, f.name))}" for f in fields(self)
                          if f.name not in ("records", "frames", "model"))
        return f"Motion({shown})"

    def point(self, name: str) -> int:
        """Index of the joint or point `name` in `point_names`; `KeyError` naming the points this motion
        holds when it was not asked for (`analyse(..., points=)`)."""
        try:
            return self.point_names.index(name)
        except ValueError:
            raise KeyError(f"this motion holds the points {', '.join(self.point_names) or '(none)'}, not {name!r}: "
                           "ask analyse(..., points=None) for every point") from None

    def link(self, name: str) -> int:
        return self.link_names.index(name)

    def joint(self, name: str) -> int:
        return self.joint_names.index(name)

    def to_frame(self):
        """A pandas DataFrame of the positions, one row each, with the columns of `mbplanar sweep`
        (``phi[deg]``, ``3.angle[deg]``, ``B.vx[m/s]``, ...). Needs pandas (``pip install mbplanar[pandas]``)."""
        from ..model import view
        return view("frame", self)

    def _repr_html_(self) -> str:
        from ..model import view
        return view("html", self)


def _shape(value) -> str:
    return f"array{value.shape}" if isinstance(value, np.ndarray) else repr(value)


_MOTION_FIELDS = tuple(f.name for f in fields(Motion))
_new = object.__new__


def _record(cls, values: dict):
    """``cls(**values)`` of a frozen record without its ``__init__`` (one ``object.__setattr__`` per
    field): `values` holds every field."""
    out = _new(cls)
    out.__dict__.update(values)
    return out


def _message(engine: Engine, requested: int, reached: int, limits: list) -> str:
    """`Motion.message`: "solved", or why positions were left out."""
    if reached == requested:
        return "solved"
    return "; ".join(describe_limit(engine, lim) for lim in limits) or \
        f"{requested - reached} position(s) could not be solved on the drawn branch"


def describe_limit(engine: Engine, lim: Limit) -> str:
    """The sentence that names a motion limit: where (each input in its model unit), which way it is met,
    the links in line and how.

    Parameters
    ----------
    engine : Engine
        The mechanism the limit belongs to (its inputs' names and units).
    lim : Limit
        A motion limit, from `Motion.limits` or `Engine.solve_limits`.

    Returns
    -------
    str
        "motion limit at t = 1.799912417 rad (going up): links 3, 4 — stretched at B (C, B, D in line)";
        "motion limit" for a mechanism without inputs.

    Raises
    ------
    AttributeError
        `lim` is not a `Limit` (no `phi`, `direction`, `links` or `kind`).

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> from mbplanar.kinematics import describe_limit
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/crank_slider_rocker_locking.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians(np.arange(0.0, 360.0, 10.0)))
    >>> print(describe_limit(engine, motion.limits[0]))
    motion limit at t = 1.799912417 rad (going up): links 3, 4 — stretched at B (C, B, D in line)
    """
    inp = engine.inputs[0]
    where = ", ".join(f"{i.name} = {i.from_si(p):.10g} {i.unit}" for i, p in zip(engine.inputs, lim.phi))
    way = {1: "going up", -1: "going down"}.get(lim.direction, "")
    return (f"motion limit at {where} ({way}): links {', '.join(lim.links)} — {lim.kind}"
            if inp else "motion limit")


def range_text(lo: float, hi: float, digits: int = 10) -> str:
    """'a … b': the range lo … hi an input moves through between motion limits (in any unit), with
    `digits` significant digits, each end rounded towards the inside and at least 1e-9 of the range from
    its limit, so that the values shown can be asked for: the engine resolves a position down to ~3e-10
    of a turn from a fold, and an end rounded to the nearest digit may lie beyond it.

    Parameters
    ----------
    lo, hi : float
        The range's ends, lo < hi, in the unit to show.
    digits : int
        Significant digits of each end.

    Returns
    -------
    str
        The two ends joined by " … ".

    Raises
    ------
    Nothing for finite floats; a non-finite end gives "nan" or "inf" in the text.

    Examples
    --------
    >>> range_text(-0.8083147211001106, 1.7999124165244385)
    '-0.8083147184 … 1.799912413'
    """
    margin = 1e-9 * (hi - lo)
    ends = []
    for x, inward in ((lo + margin, 1.0), (hi - margin, -1.0)):
        shown = float(f"{x:.{digits}g}")
        if (shown - x) * inward < 0:  # rounded outwards: one unit of the last digit back in
            step = 10.0 ** (np.floor(np.log10(abs(x))) - digits + 1) if x else 10.0 ** -digits
            shown = float(f"{shown + inward * step:.{digits}g}")
        ends.append(f"{shown:.{digits}g}")
    return " … ".join(ends)


def reach_text(inp, lo: float, hi: float, digits: int = 10) -> str:
    """`range_text` of an input's range lo … hi (SI), in its unit, with the unit.

    Parameters
    ----------
    inp : Input
        The input (`Engine.inputs`): its `from_si` and `unit`.
    lo, hi : float
        The range's ends (SI: rad or m), lo < hi.
    digits : int
        Significant digits of each end.

    Returns
    -------
    str
        "a … b unit", each end rounded inwards as `range_text` does.

    Raises
    ------
    AttributeError
        `inp` is not an `Input`.

    Examples
    --------
    >>> import math, mbplanar
    >>> from mbplanar.kinematics import reach_text
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> reach_text(engine.inputs[0], -math.pi / 2, math.pi / 3, digits=6)
    '-89.9999 … 59.9999 deg'
    """
    return f"{range_text(inp.from_si(lo), inp.from_si(hi), digits)} {inp.unit}"


def describe_crossing(engine: Engine, c: Crossing) -> str:
    """The sentence that names a change point: where (each input in its model unit), the links in line
    and how, and what that means for a real mechanism.

    Parameters
    ----------
    engine : Engine
        The mechanism the change point belongs to (its inputs' names and units).
    c : Crossing
        A change point, from `Motion.crossings`.

    Returns
    -------
    str
        The sentence ``mbplanar solve`` and ``mbplanar check`` print.

    Raises
    ------
    AttributeError
        `c` is not a `Crossing`.

    Examples
    --------
    A parallelogram four-bar: every link lines up with the ground when the crank reaches 180°.

    >>> import numpy as np, mbplanar
    >>> from mbplanar.kinematics import describe_crossing
    >>> m = mbplanar.Mechanism("parallelogram")
    >>> links = [m.add_link(name) for name in "123"]
    >>> joints = [m.add_joint(n, "R", a, b, at=xy) for n, a, b, xy in (
    ...     ("O", "0", "1", (0, 0)), ("A", "1", "2", (0, 1)), ("B", "2", "3", (2, 1)), ("C", "3", "0", (2, 0)))]
    >>> driver = m.add_input("O", unit="deg")
    >>> engine = mbplanar.Engine(m)
    >>> motion = mbplanar.analyse(engine, np.radians([90.0, 150.0, 200.0]))
    >>> print(describe_crossing(engine, motion.crossings[0]))  # doctest: +NORMALIZE_WHITESPACE
    change point at phi = 180 deg: links 2, 3 — stretched at B (A, B, C in line); two assembly branches
    cross here: the analysis follows the smooth branch, a real mechanism may switch branch unless
    something guides it through
    """
    where = ", ".join(f"{i.name} = {i.from_si(p):.10g} {i.unit}" for i, p in zip(engine.inputs, c.phi))
    return (f"change point at {where}: links {', '.join(c.links)} — {c.kind}; two assembly branches cross "
            "here: the analysis follows the smooth branch, a real mechanism may switch branch unless "
            "something guides it through")



def _point_table(engine: Engine):
    """(names, link index, drawn coordinates) of every joint (its slider point for P), higher pair (a
    gear's pitch point, a point of its carrier; a cam's follower point; a slot's pin) and point."""
    mech = engine.mech
    names, links, at = [], [], []
    for j in mech.joints.values():
        names.append(j.name)
        links.append(engine.link_index[j.slider if j.kind == "P" else j.links[0]])
        at.append(j.at)
    for h in mech.higher.values():
        law = engine.laws[h.name]
        if h.kind == "gear":
            names.append(h.name)
            links.append(engine.link_index[law.carrier])
            at.append(law.geometry.pitch)
        elif h.kind in ("cam", "slot"):
            names.append(h.name)
            links.append(engine.link_index[h.links[1]])
            at.append(h.at)
    for p in mech.points.values():
        names.append(p.name)
        links.append(engine.link_index[p.link])
        at.append(p.at)
    return names, np.array(links, int), np.array(at, float).reshape(-1, 2)


@dataclass
class _JointTable:
    """Index maps of the joints, built once per engine: revolute columns `r_col` with their links
    (`r_a`, `r_b`), prismatic columns `p_col` with carrier `p_c`, slider `p_s`, point `p_at` (Pp, 2,
    drawn, in the engine's frame: minus `Engine.centre`) and guide direction `p_u0` (Pp, 2); `drawn`
    (J,) joint values in the drawn pose."""

    r_col: np.ndarray
    r_a: np.ndarray
    r_b: np.ndarray
    p_col: np.ndarray
    p_c: np.ndarray
    p_s: np.ndarray
    p_at: np.ndarray
    p_u0: np.ndarray
    drawn: np.ndarray


def _joint_table(engine: Engine) -> _JointTable:
    joints = list(engine.mech.joints.values())
    rev = [(k, j) for k, j in enumerate(joints) if j.kind == "R"]
    pri = [(k, j) for k, j in enumerate(joints) if j.kind == "P"]
    idx = engine.link_index
    ints = lambda xs: np.array(xs, int)  # noqa: E731
    return _JointTable(
        r_col=ints([k for k, _ in rev]), r_a=ints([idx[j.links[0]] for _, j in rev]),
        r_b=ints([idx[j.links[1]] for _, j in rev]),
        p_col=ints([k for k, _ in pri]), p_c=ints([idx[j.links[0]] for _, j in pri]),
        p_s=ints([idx[j.links[1]] for _, j in pri]),
        p_at=np.array([j.at for _, j in pri], float).reshape(-1, 2) - engine.centre,  # (the engine's frame)
        p_u0=np.array([engine.laws[j.name].u0 for _, j in pri], float).reshape(-1, 2),
        drawn=np.array([engine.joint_value_drawn[j.name] for j in joints]))


def _tables(engine: Engine):
    """Point and joint tables of an engine, computed on first use and kept on the engine."""
    return engine.prepare("output tables", lambda: (_point_table(engine), _joint_table(engine)))


def point_table(engine: Engine) -> tuple[list, np.ndarray, np.ndarray]:
    """The points a `Motion` reports, in its `point_names` order: every joint (a prismatic pair's slider
    point), every higher pair's point (a gear's pitch point on its carrier, a cam's follower point, a
    slot's pin) and every named point, each with the link it moves with and where it is drawn. Made once
    per engine and kept on it.

    Parameters
    ----------
    engine : Engine
        The mechanism.

    Returns
    -------
    names : list of str
        The P points' names.
    links : ndarray, shape (P,), int
        The index (`Engine.link_index`) of the link each point moves with.
    at : ndarray, shape (P, 2)
        Where each point is drawn (m, the model's world frame).

    Raises
    ------
    Nothing for an `Engine`.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.kinematics import point_table
    >>> names, links, at = point_table(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")))
    >>> names, links, at[1].round(8)
    (['O', 'A', 'B', 'C', 'M'], array([0, 1, 2, 3, 2]), array([0.05      , 0.08660254]))
    """
    return _tables(engine)[0]


@dataclass(frozen=True)
class PointSelection:
    """The points a caller asked for: `names` (P,), each on link `links` (P,) drawn at `at` (P, 2)."""

    names: list
    links: np.ndarray
    at: np.ndarray


def point_selection(engine: Engine, points=None) -> PointSelection:
    """The points `points` (names, in the order given; None: every joint and point of the model).
    `ModelError` for a name the model does not have, or one asked twice."""
    if points is None:
        found = engine.prepared.get("every point")
        if found is not None:
            return found
    names, links, at = point_table(engine)
    if points is None:
        return engine.prepare("every point", lambda: PointSelection(list(names), links, at))
    if isinstance(points, str):
        points = [points]
    asked = list(points)
    index = {n: k for k, n in enumerate(names)}
    for k, name in enumerate(asked):
        if name not in index:
            raise ModelError(f"analyse: points: no joint or point named {name!r}; "
                             f"{did_you_mean(name, names, 'joints and points')}", source=engine.mech.source,
                             where="analyse")
        if name in asked[:k]:
            raise ModelError(f"analyse: points: {name!r} is asked twice", source=engine.mech.source,
                             where="analyse")
    rows = np.array([index[n] for n in asked], int)
    return PointSelection(asked, links[rows], at[rows].reshape(-1, 2))


def _rotated(c, s, at):
    """R(θ)·at for cos, sin (P, B) and drawn vectors at (P, 2) → (2, P, B)."""
    out = np.empty((2,) + c.shape)
    out[0] = c * at[:, 0, None] - s * at[:, 1, None]
    out[1] = s * at[:, 0, None] + c * at[:, 1, None]
    return out


def _placed_points(c, s, r, links, at):
    """Positions (2, P, B) of points drawn at `at` (P, 2) on links `links` (P,), from the links' cos,
    sin (L, B) and frame origins r (2, L, B)."""
    return r.take(links, 1) + _rotated(c.take(links, 0), s.take(links, 0), at)


def _moving_points(c, s, r, w, v, e, a, links, at, position=True):
    """Position (if asked), velocity and acceleration (2, P, B) of points drawn at `at` (P, 2) on links
    `links` (P,), from the links' cos, sin, w, e (L, B) and frame states r, v, a (2, L, B)."""
    rho = _rotated(c.take(links, 0), s.take(links, 0), at)
    wl, el = w.take(links, 0), e.take(links, 0)
    w2 = wl * wl
    # v + ω·perp(ρ) and a + ε·perp(ρ) − ω²ρ written per component (perp(ρ) = (−ρy, ρx)): the same
    # floating-point operations without the temporaries
    vel, acc = v.take(links, 1), a.take(links, 1)
    vel[0] -= wl * rho[1]
    vel[1] += wl * rho[0]
    acc[0] -= el * rho[1]
    acc[1] += el * rho[0]
    acc[0] -= w2 * rho[0]
    acc[1] -= w2 * rho[1]
    return (r.take(links, 1) + rho if position else None), vel, acc


def material_points(th, r, w, v, e, a, links, at):
    """Position, velocity and acceleration of points carried by links: r + R(θ)·at, v + ω × ρ,
    a + ε × ρ − ω²·ρ with ρ = R(θ)·at, from the link frames of a batch (`Motion.frames`).

    Parameters
    ----------
    th : ndarray, shape (B, L)
        The frames' angles (rad).
    r : ndarray, shape (B, L, 2)
        The frames' origins (m).
    w, e : ndarray, shape (B, L)
        The frames' angular velocities and accelerations (rad/s, rad/s², or analogues per unit input).
    v, a : ndarray, shape (B, L, 2)
        The velocities and accelerations of the frames' origins (m/s, m/s², or analogues).
    links : ndarray, shape (P,), int
        The frame (link index) each point moves with.
    at : ndarray, shape (P, 2)
        Where each point is drawn (m, the model's world frame: a frame is the identity in the drawn pose).

    Returns
    -------
    xy, vel, acc : ndarray, shape (B, P, 2)
        The points' positions, velocities and accelerations (in the units of `r`, `v`, `a`).

    Raises
    ------
    IndexError
        A link index past the L frames.

    Examples
    --------
    The four-bar's crank tip A (0.1 m from the pivot O, drawn on link 1 at 60°) at crank angles 0° and
    90°; with one input the frames hold analogues, so the velocity is m/rad and the acceleration m/rad²:

    >>> import numpy as np, mbplanar
    >>> from mbplanar.kinematics import material_points
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> f = mbplanar.analyse(engine, np.radians([0.0, 90.0])).frames
    >>> drawn = 0.1 * np.array([[np.cos(np.pi / 3), np.sin(np.pi / 3)]])
    >>> xy, vel, acc = material_points(f.th, f.r, f.w, f.v, f.e, f.a, np.array([1]), drawn)
    >>> xy[:, 0].round(6) + 0.0, vel[:, 0].round(6) + 0.0, acc[:, 0].round(6) + 0.0
    (array([[0.1, 0. ],
           [0. , 0.1]]), array([[ 0. ,  0.1],
           [-0.1,  0. ]]), array([[-0.1,  0. ],
           [ 0. , -0.1]]))
    """
    out = _moving_points(np.cos(th.T), np.sin(th.T), _last(r), w.T, _last(v), e.T, _last(a), links, at)
    return tuple(_first(x) for x in out)


def _flip(x):
    """(B, L, 2) ↔ (2, L, B) view: batch first at the surface, batch last inside."""
    return x.transpose(2, 1, 0)


_last = _first = _flip  # named for where the batch axis goes


def _joint_values(table: _JointTable, th, c, s, r, w, v, e, a, value=True):
    """value (if asked), rate, accel (J, B) of every joint from the link states (batch last): relative
    angle of a revolute joint, displacement of the slider point along the guide for a prismatic joint.
    Without rates (w None) the value only, and None for the rates."""
    batch, n = th.shape[1], len(table.drawn)
    t = table
    if w is None:
        out_v = np.empty((n, batch))
        out_v[t.r_col] = th[t.r_b] - th[t.r_a] + t.drawn[t.r_col, None]
        if len(t.p_col):
            d = _placed_points(c, s, r, t.p_s, t.p_at) - _placed_points(c, s, r, t.p_c, t.p_at)
            out_v[t.p_col] = t.drawn[t.p_col, None] + dot(_rotated(c[t.p_c], s[t.p_c], t.p_u0), d)
        return out_v, None, None
    out_v, out_r, out_a = (np.empty((n, batch)) for _ in range(3))
    if len(t.r_col):
        if value:
            out_v[t.r_col] = th[t.r_b] - th[t.r_a] + t.drawn[t.r_col, None]
        out_r[t.r_col] = w[t.r_b] - w[t.r_a]
        out_a[t.r_col] = e[t.r_b] - e[t.r_a]
    if len(t.p_col):
        xs, vs, as_ = _moving_points(c, s, r, w, v, e, a, t.p_s, t.p_at)
        xc, vc, ac = _moving_points(c, s, r, w, v, e, a, t.p_c, t.p_at)
        d, dd, ddd = xs - xc, vs - vc, as_ - ac
        u = _rotated(c[t.p_c], s[t.p_c], t.p_u0)
        pu = perp(u)
        wc, ec = w[t.p_c], e[t.p_c]
        pu_d, u_d = dot(pu, d), dot(u, d)
        if value:
            out_v[t.p_col] = t.drawn[t.p_col, None] + u_d
        out_r[t.p_col] = wc * pu_d + dot(u, dd)
        out_a[t.p_col] = ec * pu_d - wc * wc * u_d + 2 * wc * dot(pu, dd) + dot(u, ddd)
    return out_v, out_r, out_a


def _link_states(engine: Engine, sol):
    """th, cos θ, sin θ (L, B) and r (2, L, B) of every link, in engine.links order, in the engine's
    frame (centred on `Engine.centre`; `world_frames` converts)."""
    names, pose = engine.links, sol.pose
    th, c, s = (np.empty((len(names), len(sol.phi))) for _ in range(3))
    r = np.empty((2,) + th.shape)
    for k, n in enumerate(names):  # row by row: cheaper than np.stack for a small batch
        th[k], c[k], s[k], r[:, k] = pose.th[n], pose.c[n], pose.s[n], pose.r[n]
    return th, c, s, r


def _contact_parameters(engine: Engine, sol) -> np.ndarray:
    """The contact parameter of every higher pair (B, H) (engine.mech.higher order; 0 for gears and
    racks, which have none): where on its curve a cam's or a slot's contact is."""
    names = list(engine.mech.higher)
    out = np.zeros((len(sol.phi), len(names)))
    for bp, state in zip(engine.blocks, sol.blocks):
        for law, k in bp.params:
            out[:, names.index(law.name)] = state.q[k]
    return out


def _real(xq, xqq, om, ep):
    """Real rate and acceleration from the analogues: x' = x_q ω, x'' = x_qq ω² + x_q ε.
    om (B,) broadcasts against xq (batch axis last); ep (B,), or None for a constant input speed."""
    if ep is None:
        return xq * om, xqq * (om * om)
    return xq * om, xqq * (om * om) + xq * ep


def _instant_centres(r, v, w):
    """Instantaneous centre (2, L, B) of every link: r + perp(v)/ω; NaN where ω = 0 (translation)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        ic = r + perp(v) / w
    ic[~np.isfinite(ic)] = np.nan
    return ic


def _per_position(value, default, batch, n_in):
    """A scalar, one value per input, or one per position → (B, n_in)."""
    if value is None:
        value = default[0] if len(default) == 1 else default
    if isinstance(value, (int, float)) or np.ndim(value) == 0:  # one value for all (the usual case): filled
        return np.full((batch, n_in), float(value))
    arr = np.asarray(value, float)
    if arr.ndim == 1 and n_in == 1:
        arr = arr[:, None]
    return np.broadcast_to(arr, (batch, n_in))


CHUNK = 25_000  # positions solved at once by numpy: bounds the working memory of very long sweeps


def analyse(engine: Engine, phi, omega=None, epsilon=None, *, points=None, rates: bool = True,
            outputs=None) -> Motion:
    """Solve `phi` and return the kinematics of the positions reached (rows past a motion limit, which
    hold no solution, are dropped before anything is returned).

    Who computes it is the backend seam's choice (`engine._backend.dispatch`): the engine's compiled
    backend where it can vouch for the batch, the kernels as plain Python for one position, numpy (the
    reference) otherwise; the answers agree to rounding.

    Parameters
    ----------
    engine : Engine
        The mechanism, compiled once.
    phi : array_like
        Input values (SI: rad, or m for a slider): (B,) for one input, (B, n_in) for several.
    omega, epsilon : float or array_like, optional
        Input speed and acceleration, one value or one per position (default: the model's).
    points : list of str, optional
        The joints and points whose positions (and rates) to compute, in this order
        (`Motion.point_names`); default every joint and point. Points not asked for cost nothing.
    rates : bool
        False: positions only (link angles, points, joint values, frames); every velocity and
        acceleration array of the `Motion` is None.
    outputs : collection of str, optional
        The arrays to compute among `OUTPUTS` ("w", "e", "v", "a", "wq", "eq", "vq", "aq", "value",
        "rate", "accel", "rate_q", "accel_q", "ic", "frames"); default every one (``rates`` and the
        number of inputs allowing). The others are None. The link angles and the points' positions are
        always computed. `kinetostatics` needs "frames".

    Returns
    -------
    Motion
        Batch first: link angles (B, L), points' positions, velocities, accelerations (B, P, 2), ...

    Raises
    ------
    ModelError
        Input values that are not finite, a point the model does not have, an unknown output name, a
        speed `omega` or acceleration `epsilon` that is not finite or beyond ``|ω| ≤ 1e100``,
        ``|ε| ≤ 1e200`` (their squares and products must stay finite).

    Examples
    --------
    >>> import numpy as np
    >>> import mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> m = mbplanar.analyse(engine, np.radians([0.0, 90.0]), omega=10.0)
    >>> m.xy.shape                                   # (B, P, 2): two positions of five points
    (2, 5, 2)
    >>> m.w[:, m.link_names.index("3")].round(4)     # the rocker's angular velocity, rad/s
    array([-5.    ,  3.7222])
    """
    phi = np.asarray(phi, float)
    if not (phi.size == 1 and math.isfinite(phi.flat[0])) and not np.all(np.isfinite(phi)):
        raise ModelError("the input values phi must be finite", source=engine.mech.source, where="analyse")
    omega = _checked_rate("omega", omega, MAX_OMEGA, engine)
    epsilon = _checked_rate("epsilon", epsilon, MAX_EPSILON, engine)
    n_in = len(engine.inputs)
    phi = phi.reshape(-1, n_in) if phi.ndim <= 1 and n_in == 1 else np.atleast_2d(phi)
    sel = point_selection(engine, points)
    wanted = _wanted(engine, outputs, bool(rates))
    return dispatch(engine, "kinematics", len(phi), lambda: _reference(engine, phi, omega, epsilon, sel, wanted),
                    lambda: _sweep_request(engine, phi, omega, epsilon, sel, wanted),
                    lambda job, status: _sweep_motion(engine, job, phi, sel, wanted))


MAX_OMEGA = 1e100      # |ω|: ω² and ω²·(model size) stay far from overflow
MAX_EPSILON = 1e200


def _wanted(engine: Engine, outputs, rates: bool) -> frozenset:
    """The optional arrays a call computes (`OUTPUTS`), or ModelError naming an unknown one."""
    key = (None if outputs is None else tuple(outputs), rates)
    cache = engine.prepare("kinematics outputs", dict)
    found = cache.get(key)
    if found is None:
        asked = OUTPUTS if outputs is None else ([outputs] if isinstance(outputs, str) else list(outputs))
        unknown = [name for name in asked if name not in OUTPUTS]
        if unknown:
            raise ModelError(f"analyse: outputs: {', '.join(map(repr, unknown))} is not one of {', '.join(OUTPUTS)}",
                             source=engine.mech.source, where="analyse")
        left = set() if rates else set(RATE_OUTPUTS)
        if len(engine.inputs) != 1:
            left |= set(ANALOGUE_OUTPUTS)
        found = cache[key] = frozenset(asked) - left
    return found


def _checked_rate(name: str, value, bound: float, engine):
    """`value` (None, a number or an array) unchanged when finite and within ±bound, else ModelError."""
    if value is None:
        return None
    if value.__class__ is float and abs(value) <= bound:
        return value
    try:
        arr = np.asarray(value, float)
    except (TypeError, ValueError):
        raise ModelError(f"{name} must be a number or an array of numbers, got {value!r}",
                         source=engine.mech.source, where="analyse") from None
    if not np.all(np.isfinite(arr)) or np.any(np.abs(arr) > bound):
        bad = arr[~(np.isfinite(arr) & (np.abs(arr) <= bound))].flat[0]
        raise ModelError(f"{name} must be finite and at most {bound:g} in size, got {bad:g}",
                         source=engine.mech.source, where="analyse")
    return value


# -- the kernels' request (engine._backend, engine._tables) -----------------------------------------
def _sweep_request(engine: Engine, phi, omega, epsilon, sel: PointSelection, wanted: frozenset) -> SweepJob | str:
    """What the kinematics kernel solves and where it writes: the engine's tables, the atlas covering
    the batch, the inputs and the output arrays asked for; or why no kernel can take the batch."""
    shared = engine.prepared.get("sweep tables")
    if shared is None:
        shared = engine.prepare("sweep tables", lambda: _SweepShared(engine))
    if not shared.one_input:
        return "several inputs (the kernels follow one)"
    batch = len(phi)
    if not batch:
        return "no positions"
    plan = shared.plans.get((wanted, len(sel.names)))
    if plan is None:
        plan = shared.plans[wanted, len(sel.names)] = _OutputPlan(shared, wanted, len(sel.names))
    if batch == 1:
        return plan.one(engine, shared, float(phi[0, 0]), omega, epsilon, sel)
    else:
        x = np.array(phi[:, 0], float)  # (contiguous, writeable: the types the compiled kernel was made for)
        lo, hi = float(x.min()), float(x.max())
        om, ep = _speed(omega, shared.omega, batch), _speed(epsilon, shared.epsilon, batch)
        ep_any = bool(ep.any())
        out = plan.many(batch)
    if not (abs(lo - shared.phi0) <= shared.reach and abs(hi - shared.phi0) <= shared.reach):  # `within_walk`
        return "input values beyond the walk from the drawn pose (numpy reduces them by the period)"
    rates = plan.rates
    return SweepJob(shared.tables, _covering(engine, lo, hi), shared.tol,
                    SweepIn(x, om, ep, rates and ep_any, rates, sel.links, sel.at, shared.offsets[rates]), out,
                    engine.threads, shared.store, batch)


class _SweepShared:
    """What every kinematics request of an engine shares: the kernel's tables and tolerances, the
    record layouts (without, with rates), the output plans (`_OutputPlan`), the empty arrays standing
    for outputs not asked for, the Motion's names, and the store where backends keep their work arrays
    and compiled entries."""

    def __init__(self, engine: Engine):
        self.one_input = len(engine.inputs) == 1
        self.tables = sweep_tables(engine)
        self.tol = engine.tol.kernel()
        n_l, n_j = len(engine.links), len(engine.mech.joints)
        self.contact = bool(engine.mech.higher)  # (the records hold the contact parameters)
        self.layouts = {r: record_layout(n_l, n_j, r, len(engine.mech.higher)) for r in (False, True)}
        self.offsets = {r: self.layouts[r][1] for r in (False, True)}
        self.sizes = (n_l, n_j)
        self.empty, self.plans, self.store = {}, {}, {}
        if self.one_input:
            inp = engine.inputs[0]
            self.omega, self.epsilon = float(inp.omega), float(inp.epsilon)
            self.phi0, self.reach = float(engine.phi_drawn[0]), far_span(engine.solver)
        self.names = dict(link_names=list(engine.links), joint_names=list(engine.mech.joints), model=engine.mech)
        self.fields = {**_NONE, **self.names}  # (a Motion's fields before a request fills them)

    def none(self, shape: tuple) -> np.ndarray:
        """An empty float array of `shape` (its first dimension 0): an output not asked for."""
        found = self.empty.get(shape)
        if found is None:
            found = self.empty[shape] = np.empty(shape)
        return found


_RECORDED = ("frames", "value", "wq", "eq", "rate_q", "accel_q")  # views of the kernel's records
_PAIRS = {"w": "e", "e": "w", "v": "a", "a": "v", "vq": "aq", "aq": "vq", "rate": "accel", "accel": "rate"}
_OUT = SweepOut._fields


class _OutputPlan:
    """The arrays the kernel writes for one kind of request (the outputs `wanted`, P points): those
    asked for, allocated per call (`one`, `many`), the others empty (a w or v asked for brings its e or
    a: the kernel writes them together); the frames, joint values and link analogues go to the records.
    One position's arrays are the fields of one structured array (one allocation, every field
    C-contiguous). Which `Motion` field each output becomes (`motion_arrays`, `motion_records`)."""

    def __init__(self, shared: _SweepShared, wanted: frozenset, n_p: int, direct: bool = False):
        n_l, n_j = shared.sizes
        self.rates = rates = any(name in wanted for name in RATE_OUTPUTS)
        per = {"angle": (n_l,), "xy": (n_p, 2), "w": (n_l,), "e": (n_l,), "v": (n_p, 2), "a": (n_p, 2),
               "wq": (n_l,), "eq": (n_l,), "vq": (n_p, 2), "aq": (n_p, 2), "value": (n_j,), "rate": (n_j,),
               "accel": (n_j,), "rate_q": (n_j,), "accel_q": (n_j,), "ic": (n_l, 2), "rows": (0,), "valid": ()}
        own = ("w", "e", "v", "a", "vq", "aq", "rate", "accel", "ic") + (_RECORDED[1:] if direct else ())
        written = {"angle", "xy", "valid"} | {name for name in own if name in wanted or _PAIRS.get(name) in wanted}
        self.layout = shared.layouts[rates][0] if not direct and any(n in wanted for n in _RECORDED) else None
        if self.layout is not None:
            written.add("rows")
            per["rows"] = (self.layout.itemsize // 8,)
        self.shapes = {name: per[name] for name in _OUT if name in written}
        self.width = sum(math.prod(shape) for name, shape in self.shapes.items() if name != "valid")  # (per position)
        self.template = [None if name in written else shared.none((0,) + per[name]) for name in _OUT]
        self.slots = [k for k, name in enumerate(_OUT) if name in written]
        fields_ = [("phi", float, (1,)), ("omega", float, (1,)), ("epsilon", float, (1,))]  # (as `Position` names them)
        fields_ += [(name, float, self.shapes[name]) for name in _OUT if name in written and name not in ("valid", "rows")]
        if self.layout is not None:
            fields_.append(("rows", self.layout))  # (the records, a structured field: no view to make)
        self.one_dtype = np.dtype(fields_)  # (floats only: a copy of its buffer is a memcpy)
        self.motion_arrays = [(name, _OUT.index(name)) for name in ("w", "e", "v", "a", "vq", "aq", "rate", "accel", "ic")
                              if name in wanted]
        self.motion_records = [name for name in ("value", "wq", "eq", "rate_q", "accel_q") if name in wanted]
        self.frames = "frames" in wanted

        self.local = threading.local()

    def one(self, engine: Engine, shared: _SweepShared, x: float, omega, epsilon, sel) -> SweepJob | str:
        """The request of one position: the kernel writes into this thread's own record (`one_dtype`,
        made once; `copied` gives the answer its own copy), so that a request costs no allocation and
        its arrays have the types the compiled kernel was made for."""
        state = getattr(self.local, "state", None)
        if state is None:
            buffer = np.zeros(self.one_dtype.itemsize // 8)
            rec, inputs = np.ndarray((1,), self.one_dtype, buffer), np.ndarray((), self.one_dtype, buffer)
            slots = self.template.copy()
            for k in self.slots:
                name = _OUT[k]
                slots[k] = (np.zeros(1, np.bool_) if name == "valid" else
                            rec["rows"].view(np.float64).reshape(1, -1) if name == "rows" else rec[name])
            state = self.local.state = [buffer, inputs["phi"], inputs["omega"], inputs["epsilon"],
                                        tuple.__new__(SweepOut, slots), {}]
        buffer, xs, om, ep, out, jobs = state
        if not abs(x - shared.phi0) <= shared.reach:  # `within_walk`
            return "input values beyond the walk from the drawn pose (numpy reduces them by the period)"
        xs[0] = x
        om[0] = shared.omega if omega is None else float(_per_position(omega, [0.0], 1, 1)[0, 0])
        ep[0] = shared.epsilon if epsilon is None else float(_per_position(epsilon, [0.0], 1, 1)[0, 0])
        atlas = _covering(engine, x, x)
        key = (ep[0] != 0.0, tuple(sel.names))
        job = jobs.get(key)
        if job is None or job.atlas is not atlas:
            rates = self.rates
            job = jobs[key] = SweepJob(shared.tables, atlas, shared.tol,
                                       SweepIn(xs, om, ep, rates and key[0], rates, sel.links, sel.at,
                                               shared.offsets[rates]), out, 1, shared.store, 1)
        return job

    def copied(self, shape: tuple = (1,)) -> np.ndarray:
        """A copy of this thread's one-position record (`one`), of `shape` ((1,): with the batch axis; ():
        without): the answer's own arrays."""
        return _ndarray(shape, self.one_dtype, self.local.state[0].copy())

    def many(self, batch: int) -> SweepOut:
        """The outputs of `batch` positions: the float arrays consecutive parts of one block, each
        C-contiguous (one allocation: freed together, the block is kept by the allocator for the next
        request, where a dozen arrays freed at once went back to the system and the next request's
        pages faulted in again, as much time as the kernel's); `valid` its own."""
        slots = self.template.copy()
        block = np.empty(batch * self.width)
        start = 0
        for k in self.slots:
            name = _OUT[k]
            if name == "valid":
                slots[k] = np.empty(batch, np.bool_)
                continue
            shape = self.shapes[name]
            size = batch * math.prod(shape)
            slots[k] = block[start:start + size].reshape((batch,) + shape)
            start += size
        return tuple.__new__(SweepOut, slots)


def _speed(value, default, batch: int) -> np.ndarray:
    """The input's speed or acceleration per position (B,), contiguous: `value` one number (None: the
    model's `default`) or one per position."""
    if value is None or isinstance(value, (int, float)):
        out = np.empty(batch)
        out.fill(default if value is None else value)  # (np.full's Python wrapper costs more than the fill)
        return out
    return np.ascontiguousarray(_per_position(value, [default], batch, 1).reshape(-1), float)


def _covering(engine: Engine, lo: float, hi: float):
    """`AtlasTables` of the atlas covering lo … hi (`Atlas.cover`). A batch inside the nodes the tables
    were made from (the usual case: the same range again) neither asks the atlas to grow nor makes them
    again: `cover` would find nothing to do there."""
    found = engine.prepared.get("atlas tables")
    atlas = engine._atlas
    if found is not None and found[0] <= lo and hi <= found[1] and atlas is not None and found[2] is atlas._arrays:
        return found[3]
    atlas = engine.atlas()
    atlas.cover(lo, hi)
    arrays = atlas.arrays()
    tables = atlas_tables(arrays, (atlas.limits[-1] is not None, atlas.limits[+1] is not None), atlas.crossings)
    grid = tables.grid
    engine.prepared["atlas tables"] = (float(grid[0]), float(grid[-1]), arrays, tables,
                                       bool(atlas.crossings or atlas.limits[-1] is not None
                                            or atlas.limits[+1] is not None))
    return tables


def _sweep_motion(engine: Engine, job: SweepJob, phi, sel: PointSelection, wanted: frozenset) -> Motion:
    """The `Motion` of a request the kernel wrote (its valid rows)."""
    out, inp = job.out, job.inp
    batch = job.size
    valid = out.valid
    complete = valid[0] if batch == 1 else bool(valid.all())
    if engine.prepared["atlas tables"][4]:  # (a limit or a change point known: those met)
        x = inp.x
        lo, hi = (float(x[0]),) * 2 if batch == 1 else (float(x.min()), float(x.max()))
        limits, crossings = met_along(engine.atlas(), lo, hi)
    else:
        limits, crossings = [], []
    shared = engine.prepared["sweep tables"]
    plan = shared.plans[wanted, len(sel.names)]
    fields_ = shared.fields.copy()
    if batch == 1 and complete:  # (the thread's one-position record: the answer gets its own copy)
        rec = plan.copied()
        fields_.update(phi=phi, omega=rec["omega"], epsilon=rec["epsilon"], point_names=list(sel.names),
                       angle=rec["angle"], xy=rec["xy"], limits=limits, crossings=crossings, requested=1,
                       success=True, message="solved")
        for name, _ in plan.motion_arrays:
            fields_[name] = rec[name]
        rows = rec["rows"] if plan.layout is not None else None
    else:
        if complete:
            fields_.update(phi=phi, omega=inp.om[:, None], epsilon=inp.ep[:, None], point_names=list(sel.names),
                           angle=out.angle, xy=out.xy, limits=limits, crossings=crossings, requested=batch,
                           success=True, message="solved")
        else:
            keep = np.flatnonzero(valid)
            out = tuple.__new__(SweepOut, [(a[keep] if len(a) else a) for a in out])
            fields_.update(phi=phi[keep], omega=inp.om[keep, None], epsilon=inp.ep[keep, None],
                           point_names=list(sel.names), angle=out.angle, xy=out.xy, limits=limits,
                           crossings=crossings, requested=batch, success=len(keep) == batch,
                           message=_message(engine, batch, len(keep), limits))
        for name, k in plan.motion_arrays:
            fields_[name] = out[k]
        rows = out.rows.reshape(-1).view(plan.layout) if plan.layout is not None else None
    if rows is not None:
        fields_["records"] = rows
        for name in plan.motion_records:
            fields_[name] = rows[name]
        if plan.frames:
            frames = fields_["frames"] = _new(Frames)
            state = frames.__dict__
            state.update(_NO_RATES)
            for name, key in _FRAME_FIELDS[plan.rates]:
                state[name] = rows[key]
            if shared.contact:
                state["contact"] = rows["contact"]
    return _record(Motion, fields_)


#: the `Frames` fields that are fields of the records (without, with rates), and those left None
_FRAME_FIELDS = {False: (("th", "th"), ("r", "r")),
                 True: (("th", "th"), ("r", "r"), ("w", "wq"), ("v", "fv"), ("e", "eq"), ("a", "fa"))}
_NO_RATES = dict(w=None, v=None, e=None, a=None, analogues=True)


_NONE = dict.fromkeys(_MOTION_FIELDS)
_ndarray = np.ndarray


def one_position(engine: Engine, x: float, omega, epsilon, reference):
    """One position's record (0-d, structured: angle, xy, w, e, v, a, wq, eq, vq, aq, value, rate, accel,
    rate_q, accel_q, ic, and phi, omega, epsilon the input's value, speed, acceleration; batch axis taken off) as
    a backend solves it (`mbplanar.position`), or ``reference()`` where every backend declines: the
    request is `analyse`'s of a batch of one, its arrays the record's own."""
    shared = engine.prepared.get("sweep tables")
    if shared is None:
        shared = engine.prepare("sweep tables", lambda: _SweepShared(engine))
    plan = shared.plans.get("position")
    if plan is None:
        sel = point_selection(engine)
        plan = shared.plans["position"] = _OutputPlan(shared, _wanted(engine, None, True), len(sel.names), direct=True)
        plan.sel = sel
    if not shared.one_input:
        return reference()
    return dispatch(engine, "kinematics", 1, reference,
                    lambda: plan.one(engine, shared, x, omega, epsilon, plan.sel),
                    lambda job, status: plan.copied(()) if job.out.valid[0] else reference())


# -- numpy ------------------------------------------------------------------------------------------
def _reference(engine: Engine, phi: np.ndarray, omega, epsilon, sel: PointSelection, wanted: frozenset) -> Motion:
    """`analyse` by numpy: one batch, or chunks of a long sweep of one input."""
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        if len(engine.inputs) != 1 or len(phi) <= CHUNK:
            return _motion(engine, solve_positions(engine, phi), omega, epsilon, sel, wanted)
        return _analyse_chunks(engine, phi, omega, epsilon, sel, wanted)


def _analyse_chunks(engine: Engine, phi, omega, epsilon, sel, wanted) -> Motion:
    """A long sweep of one input in chunks of `CHUNK` positions, copied into arrays allocated once, so
    that the peak memory is the result plus one chunk's work. Same answers as one batch: every position
    is predicted from the same atlas and corrected on its own."""
    batch = len(phi)
    omega = _per_position(omega, [i.omega for i in engine.inputs], batch, 1)
    epsilon = _per_position(epsilon, [i.epsilon for i in engine.inputs], batch, 1)
    out, frames, fill, limits, crossings, first = {}, {}, 0, [], [], None
    for start in range(0, batch, CHUNK):
        part = slice(start, start + CHUNK)
        m = _motion(engine, solve_positions(engine, phi[part]), omega[part], epsilon[part], sel, wanted)
        if first is None:
            first = m
            out = {f.name: np.empty((batch,) + getattr(m, f.name).shape[1:]) for f in fields(m)
                   if isinstance(getattr(m, f.name), np.ndarray)}
            if m.frames is not None:
                frames = {f.name: np.empty((batch,) + getattr(m.frames, f.name).shape[1:]) for f in fields(m.frames)
                          if isinstance(getattr(m.frames, f.name), np.ndarray)}
        n = len(m.phi)
        for name, arr in out.items():
            arr[fill:fill + n] = getattr(m, name)
        for name, arr in frames.items():
            arr[fill:fill + n] = getattr(m.frames, name)
        fill += n
        limits += [lim for lim in m.limits if not any(lim is seen for seen in limits)]
        crossings += [c for c in m.crossings if not any(c is seen for seen in crossings)]
        del m
    made = {name: arr[:fill] for name, arr in out.items()}
    if first.frames is not None:
        made["frames"] = replace(first.frames, **{name: arr[:fill] for name, arr in frames.items()})
    return replace(first, **made, requested=batch, limits=limits, crossings=crossings, success=fill == batch,
                   message=_message(engine, batch, fill, limits))


def positions_at_limits(engine: Engine, limits: list) -> Motion:
    """The configurations at located motion limits (those with `Limit.q`, in that order) as a `Motion`:
    exact positions, link angles and joint values where a sweep can only come within `H_MIN`. Every
    rate and analogue is NaN: at a fold (dead point) the driven links' rates are infinite.

    Parameters
    ----------
    engine : Engine
        The mechanism.
    limits : list of Limit
        Motion limits of `engine` (`Motion.limits`); those not located (`q` None) are left out.

    Returns
    -------
    Motion
        One position per located limit (batch first, SI), its `phi` the limits' inputs; every rate NaN.

    Raises
    ------
    Nothing is checked: the limits must be `engine`'s own (another engine's give positions that mean
    nothing).

    Examples
    --------
    The locking crank-slider-rocker stops where links 3 and 4 stretch into line (t = 1.7999 rad): the
    rocker links 3 and 4 then have the same angle.

    >>> import numpy as np, mbplanar
    >>> from mbplanar.kinematics import positions_at_limits
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/crank_slider_rocker_locking.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians(np.arange(0.0, 360.0, 10.0)))
    >>> at = positions_at_limits(engine, motion.limits)
    >>> at.phi.round(6), np.degrees(at.angle[0, [3, 4]]).round(4), bool(np.isnan(at.w).all())
    (array([[1.799912]]), array([-55.1076, -55.1076]), True)
    """
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        m = _motion(engine, engine.solve_limits(limits), None, None, point_selection(engine),
                    _wanted(engine, None, True))
    nan = {name: np.full_like(getattr(m, name), np.nan) for name in RATE_OUTPUTS if getattr(m, name) is not None}
    frames = replace(m.frames, **{name: np.full_like(getattr(m.frames, name), np.nan) for name in ("w", "v", "e", "a")
                                  if getattr(m.frames, name) is not None})
    return replace(m, **nan, frames=frames)


def _motion(engine: Engine, sol, omega, epsilon, sel: PointSelection, wanted: frozenset) -> Motion:
    """The kinematics of a solved batch (only its valid rows), of the points `sel`, with the arrays
    `wanted`."""
    n_in = len(engine.inputs)
    phi = sol.phi
    batch = len(phi)
    keep = slice(None) if sol.valid.all() else np.flatnonzero(sol.valid)
    omega = _per_position(omega, [i.omega for i in engine.inputs], batch, n_in)
    epsilon = _per_position(epsilon, [i.epsilon for i in engine.inputs], batch, n_in)
    # the joint values are relative: computed in the engine's frame (`Engine.centre`), where positions
    # are vectors within the mechanism; the link frames are converted to the world convention
    # (`world_frames`) and the points follow from them, as `Motion.frames` reports them
    th, c, s, r_engine = _link_states(engine, sol)
    links, at = sel.links, sel.at
    joints = _tables(engine)[1]
    alpha = np.array([engine.reference_angle[n] for n in engine.links])
    out = dict.fromkeys(_MOTION_FIELDS)
    out.update(phi=phi[keep], omega=omega[keep], epsilon=epsilon[keep], link_names=list(engine.links),
               point_names=list(sel.names), joint_names=list(engine.mech.joints), angle=(th.T + alpha)[keep],
               limits=sol.limits, crossings=sol.crossings, requested=batch, model=engine.mech)
    contact = _contact_parameters(engine, sol)[keep] if engine.mech.higher else None
    rates = any(name in wanted for name in RATE_OUTPUTS)
    if not rates:
        r = world_frames(engine.centre, c, s, r_engine)[0]
        out["xy"] = _first(_placed_points(c, s, r, links, at))[keep]
        if "value" in wanted:
            out["value"] = _joint_values(joints, th, c, s, r_engine, None, None, None, None)[0].T[keep]
        if "frames" in wanted:
            out["frames"] = Frames(th.T[keep], _first(r)[keep], contact=contact)
        return _finished(engine, out)
    frames = dict(th=th.T[keep], contact=contact)
    if n_in == 1:
        engine.solver.rates(sol, np.ones((batch, 1)), np.zeros((batch, 1)))
        wq, eq = sol.w.T, sol.e.T
        value, rq, accq = _joint_values(joints, th, c, s, r_engine, wq, _last(sol.v), eq, _last(sol.a))
        r, vq_f, aq_f = world_frames(engine.centre, c, s, r_engine, wq, _last(sol.v), eq, _last(sol.a))
        om, ep = omega[:, 0], epsilon[:, 0]
        ep = ep if ep.any() else None  # constant input speed: x'' = x_qq ω²
        w, e = _real(wq, eq, om, ep)
        v, a = _real(vq_f, aq_f, om, ep)
        xy, pvq, paq = _moving_points(c, s, r, wq, vq_f, eq, aq_f, links, at)
        pv, pa = _real(pvq, paq, om, ep)
        rate, accel = _real(rq, accq, om, ep)
        out.update(wq=wq.T[keep], eq=eq.T[keep], vq=_first(pvq)[keep], aq=_first(paq)[keep], rate_q=rq.T[keep],
                   accel_q=accq.T[keep])
        frames.update(w=wq.T[keep], v=_first(vq_f)[keep], e=eq.T[keep], a=_first(aq_f)[keep], analogues=True)
    else:
        engine.solver.rates(sol, omega, epsilon)
        w, e = sol.w.T, sol.e.T
        value, rate, accel = _joint_values(joints, th, c, s, r_engine, w, _last(sol.v), e, _last(sol.a))
        r, v, a = world_frames(engine.centre, c, s, r_engine, w, _last(sol.v), e, _last(sol.a))
        xy, pv, pa = _moving_points(c, s, r, w, v, e, a, links, at)
        frames.update(w=w.T[keep], v=_first(v)[keep], e=e.T[keep], a=_first(a)[keep], analogues=False)
    out.update(w=w.T[keep], e=e.T[keep], xy=_first(xy)[keep], v=_first(pv)[keep], a=_first(pa)[keep],
               value=value.T[keep], rate=rate.T[keep], accel=accel.T[keep],
               ic=_first(_instant_centres(r, v, w))[keep], frames=Frames(r=_first(r)[keep], **frames))
    for name in OUTPUTS:
        if name not in wanted:
            out[name] = None
    return _finished(engine, out)


def _finished(engine: Engine, out: dict) -> Motion:
    reached, requested = len(out["angle"]), out["requested"]
    out["success"] = reached == requested
    out["message"] = _message(engine, requested, reached, out["limits"])
    return _record(Motion, out)
