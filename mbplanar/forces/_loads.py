"""External loads on the links: their evaluation over a batch of positions.

The table reader (`mbplanar.table`) reads the `loads` rows and `[gravity]` once, into
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
- `friction`: a constant force `force = F` along the guide opposing the slider's velocity.

`at` is a point name (a joint or point of interest of the link) or coordinates `[x, y]` (in the
table's `length_unit`) of a material point of the link in the exact drawn pose (for a sketched model
prefer a named point); it defaults to the link's centre (or, for guide forces, the joint's slider point).
`[gravity]` (`g` in m/s², `direction` in degrees, default −90) adds m·g at the centre of every link with a
mass. Gravity is not a `LoadValue` row of the table: `evaluate_loads` appends one per heavy link.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError, ModelWarning, MotionError
from ..model._model import LOAD_TYPES, Gravity, Load

__all__ = ["Load", "Gravity", "LoadValue", "read_loads", "read_gravity", "evaluate_loads", "load_power", "heavy_links",
           "has_force_data", "warn_idle_resistances", "LOAD_TYPES"]


@dataclass
class LoadValue:
    """A load evaluated over a batch: `force` (B, 2) at `point` (B, 2) and `moment` (B,) on link index
    `link` (engine.links order)."""

    name: str
    link: int
    force: np.ndarray
    point: np.ndarray
    moment: np.ndarray


def has_force_data(mech) -> bool:
    """True when the model has loads, gravity or mass data (otherwise every reaction is zero)."""
    return bool(mech.loads or mech.gravity or any(lk.mass or lk.inertia for lk in mech.links.values()))


def read_loads(mech) -> list[Load]:
    """The model's loads (read and checked with the table: `Mechanism.loads`)."""
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
    """Positions (B, 2) of the material point drawn at `at` (2,) on link index `link`."""
    th, r = motion.frames["th"][:, link], motion.frames["r"][:, link]
    c, s = np.cos(th), np.sin(th)
    out = np.empty(r.shape)
    out[:, 0] = r[:, 0] + (c * at[0] - s * at[1])
    out[:, 1] = r[:, 1] + (s * at[0] + c * at[1])
    return out


def load_power(load: LoadValue, w, v, r) -> np.ndarray:
    """Power (B,) of a load for link frame velocities w (B, L), v (B, L, 2) and origins r (B, L, 2):
    F·(v + ω × (point − r)) + M·ω. With the analogues it is the load's reduced moment."""
    k = load.link
    wk = w[:, k]
    dx, dy = load.point[:, 0] - r[:, k, 0], load.point[:, 1] - r[:, k, 1]
    return (load.force[:, 0] * (v[:, k, 0] - wk * dy) + load.force[:, 1] * (v[:, k, 1] + wk * dx)
            + load.moment * wk)


def guide_direction(engine, motion, joint: str) -> np.ndarray:
    """Unit vector (B, 2) of a prismatic joint's guide, turning with its carrier."""
    j = engine.mech.joints[joint]
    u0 = engine.laws[joint].u0
    th = motion.frames["th"][:, engine.link_index[j.carrier]]
    c, s = np.cos(th), np.sin(th)
    out = np.empty(th.shape + (2,))
    out[:, 0] = c * u0[0] - s * u0[1]
    out[:, 1] = s * u0[0] + c * u0[1]
    return out


def joint_rate_sign(motion, joint: str) -> np.ndarray:
    """Rate of a joint (B,): its analogue (d/dφ) with one input, its real rate otherwise."""
    k = motion.joint(joint)
    return (motion.rate_q if motion.rate_q is not None else motion.rate)[:, k]


def heavy_links(mech) -> list[tuple[str, object, tuple[float, float]]]:
    """(name, link, drawn centre) of every moving link with mass or inertia, in the table's order: the
    links that weigh and have d'Alembert loads; the centre is (0, 0) for a link with inertia only and
    no centre (its load is a pure moment)."""
    return [(name, lk, centre_of(mech, name) if (lk.mass or lk.centre) else (0.0, 0.0))
            for name, lk in mech.links.items() if name != mech.ground and (lk.mass or lk.inertia)]


def evaluate_loads(engine, motion, loads: list[Load] | None = None,
                   gravity: Gravity | None | bool = True) -> list[LoadValue]:
    """Every load (the model's rows unless `loads` is given, plus gravity on heavy links unless
    `gravity` is False) over the batch of `motion`."""
    mech = engine.mech
    loads = mech.loads if loads is None else loads
    if gravity is True:
        gravity = mech.gravity
    out = [_evaluate(engine, motion, load) for load in loads]
    if gravity:
        for name, lk, centre in heavy_links(mech):
            if lk.mass:
                k = engine.link_index[name]
                point = world_points(motion, k, centre)
                force = np.broadcast_to(lk.mass * gravity.vector, point.shape).copy()
                out.append(LoadValue(f"gravity on {name}", k, force, point, np.zeros(len(point))))
    return out


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
    (None for a guide force, `guide_force_size` along `guide_direction`) and its moment."""
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
    back over s < 0): it does no work there, which is rarely what the table meant."""
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
    from ..kinematics._motion import analyse
    inp = engine.inputs[0]
    m = analyse(engine, np.array([inp.to_si(load.zero_at)]))
    if not m.success:
        raise MotionError(f"zero_at = {load.zero_at} {inp.unit} cannot be reached: {m.message}",
                          source=engine.mech.source, where=load.name)
    return float(m.value[0, m.joint(load.joint)])
