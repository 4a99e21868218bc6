"""The keys of the table, declared once: what the reader accepts and what the JSON Schema describes.

A `Section` is one table of the format (the document's top level, a `links` row, `[input]`,
`[gravity]`, ...): its `Key`s, each with a type, a unit, a default and a line of description. The table
reader (`_table.Row`) reads a row's keys through its section: it takes the default and the checks from
the `Key` and refuses, as a programming error, to read a key its section does not declare; so every key
the reader accepts is declared here. `mbplanar.formats.schema` turns the sections into the JSON Schema
printed by `mbplanar schema` (with the sections the cam and the forces declare beside their readers).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ._model import (ANGLE_UNITS, FOLLOWERS, HIGHER_KINDS, INERTIA_UNITS, LENGTH_UNITS, LOAD_TYPES, MOMENT_UNITS,
                     RHO_STEEL)

__all__ = ["Key", "Section", "MISSING", "UNITS", "DOCUMENT", "LINK", "JOINT", "POINT", "INPUT", "GRAVITY",
           "DYNAMICS", "FLYWHEEL", "PARAMETER", "LOAD_COMMON", "SWITCH", "LOADS", "GUIDE_LOADS", "CURVE", "HIGHER",
           "TOLERANCE", "CLEARANCE", "TOLERANCES", "SECTIONS"]


class _Missing:
    def __repr__(self):
        return "MISSING"


MISSING = _Missing()  # a key without a literal default

#: what each unit word of a `Key` means in the file
UNITS = {
    "length": "the table's length_unit (m unless it says cm, mm or in)",
    "deg": "degrees",
    "kg": "kg",
    "inertia": "the table's inertia_unit (kg*m^2 unless it says kg*cm^2, kg*mm^2 or kg*in^2)",
    "moment": "the table's moment_unit (N*m unless it says N*cm, N*mm or N*in)",
    "N": "newtons",
    "N/m": "N/m",
    "N*s/m": "N*s/m (in a joint: N*m*s/rad in the moment unit)",
    "moment*s/rad": "the moment unit times s/rad",
    "rad/s": "rad/s (m/s for a prismatic input)",
    "rad/s^2": "rad/s^2 (m/s^2 for a prismatic input)",
    "rpm": "revolutions per minute",
    "m/s^2": "m/s^2",
    "kg/m^3": "kg/m^3",
    "s": "seconds",
    "input": "the input's unit (deg, rad, or a length unit for a prismatic input)",
    "per input": "one value per input, in its unit",
    "dimension": "the dimension's own unit: the length_unit for lengths and coordinates, degrees for a guide's "
                 "angle, the input's unit for its zero, a parameter's unit for a parameter",
}


@dataclass(frozen=True)
class Key:
    """One key of a section.

    `kind` is one of "text" (a name: text or a whole number), "number", "integer", "boolean", "choice"
    (one of `choices`), "pair" ([x, y]), "names" (a list of `count` names), "numbers" (a list of
    numbers), "table" (the `Section` `section`), "rows" (a list of `section` rows, or a table of named
    rows), "any" (kept as written) or "custom" (its JSON Schema is `schema`). `unit` is a word of `UNITS`;
    `default` the value an absent key takes (`MISSING`: none, or one the reader computes, said in
    `default_doc`). `positive`, `nonzero`, `minimum`, `maximum` bound a number; `parameter` says which kind of
    `[parameters]` entry may stand for it ("length", "plain", "input", "angle"); `message` is what the
    reader says when a bound is broken.

    Examples
    --------
    >>> from mbplanar.model import CLEARANCE
    >>> key = CLEARANCE["clearance"]
    >>> key.kind, key.unit, key.required, key.minimum
    ('number', 'length', True, 0.0)
    """

    name: str
    kind: str
    doc: str
    unit: str = ""
    default: object = MISSING
    default_doc: str = ""
    required: bool = False
    positive: bool = False
    nonzero: bool = False
    minimum: float | None = None
    maximum: float | None = None
    exclusive: bool = False          # the bounds are exclusive
    choices: tuple = ()
    count: int = 2
    section: "Section | str | None" = None
    named: bool = False              # rows may also be a table of named rows ([links.2])
    schema: dict | None = None
    parameter: str | None = None
    message: str = ""                # the reader's words when a bound is broken ({key}, {value})


@dataclass(frozen=True)
class Section:
    """A table of the format: its `keys`, where it sits (`title`, e.g. "links[]") and what it is.

    `name` is its short name (a key of `SECTIONS`), `doc` what it is, `extra` more JSON Schema of the whole
    table (the keys one of which is required, ...). ``key in section`` and ``section[key]`` look a key up
    by name (a `KeyError` naming the section for another); `with_keys` extends it (a reader's own
    section); `parameter_fields` lists the numbers a ``[parameters]`` entry may stand for.

    Examples
    --------
    >>> from mbplanar.model import JOINT, SECTIONS
    >>> JOINT.title, "guide" in JOINT, SECTIONS["joint"] is JOINT
    ('joints[]', True, True)
    >>> SECTIONS["point"].parameter_fields()      # what a parameter may stand for in a points row
    {'fraction': 'plain', 'distance': 'dimension', 'offset': 'length'}
    """

    name: str
    title: str
    doc: str
    keys: tuple[Key, ...]
    extra: dict = field(default_factory=dict)   # further JSON Schema of the whole table (e.g. required ones)

    def __post_init__(self):
        names = [k.name for k in self.keys]
        if len(names) != len(set(names)):
            raise ValueError(f"section {self.name}: a key is declared twice")

    def __contains__(self, name) -> bool:
        return any(k.name == name for k in self.keys)

    def __getitem__(self, name) -> Key:
        for k in self.keys:
            if k.name == name:
                return k
        raise KeyError(f"'{name}' is not a key of the table's {self.title} section")

    @property
    def names(self) -> frozenset:
        return frozenset(k.name for k in self.keys)

    def with_keys(self, *keys: Key, name: str | None = None, title: str | None = None, doc: str | None = None):
        """This section with more keys (and maybe another name)."""
        return Section(name or self.name, title or self.title, doc or self.doc, self.keys + keys, self.extra)

    def parameter_fields(self) -> dict[str, str]:
        """The number keys a `[parameters]` entry may stand for, with the kind of number they hold."""
        return {k.name: k.parameter for k in self.keys if k.parameter and k.kind == "number"}


COMMENT = Key("comment", "any", "a note, ignored")
_NAME_SCHEMA = {"type": ["string", "integer"]}
_XY = {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}
_XY_OR_PARAMETER = {"type": "array", "items": {"type": ["number", "string"]}, "minItems": 2, "maxItems": 2}
_TWO_NAMES = {"type": "array", "items": _NAME_SCHEMA, "minItems": 2, "maxItems": 2}

_MASS = "mass and inertia must not be negative"
LINK = Section("link", "links[]", "one moving link (the ground need not be listed)", (
    Key("name", "text", "the link's name, as the joints name it", required=True),
    Key("length", "number", "the distance between the link's two revolute joints (makes the drawing a sketch)",
        unit="length", positive=True, parameter="dimension"),
    Key("lengths", "custom", "exact distances [P, Q, L] between points of the link (joints or points)",
        unit="length", default_doc="[]", schema={"type": "array", "items": {
            "type": "array", "minItems": 3, "maxItems": 3, "additionalItems": False,
            "items": [_NAME_SCHEMA, _NAME_SCHEMA, {"type": ["number", "string"], "exclusiveMinimum": 0}]}}),
    Key("angle", "names", "the two points [P, Q] whose direction is reported as the link's angle",
        default_doc="its first two revolute joints"),
    Key("angle_offset", "number", "added to the reported angle (a body axis at an angle to P→Q)", unit="deg",
        default=0.0),
    Key("mass", "number", "mass, for forces and dynamics", unit="kg", default=0.0, minimum=0.0, parameter="plain",
        message=_MASS),
    Key("inertia", "number", "moment of inertia about the centre of mass", unit="inertia", default=0.0,
        minimum=0.0, parameter="plain", message=_MASS),
    Key("centre", "custom", "the centre of mass: a point's name, or [x, y] in the drawing (a point "
        "'<link>:centre')", unit="length", schema={"anyOf": [_NAME_SCHEMA, _XY]}),
    COMMENT,
))

_POLAR = {"type": "object", "description": "a polar placement from another joint",
          "properties": {"from": _NAME_SCHEMA, "length": {"type": ["number", "string"]},
                         "angle": {"type": ["number", "string"]}},
          "required": ["from", "length", "angle"], "additionalProperties": False}

JOINT = Section("joint", "joints[]", "one lower pair (kinematic pair of the fifth class); the higher pairs "
                "(type gear, rack, cam, slot) have their own keys", (
    Key("name", "text", "the joint's name", required=True),
    Key("type", "choice", "revolute (R) or prismatic (P)", required=True, choices=("R", "P", "r", "p")),
    Key("links", "names", "the two links it joins; for P, the link that carries the guide first", required=True),
    Key("at", "custom", "its position in the drawing: [x, y], or { from = JOINT, length = L, angle = DEG }",
        unit="length", required=True, parameter="length", schema={"anyOf": [_XY_OR_PARAMETER, _POLAR]}),
    Key("guide", "custom", "P only: the guide's direction in the drawing, an angle or two points [P, Q] of the "
        "carrier", unit="deg", parameter="angle", schema={"anyOf": [{"type": ["number", "string"]}, _TWO_NAMES]}),
    Key("carrier", "text", "P only: the link that carries the guide, when it is not listed first",
        default_doc="the first of links"),
    COMMENT,
))

# -- higher pairs: one row type each, and the curve a cam's profile or a slot's path is --------------------
_POINTS_SCHEMA = {"type": "array", "items": _XY, "minItems": 2}
CURVE = Section("curve", "a cam's profile, a slot's path", "a curve drawn on a link: a circle (or an arc of one), "
                "a smooth spline through points, or the profile `mbplanar cam` wrote", (
    Key("centre", "pair", "a circle: its centre in the drawing", unit="length"),
    Key("radius", "number", "a circle: its radius", unit="length", positive=True, parameter="dimension",
        default_doc="a slot's: the pin's distance from the centre"),
    Key("arc", "pair", "a circle: only the arc [from, to], counter-clockwise, angles from +x at the centre",
        unit="deg", default_doc="the whole circle"),
    Key("points", "custom", "a spline: its points [[x, y], ...] in the drawing", unit="length",
        schema=_POINTS_SCHEMA),
    Key("closed", "boolean", "a spline: periodic, back at its first point after the last",
        default_doc="true for a cam's profile, false for a slot"),
    Key("parameter", "numbers", "a spline: its parameter at each point (one more for a closed curve)",
        default_doc="the cumulative chord length"),
    Key("degree", "choice", "a spline: its degree", choices=(3, 5), default=5),
    Key("file", "text", "or: the points from a CSV file (mbplanar cam's profile, in mm, or columns x, y in the "
        "table's length unit), relative to the model file"),
    Key("column", "choice", "with file: which curve of mbplanar cam's file", choices=("profile", "pitch"),
        default="profile"),
    Key("offset", "pair", "with file: where the file's origin is in the drawing", unit="length",
        default_doc="[0, 0]"),
    Key("rotate", "number", "with file: the file's points turned by this angle about its origin", unit="deg",
        default=0.0),
    COMMENT,
))

_TWO_COUNTS = {"type": "array", "items": {"type": "integer", "minimum": 1}, "minItems": 2, "maxItems": 2}
_TWO_LENGTHS = {"type": "array", "items": {"type": ["number", "string"]}, "minItems": 2, "maxItems": 2}
_PRESSURE = Key("pressure_angle", "number", "the line of action's angle to the common tangent: the contact "
                "force's direction", unit="deg", default=20.0, minimum=0.0, maximum=90.0, exclusive=True,
                parameter="angle", message="'pressure_angle' must be between 0 and 90 degrees, got {value:g}")
_NAME_OR_XY_PAIR = {"anyOf": [_NAME_SCHEMA, _XY_OR_PARAMETER]}


def _higher(kind: str, doc: str, *keys: Key) -> Section:
    return Section(f"{kind}_pair", f"joints[] ({kind})", doc, (
        Key("name", "text", "the pair's name", required=True),
        Key("type", "choice", doc, required=True, choices=(kind,)), *keys, COMMENT))


HIGHER = {
    "gear": _higher(
        "gear", "two gears in mesh (a higher pair): r_a(θ_a − θ_c) = ∓r_b(θ_b − θ_c)",
        Key("links", "names", "the two gears [a, b]; with mesh = internal, b has the internal teeth",
            required=True),
        Key("teeth", "custom", "tooth numbers [z_a, z_b] (with module: the pitch radii m·z/2)",
            schema=_TWO_COUNTS),
        Key("module", "number", "the module m", unit="length", positive=True, parameter="dimension"),
        Key("radii", "custom", "or: the pitch radii [r_a, r_b] (a shifted pair's working ones)", unit="length",
            schema=_TWO_LENGTHS),
        Key("mesh", "choice", "external or internal teeth", choices=("external", "internal"), default="external"),
        Key("carrier", "text", "the link on which both gears' centres are fixed (the ground for fixed axes)",
            default_doc="the link that holds both gears' pivots"),
        _PRESSURE,
        Key("at", "custom", "the pitch point in the drawing (checked against the centres and radii)",
            unit="length", default_doc="from the centres and the radii", schema=_XY_OR_PARAMETER)),
    "rack": _higher(
        "rack", "a pinion rolling on a rack (a higher pair): s = r·Δθ",
        Key("links", "names", "[pinion, rack]", required=True),
        Key("radius", "number", "the pinion's pitch radius", unit="length", positive=True, parameter="dimension"),
        Key("teeth", "integer", "or: the pinion's tooth number (with module)", minimum=1,
            message="'teeth' must be a whole number >= 1, got {value:g}"),
        Key("module", "number", "the module m", unit="length", positive=True, parameter="dimension"),
        Key("guide", "number", "the direction of the rack's pitch line in the drawing", unit="deg",
            parameter="angle", default_doc="square to the pinion's centre and the pitch point"),
        _PRESSURE,
        Key("at", "custom", "the pitch point (on the rack's pitch line, a pitch radius from the pinion's centre) in "
            "the drawing", unit="length", required=True, schema=_XY_OR_PARAMETER)),
    "cam": _higher(
        "cam", "a cam and its follower (a higher pair): the follower's element touches the profile",
        Key("links", "names", "[cam, follower]", required=True),
        Key("follower", "choice", "the follower's element", choices=FOLLOWERS, required=True),
        Key("at", "custom", "the follower's point: the knife's tip, the roller's or the circle's centre, a point "
            "of the flat face: a point or joint of the follower, or [x, y] in the drawing", unit="length",
            required=True, schema=_NAME_OR_XY_PAIR),
        Key("radius", "number", "the roller's or the circular face's radius", unit="length", positive=True,
            parameter="dimension"),
        Key("face", "number", "the flat face's direction in the drawing", unit="deg", parameter="angle",
            default_doc="along the profile's tangent at the contact"),
        Key("profile", "table", "the cam's profile in the drawing", section=CURVE, required=True)),
    "slot": _higher(
        "slot", "a pin in a curved slot (a higher pair); a straight slot is a P pair",
        Key("links", "names", "[the link with the slot, the pin's link]", required=True),
        Key("at", "custom", "the pin's centre: a point or joint of the pin's link, or [x, y] in the drawing",
            unit="length", required=True, schema=_NAME_OR_XY_PAIR),
        Key("path", "table", "the slot's centre line in the drawing", section=CURVE, required=True)),
}
assert tuple(HIGHER) == HIGHER_KINDS

POINT = Section("point", "points[]", "a point of interest on a link: a centre of mass, a coupler point", (
    Key("name", "text", "the point's name", required=True),
    Key("link", "text", "the link it belongs to", required=True),
    Key("at", "custom", "its position in the drawing", unit="length", parameter="length", schema=_XY_OR_PARAMETER),
    Key("along", "names", "or: on the line from point P to point Q of the link"),
    Key("fraction", "number", "with along: at P + fraction·(Q − P)", parameter="plain"),
    Key("distance", "number", "with along: at this distance from P towards Q", unit="length",
        parameter="dimension"),
    Key("offset", "number", "with along: this far to the left of P→Q", unit="length", default=0.0,
        parameter="length"),
    COMMENT,
))

INPUT = Section("input", "[input]", "one input (a driven joint) per degree of freedom", (
    Key("joint", "text", "the driving joint", required=True),
    Key("name", "text", "the generalized coordinate's name", default="phi"),
    Key("unit", "choice", "how φ is written (in any case)", choices=(*ANGLE_UNITS, *LENGTH_UNITS),
        default_doc="deg (revolute), the length_unit (prismatic)"),
    Key("zero", "number", "the joint's value when φ = 0", unit="input", default=0.0, parameter="input"),
    Key("sense", "custom", "the joint's value = zero + sense·φ", default=1,
        schema={"enum": [1, -1, 1.0, -1.0, "ccw", "cw"]}),
    Key("drawn_at", "number", "φ in the drawing; with it the drawing is a sketch", unit="input",
        default_doc="measured", parameter="input"),
    Key("omega", "number", "input speed dφ/dt for forces and dynamics", unit="rad/s", default=1.0,
        parameter="plain"),
    Key("rpm", "number", "instead of omega, for a revolute input", unit="rpm"),
    Key("epsilon", "number", "input acceleration d²φ/dt²", unit="rad/s^2", default=0.0),
    Key("sweep", "custom", "the default range [from, to] of sweep, check and the pictures", unit="input",
        default_doc="a full turn (revolute); required for a prismatic input", schema=_XY),
    Key("steps", "integer", "the default number of intervals of sweep", minimum=1, default_doc="72",
        message="steps must be a whole number ≥ 1, got {value:g}"),
    COMMENT,
))

GRAVITY = Section("gravity", "[gravity]", "uniform gravity on every link with a mass, at its centre", (
    Key("g", "number", "gravitational acceleration", unit="m/s^2", default=9.81, minimum=0.0,
        message="'g' must be >= 0 (turn 'direction' instead), got {value:g}"),
    Key("direction", "number", "its direction", unit="deg", default=-90.0),
    COMMENT,
))

_SHAFT = "'shaft_inertia' and 'motor_inertia' must be >= 0"
FLYWHEEL = Section("flywheel", "[dynamics.flywheel]", "where the flywheel goes and what is already there", (
    Key("shaft_inertia", "number", "inertia already on the crank shaft (gears, couplings)", unit="inertia",
        default=0.0, minimum=0.0, message=_SHAFT),
    Key("motor_rpm", "number", "put the flywheel on a motor shaft turning this fast", unit="rpm", positive=True),
    Key("link", "text", "or: put the flywheel on this link, a shaft the model's gears turn at a constant ratio "
        "to the crank (its speed ratio comes from the gears)"),
    Key("motor_inertia", "number", "the motor rotor's inertia, on the motor shaft", unit="inertia", default=0.0,
        minimum=0.0, message=_SHAFT),
    Key("density", "number", "the flywheel's material", unit="kg/m^3", default=RHO_STEEL, positive=True),
    Key("inertia", "number", "the first group the built machine has on the crank shaft besides the crank's own "
        "(flywheel, shafts, motor reduced to the crank): what simulate puts on the crank", unit="inertia",
        minimum=0.0, message="'shaft_inertia', 'motor_inertia' and 'inertia' must be >= 0"),
    COMMENT,
))

DYNAMICS = Section("dynamics", "[dynamics]", "machine dynamics of a crank-driven machine", (
    Key("delta", "number", "coefficient of speed fluctuation (ω_max − ω_min)/ω_m", required=True, positive=True,
        minimum=0.0, maximum=1.0, exclusive=True,
        message="'delta' = {value} must be between 0 and 1 (it is (ω_max − ω_min)/ω_m)"),
    Key("omega_mean", "number", "mean speed ω_m", unit="rad/s", positive=True, default_doc="the input's omega"),
    Key("rpm_mean", "number", "instead of omega_mean", unit="rpm", positive=True),
    Key("driving_moment", "number", "driving moment along φ", unit="moment",
        default_doc="the constant that balances the cycle"),
    Key("motor_slope", "number", "motor characteristic M_dr(ω) = M_dr − slope·(ω − ω_m), for the simulation",
        unit="moment*s/rad", default=0.0, minimum=0.0,
        message="'motor_slope' must be >= 0 (a motor gives less moment when faster)"),
    Key("flywheel", "table", "the flywheel's place and the inertia already there", section=FLYWHEEL),
    COMMENT,
))

PARAMETER = Section("parameter", "[parameters] entry", "a named design dimension given as a table", (
    Key("value", "number", "its value", required=True),
    Key("unit", "choice", "its unit (in any case)", choices=(*LENGTH_UNITS, *ANGLE_UNITS),
        default_doc="the unit of the field that uses it"),
    COMMENT,
))

# -- [tolerances]: the accuracy of the mechanism (mbplanar.accuracy, docs/accuracy.md) -------------------
_BAND = {"anyOf": [{"type": "number", "minimum": 0},
                   {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}]}
TOLERANCE = Section("tolerance", "[tolerances] dimensions[]", "one toleranced dimension and its band", (
    Key("name", "text", "the dimension: a parameter's name, links.L.length, links.L.P-Q, joints.J.x, joints.J.y, "
        "joints.J.guide, joints.J.offset, points.P.x, .y, .fraction, .distance, .offset, input.zero, or a "
        "higher pair's: joints.G.radius_a, .radius_b (gear), joints.K.radius, .guide, .x, .y (rack), "
        "joints.K.radius, .face, .x, .y, .profile.x, .profile.y, .profile.radius (cam), joints.S.x, .y, "
        ".path.x, .path.y, .path.radius (slot)",
        required=True),
    Key("band", "custom", "a symmetric band ±b, or the deviations [lower, upper] (uniform between them)",
        unit="dimension", schema=_BAND),
    Key("sigma", "number", "or: the standard deviation of a normal distribution about the nominal value",
        unit="dimension", minimum=0.0, message="'sigma' must not be negative, got {value:g}"),
    COMMENT,
))
CLEARANCE = Section("clearance", "[tolerances] clearances[]", "the clearance of one pair", (
    Key("joint", "text", "the pair (R or P)", required=True),
    Key("clearance", "number", "R: the radial clearance (hole radius minus pin radius); P: the block's largest "
        "offset across its guide", unit="length", required=True, minimum=0.0,
        message="'clearance' must not be negative, got {value:g}"),
    COMMENT,
))
TOLERANCES = Section("tolerances", "[tolerances]", "the mechanism's tolerances and clearances (docs/accuracy.md)", (
    Key("dimensions", "rows", "the toleranced dimensions, one row each", section=TOLERANCE),
    Key("clearances", "rows", "the pairs' clearances, one row each", section=CLEARANCE),
    Key("outputs", "custom", "what is reported: points and joints (their x and y), links (their angle), or "
        "X.x, X.y, L.angle, J.value", default_doc="every joint, point and moving link",
        schema={"type": "array", "items": {"type": ["string", "integer"]}}),
    Key("samples", "integer", "Monte Carlo samples", default=100000, minimum=1,
        message="'samples' must be a whole number >= 1, got {value:g}"),
    Key("seed", "integer", "the Monte Carlo's seed", default=0, minimum=0,
        message="'seed' must be a whole number >= 0, got {value:g}"),
    Key("positions", "integer", "positions over the cycle", default=360, minimum=2,
        message="'positions' must be a whole number >= 2, got {value:g}"),
    COMMENT,
))


# -- loads: the keys every row may have, then each type's -----------------------------------------------
_NAME_OR_XY = {"anyOf": [_NAME_SCHEMA, _XY]}
LOAD_COMMON = (
    Key("type", "choice", "the kind of load", required=True,
        choices=LOAD_TYPES),
    Key("name", "text", "a unique name, used in reports instead of loads[i]", schema={"type": "string", "minLength": 1}),
    COMMENT,
)
SWITCH = (
    Key("switch", "text", "a joint or point whose velocity's sign switches the row on and off"),
    Key("switch_direction", "number", "for a point: the direction its velocity is measured along", unit="deg",
        default=0.0),
    Key("when", "choice", "active while the switch's velocity is >= 0 (forward) or <= 0 (backward)",
        choices=("forward", "backward")),
)
_AT = Key("at", "custom", "where it acts: a point or joint on the link, or [x, y] of a material point in the "
          "drawing", unit="length", default_doc="the link's centre", schema=_NAME_OR_XY)
_LINK = Key("link", "text", "the moving link it acts on", required=True)
_GUIDE_LINK = Key("link", "text", "the link it acts on", default_doc="the joint's slider")
_GUIDE_AT = Key("at", "custom", "where it acts", unit="length", default_doc="the joint", schema=_NAME_OR_XY)
_PRISMATIC = Key("joint", "text", "the prismatic pair it acts along", required=True)
_TWO_LINKS = Key("links", "names", "the two links [a, b] it acts between (on b, and the reverse on a)",
                 default_doc="the links of the named end points")
_ENDS = Key("at", "custom", "its two ends [P, Q]: names of points, or [x, y] in the drawing", unit="length",
            required=True, schema={"type": "array", "minItems": 2, "maxItems": 2, "items": _NAME_OR_XY})


_SPRING = "'stiffness' and 'free_length' must be >= 0"


def _load(kind: str, doc: str, *keys: Key) -> Section:
    """A load type's row: the keys of every row, its own, and the switch's (a guide force has its joint)."""
    switch = () if kind in GUIDE_LOADS else SWITCH
    return Section(f"load_{kind}", f"loads[] ({kind})", doc, LOAD_COMMON + keys + switch,
                   {"dependencies": {"switch": ["when"], "switch_direction": ["switch"]}} if switch else {})


GUIDE_LOADS = ("resistance", "friction")   # forces along a prismatic pair


LOADS = {
    "force": _load("force", "a constant force", _LINK, _AT,
                   Key("force", "pair", "[Fx, Fy]", unit="N", required=True)),
    "weight": _load("weight", "a weight that is not m·g, along the gravity direction", _LINK, _AT,
                    Key("weight", "number", "its size", unit="N", required=True)),
    "moment": _load("moment", "a constant moment, counter-clockwise positive", _LINK,
                    Key("moment", "number", "its size", unit="moment", required=True)),
    "resistance": _load(
        "resistance", "a force along a guide opposing the slider's motion: constant, or a diagram in s",
        _PRISMATIC, _GUIDE_LINK, _GUIDE_AT,
        Key("force", "custom", "its size, or the diagram's forces (one per s)", unit="N", required=True,
            schema={"anyOf": [{"type": "number"}, {"type": "array", "items": {"type": "number"}}]}),
        Key("s", "numbers", "the diagram's displacements (times stroke)"),
        Key("stroke", "number", "the scale of s", unit="length", default=1.0, nonzero=True),
        Key("when", "choice", "when it acts: the joint's rate analogue >= 0, <= 0, or always",
            choices=("forward", "backward", "always"), default="always"),
        Key("zero_at", "number", "the input value where s = 0", unit="input")),
    "friction": _load("friction", "a constant force opposing the slider's velocity", _PRISMATIC, _GUIDE_LINK,
                      _GUIDE_AT, Key("force", "number", "its size", unit="N", required=True)),
    "spring": _load(
        "spring", "a spring between two links: linear, or a tension table in its length", _TWO_LINKS, _ENDS,
        Key("stiffness", "number", "spring rate", unit="N/m", minimum=0.0, message=_SPRING),
        Key("free_length", "number", "unstretched length", unit="length", minimum=0.0,
            default_doc="the ends' drawn distance", message=_SPRING),
        Key("preload", "number", "tension at the free length", unit="N", default=0.0),
        Key("length", "numbers", "or: the table's lengths (increasing)", unit="length"),
        Key("force", "numbers", "the table's tensions", unit="N")),
    "damper": _load(
        "damper", "a linear damper between two points, or a rotational one in a revolute joint", _TWO_LINKS,
        Key("at", "custom", "its two ends [P, Q] (a linear damper)", unit="length",
            schema={"type": "array", "minItems": 2, "maxItems": 2, "items": _NAME_OR_XY}),
        Key("damping", "number", "damping coefficient", unit="N*s/m", required=True, minimum=0.0,
            message="'damping' must be >= 0, got {value}"),
        Key("joint", "text", "a revolute joint (a rotational damper)")),
    "torque": _load("torque", "a constant torque between two links",
                    Key("links", "names", "the two links [a, b]: the torque acts on b, its reaction on a",
                        required=True),
        Key("moment", "number", "its size", unit="moment", required=True)),
}

DOCUMENT = Section("document", "top level", "a mechanism's table of kinematic pairs", (
    Key("name", "text", "the model's name, used in output", default_doc="the file's name"),
    Key("title", "text", "a longer title for pictures and reports", default=""),
    Key("ground", "text", "the name of the frame link", default="0"),
    Key("length_unit", "choice", "the unit of every length and coordinate (in: inch; the reader takes any case)",
        choices=tuple(LENGTH_UNITS), default="m"),
    Key("inertia_unit", "choice", "the unit of every inertia (the reader takes any case, · for * and ² for ^2)",
        choices=tuple(INERTIA_UNITS), default="kg*m^2"),
    Key("moment_unit", "choice", "the unit of every moment (the reader takes any case, · for *)",
        choices=tuple(MOMENT_UNITS), default="N*m"),
    Key("links", "rows", "the moving links", section=LINK, named=True),
    Key("joints", "rows", "the pairs, one row each (lower pairs R, P; higher pairs gear, rack, cam, slot)",
        section=JOINT, required=True, named=True),
    Key("points", "rows", "points of interest", section=POINT, named=True),
    Key("input", "table", "the input of a one-input mechanism", section=INPUT),
    Key("inputs", "rows", "the inputs of a mechanism with several (the first is the main one)", section=INPUT),
    Key("loads", "custom", "external loads and force elements, one row each (see each type)"),
    Key("gravity", "table", "uniform gravity", section=GRAVITY),
    Key("dynamics", "table", "machine dynamics data", section=DYNAMICS),
    Key("parameters", "custom", "named design dimensions: name = number or { value, unit }"),
    Key("description", "any", "free text, kept and ignored"),
    Key("plot", "any", "settings kept for the pictures"),
    Key("cam", "table", "a cam timed by this linkage (see docs/cam.md)", section="cam"),
    Key("gears", "table", "the drive's gears: a spur pair, a planetary train (see docs/gears.md)", section="gears"),
    Key("friction", "table", "friction in the pairs (see docs/forces.md)", section="friction"),
    Key("simulate", "table", "the motion under given forces (see docs/forces.md)", section="simulate"),
    Key("synthesis", "any", "the summary of the synthesis that made the model (written by mbplanar synth)"),
    Key("tolerances", "table", "tolerances and clearances, for mbplanar accuracy (see docs/accuracy.md)",
        section=TOLERANCES),
))

#: every section of the model layer by name (the cam's and the forces' sit beside their readers)
SECTIONS = {s.name: s for s in (DOCUMENT, LINK, JOINT, POINT, INPUT, GRAVITY, DYNAMICS, FLYWHEEL, PARAMETER,
                                TOLERANCES, TOLERANCE, CLEARANCE, *LOADS.values(), CURVE, *HIGHER.values())}
