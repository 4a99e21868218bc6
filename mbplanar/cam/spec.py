"""Reading a cam: the `[cam]` section of a model file, or a cam file whose `[cam]` names a model.

Lengths in metres (or `length_unit` = "mm", "cm", "in" in `[cam]`, in any case; a model's `[cam]` takes
the model's `length_unit`), angles in degrees. A stroke or a length 100 times larger or smaller than the
cam's size (its base radius, centre distance or arm; else the model's drawing) warns with the numbers
(`mbplanar.model._scale`). A phase angle, the
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
from ..model import LENGTH_UNITS, MISSING, Key, Section, drawing_size, unit_spelling, warn_scale
from .followers import CONTACTS, MOTIONS
from .laws import LAWS

__all__ = ["CamSpec", "PhaseSpec", "EventSpec", "DynamicsSpec", "read_cam", "parse_cam", "evaluate", "CAM",
           "CAM_FILE"]

_EXPRESSION = {"type": ["number", "string"]}

# -- the keys of [cam], declared once: the reader below reads them through these, the JSON Schema shows them
CAM_PHASE = Section("cam_phase", "[cam] phases[]", "one phase of the motion program", (
    Key("kind", "choice", "the phase", required=True, choices=("rise", "return", "dwell", "polynomial")),
    Key("angle", "custom", "its cam angle: degrees, an expression on event names, or \"rest\" (what is left of "
        "360°)", unit="deg", required=True, schema=_EXPRESSION),
    Key("law", "choice", "the motion law of a rise or return", choices=tuple(LAWS) + ("polynomial",),
        default_doc="dwell (dwell), polynomial (polynomial); required for a rise or return"),
    Key("k", "number", "constant acceleration: a₁/a₂", default=1.0, positive=True),
    Key("stroke", "number", "the lift (a return: the whole lift by default)", unit="length", positive=True),
    Key("swing", "number", "oscillating follower: the stroke as an angle (the arc at the arm)", unit="deg",
        positive=True),
    Key("start", "numbers", "polynomial: [s, v, a, ...] at its start (m, m/rad, m/rad², ...)", default=[]),
    Key("end", "numbers", "polynomial: [s, v, a, ...] at its end", default=[])))
CAM_EVENT = Section("cam_event", "[cam] events[]", "a timing event on the model", (
    Key("name", "text", "its name, usable in angle, start and window expressions", required=True),
    Key("point", "text", "a joint or point of the model", required=True),
    Key("coordinate", "choice", "the coordinate followed", choices=("x", "y"), default="x"),
    Key("fraction", "number", "the event: the point's displacement from its minimum is this fraction of its "
        "stroke"),
    Key("measure", "choice", "fraction, or forward_angle (the input angle from the minimum to the maximum)",
        choices=("fraction", "forward_angle"), default="fraction"),
    Key("direction", "choice", "which root when there are several", choices=("rising", "falling", "any"))))
CAM_DYNAMICS = Section("cam_dynamics", "[cam.dynamics]", "cam speed, follower inertia and spring", (
    Key("rpm", "number", "the cam speed (or omega)", unit="rpm", positive=True),
    Key("omega", "number", "the cam speed (or rpm)", unit="rad/s", positive=True),
    Key("mass", "number", "follower mass (kg; oscillating: inertia about the pivot, kg·m²)", default=0.0,
        minimum=0.0),
    Key("spring_rate", "number", "spring rate (N/m or N·m/rad)", default=0.0, minimum=0.0),
    Key("preload", "number", "spring force at s = 0 (N or N·m)", default=0.0),
    Key("force", "number", "a constant load resisting the rise (N or N·m)", default=0.0)))
CAM = Section("cam", "[cam]", "a cam: follower, motion program, sizing (docs/cam.md)", (
    Key("model", "text", "cam files only: the linkage model whose cycle times the cam (a path)"),
    Key("follower", "choice", "the follower's motion", choices=MOTIONS, default="translating"),
    Key("contact", "choice", "the follower's contact", choices=CONTACTS, default="roller"),
    Key("rotation", "choice", "the cam's sense", choices=("ccw", "cw"), default="ccw"),
    Key("length_unit", "choice", "the unit of every length of [cam] (in any case)", choices=tuple(LENGTH_UNITS),
        default_doc="m (a model's [cam]: the model's length_unit)"),
    Key("base_radius", "number", "translating: from the cam centre to the roller centre at s = 0; flat: to the "
        "face", unit="length", positive=True),
    Key("offset", "custom", "translating: the follower line's x, or \"free\" (sizing chooses it)",
        unit="length", default=0.0, schema={"anyOf": [{"type": "number"}, {"const": "free"}]}),
    Key("roller", "number", "roller radius", unit="length", positive=True),
    Key("roller_ratio", "number", "or: the roller radius over r₀ (after sizing)", positive=True),
    Key("arm", "number", "oscillating: pivot to roller centre", unit="length", positive=True),
    Key("centre_distance", "number", "oscillating: pivot to cam centre", unit="length", positive=True),
    Key("arm_angle", "number", "oscillating: from the pivot→cam-centre line to the arm at s = 0", unit="deg"),
    Key("face_offset", "number", "oscillating flat face: from the pivot to the face", unit="length", default=0.0),
    Key("pressure_limit", "number", "largest pressure angle of both strokes", unit="deg", default=30.0),
    Key("rise_limit", "number", "the rise's own limit", unit="deg", default_doc="pressure_limit"),
    Key("return_limit", "number", "the return's own limit", unit="deg", default_doc="pressure_limit"),
    Key("size", "boolean", "find the smallest cam", default=False),
    Key("min_radius", "number", "flat face sizing: smallest radius of curvature of the profile", unit="length",
        default_doc="0.1·stroke"),
    Key("samples", "number", "cam angles of the profile (a whole number)", default=1440.0, positive=True),
    Key("start", "custom", "the linkage's input value at cam angle 0 (a number or an expression)", unit="input",
        default=0.0, schema=_EXPRESSION),
    Key("window", "custom", "the rise must lie between these input values [from, to]", unit="input",
        default=[], schema={"type": "array", "items": _EXPRESSION, "minItems": 2, "maxItems": 2}),
    Key("title", "text", "the cam's title", default_doc="the file's title"),
    Key("phases", "rows", "the motion program: rise, dwell, return rows adding up to 360°", required=True,
        section=CAM_PHASE),
    Key("events", "rows", "timing events on the model", section=CAM_EVENT),
    Key("dynamics", "table", "spring and inertia", section=CAM_DYNAMICS)))
#: a cam file (no linkage of its own): its keys
CAM_FILE = Section("cam_file", "cam file", "a cam file: a [cam] that names its model", (
    Key("cam", "table", "the cam", section=CAM, required=True),
    Key("name", "text", "its name"),
    Key("title", "text", "its title")))


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
    length_unit: str = "m"                   # the unit the section's lengths were written in


class _Table:
    """Typed reads of one TOML table with errors naming the file and the table; the keys it reads are those
    its `section` declares (a key's default, when not given, is the declared one)."""

    def __init__(self, data, where, section: Section):
        if not isinstance(data, dict):
            raise ModelError(f"{where}: expected a table {{...}}, got {type(data).__name__}")
        self.data, self.where, self.used, self.section = data, where, set(), section

    def fail(self, msg):
        raise ModelError(f"{self.where}: {msg}")

    def get(self, key, default=MISSING, kind=float, required=None, positive=None):
        declared = self.section[key]   # (a KeyError: read but not declared)
        default = (None if declared.default is MISSING else declared.default) if default is MISSING else default
        required = declared.required if required is None else required
        positive = declared.positive if positive is None else positive
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
    """Read a cam file, or a model file with a `[cam]` section (its linkage then times the cam).

    Parameters
    ----------
    path : str or Path
        The TOML file.

    Returns
    -------
    CamSpec
        The cam's description in the file's units (lengths in `length_unit`, angles in degrees); a
        `[cam] model` is read too (`linkage`).

    Raises
    ------
    ModelError
        An unreadable file, a TOML syntax error, unknown or mistyped keys (naming the file, table and
        row), or a linkage model that does not read.

    Examples
    --------
    >>> from mbplanar.cam import read_cam
    >>> spec = read_cam("models/cam_roller.toml")
    >>> spec.motion, spec.contact, spec.length_unit, spec.base_radius, spec.roller     # m, as SI inside
    ('translating', 'roller', 'mm', 0.05, 0.01)
    >>> [(p.kind, p.angle, p.law) for p in spec.phases][:2]
    [('rise', 120.0, 'cycloidal'), ('dwell', 60.0, 'dwell')]
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
    """A cam's description from a parsed TOML document: a cam file's, or a model's with a `[cam]`.

    Parameters
    ----------
    data : dict
        The document as `tomllib` gives it: a `[cam]` table (follower, contact, sizes, limits,
        `phases`, optional `events`, `[cam.dynamics]`), and a model's tables when it is a model file.
    source : str
        The file's name, for the messages.

    Returns
    -------
    CamSpec
        The description, checked key by key.

    Raises
    ------
    ModelError
        No `[cam]` section, unknown or mistyped keys, a non-positive size, a bad phase row or unit,
        an expression that does not read (the message names the table and row).

    Examples
    --------
    A translating knife-edge, simple-harmonic rise and return over half a turn each:

    >>> from mbplanar.cam import parse_cam
    >>> cam = {"follower": "translating", "contact": "knife", "base_radius": 0.04,
    ...        "phases": [{"kind": "rise", "angle": 180.0, "law": "simple_harmonic", "stroke": 0.02},
    ...                   {"kind": "return", "angle": 180.0, "law": "simple_harmonic"}]}
    >>> spec = parse_cam({"cam": cam})
    >>> spec.base_radius, spec.rise_limit, [p.kind for p in spec.phases]        # default limit: 30°
    (0.04, 30.0, ['rise', 'return'])
    >>> parse_cam({"cam": {**cam, "folower": "translating"}})
    Traceback (most recent call last):
    ...
    mbplanar.errors.ModelError: <cam>: [cam]: unknown key(s) folower
    """
    if "cam" not in data:
        raise ModelError(f"{source}: no [cam] section")
    linkage = None
    if "links" in data or "joints" in data:               # a model file carrying its cam
        from ..model import parse_model
        linkage = parse_model(data, source=source)
    else:
        unknown = set(data) - CAM_FILE.names
        if unknown:
            raise ModelError(f"{source}: unknown key(s) {', '.join(sorted(unknown))} in a cam file")
    t = _Table(data["cam"], f"{source}: [cam]", CAM)
    # a model's [cam] measures in the model's length_unit unless it says otherwise
    given = t.get("length_unit", linkage.units.length if linkage is not None else "m", str)
    unit_name = unit_spelling(given, LENGTH_UNITS)
    if unit_name is None:
        t.fail(f"length_unit must be one of {', '.join(LENGTH_UNITS)} (in any case), got '{given}'")
    unit = LENGTH_UNITS[unit_name]
    model = t.get("model", kind=str)
    if model is not None:
        if linkage is not None:
            t.fail("'model' names another model, but this file is a model itself")
        model = str((Path(source).parent / model))
    motion = t.get("follower", kind=str)
    contact = t.get("contact", kind=str)
    rotation = {"ccw": 1, "cw": -1}.get(t.get("rotation", kind=str))
    if rotation is None:
        t.fail(f"rotation must be 'ccw' or 'cw', got {data['cam']['rotation']!r}")

    def length(key, default=None):
        v = t.get(key, None, float)
        return default if v is None else v * unit

    limit = t.get("pressure_limit")
    offset = data["cam"].get("offset", CAM["offset"].default)
    if isinstance(offset, str):
        t.used.add("offset")
        if offset != "free":
            t.fail(f"offset must be a length or \"free\", got {offset!r}")
    else:
        offset = length("offset", CAM["offset"].default)
    window = t.get("window", kind=list)
    if window and len(window) != 2:
        t.fail(f"window must be [from, to], got {window!r}")
    spec = CamSpec(
        source=source, model=model, motion=motion, contact=contact, rotation=rotation,
        phases=_phases(data["cam"].get("phases"), t, unit),
        events=_events(data["cam"].get("events", []), t),
        base_radius=length("base_radius"), offset=offset,
        roller=length("roller"), roller_ratio=t.get("roller_ratio"),
        arm=length("arm"), centre_distance=length("centre_distance"),
        arm_angle=t.get("arm_angle"), face_offset=length("face_offset", CAM["face_offset"].default),
        rise_limit=t.get("rise_limit", limit), return_limit=t.get("return_limit", limit),
        size=t.get("size", kind=bool), min_radius=length("min_radius"),
        samples=int(t.get("samples")), start=t.get("start", kind="angle"),
        window=tuple(window), dynamics=_dynamics(data["cam"].get("dynamics"), t, unit),
        title=t.get("title", str(data.get("title", "")), str), linkage=linkage, length_unit=unit_name)
    t.used |= {"phases", "events", "dynamics"}
    t.done()
    _check_scale(spec, unit_name, t.where)
    return spec


def _check_scale(spec: CamSpec, unit_name: str, where: str):
    """Warn for a stroke or a length 100 times larger or smaller than the cam's size: its base radius,
    else its centre distance or arm, else the smallest radius asked for, else the linkage's drawing."""
    unit = LENGTH_UNITS[unit_name]
    named = [("base_radius", spec.base_radius), ("centre_distance", spec.centre_distance), ("arm", spec.arm),
             ("min_radius", spec.min_radius)]
    ref = next(((k, v) for k, v in named if v), None)
    if ref is None and spec.linkage is not None and drawing_size(spec.linkage):
        ref = ("the drawing", drawing_size(spec.linkage))
    if ref is None:
        return
    reference = f"{ref[0]} =" if ref[0] != "the drawing" else "the linkage's drawing spans"
    for phase in spec.phases:
        if phase.stroke is not None:
            warn_scale("its stroke =", phase.stroke, ref[1], unit_name, unit, where=phase.where, reference=reference)
    for key, value in (("roller", spec.roller), ("offset", spec.offset), ("face_offset", spec.face_offset),
                       *named):
        if key != ref[0] and isinstance(value, float):
            warn_scale(f"{key} =", value, ref[1], unit_name, unit, where=where, reference=reference)


def _phases(rows, t, unit):
    if not isinstance(rows, list) or not rows:
        t.fail("missing 'phases' (a list of rise, dwell and return rows)")
    out = []
    for i, raw in enumerate(rows):
        r = _Table(raw, f"{t.where} phases[{i}]", CAM_PHASE)
        kind = r.get("kind", kind=str)
        if kind not in CAM_PHASE["kind"].choices:
            r.fail(f"kind must be rise, return, dwell or polynomial, got '{kind}'")
        angle = r.get("angle", kind="angle")
        stroke, swing = r.get("stroke", positive=False), r.get("swing", positive=False)  # (checked here:)
        for name, value in (("stroke", stroke), ("swing", swing)):
            if value is not None and value <= 0:
                r.fail(f"the {name} must be positive, got {value:g}")
        if stroke is not None and swing is not None:
            r.fail("give 'stroke' (the arc at the arm) or 'swing' (deg), not both")
        law = r.get("law", "dwell" if kind == "dwell" else "polynomial" if kind == "polynomial" else None,
                    str, required=kind in ("rise", "return"))
        ends = []
        for key in ("start", "end"):
            v = r.get(key, kind=list, required=kind == "polynomial")
            if not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v):
                r.fail(f"'{key}' must be a list of numbers [s, v, a, ...]")
            ends.append(tuple(float(x) * unit for x in v))
        out.append(PhaseSpec(kind, angle, law, r.get("k"),
                             None if stroke is None else stroke * unit, ends[0], ends[1], r.where, swing))
        r.done()
    return tuple(out)


def _events(rows, t):
    if not isinstance(rows, list):
        t.fail("'events' must be a list of rows")
    out = []
    for i, raw in enumerate(rows):
        r = _Table(raw, f"{t.where} events[{i}]", CAM_EVENT)
        out.append(EventSpec(r.get("name", kind=str), r.get("point", kind=str), r.get("coordinate", kind=str),
                             r.get("fraction"), r.get("measure", kind=str), r.get("direction", kind=str)))
        r.done()
    return tuple(out)


def _dynamics(raw, t, unit):
    if raw is None:
        return None
    r = _Table(raw, f"{t.where} dynamics", CAM_DYNAMICS)
    rpm = r.get("rpm")
    omega = r.get("omega")
    if (rpm is None) == (omega is None):
        r.fail("give the cam speed as 'rpm' or 'omega' (rad/s)")
    spec = DynamicsSpec(omega if omega is not None else rpm * math.pi / 30, r.get("mass"),
                        r.get("spring_rate"), r.get("preload"), r.get("force"))
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
