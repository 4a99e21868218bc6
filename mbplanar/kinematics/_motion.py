"""Kinematic results for every link, joint and point: positions, analogues (d/dφ, d²/dφ²) and real
velocities and accelerations, instantaneous centres of velocity.

`analyse(engine, phi, omega, epsilon)` solves a batch and returns a `Motion`: arrays with the batch
first, in SI units (m, rad, s). Real values follow the analogues: v = v_q·ω, a = a_q·ω² + v_q·ε.
``points=[...]`` asks for some points only, ``rates=False`` for positions only (the link angles are
always there).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from dataclasses import fields as dataclass_fields

import numpy as np

from ..errors import MbplanarError, ModelError, did_you_mean
from ..engine._backend import dispatch
from ..engine._constraints import dot, perp, world_frames
from ..engine._solver import Crossing, Engine, Limit

__all__ = ["Motion", "RatesNotComputed", "analyse", "positions_at_limits", "point_selection"]


@dataclass
class Motion:
    """Kinematics of a batch of positions (only those reached on the drawn branch).

    phi (B, n_in): input values (SI); omega, epsilon (B, n_in): input speed and acceleration.
    Links: angle, w, e (B, L) real; wq, eq analogues. Points: xy, v, a (B, P, 2); vq, aq analogues.
    Joints: value, rate, accel (B, J); rate_q, accel_q analogues. Analogues are None with several inputs.
    `point_names` are the points asked for (`analyse(..., points=)`, default every joint and point).
    Without rates (`has_rates` False, `analyse(..., rates=False)`) the arrays of `RATE_NAMES` were not
    computed: reading one raises `RatesNotComputed`.
    The compiled backend passes None for the arrays of `DERIVED`: the points' analogues from the link
    frames, the joints' real rates from their analogues (v = v_q·ω, a = a_q·ω² + v_q·ε, ...), computed
    when first read, and kept.

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

    engine: Engine
    phi: np.ndarray
    omega: np.ndarray
    epsilon: np.ndarray
    link_names: list
    angle: np.ndarray
    w: np.ndarray
    e: np.ndarray
    point_names: list
    xy: np.ndarray
    v: np.ndarray
    a: np.ndarray
    joint_names: list
    value: np.ndarray
    rate: np.ndarray
    accel: np.ndarray
    ic: np.ndarray
    vq: np.ndarray | None  # no default: a derived array is missing from the instance until first read
    aq: np.ndarray | None
    wq: np.ndarray | None = None
    eq: np.ndarray | None = None
    rate_q: np.ndarray | None = None
    accel_q: np.ndarray | None = None
    requested: int = 0
    limits: list[Limit] = field(default_factory=list)
    frames: dict = field(default_factory=dict)
    crossings: list[Crossing] = field(default_factory=list)  # change points passed in the range asked
    # the compiled backend's output (B,) of structured rows: the frames, analogues and joint values above
    # are views of it, the arrays of DERIVED are computed from it; None from the numpy path (the
    # compiled kinetostatics reads it a position at a time)
    rows: np.ndarray | None = field(default=None, repr=False)
    has_rates: bool = True  # False: positions only, the arrays of RATE_NAMES were not computed
    # a backend's (motion) → {name: array} of `REFILLED` where it did not write them (the compiled
    # backend's records, the frames and joint values, and with rates the analogues, all views of the
    # records): computed when first read
    refill: object = field(default=None, repr=False, compare=False)

    @property
    def success(self) -> bool:
        return len(self.phi) == self.requested

    @property
    def message(self) -> str:
        if self.success:
            return "solved"
        return "; ".join(describe_limit(self.engine, lim) for lim in self.limits) or \
            f"{self.requested - len(self.phi)} position(s) could not be solved on the drawn branch"

    def __post_init__(self):
        lazy = self.refill is not None
        absent = ((RATE_NAMES if not self.has_rates else ())
                  + (DERIVED if self.rows is not None or (lazy and self.has_rates) else ())
                  + (REFILLED if lazy else ()))
        for name in absent:
            if self.__dict__.get(name, 0) is None:
                del self.__dict__[name]  # so that reading it reaches __getattr__

    def __getattr__(self, name):
        if name in RATE_NAMES and not self.__dict__.get("has_rates", True):
            raise RatesNotComputed(f"Motion.{name}: this motion holds positions only (analyse(..., rates=False)); "
                                   "ask analyse(..., rates=True) for velocities and accelerations")
        if (name in REFILLED or name in DERIVED) and self.__dict__.get("refill") is not None \
                and "rows" not in self.__dict__:  # (the records and their views not made yet)
            for key, value in self.refill(self).items():
                if key not in self.__dict__:
                    setattr(self, key, value)
            return getattr(self, name)
        if name not in DERIVED or (self.__dict__.get("rows") is None and self.__dict__.get("refill") is None):
            raise AttributeError(f"'Motion' object has no attribute '{name}'")
        value = _derived(self, name)
        setattr(self, name, value)
        return value

    def fields(self) -> dict:
        """Every field's value as stored (None for an array not computed or not derived yet)."""
        return {f.name: self.__dict__.get(f.name) for f in dataclass_fields(self)}

    def __repr__(self) -> str:
        shown = ", ".join(f"{k}=array{v.shape}" if isinstance(v, np.ndarray) else f"{k}={v!r}"
                          for k, v in self.fields().items() if k not in ("engine", "rows", "frames", "refill"))
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
        from ..model._views import view
        return view("frame", self)

    def _repr_html_(self) -> str:
        from ..model._views import view
        return view("html", self)


class _Absent:
    """The class-level default of a field that may be missing from an instance (the analogues wq, eq,
    rate_q, accel_q and the compiled records, None by default): reading it where the instance has none goes to
    `Motion.__getattr__` (positions only: `RatesNotComputed`), as for the fields without a default."""

    def __init__(self, name: str):
        self.name = name

    def __get__(self, obj, owner=None):
        if obj is None:
            return None
        return obj.__getattr__(self.name)


for _name in ("wq", "eq", "rate_q", "accel_q", "rows"):  # after @dataclass has taken their default None
    setattr(Motion, _name, _Absent(_name))


DERIVED = ("vq", "aq", "rate", "accel", "ic")  # follow from the compiled frames and joint analogues
REFILLED = ("value", "frames", "rows", "wq", "eq", "rate_q", "accel_q")  # a backend's `refill` gives them
# (positions only: the first three)
RATE_NAMES = ("w", "e", "v", "a", "wq", "eq", "vq", "aq", "rate", "accel", "rate_q", "accel_q", "ic")


class RatesNotComputed(AttributeError, MbplanarError):
    """A velocity or acceleration read from a `Motion` analysed with ``rates=False``."""


def _derived(m: Motion, name: str) -> np.ndarray:
    """An array of `DERIVED` of a one-input Motion from its link frames (analogues) and the input's
    ω, ε (B, 1)."""
    om, ep = m.omega, m.epsilon
    if name in ("vq", "aq"):  # (the compiled records hold cos θ, sin θ)
        sel = point_selection(m.engine, m.point_names)
        r = m.rows
        _, m.vq, m.aq = (None if x is None else _first(x) for x in _moving_points(
            r["cos"].T, r["sin"].T, _last(r["r"]), r["wq"].T, _last(r["fv"]), r["eq"].T, _last(r["fa"]), sel.links,
            sel.at, position=False))
        return getattr(m, name)
    if name == "ic":  # r + perp(v)/ω of every link frame; NaN where the link does not turn
        return _first(_instant_centres(_last(m.frames["r"]), _last(m.frames["v"] * om[..., None]), m.w.T))
    rate, accel = _real(m.rate_q, m.accel_q, om, ep)  # "rate", "accel"
    return rate if name == "rate" else accel


def describe_limit(engine: Engine, lim: Limit) -> str:
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
    """`range_text` of an input's range lo … hi (SI), in its unit, with the unit."""
    return f"{range_text(inp.from_si(lo), inp.from_si(hi), digits)} {inp.unit}"


def describe_crossing(engine: Engine, c: Crossing) -> str:
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


@dataclass(frozen=True)
class PointSelection:
    """The points a caller asked for: `names` (P,), each on link `links` (P,) drawn at `at` (P, 2)."""

    names: list
    links: np.ndarray
    at: np.ndarray


def point_selection(engine: Engine, points=None) -> PointSelection:
    """The points `points` (names, in the order given; None: every joint and point of the model).
    `ModelError` for a name the model does not have, or one asked twice."""
    names, links, at = _tables(engine)[0]
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
    """Position, velocity and acceleration (B, P, 2) of points drawn at `at` (P, 2) on links `links`
    (P,), from batch-first link states th, w, e (B, L) and r, v, a (B, L, 2)."""
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


CHUNK = 25_000  # positions solved at once: bounds the working memory of very long sweeps


def analyse(engine: Engine, phi, omega=None, epsilon=None, *, points=None, rates: bool = True) -> Motion:
    """Solve `phi` and return the kinematics of the positions reached.

    Rows past a motion limit, which hold no solution, are dropped before anything is returned (the
    limit is in `Motion.limits`). The engine's compiled backend takes the batch where it can
    (`engine._backend.dispatch`); numpy, the reference, does the rest.

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
        False: positions only (link angles, points, joint values); the velocities and accelerations
        are not computed and reading one raises `RatesNotComputed`.

    Returns
    -------
    Motion
        Batch first: link angles (B, L), points' positions, velocities, accelerations (B, P, 2), ...

    Raises
    ------
    ModelError
        Input values that are not finite, a point the model does not have, a speed `omega` or
        acceleration `epsilon` that is not finite or beyond ``|ω| ≤ 1e100``, ``|ε| ≤ 1e200`` (their
        squares and products must stay finite).

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
    if not np.all(np.isfinite(phi)):
        raise ModelError("the input values phi must be finite", source=engine.mech.source, where="analyse")
    omega = _checked_rate("omega", omega, MAX_OMEGA, engine)
    epsilon = _checked_rate("epsilon", epsilon, MAX_EPSILON, engine)
    return dispatch(engine, "kinematics", _reference, phi, omega, epsilon, point_selection(engine, points),
                    bool(rates))


MAX_OMEGA = 1e100      # |ω|: ω² and ω²·(model size) stay far from overflow
MAX_EPSILON = 1e200


def _checked_rate(name: str, value, bound: float, engine):
    """`value` (None, a number or an array) unchanged when finite and within ±bound, else ModelError."""
    if value is None:
        return None
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


def _reference(engine: Engine, phi: np.ndarray, omega, epsilon, points=None, rates=True) -> Motion:
    """`analyse` by numpy: one batch, or chunks of a long sweep of one input."""
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        if len(engine.inputs) != 1 or phi.size <= CHUNK:
            return _analyse(engine, phi, omega, epsilon, points, rates)
        return _analyse_chunks(engine, phi.reshape(-1, 1), omega, epsilon, points, rates)


def _analyse_chunks(engine: Engine, phi, omega, epsilon, points, rates) -> Motion:
    """A long sweep of one input in chunks of `CHUNK` positions, copied into arrays allocated once, so
    that the peak memory is the result plus one chunk's work. Same answers as one batch: every position
    is predicted from the same atlas and corrected on its own."""
    batch = len(phi)
    omega = _per_position(omega, [i.omega for i in engine.inputs], batch, 1)
    epsilon = _per_position(epsilon, [i.epsilon for i in engine.inputs], batch, 1)
    out, frames, fill, limits, crossings, first = {}, {}, 0, [], [], None
    for start in range(0, batch, CHUNK):
        part = slice(start, start + CHUNK)
        m = _analyse(engine, phi[part], omega[part], epsilon[part], points, rates)
        if first is None:
            first = m
            for name, value in vars(m).items():
                if isinstance(value, np.ndarray):
                    out[name] = np.empty((batch,) + value.shape[1:], value.dtype)
            aliases = {name: next((f for f in out if np.may_share_memory(value, getattr(m, f))), None)
                       for name, value in m.frames.items()}  # frames["w"] is the array of wq, ...
            frames = {name: np.empty((batch,) + value.shape[1:]) for name, value in m.frames.items()
                      if aliases[name] is None}
        n = len(m.phi)
        for name, arr in out.items():
            arr[fill:fill + n] = getattr(m, name)
        for name, arr in frames.items():
            arr[fill:fill + n] = m.frames[name]
        fill += n
        limits += [lim for lim in m.limits if not any(lim is seen for seen in limits)]
        crossings += [c for c in m.crossings if not any(c is seen for seen in crossings)]
        del m
    fields = {name: arr[:fill] for name, arr in out.items()}
    frames = {name: (fields[aliases[name]] if aliases[name] else frames[name][:fill]) for name in aliases}
    return Motion(**{**first.fields(), **fields, "requested": batch, "limits": limits, "frames": frames,
                     "crossings": crossings})


def _analyse(engine: Engine, phi, omega=None, epsilon=None, points=None, rates=True) -> Motion:
    """Solve `phi` (SI; (B,) or (B, n_in)) and return the kinematics of the positions reached.

    omega, epsilon: input speed and acceleration, scalars or per position (default: the model's).
    With one input everything is computed once as analogues (d/dφ, d²/dφ²) and the real rates follow
    by v = v_q·ω, a = a_q·ω² + v_q·ε.
    """
    n_in = len(engine.inputs)
    phi = np.asarray(phi, float)
    phi = phi.reshape(-1, n_in) if phi.ndim <= 1 and n_in == 1 else np.atleast_2d(phi)
    return _motion(engine, engine.solve(phi), omega, epsilon, points, rates)


def positions_at_limits(engine: Engine, limits: list) -> Motion:
    """The configurations at located motion limits (those with `Limit.q`, in that order) as a `Motion`:
    exact positions, link angles and joint values where a sweep can only come within `H_MIN`. Every
    rate and analogue is NaN: at a fold (dead point) the driven links' rates are infinite."""
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        m = _motion(engine, engine.solve_limits(limits), None, None)
    for name in ("w", "e", "v", "a", "rate", "accel", "ic", "wq", "eq", "vq", "aq", "rate_q", "accel_q"):
        if getattr(m, name) is not None:
            setattr(m, name, np.full_like(getattr(m, name), np.nan))
    m.frames = {name: (x if name in ("th", "r", "contact") else np.full_like(x, np.nan)) for name, x in m.frames.items()}
    return m


def _motion(engine: Engine, sol, omega, epsilon, points=None, rates=True) -> Motion:
    """The kinematics of a solved batch (only its valid rows), of the points `points` (a
    `PointSelection`, or None for every point), with or without the rates."""
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
    sel = points if points is not None else point_selection(engine)
    links, at = sel.links, sel.at
    joints = _tables(engine)[1]
    alpha = np.array([engine.reference_angle[n] for n in engine.links])
    common = dict(engine=engine, phi=phi[keep], omega=omega[keep], epsilon=epsilon[keep], link_names=list(engine.links),
                  angle=(th.T + alpha)[keep], point_names=list(sel.names), joint_names=list(engine.mech.joints),
                  requested=batch, limits=sol.limits, crossings=sol.crossings)
    frames = {"th": th.T[keep]}
    if engine.mech.higher:
        frames["contact"] = _contact_parameters(engine, sol)[keep]
    if not rates:
        value = _joint_values(joints, th, c, s, r_engine, None, None, None, None)[0]
        r = world_frames(engine.centre, c, s, r_engine)[0]
        frames["r"] = _first(r)[keep]
        return Motion(**common, w=None, e=None, xy=_first(_placed_points(c, s, r, links, at))[keep], v=None, a=None,
                      value=value.T[keep], rate=None, accel=None, ic=None, vq=None, aq=None,
                      frames=frames, has_rates=False)
    analog = n_in == 1
    if analog:
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
    else:
        engine.solver.rates(sol, omega, epsilon)
        w, e = sol.w.T, sol.e.T
        value, rate, accel = _joint_values(joints, th, c, s, r_engine, w, _last(sol.v), e, _last(sol.a))
        r, v, a = world_frames(engine.centre, c, s, r_engine, w, _last(sol.v), e, _last(sol.a))
        xy, pv, pa = _moving_points(c, s, r, w, v, e, a, links, at)
    frames["r"] = _first(r)[keep]
    m = Motion(**common, w=w.T[keep], e=e.T[keep], xy=_first(xy)[keep], v=_first(pv)[keep], a=_first(pa)[keep],
               vq=None, aq=None, value=value.T[keep], rate=rate.T[keep], accel=accel.T[keep],
               ic=_first(_instant_centres(r, v, w))[keep], frames=frames)
    if analog:
        m.wq, m.eq, m.vq, m.aq = wq.T[keep], eq.T[keep], _first(pvq)[keep], _first(paq)[keep]
        m.rate_q, m.accel_q = rq.T[keep], accq.T[keep]
        m.frames.update(w=wq.T[keep], v=_first(vq_f)[keep], e=eq.T[keep], a=_first(aq_f)[keep])
    return m
