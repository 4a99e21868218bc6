"""External loads on the links, read as data from a model's `[gravity]` section and `loads` rows.

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

`at` is a point name (a joint or point of interest of the link) or coordinates `[x, y]` of a material
point of the link in the exact drawn pose (for a sketched model prefer a named point); it defaults to the link's centre (or, for guide forces, the joint's slider point).
`[gravity]` (`g` in m/s², `direction` in degrees, default −90) adds m·g at the centre of every link with a
mass. Gravity is not a `LoadValue` row of the table: `evaluate_loads` appends one per heavy link.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..errors import ModelError, MotionError

__all__ = ["Load", "Gravity", "LoadValue", "read_loads", "read_gravity", "evaluate_loads", "load_power", "heavy_links",
           "has_force_data",
           "LOAD_TYPES"]

LOAD_TYPES = ("force", "weight", "moment", "resistance", "friction")
_WHEN = ("forward", "backward", "always")


@dataclass(frozen=True)
class Gravity:
    """Uniform gravity: acceleration `g` (m/s²) along `direction` (rad, default −π/2)."""

    g: float = 9.81
    direction: float = -math.pi / 2

    @property
    def vector(self) -> np.ndarray:
        return self.g * np.array([math.cos(self.direction), math.sin(self.direction)])


@dataclass(frozen=True)
class Load:
    """One row of `loads`, checked. `at` is drawn coordinates on `link` (None: see the law)."""

    index: int
    kind: str
    link: str
    at: tuple[float, float] | None = None
    force: tuple[float, float] = (0.0, 0.0)
    moment: float = 0.0
    magnitude: float = 0.0
    joint: str | None = None
    s: tuple[float, ...] = ()
    table: tuple[float, ...] = ()
    when: str = "always"
    zero_at: float | None = None
    label: str | None = None

    @property
    def name(self) -> str:
        """The row's `name`, else its place in the table, loads[i]."""
        return self.label or f"loads[{self.index}]"


@dataclass
class LoadValue:
    """A load evaluated over a batch: `force` (B, 2) at `point` (B, 2) and `moment` (B,) on link index
    `link` (engine.links order)."""

    name: str
    link: int
    force: np.ndarray
    point: np.ndarray
    moment: np.ndarray


# -- reading ----------------------------------------------------------------------------------------
def has_force_data(mech) -> bool:
    """True when the model has loads, gravity or mass data (otherwise every reaction is zero)."""
    return bool(mech.extras.get("loads") or mech.extras.get("gravity")
                or any(lk.mass or lk.inertia for lk in mech.links.values()))


def read_gravity(mech) -> Gravity | None:
    """The `[gravity]` section, or None."""
    raw = mech.extras.get("gravity")
    if raw is None:
        return None
    where = f"{mech.source}: gravity"
    if not isinstance(raw, dict):
        raise ModelError(f"{where}: expected a table with g (and direction)")
    unknown = set(raw) - {"g", "direction"}
    if unknown:
        raise ModelError(f"{where}: unknown key(s) {', '.join(sorted(unknown))}")
    g = _number(raw.get("g", 9.81), f"{where}: 'g'")
    direction = _number(raw.get("direction", -90.0), f"{where}: 'direction'")
    return Gravity(g, math.radians(direction))


def read_loads(mech) -> list[Load]:
    """Check the `loads` rows of an (assembled) mechanism and return them as `Load`s."""
    rows = mech.extras.get("loads", [])
    if not isinstance(rows, list):
        raise ModelError(f"{mech.source}: 'loads' must be a list of rows")
    loads = [_read_load(mech, i, raw) for i, raw in enumerate(rows)]
    seen = {}
    for ld in loads:
        if ld.name in seen or ld.name.startswith("gravity on "):
            why = f"is also loads[{seen[ld.name]}]'s" if ld.name in seen else "is kept for gravity"
            raise ModelError(f"{mech.source}: loads[{ld.index}]: the name '{ld.name}' {why}")
        seen[ld.name] = ld.index
    return loads


_KEYS = {
    "force": {"link", "at", "force"},
    "weight": {"link", "at", "weight"},
    "moment": {"link", "moment"},
    "resistance": {"joint", "link", "at", "force", "s", "stroke", "when", "zero_at"},
    "friction": {"joint", "link", "at", "force"},
}


def _read_load(mech, i: int, raw) -> Load:
    where = f"{mech.source}: loads[{i}]"
    if not isinstance(raw, dict):
        raise ModelError(f"{where}: expected a table {{type = ..., ...}}")
    label = raw.get("name")
    if label is not None and (not isinstance(label, str) or not label.strip()):
        raise ModelError(f"{where}: 'name' must be a non-empty text, got {label!r}")
    return replace(_read_load_row(mech, i, raw, where), label=label)


def _read_load_row(mech, i: int, raw, where) -> Load:
    kind = raw.get("type")
    if kind not in LOAD_TYPES:
        raise ModelError(f"{where}: 'type' must be one of {', '.join(LOAD_TYPES)}, got {kind!r}")
    where = f"{where} ({kind})"
    unknown = set(raw) - _KEYS[kind] - {"type", "name"}
    if unknown:
        raise ModelError(f"{where}: unknown key(s) {', '.join(sorted(unknown))}")
    if kind in ("resistance", "friction"):
        return _read_guide_load(mech, i, raw, kind, where)
    link = _link(mech, raw, where)
    at = _point(mech, link, raw.get("at"), where)
    if kind == "force":
        force = _pair(raw.get("force"), f"{where}: 'force'")
        return Load(i, kind, link, at, force=force)
    if kind == "weight":
        return Load(i, kind, link, at, magnitude=_number(_need(raw, "weight", where), f"{where}: 'weight'"))
    return Load(i, kind, link, moment=_number(_need(raw, "moment", where), f"{where}: 'moment'"))


def _read_guide_load(mech, i, raw, kind, where) -> Load:
    joint = str(_need(raw, "joint", where))
    j = mech.joints.get(joint)
    if j is None or j.kind != "P":
        raise ModelError(f"{where}: joint '{joint}' is not a prismatic joint of the model")
    link = str(raw.get("link", j.slider))
    if link not in j.links or link == mech.ground:
        raise ModelError(f"{where}: link '{link}' must be the moving link of joint '{joint}' the force acts on")
    at = _point(mech, link, raw.get("at"), where)
    if kind == "friction":
        return Load(i, kind, link, at, joint=joint,
                    magnitude=_number(_need(raw, "force", where), f"{where}: 'force'"), when="always")
    when = raw.get("when", "always")
    if when not in _WHEN:
        raise ModelError(f"{where}: 'when' must be one of {', '.join(_WHEN)}, got {when!r}")
    force = _need(raw, "force", where)
    zero_at = raw.get("zero_at")
    if zero_at is not None:
        zero_at = _number(zero_at, f"{where}: 'zero_at'")
    if not isinstance(force, list):
        if "s" in raw:
            raise ModelError(f"{where}: with 's' the 'force' must be a list of the same length")
        return Load(i, kind, link, at, joint=joint, magnitude=_number(force, f"{where}: 'force'"), when=when)
    s = _numbers(_need(raw, "s", where), f"{where}: 's'")
    table = _numbers(force, f"{where}: 'force'")
    if len(s) != len(table) or len(s) < 2:
        raise ModelError(f"{where}: 's' and 'force' must be lists of equal length (at least 2), "
                         f"got {len(s)} and {len(table)}")
    stroke = _number(raw.get("stroke", 1.0), f"{where}: 'stroke'")
    s = tuple(x * stroke for x in s)
    if any(b <= a for a, b in zip(s, s[1:])):
        raise ModelError(f"{where}: 's' must increase strictly")
    return Load(i, kind, link, at, joint=joint, s=s, table=table, when=when, zero_at=zero_at)


def _need(raw, key, where):
    if key not in raw:
        raise ModelError(f"{where}: missing '{key}'")
    return raw[key]


def _number(value, where) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ModelError(f"{where} must be a finite number, got {value!r}")
    return float(value)


def _numbers(value, where) -> tuple[float, ...]:
    if not isinstance(value, list):
        raise ModelError(f"{where} must be a list of numbers, got {value!r}")
    return tuple(_number(v, f"{where}[{k}]") for k, v in enumerate(value))


def _pair(value, where) -> tuple[float, float]:
    if not isinstance(value, list) or len(value) != 2:
        raise ModelError(f"{where} must be [x, y], got {value!r}")
    return _numbers(value, where)


def _link(mech, raw, where) -> str:
    link = str(_need(raw, "link", where))
    if link not in mech.links or link == mech.ground:
        raise ModelError(f"{where}: '{link}' is not a moving link of the model")
    return link


def _point(mech, link: str, at, where) -> tuple[float, float] | None:
    """Drawn coordinates of `at` (a name or [x, y]) on `link`; None when not given."""
    if at is None:
        return None
    if isinstance(at, list):
        return _pair(at, f"{where}: 'at'")
    name = str(at)
    if name in mech.points:
        if mech.points[name].link != link:
            raise ModelError(f"{where}: point '{name}' is on link '{mech.points[name].link}', not '{link}'")
        return tuple(mech.points[name].at)
    if name in mech.joints:
        if link not in mech.joints[name].links:
            raise ModelError(f"{where}: joint '{name}' does not belong to link '{link}'")
        return tuple(mech.joints[name].at)
    raise ModelError(f"{where}: 'at' = '{name}' is neither a point nor a joint of the model")


def centre_of(mech, link: str, why: str = "a link with mass needs a 'centre' point") -> tuple[float, float]:
    """Drawn coordinates of a link's centre of mass (ModelError `why` if the link has none)."""
    lk = mech.links[link]
    if lk.centre is None:
        raise ModelError(f"{mech.source}: links '{link}': {why}")
    name = lk.centre
    return tuple(mech.points[name].at if name in mech.points else mech.joints[name].at)


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
    loads = read_loads(mech) if loads is None else loads
    if gravity is True:
        gravity = read_gravity(mech)
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
    at = load.at if load.at is not None else _default_point(mech, load)
    if load.kind == "force":
        return at, np.asarray(load.force, float), 0.0
    if load.kind == "weight":
        g = read_gravity(mech) or Gravity()
        return at, load.magnitude * np.array([math.cos(g.direction), math.sin(g.direction)]), 0.0
    if load.kind == "moment":
        return at, np.zeros(2), float(load.moment)
    return at, None, 0.0


def _default_point(mech, load: Load):
    """Where a load without `at` acts: the joint's slider point (guide forces), else the link's centre,
    else its first joint (for a pure moment the point does not matter)."""
    if load.joint:
        return mech.joints[load.joint].at
    if mech.links[load.link].centre is not None or load.kind != "moment":
        return centre_of(mech, load.link, f"{load.name} has no 'at' and the link has no 'centre'")
    return mech.joints_of(load.link)[0].at


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
        raise ModelError(f"{engine.mech.source}: {load.name}: 'zero_at' needs a model with one input")
    from ..kinematics._motion import analyse
    inp = engine.inputs[0]
    m = analyse(engine, np.array([inp.to_si(load.zero_at)]))
    if not m.success:
        raise MotionError(f"{engine.mech.source}: {load.name}: zero_at = {load.zero_at} cannot be reached: "
                          f"{m.message}")
    return float(m.value[0, m.joint(load.joint)])
