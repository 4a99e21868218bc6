"""External loads on the links: their evaluation over a batch of positions.

The table reader (`mbplanar.model._table`) reads the `loads` rows and `[gravity]` once, into
`Mechanism.loads` (`Load` records) and `Mechanism.gravity` (SI units); this module only evaluates them.

Every load law is plain data (numbers, names, tables), never an expression that gets evaluated. A load
evaluated over a batch of positions (`evaluate_loads(engine, motion)`) is a `LoadValue`: the link it acts
on, a force (B, 2) applied at a point (B, 2) and a moment (B,) — SI units, counter-clockwise positive.

Laws (one TOML row each in `loads = [...]`, `type` selects the law):

- `force`: a constant force `force = [fx, fy]` (N) on `link` at `at`;
- `weight`: a weight `weight = G` (N) on `link` at `at`, along the gravity direction (default −y); for
  weights that are not m·g (seed 003);
- `moment`: a constant moment `moment = M` (N·m) on `link`;
- `resistance`: a force along a prismatic joint's guide on its slider that opposes the slider's motion
  relative to the carrier, of constant size `force = F` or piecewise linear in the slider's displacement
  (`s = [...]`, `force = [...]`, optionally `stroke` multiplying `s`, `zero_at` the input value where
  s = 0), acting only `when = "forward"` (joint rate ≥ 0), `"backward"` (rate ≤ 0) or `"always"`;
- `friction`: a constant force `force = F` along the guide opposing the slider's velocity;
- `spring`: a spring between two points (on links a, b): tension T = `preload` + `stiffness`·(l −
  `free_length`) (free length default: the exact drawn distance), or T(l) from a table; it pulls the
  ends together while T > 0;
- `damper`: a linear damper between two points, tension c·dl/dt; or a rotational damper in a revolute
  pair: −c·(ω_b − ω_a) on its second link b, the opposite on a;
- `torque`: a moment M on the second of two links and −M on the first.

Any row can be switched on the sign of a velocity (`switch`: a joint's rate or a point's velocity along a
direction, `when` "forward" or "backward").

`at` is a point name (a joint or point of interest of the link) or coordinates `[x, y]` (in the
table's `length_unit`) of a material point of the link in the exact drawn pose (for a sketched model
prefer a named point); it defaults to the link's centre (or, for guide forces, the joint's slider point).
`[gravity]` (`g` in m/s², `direction` in degrees, default −90) adds m·g at the centre of every link with a
mass. Gravity is not a `LoadValue` row of the table: `evaluate_loads` appends one per heavy link.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, replace

import numpy as np

from ..errors import ModelError, ModelWarning, MotionError
from ..model import ELEMENT_TYPES, LOAD_TYPES, Gravity, Load

__all__ = ["Load", "Gravity", "LoadValue", "read_loads", "read_gravity", "evaluate_loads", "load_power", "heavy_links",
           "has_force_data", "warn_idle_resistances", "real_frames", "point_motion", "spring_tension",
           "spring_energy", "free_length", "drawn_end", "needs_numpy", "LOAD_TYPES", "ELEMENT_TYPES", "constant_parts",
           "world_points"]


@dataclass(frozen=True, eq=False)
class LoadValue:
    """A load evaluated over a batch of B positions (`evaluate_loads`, `inertia_loads`), SI.

    Attributes
    ----------
    name : str
        The row's label ("resistance"), or what made it ("gravity on 2", "inertia of 2").
    link : int
        The index of the link it acts on (`Engine.link_index`, `Motion.link_names` order).
    force : ndarray, shape (B, 2)
        The force (N).
    point : ndarray, shape (B, 2)
        Where it acts (m).
    moment : ndarray, shape (B,)
        A moment besides the force (N·m, counter-clockwise).

    Examples
    --------
    Gravity on the 2 kg coupler of the loaded four-bar, at its centre S2:

    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians([60.0, 150.0]), omega=10.0)
    >>> from mbplanar.forces import evaluate_loads
    >>> weight = evaluate_loads(engine, motion)[1]
    >>> weight.name, weight.link, weight.force.round(3) + 0.0, weight.point.round(4)
    ('gravity on 2', 2, array([[  0.  , -19.62],
           [  0.  , -19.62]]), array([[0.1758, 0.1683],
           [0.0399, 0.1306]]))
    """

    name: str
    link: int
    force: np.ndarray
    point: np.ndarray
    moment: np.ndarray


def has_force_data(mech) -> bool:
    """True when the model has loads, gravity or mass data (otherwise every reaction is zero).

    Parameters
    ----------
    mech : Mechanism
        The model.

    Returns
    -------
    bool
        Whether the model has a `loads` row, `[gravity]`, or a link with a mass or an inertia.

    Raises
    ------
    AttributeError
        `mech` is not a `Mechanism`.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.forces import has_force_data
    >>> has_force_data(mbplanar.read_model("models/fourbar_loaded.toml"))
    True
    >>> has_force_data(mbplanar.read_model("models/fourbar.toml"))
    False
    """
    return bool(mech.loads or mech.gravity or any(lk.mass or lk.inertia for lk in mech.links.values()))


def read_loads(mech) -> list[Load]:
    """The model's loads (read and checked with the table: `Mechanism.loads`).

    Parameters
    ----------
    mech : Mechanism
        The model.

    Returns
    -------
    list of Load
        The `loads` rows in the table's order, SI.

    Raises
    ------
    AttributeError
        `mech` is not a `Mechanism` (the rows were checked when the table was read: `ModelError` there).

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.forces import read_loads
    >>> [(ld.name, ld.kind, ld.link, ld.moment) for ld in read_loads(mbplanar.read_model("models/fourbar_loaded.toml"))]
    [('resistance', 'moment', '3', -5.0)]
    """
    return list(mech.loads)


def read_gravity(mech) -> Gravity | None:
    """The model's gravity (`Mechanism.gravity`), or None."""
    return mech.gravity


def named_point(mech, name: str) -> tuple[float, float]:
    """Drawn coordinates of a point of interest or joint `name` (exact once assembled)."""
    return tuple(mech.points[name].at if name in mech.points else mech.joints[name].at)


def centre_of(mech, link: str, why: str = "a link with mass needs a 'centre' point") -> tuple[float, float]:
    """Drawn coordinates of a link's centre of mass (ModelError `why` if the link has none)."""
    lk = mech.links[link]
    if lk.centre is None:
        raise ModelError(why, source=mech.source, where=f"link '{link}'")
    return named_point(mech, lk.centre)


# -- evaluating -------------------------------------------------------------------------------------
def world_points(motion, link: int, at) -> np.ndarray:
    """Positions of the material point drawn at `at` on a link, over the batch of `motion`.

    Parameters
    ----------
    motion : Motion
        Positions with their frames (batch B).
    link : int
        The link's index (`Engine.link_index`).
    at : array_like, shape (2,)
        Where the point is drawn (m, the model's frame).

    Returns
    -------
    ndarray, shape (B, 2)
        Its positions (m).

    Raises
    ------
    IndexError
        A link index past the motion's links.

    Examples
    --------
    The coupler's pin A, drawn at (0.05, 0.0866) with the crank at 60°, is back there at 60° and 0.1 m
    from the pivot O at 150°:

    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians([60.0, 150.0]), omega=10.0)
    >>> from mbplanar.forces import world_points
    >>> world_points(motion, 2, np.array([0.05, 0.0866])).round(6)
    array([[ 0.05    ,  0.0866  ],
           [-0.086603,  0.049997]])
    """
    th, r = motion.frames.th[:, link], motion.frames.r[:, link]
    c, s = np.cos(th), np.sin(th)
    out = np.empty(r.shape)
    out[:, 0] = r[:, 0] + (c * at[0] - s * at[1])
    out[:, 1] = r[:, 1] + (s * at[0] + c * at[1])
    return out


def load_power(load: LoadValue, w, v, r) -> np.ndarray:
    """Power (B,) of a load for link frame velocities w (B, L), v (B, L, 2) and origins r (B, L, 2):
    F·(v + ω × (point − r)) + M·ω. With the analogues it is the load's reduced moment.

    Parameters
    ----------
    load : LoadValue
        The load over B positions.
    w : ndarray, shape (B, L)
        The link frames' angular velocities (rad/s, or analogues rad/rad).
    v : ndarray, shape (B, L, 2)
        The velocities of the frames' origins (m/s, or analogues m/rad).
    r : ndarray, shape (B, L, 2)
        The frames' origins (m).

    Returns
    -------
    ndarray, shape (B,)
        The power (W), or with the analogues the reduced moment (N·m).

    Raises
    ------
    IndexError
        A load on a link past the L frames.

    Examples
    --------
    The −5 N·m on the rocker of the loaded four-bar: its reduced moment on the crank is −5·ω₃/ω₁, its
    power at 10 rad/s ten times that:

    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians([60.0, 150.0]), omega=10.0)
    >>> from mbplanar.forces import evaluate_loads, load_power
    >>> resistance = evaluate_loads(engine, motion)[0]
    >>> f = motion.frames
    >>> load_power(resistance, f.w, f.v, f.r).round(6), (-5 * f.w[:, 3]).round(6)
    (array([-1.087183, -1.774365]), array([-1.087183, -1.774365]))
    >>> load_power(resistance, motion.w, motion.v, f.r).round(5)
    array([-10.87183, -17.74365])
    """
    k = load.link
    wk = w[:, k]
    dx, dy = load.point[:, 0] - r[:, k, 0], load.point[:, 1] - r[:, k, 1]
    return (load.force[:, 0] * (v[:, k, 0] - wk * dy) + load.force[:, 1] * (v[:, k, 1] + wk * dx)
            + load.moment * wk)


def guide_direction(engine, motion, joint: str) -> np.ndarray:
    """Unit vector (B, 2) of a prismatic joint's guide, turning with its carrier."""
    j = engine.mech.joints[joint]
    u0 = engine.laws[joint].u0
    th = motion.frames.th[:, engine.link_index[j.carrier]]
    c, s = np.cos(th), np.sin(th)
    out = np.empty(th.shape + (2,))
    out[:, 0] = c * u0[0] - s * u0[1]
    out[:, 1] = s * u0[0] + c * u0[1]
    return out


def joint_rate_sign(motion, joint: str) -> np.ndarray:
    """A joint's rate (B,) for the sign of the motion: its analogue (d/dφ) with one input, with the sign of
    the input's speed (so a load opposing the motion still opposes it when the input runs backwards),
    its real rate otherwise."""
    k = motion.joint(joint)
    if motion.rate_q is None:
        return motion.rate[:, k]
    # the analogue's sign, turned round where the input runs backwards (at rest: the motion along +φ)
    return motion.rate_q[:, k] * np.where(motion.omega[:, 0] < 0, -1.0, 1.0)


def heavy_links(mech) -> list[tuple[str, object, tuple[float, float]]]:
    """(name, link, drawn centre) of every moving link with mass or inertia, in the table's order: the
    links that weigh and have d'Alembert loads; the centre is (0, 0) for a link with inertia only and
    no centre (its load is a pure moment).

    Parameters
    ----------
    mech : Mechanism
        The model as the engine holds it (`Engine.mech`: assembled, its named points placed).

    Returns
    -------
    list of tuple
        (name, `Link`, (x, y) of its centre of mass in the drawn pose, m).

    Raises
    ------
    ModelError
        A link with a mass and no centre.
    TypeError
        A model read but not assembled (a named centre not yet placed).

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.forces import heavy_links
    >>> mech = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml")).mech
    >>> [(name, link.mass, tuple(round(x, 6) for x in centre)) for name, link, centre in heavy_links(mech)]
    [('2', 2.0, (0.1758, 0.168299)), ('3', 1.5, (0.3008, 0.124997))]
    """
    return [(name, lk, centre_of(mech, name) if (lk.mass or lk.centre) else (0.0, 0.0))
            for name, lk in mech.links.items() if name != mech.ground and (lk.mass or lk.inertia)]


def evaluate_loads(engine, motion, loads: list[Load] | None = None,
                   gravity: Gravity | None | bool = True) -> list[LoadValue]:
    """Every load (the model's rows unless `loads` is given, plus gravity on heavy links unless
    `gravity` is False) over the batch of `motion`.

    Parameters
    ----------
    engine : Engine
        The mechanism.
    motion : Motion
        Positions with their rates (batch B): speed-dependent rows (resistances, dampers, switched
        rows) read them.
    loads : list of Load, optional
        The rows to evaluate (default: the model's, `read_loads`).
    gravity : Gravity, None or bool
        True: the model's `[gravity]`; False or None: no weights; a `Gravity`: that one.

    Returns
    -------
    list of LoadValue
        One per row (two per spring, damper or torque: one on each link), then one weight per link
        with a mass.

    Raises
    ------
    MotionError
        A resistance's `zero_at` cannot be reached.
    ModelError
        `zero_at` on a model with several inputs.

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians([60.0, 150.0]), omega=10.0)
    >>> from mbplanar.forces import evaluate_loads
    >>> [(ld.name, ld.link, ld.moment.tolist()) for ld in evaluate_loads(engine, motion, gravity=False)]
    [('resistance', 3, [-5.0, -5.0])]
    >>> [ld.name for ld in evaluate_loads(engine, motion)]
    ['resistance', 'gravity on 2', 'gravity on 3']
    """
    mech = engine.mech
    loads = mech.loads if loads is None else loads
    if gravity is True:
        gravity = mech.gravity
    out = [value for load in loads for value in _evaluate_switched(engine, motion, load)]
    if gravity:
        for name, lk, centre in heavy_links(mech):
            if lk.mass:
                k = engine.link_index[name]
                point = world_points(motion, k, centre)
                force = np.broadcast_to(lk.mass * gravity.vector, point.shape).copy()
                out.append(LoadValue(f"gravity on {name}", k, force, point, np.zeros(len(point))))
    return out


def needs_numpy(mech) -> bool:
    """True when a model has rows that only the numpy kinetostatics evaluates (springs, dampers,
    torques between links, switched rows)."""
    return any(ld.kind in ELEMENT_TYPES or ld.switch for ld in read_loads(mech))


def real_frames(engine, motion, links=slice(None)):
    """Real (w, v, e, a) of the link frames `links` (default all): (B, L), (B, L, 2), (B, L), (B, L, 2)."""
    f = motion.frames
    if f.analogues:
        om, ep = motion.omega[:, :1], motion.epsilon[:, :1]
        v, a = f.v[:, links], f.a[:, links]
        real_a = a * om[..., None] ** 2 + v * ep[..., None]
        return motion.w[:, links], v * om[..., None], motion.e[:, links], real_a
    return f.w[:, links], f.v[:, links], f.e[:, links], f.a[:, links]


def point_motion(engine, motion, link: int, at) -> tuple[np.ndarray, np.ndarray]:
    """Position and real velocity (B, 2) each of the material point drawn at `at` (2,) on link `link`."""
    xy = world_points(motion, link, at)
    w, v, _, _ = real_frames(engine, motion, [link])
    r = motion.frames.r[:, link]
    vel = v[:, 0].copy()
    vel[:, 0] -= w[:, 0] * (xy[:, 1] - r[:, 1])
    vel[:, 1] += w[:, 0] * (xy[:, 0] - r[:, 0])
    return xy, vel


def _evaluate_switched(engine, motion, load: Load) -> list[LoadValue]:
    """The load's values, zero where its switch is off."""
    out = _evaluate_element(engine, motion, load) if load.kind in ELEMENT_TYPES else [_evaluate(engine, motion, load)]
    if load.switch is None:
        return out
    speed = _switch_speed(engine, motion, load)
    on = (speed >= 0) if load.when == "forward" else (speed <= 0)
    return [replace(value, force=np.where(on[:, None], value.force, 0.0), moment=np.where(on, value.moment, 0.0))
            for value in out]


def _switch_speed(engine, motion, load: Load) -> np.ndarray:
    """The velocity (B,) whose sign switches a row: a joint's rate, or a point's velocity along the
    row's direction (fixed to the frame)."""
    mech = engine.mech
    if load.switch in mech.joints:
        return motion.rate[:, motion.joint(load.switch)]
    k = motion.point(load.switch)
    d = load.switch_direction
    return motion.v[:, k, 0] * math.cos(d) + motion.v[:, k, 1] * math.sin(d)


def _element_ends(engine, motion, load: Load):
    """Both ends of a two-point element: link indices, positions and real velocities (B, 2)."""
    ka, kb = engine.link_index[load.other], engine.link_index[load.link]
    pa, va = point_motion(engine, motion, ka, np.asarray(drawn_end(engine.mech, load, 0), float))
    pb, vb = point_motion(engine, motion, kb, np.asarray(drawn_end(engine.mech, load, 1), float))
    return ka, kb, pa, va, pb, vb


def drawn_end(mech, load: Load, end: int) -> tuple[float, float]:
    """Drawn coordinates (exact pose) of an element's end on `other` (0) or on `link` (1).

    Parameters
    ----------
    mech : Mechanism
        The model as the engine holds it (`Engine.mech`: assembled, its named points placed).
    load : Load
        A spring or damper row between two points.
    end : int
        0: the end on the row's `other` link; 1: on its `link`.

    Returns
    -------
    tuple of float
        (x, y) in the drawn pose (m).

    Raises
    ------
    KeyError
        An end at a point the model does not have.

    Examples
    --------
    Andrews' squeezer: its spring runs from the frame point C = (0.014, 0.072) to the point D of body 3.

    >>> import mbplanar
    >>> from mbplanar.forces import drawn_end, read_loads
    >>> mech = mbplanar.Engine(mbplanar.read_model("models/squeezer.toml")).mech
    >>> spring = next(ld for ld in read_loads(mech) if ld.kind == "spring")
    >>> [tuple(round(x, 6) for x in drawn_end(mech, spring, end)) for end in (0, 1)]
    [(0.014, 0.072), (-0.010472, 0.025358)]
    """
    at, point = (load.other_at, load.other_point) if end == 0 else (load.at, load.point)
    return at if at is not None else named_point(mech, point)


def free_length(mech, load: Load) -> float:
    """A linear spring's free length: given, or its ends' distance in the (exact) drawn pose."""
    if load.free_length is not None:
        return load.free_length
    return math.dist(drawn_end(mech, load, 0), drawn_end(mech, load, 1))


def spring_tension(mech, load: Load, length: np.ndarray) -> np.ndarray:
    """Tension (B,) of a spring row at `length` (B,) (N, pulling its ends together when positive)."""
    if load.table:
        return np.interp(length, load.s, load.table)
    return load.preload + load.stiffness * (length - free_length(mech, load))


def spring_energy(engine, motion, load: Load) -> np.ndarray:
    """Potential energy (B,) of a spring row (J): ∫T dl from the free length (linear), or from the
    table's first length (a table), so that only its changes matter."""
    _, _, pa, _, pb, _ = _element_ends(engine, motion, load)
    length = np.hypot(*(pb - pa).T)
    if not load.table:
        x = length - free_length(engine.mech, load)
        return load.preload * x + 0.5 * load.stiffness * x * x
    ls, fs = np.asarray(load.s), np.asarray(load.table)
    nodes = np.concatenate([[0.0], np.cumsum(np.diff(ls) * (fs[1:] + fs[:-1]) / 2)])
    k = np.clip(np.searchsorted(ls, length, side="right") - 1, 0, len(ls) - 2)
    slope = (fs[k + 1] - fs[k]) / (ls[k + 1] - ls[k])
    x = length - ls[k]
    return nodes[k] + fs[k] * x + 0.5 * slope * x * x


def _evaluate_element(engine, motion, load: Load) -> list[LoadValue]:
    """A spring, damper or torque: equal and opposite loads on its two links."""
    batch = len(motion.phi)
    zero2, zero = np.zeros((batch, 2)), np.zeros(batch)
    if load.kind == "torque" or load.joint:
        ka, kb = engine.link_index[load.other], engine.link_index[load.link]
        if load.kind == "torque":
            m = np.full(batch, load.moment)
        else:
            w, _, _, _ = real_frames(engine, motion, [ka, kb])
            m = -load.damping * (w[:, 1] - w[:, 0])
        origin = motion.frames.r
        return [LoadValue(load.name, kb, zero2, origin[:, kb].copy(), m),
                LoadValue(load.name, ka, zero2.copy(), origin[:, ka].copy(), -m)]
    ka, kb, pa, va, pb, vb = _element_ends(engine, motion, load)
    d = pb - pa
    length = np.hypot(d[:, 0], d[:, 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        u = d / length[:, None]
    if load.kind == "spring":
        tension = spring_tension(engine.mech, load, length)
    else:
        tension = load.damping * np.einsum("bi,bi->b", u, vb - va)
    force = tension[:, None] * u  # on a, towards b
    return [LoadValue(load.name, kb, -force, pb, zero), LoadValue(load.name, ka, force, pa, zero.copy())]


def _evaluate(engine, motion, load: Load) -> LoadValue:
    k = engine.link_index[load.link]
    batch = len(motion.phi)
    at, force, moment = constant_parts(engine.mech, load)
    point = world_points(motion, k, np.asarray(at, float))
    if force is None:
        force = guide_force_size(engine, motion, load)[:, None] * guide_direction(engine, motion, load.joint)
    else:
        force = np.tile(force, (batch, 1))
    return LoadValue(load.name, k, force, point, np.full(batch, moment))


def constant_parts(mech, load: Load) -> tuple[tuple[float, float], np.ndarray | None, float]:
    """What does not vary with the position: the drawn point `at` the load acts at, its force (2,)
    (None for a guide force, `guide_force_size` along `guide_direction`) and its moment.

    Parameters
    ----------
    mech : Mechanism
        The model as the engine holds it (`Engine.mech`: assembled, its named points placed).
    load : Load
        One of its `force`, `weight`, `moment`, `resistance` or `friction` rows.

    Returns
    -------
    at : tuple of float
        The drawn point it acts at (m).
    force : ndarray, shape (2,), or None
        Its force (N); None for a guide force (its size varies with the motion).
    moment : float
        Its moment (N·m).

    Raises
    ------
    KeyError
        A row at a point the model does not have.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.forces import constant_parts, read_loads
    >>> mech = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml")).mech
    >>> at, force, moment = constant_parts(mech, read_loads(mech)[0])
    >>> tuple(round(x, 6) for x in at), force, moment
    ((0.3008, 0.124997), array([0., 0.]), -5.0)
    """
    at = load.at if load.at is not None else named_point(mech, load.point)
    if load.kind == "force":
        return at, np.asarray(load.force, float), 0.0
    if load.kind == "weight":
        g = mech.gravity or Gravity()
        return at, load.magnitude * np.array([math.cos(g.direction), math.sin(g.direction)]), 0.0
    if load.kind == "moment":
        return at, np.zeros(2), float(load.moment)
    return at, None, 0.0


def guide_force_size(engine, motion, load: Load) -> np.ndarray:
    """Signed size (B,) of a guide force (`resistance`, `friction`) along its guide direction: it
    opposes the slider's motion relative to the carrier."""
    j = engine.mech.joints[load.joint]
    rate = joint_rate_sign(motion, load.joint)
    if load.table:
        s = motion.value[:, motion.joint(load.joint)] - _displacement_zero(engine, load)
        size = np.interp(s, load.s, load.table)
    else:
        size = np.full(len(rate), load.magnitude)
    if load.when == "forward":
        along = np.where(rate >= 0, -1.0, 0.0)
    elif load.when == "backward":
        along = np.where(rate <= 0, 1.0, 0.0)
    else:
        along = -np.sign(rate)
    if load.link == j.carrier:  # the carrier feels the opposite of what the slider feels
        along = -along
    return along * size


def warn_idle_resistances(engine, motion):
    """A `ModelWarning` for each resistance with an `s` diagram that is zero at every position of
    `motion` while it acts (e.g. `when = "backward"` with a diagram on s > 0 while the slider moves
    back over s < 0): it does no work there, which is rarely what the table meant.

    Parameters
    ----------
    engine : Engine
        The mechanism.
    motion : Motion
        The positions a command is about to work on (two or more; with rates).

    Returns
    -------
    None
        The warnings go through `warnings.warn`.

    Raises
    ------
    ModelWarning
        When warnings are errors (``-W error``), for the first idle resistance.

    Examples
    --------
    The shaper's cutting force acts on the working stroke: over a whole turn it works, over a stretch of
    the return stroke alone (crank at 240°–290°) it does nothing.

    >>> import warnings, numpy as np, mbplanar
    >>> from mbplanar.forces import warn_idle_resistances
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/shaper.toml"))
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     warn_idle_resistances(engine, mbplanar.analyse(engine, np.radians(np.arange(0.0, 360.0, 10.0))))
    ...     warn_idle_resistances(engine, mbplanar.analyse(engine, np.radians(np.arange(240.0, 300.0, 10.0))))
    >>> [str(w.message) for w in caught]  # doctest: +NORMALIZE_WHITESPACE
    ["models/shaper.toml: cutting: the resistance does no work over the 6 positions: it acts (forward) over
    no position, where its diagram (s = 0 … 0.5 m) gives 0 N; check the sign of 's', 'zero_at' or 'when'"]
    """
    units = engine.mech.units
    for load in engine.mech.loads:
        if load.kind != "resistance" or not load.table or len(motion.phi) < 2:
            continue
        size = guide_force_size(engine, motion, load)
        if np.any(size != 0):
            continue
        s = motion.value[:, motion.joint(load.joint)] - _displacement_zero(engine, load)
        rate = joint_rate_sign(motion, load.joint)
        active = {"forward": rate >= 0, "backward": rate <= 0}.get(load.when, np.ones(len(s), bool))
        k = units.length_scale
        span = (f"s = {s[active].min() / k:.4g} … {s[active].max() / k:.4g} {units.length}" if active.any()
                else "no position")
        warnings.warn(ModelWarning(
            f"{engine.mech.source}: {load.name}: the resistance does no work over the {len(s)} positions: "
            f"it acts ({load.when}) over {span}, where its diagram (s = {load.s[0] / k:.4g} … "
            f"{load.s[-1] / k:.4g} {units.length}) gives 0 N; check the sign of 's', 'zero_at' or 'when'"),
            stacklevel=2)


def _displacement_zero(engine, load: Load) -> float:
    """The joint's value at the input value `zero_at` (the diagram's s = 0), or 0 (drawn pose)."""
    if load.zero_at is None:
        return 0.0
    cache = engine.prepare("displacement zero", dict)
    key = (load.joint, load.zero_at)
    if key not in cache:
        cache[key] = _joint_value_at(engine, load)
    return cache[key]


def _joint_value_at(engine, load: Load) -> float:
    if len(engine.inputs) != 1:
        raise ModelError("'zero_at' needs a model with one input", source=engine.mech.source, where=load.name)
    from ..kinematics import analyse
    inp = engine.inputs[0]
    m = analyse(engine, np.array([inp.to_si(load.zero_at)]))
    if not m.success:
        raise MotionError(f"zero_at = {load.zero_at} {inp.unit} cannot be reached: {m.message}",
                          source=engine.mech.source, where=load.name)
    return float(m.value[0, m.joint(load.joint)])
