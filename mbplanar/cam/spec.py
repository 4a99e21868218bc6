"""Reading a cam: the `[cam]` section of a model file, or a cam file whose `[cam]` names a model.

Lengths in metres (or `length_unit` = "mm" / "cm" in `[cam]`), angles in degrees. A phase angle, the
cam's `start` and the `window` may be numbers or arithmetic on the names of timing events
(``"abs(fp2) + 0.5*fp1 - 10"``: + − * / and abs, min, max). See docs/cam.md for every key.
"""

from __future__ import annotations

import ast
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import ModelError
from ..model._model import LENGTH_UNITS, unit_name

__all__ = ["CamSpec", "PhaseSpec", "EventSpec", "DynamicsSpec", "read_cam", "parse_cam", "evaluate"]



@dataclass(frozen=True)
class PhaseSpec:
    """One `[[cam.phases]]` row (angle still unevaluated; lengths in m)."""

    kind: str
    angle: float | str
    law: str = "dwell"
    k: float = 1.0
    stroke: float | None = None
    start: tuple[float, ...] = ()
    end: tuple[float, ...] = ()
    where: str = ""
    swing: float | None = None               # deg: an oscillating follower's stroke as an angle


@dataclass(frozen=True)
class EventSpec:
    """One `[[cam.events]]` row."""

    name: str
    point: str
    coordinate: str = "x"
    fraction: float | None = None
    measure: str = "fraction"
    direction: str | None = None


@dataclass(frozen=True)
class DynamicsSpec:
    """`[cam.dynamics]`: cam speed, follower inertia and spring (SI)."""

    speed: float                  # rad/s
    mass: float = 0.0             # translating: kg; oscillating: inertia about the pivot, kg·m²
    spring_rate: float = 0.0      # N/m or N·m/rad
    preload: float = 0.0          # N or N·m at s = 0
    force: float = 0.0            # constant load on the follower, N or N·m, resisting the rise


@dataclass(frozen=True)
class CamSpec:
    """Everything a `[cam]` section says, in SI (angles still degrees where they may be expressions)."""

    source: str
    model: str | None
    motion: str
    contact: str
    rotation: int
    phases: tuple[PhaseSpec, ...]
    events: tuple[EventSpec, ...] = ()
    base_radius: float | None = None
    offset: float | str = 0.0
    roller: float | None = None
    roller_ratio: float | None = None
    arm: float | None = None
    centre_distance: float | None = None
    arm_angle: float | None = None           # deg
    face_offset: float = 0.0
    rise_limit: float = 30.0                 # deg
    return_limit: float = 30.0               # deg
    size: bool = False
    min_radius: float | None = None
    samples: int = 1440
    start: float | str = 0.0
    window: tuple = ()
    dynamics: DynamicsSpec | None = None
    title: str = ""
    linkage: object = field(default=None, compare=False, repr=False)


class _Table:
    """Typed reads of one TOML table with errors naming the file and the table."""

    def __init__(self, data, where):
        if not isinstance(data, dict):
            raise ModelError(f"{where}: expected a table {{...}}, got {type(data).__name__}")
        self.data, self.where, self.used = data, where, set()

    def fail(self, msg):
        raise ModelError(f"{self.where}: {msg}")

    def get(self, key, default=None, kind=float, required=False, positive=False):
        self.used.add(key)
        if key not in self.data:
            if required:
                self.fail(f"missing '{key}'")
            return default
        value = self.data[key]
        if kind is float:
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                self.fail(f"'{key}' must be a finite number, got {value!r}")
            value = float(value)
            if positive and value <= 0:
                self.fail(f"'{key}' must be positive, got {value:g}")
            return value
        if kind == "angle":          # a number or an expression on event names
            if isinstance(value, bool) or not isinstance(value, (int, float, str)):
                self.fail(f"'{key}' must be a number (degrees) or an expression, got {value!r}")
            return float(value) if not isinstance(value, str) else value
        if not isinstance(value, kind) or isinstance(value, bool) and kind is not bool:
            self.fail(f"'{key}' must be {kind.__name__}, got {value!r}")
        return value

    def done(self):
        unknown = set(self.data) - self.used
        if unknown:
            self.fail(f"unknown key(s) {', '.join(sorted(unknown))}")


def read_cam(path) -> CamSpec:
    """Read a cam file, or a model file with a `[cam]` section.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    CamSpec

    Raises
    ------
    ModelError
        unreadable file, TOML syntax, unknown or mistyped keys (naming the file, table and row).
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise ModelError(f"{path}: cannot read the cam file ({exc.strerror or exc})") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"{path}: TOML syntax error: {exc}") from None
    return parse_cam(data, source=str(path))


def parse_cam(data: dict, source: str = "<cam>") -> CamSpec:
    """A `CamSpec` from a parsed TOML document (a cam file or a model with `[cam]`)."""
    if "cam" not in data:
        raise ModelError(f"{source}: no [cam] section")
    linkage = None
    if "links" in data or "joints" in data:               # a model file carrying its cam
        from ..model import parse_model
        linkage = parse_model(data, source=source)
    else:
        unknown = set(data) - {"cam", "name", "title"}
        if unknown:
            raise ModelError(f"{source}: unknown key(s) {', '.join(sorted(unknown))} in a cam file")
    t = _Table(data["cam"], f"{source}: [cam]")
    # a model's [cam] measures in the model's length_unit unless it says otherwise
    written = t.get("length_unit", data.get("length_unit", "m") if linkage is not None else "m", str)
    if unit_name(written, LENGTH_UNITS) is None:
        t.fail(f"length_unit must be one of {', '.join(LENGTH_UNITS)} (in any case), got '{written}'")
    unit = LENGTH_UNITS[unit_name(written, LENGTH_UNITS)]
    model = t.get("model", None, str)
    if model is not None:
        if linkage is not None:
            t.fail("'model' names another model, but this file is a model itself")
        model = str((Path(source).parent / model))
    motion = t.get("follower", "translating", str)
    contact = t.get("contact", "roller", str)
    rotation = {"ccw": 1, "cw": -1}.get(t.get("rotation", "ccw", str))
    if rotation is None:
        t.fail(f"rotation must be 'ccw' or 'cw', got {data['cam']['rotation']!r}")

    def length(key, default=None, positive=False):
        v = t.get(key, None, float, positive=positive)
        return default if v is None else v * unit

    limit = t.get("pressure_limit", 30.0)
    offset = data["cam"].get("offset", 0.0)
    if isinstance(offset, str):
        t.used.add("offset")
        if offset != "free":
            t.fail(f"offset must be a length or \"free\", got {offset!r}")
    else:
        offset = length("offset", 0.0)
    window = t.get("window", (), list)
    if window and len(window) != 2:
        t.fail(f"window must be [from, to], got {window!r}")
    spec = CamSpec(
        source=source, model=model, motion=motion, contact=contact, rotation=rotation,
        phases=_phases(data["cam"].get("phases"), t, unit),
        events=_events(data["cam"].get("events", []), t),
        base_radius=length("base_radius", positive=True), offset=offset,
        roller=length("roller", positive=True), roller_ratio=t.get("roller_ratio", None, positive=True),
        arm=length("arm", positive=True), centre_distance=length("centre_distance", positive=True),
        arm_angle=t.get("arm_angle"), face_offset=length("face_offset", 0.0),
        rise_limit=t.get("rise_limit", limit), return_limit=t.get("return_limit", limit),
        size=t.get("size", False, bool), min_radius=length("min_radius"),
        samples=int(t.get("samples", 1440.0, positive=True)), start=t.get("start", 0.0, "angle"),
        window=tuple(window), dynamics=_dynamics(data["cam"].get("dynamics"), t, unit),
        title=t.get("title", str(data.get("title", "")), str), linkage=linkage)
    t.used |= {"phases", "events", "dynamics"}
    t.done()
    return spec


def _phases(rows, t, unit):
    if not isinstance(rows, list) or not rows:
        t.fail("missing 'phases' (a list of rise, dwell and return rows)")
    out = []
    for i, raw in enumerate(rows):
        r = _Table(raw, f"{t.where} phases[{i}]")
        kind = r.get("kind", None, str, required=True)
        if kind not in ("rise", "return", "dwell", "polynomial"):
            r.fail(f"kind must be rise, return, dwell or polynomial, got '{kind}'")
        angle = r.get("angle", None, "angle", required=True)
        stroke, swing = r.get("stroke"), r.get("swing")
        for name, value in (("stroke", stroke), ("swing", swing)):
            if value is not None and value <= 0:
                r.fail(f"the {name} must be positive, got {value:g}")
        if stroke is not None and swing is not None:
            r.fail("give 'stroke' (the arc at the arm) or 'swing' (deg), not both")
        law = r.get("law", "dwell" if kind == "dwell" else "polynomial" if kind == "polynomial" else None,
                    str, required=kind in ("rise", "return"))
        ends = []
        for key in ("start", "end"):
            v = r.get(key, [], list, required=kind == "polynomial")
            if not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v):
                r.fail(f"'{key}' must be a list of numbers [s, v, a, ...]")
            ends.append(tuple(float(x) * unit for x in v))
        out.append(PhaseSpec(kind, angle, law, r.get("k", 1.0, positive=True),
                             None if stroke is None else stroke * unit, ends[0], ends[1], r.where, swing))
        r.done()
    return tuple(out)


def _events(rows, t):
    if not isinstance(rows, list):
        t.fail("'events' must be a list of rows")
    out = []
    for i, raw in enumerate(rows):
        r = _Table(raw, f"{t.where} events[{i}]")
        out.append(EventSpec(r.get("name", None, str, required=True), r.get("point", None, str, required=True),
                             r.get("coordinate", "x", str), r.get("fraction"),
                             r.get("measure", "fraction", str), r.get("direction", None, str)))
        r.done()
    return tuple(out)


def _dynamics(raw, t, unit):
    if raw is None:
        return None
    r = _Table(raw, f"{t.where} dynamics")
    rpm = r.get("rpm", None, positive=True)
    omega = r.get("omega", None, positive=True)
    if (rpm is None) == (omega is None):
        r.fail("give the cam speed as 'rpm' or 'omega' (rad/s)")
    spec = DynamicsSpec(omega if omega is not None else rpm * math.pi / 30, r.get("mass", 0.0),
                        r.get("spring_rate", 0.0), r.get("preload", 0.0), r.get("force", 0.0))
    if spec.mass < 0 or spec.spring_rate < 0:
        r.fail("mass and spring_rate must not be negative")
    r.done()
    return spec


_FUNCS = {"abs": abs, "min": min, "max": max}


def evaluate(expr, names: dict, where: str) -> float:
    """A number, or the value of an arithmetic expression on `names` (+ − * /, abs, min, max)."""
    if not isinstance(expr, str):
        return float(expr)
    try:
        tree = ast.parse(expr, mode="eval")
    except SyntaxError:
        raise ModelError(f"{where}: cannot read the expression {expr!r}") from None

    def walk(node):
        if isinstance(node, ast.Expression):
            return walk(node.body)
        if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
            return float(node.value)
        if isinstance(node, ast.Name):
            if node.id not in names:
                known = ", ".join(names) or "none defined"
                raise ModelError(f"{where}: unknown name '{node.id}' in {expr!r} (events: {known})")
            return float(names[node.id])
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
            v = walk(node.operand)
            return -v if isinstance(node.op, ast.USub) else v
        if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Add, ast.Sub, ast.Mult, ast.Div)):
            a, b = walk(node.left), walk(node.right)
            ops = {ast.Add: a + b, ast.Sub: a - b, ast.Mult: a * b}
            if isinstance(node.op, ast.Div):
                if b == 0:
                    raise ModelError(f"{where}: division by zero in {expr!r}")
                return a / b
            return ops[type(node.op)]
        if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in _FUNCS
                and not node.keywords):
            return float(_FUNCS[node.func.id](*(walk(a) for a in node.args)))
        raise ModelError(f"{where}: only numbers, event names, + - * / and abs/min/max are allowed in "
                         f"{expr!r}")

    return walk(tree)
