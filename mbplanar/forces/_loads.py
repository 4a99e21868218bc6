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
- `friction`: a constant force `force = F` along the guide opposing the slider's velocity;
- `spring`: a spring between two points `at = [P, Q]` (on the links `links = [a, b]`, which a point
  names itself): tension T = `preload` + `stiffness`·(l − `free_length`) (N, N/m, m; free length
  default: the drawn distance), or T(l) piecewise linear from `length = [...]`, `force = [...]`; it
  pulls P towards Q and Q towards P while T > 0;
- `damper`: a linear damper between two points (`at`, `links` as for a spring), tension c·dl/dt
  (`damping` c in N·s/m); or, with `joint = J` (a revolute pair), a rotational damper: moment
  −c·(ω_b − ω_a) on the pair's second link b and the opposite on a (c in N·m·s/rad);
- `torque`: a moment `moment = M` (N·m) on the second link of `links = [a, b]` and −M on the first.

Any row can be switched on the sign of a velocity: `switch = J` (a joint: its rate) or `switch = P` (a
point: its velocity along `switch_direction`, degrees, default 0), with `when = "forward"` (active while
that velocity is ≥ 0) or `"backward"` (≤ 0).

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
           "has_force_data", "real_frames", "point_motion", "spring_energy", "needs_numpy",
           "LOAD_TYPES"]

LOAD_TYPES = ("force", "weight", "moment", "resistance", "friction", "spring", "damper", "torque")
ELEMENT_TYPES = ("spring", "damper", "torque")  # act between two links
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
    other: str | None = None                     # spring, damper, torque: the second link
    other_at: tuple[float, float] | None = None  # ... and the drawn point on it
    stiffness: float = 0.0
    free_length: float = 0.0
    preload: float = 0.0
    damping: float = 0.0
    switch: str | None = None                    # joint or point whose velocity sign switches the row
    switch_direction: float = 0.0                # rad, for a point

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
    "spring": {"links", "at", "stiffness", "free_length", "preload", "length", "force"},
    "damper": {"links", "at", "damping", "joint"},
    "torque": {"links", "moment"},
}
_SWITCH_KEYS = {"switch", "switch_direction", "when"}


def _read_load(mech, i: int, raw) -> Load:
    where = f"{mech.source}: loads[{i}]"
    if not isinstance(raw, dict):
        raise ModelError(f"{where}: expected a table {{type = ..., ...}}")
    label = raw.get("name")
    if label is not None and (not isinstance(label, str) or not label.strip()):
        raise ModelError(f"{where}: 'name' must be a non-empty text, got {label!r}")
    load = replace(_read_load_row(mech, i, raw, where), label=label)
    if "switch" in raw:
        load = _read_switch(mech, raw, load, f"{where} ({load.kind})")
    return load


def _read_switch(mech, raw, load: Load, where) -> Load:
    """`switch` (a joint or point name), `switch_direction` (deg, points) and `when` of any row."""
    name = str(raw["switch"])
    if name not in mech.joints and name not in mech.points:
        raise ModelError(f"{where}: 'switch' = '{name}' is neither a joint nor a point of the model")
    if "switch_direction" in raw and name not in mech.points:
        raise ModelError(f"{where}: 'switch_direction' applies to a point; '{name}' is a joint")
    direction = math.radians(_number(raw.get("switch_direction", 0.0), f"{where}: 'switch_direction'"))
    when = raw.get("when")
    if when not in ("forward", "backward"):
        raise ModelError(f"{where}: a switched row needs 'when' = \"forward\" (active while the velocity is "
                         f">= 0) or \"backward\" (<= 0), got {when!r}")
    return replace(load, switch=name, switch_direction=direction, when=when)


def _read_load_row(mech, i: int, raw, where) -> Load:
    kind = raw.get("type")
    if kind not in LOAD_TYPES:
        raise ModelError(f"{where}: 'type' must be one of {', '.join(LOAD_TYPES)}, got {kind!r}")
    where = f"{where} ({kind})"
    switch_keys = _SWITCH_KEYS if "switch" in raw else set()
    unknown = set(raw) - _KEYS[kind] - {"type", "name"} - switch_keys
    if unknown:
        raise ModelError(f"{where}: unknown key(s) {', '.join(sorted(unknown))}")
    if kind in ("resistance", "friction"):
        if switch_keys:
            raise ModelError(f"{where}: a guide force is switched by its own joint ('when'); no 'switch'")
        return _read_guide_load(mech, i, raw, kind, where)
    if kind in ELEMENT_TYPES:
        return _read_element(mech, i, raw, kind, where)
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


def _read_element(mech, i, raw, kind, where) -> Load:
    """A spring, damper or torque between two links."""
    if kind == "damper" and "joint" in raw:
        return _read_rotary_damper(mech, i, raw, where)
    if kind == "torque":
        a, b = _two_links(mech, raw.get("links"), where, required=True)
        return Load(i, kind, b, None, moment=_number(_need(raw, "moment", where), f"{where}: 'moment'"),
                    other=a)
    ends = _need(raw, "at", where)
    if not isinstance(ends, list) or len(ends) != 2:
        raise ModelError(f"{where}: 'at' must be [P, Q], two points (names or [x, y]), got {ends!r}")
    links = _end_links(mech, ends, raw.get("links"), where)
    (pa, pb) = (_point(mech, link, end, where) for link, end in zip(links, ends))
    drawn = math.dist(pa, pb)
    if kind == "damper":
        c = _number(_need(raw, "damping", where), f"{where}: 'damping'")
        if c < 0:
            raise ModelError(f"{where}: 'damping' must be >= 0, got {c}")
        return Load(i, kind, links[1], pb, other=links[0], other_at=pa, damping=c)
    if drawn == 0:
        raise ModelError(f"{where}: the spring's ends coincide in the drawn pose")
    if "length" in raw or isinstance(raw.get("force"), list):
        if {"stiffness", "free_length", "preload"} & set(raw):
            raise ModelError(f"{where}: give either a table (length, force) or stiffness/free_length/preload")
        ls = _numbers(_need(raw, "length", where), f"{where}: 'length'")
        fs = _numbers(_need(raw, "force", where), f"{where}: 'force'")
        if len(ls) != len(fs) or len(ls) < 2 or any(b <= a for a, b in zip(ls, ls[1:])) or ls[0] < 0:
            raise ModelError(f"{where}: 'length' (increasing, >= 0) and 'force' must be lists of equal length "
                             f"(at least 2), got {len(ls)} and {len(fs)}")
        return Load(i, kind, links[1], pb, other=links[0], other_at=pa, s=ls, table=fs)
    k = _number(_need(raw, "stiffness", where), f"{where}: 'stiffness'")
    free = _number(raw.get("free_length", drawn), f"{where}: 'free_length'")
    if k < 0 or free < 0:
        raise ModelError(f"{where}: 'stiffness' and 'free_length' must be >= 0")
    return Load(i, kind, links[1], pb, other=links[0], other_at=pa, stiffness=k, free_length=free,
                preload=_number(raw.get("preload", 0.0), f"{where}: 'preload'"))


def _read_rotary_damper(mech, i, raw, where) -> Load:
    if "at" in raw or "links" in raw:
        raise ModelError(f"{where}: a rotational damper takes 'joint' only (no 'at' or 'links')")
    joint = str(raw["joint"])
    j = mech.joints.get(joint)
    if j is None or j.kind != "R":
        raise ModelError(f"{where}: joint '{joint}' is not a revolute joint of the model")
    c = _number(_need(raw, "damping", where), f"{where}: 'damping'")
    if c < 0:
        raise ModelError(f"{where}: 'damping' must be >= 0, got {c}")
    return Load(i, "damper", j.links[1], None, joint=joint, other=j.links[0], damping=c)


def _two_links(mech, value, where, required=False):
    if value is None and not required:
        return None
    if not isinstance(value, list) or len(value) != 2 or value[0] == value[1]:
        raise ModelError(f"{where}: 'links' must be two different links [a, b], got {value!r}")
    for name in value:
        if str(name) not in mech.links and str(name) != mech.ground:
            raise ModelError(f"{where}: '{name}' in 'links' is not a link of the model")
    return str(value[0]), str(value[1])


def _end_links(mech, ends, links, where) -> tuple[str, str]:
    """The links of a two-point element's ends: `links` if given, else each point's own link."""
    given = _two_links(mech, links, where)
    if given is not None:
        return given
    out = []
    for end in ends:
        if isinstance(end, str) and end in mech.points:
            out.append(mech.points[end].link)
        else:
            raise ModelError(f"{where}: say on which links the ends lie ('links = [a, b]'): {end!r} is "
                             "not a named point of one link")
    if out[0] == out[1]:
        raise ModelError(f"{where}: both ends are on link '{out[0]}'")
    return out[0], out[1]


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
    if not isinstance(at, str):
        raise ModelError(f"{where}: 'at' must be a point's name or [x, y], got {at!r}")
    name = at
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
    if "v" in f and motion.wq is not None:
        om, ep = motion.omega[:, :1], motion.epsilon[:, :1]
        v, a = f["v"][:, links], f["a"][:, links]
        real_a = a * om[..., None] ** 2 + v * ep[..., None]
        return motion.w[:, links], v * om[..., None], motion.e[:, links], real_a
    sol = engine.solve(motion.phi)
    engine.rates(sol, motion.omega, motion.epsilon)
    return sol.w[:, links], sol.v[:, links], sol.e[:, links], sol.a[:, links]


def point_motion(engine, motion, link: int, at) -> tuple[np.ndarray, np.ndarray]:
    """Position and real velocity (B, 2) each of the material point drawn at `at` (2,) on link `link`."""
    xy = world_points(motion, link, at)
    w, v, _, _ = real_frames(engine, motion, [link])
    r = motion.frames["r"][:, link]
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
    for value in out:
        value.force = np.where(on[:, None], value.force, 0.0)
        value.moment = np.where(on, value.moment, 0.0)
    return out


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
    pa, va = point_motion(engine, motion, ka, np.asarray(load.other_at, float))
    pb, vb = point_motion(engine, motion, kb, np.asarray(load.at, float))
    return ka, kb, pa, va, pb, vb


def spring_tension(load: Load, length: np.ndarray) -> np.ndarray:
    """Tension (B,) of a spring row at `length` (B,) (N, pulling its ends together when positive)."""
    if load.table:
        return np.interp(length, load.s, load.table)
    return load.preload + load.stiffness * (length - load.free_length)


def spring_energy(engine, motion, load: Load) -> np.ndarray:
    """Potential energy (B,) of a spring row (J): ∫T dl from the free length (linear), or from the
    table's first length (a table), so that only its changes matter."""
    _, _, pa, _, pb, _ = _element_ends(engine, motion, load)
    length = np.hypot(*(pb - pa).T)
    if not load.table:
        x = length - load.free_length
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
        origin = motion.frames["r"]
        return [LoadValue(load.name, kb, zero2, origin[:, kb].copy(), m),
                LoadValue(load.name, ka, zero2.copy(), origin[:, ka].copy(), -m)]
    ka, kb, pa, va, pb, vb = _element_ends(engine, motion, load)
    d = pb - pa
    length = np.hypot(d[:, 0], d[:, 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        u = d / length[:, None]
    if load.kind == "spring":
        tension = spring_tension(load, length)
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
