"""The mechanism model: links, joints, points of interest and inputs, as written in a table of pairs.

A `Mechanism` holds what the user wrote: coordinates of every joint and point in one drawn pose (metres),
optionally link dimensions that make that pose a sketch. `mbplanar.model.assemble` turns it into an
exact model (same type, `exact=True`) that the engine uses. Everything here is plain data in SI units;
angles are radians except where a name ends in `_deg`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import ModelError

__all__ = ["Units", "Link", "Joint", "Curve", "HigherPair", "Point", "Input", "Load", "Gravity", "FlywheelSpec",
           "DynamicsSpec", "Mechanism", "HIGHER_KINDS", "FOLLOWERS", "LENGTH_UNITS", "INERTIA_UNITS", "MOMENT_UNITS",
           "ANGLE_UNITS", "unit_spelling", "LOAD_TYPES", "ELEMENT_TYPES", "RHO_STEEL"]

INCH = 0.0254  # m, exactly
LENGTH_UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "in": INCH}
INERTIA_UNITS = {"kg*m^2": 1.0, "kg*cm^2": 1e-4, "kg*mm^2": 1e-6, "kg*in^2": INCH * INCH}
MOMENT_UNITS = {"N*m": 1.0, "N*cm": 1e-2, "N*mm": 1e-3, "N*in": INCH}
ANGLE_UNITS = {"deg": math.pi / 180.0, "rad": 1.0}
_SYNONYMS = {"inch": "in", "inches": "in", "degrees": "deg", "degree": "deg", "radians": "rad", "radian": "rad"}


def unit_spelling(name, allowed) -> str | None:
    """The unit of `allowed` that `name` spells, however the table's author typed it.

    Case, blanks, "·" or "." for "*", "²" for "^2" and the long names ("inch", "degrees", "radian") are
    forgiven, so that ``length_unit = "MM"`` reads as "mm" and ``moment_unit = "n·mm"`` as "N*mm".

    Parameters
    ----------
    name : object
        What the table says (usually a str).
    allowed : dict or tuple of str
        The unit names to choose from, e.g. `LENGTH_UNITS` (a dict: its keys).

    Returns
    -------
    str or None
        The key of `allowed` spelt, or None when `name` names none of them or is not text.

    Raises
    ------
    Nothing: any other input gives None, for the caller to report with the file and the key.

    Examples
    --------
    >>> from mbplanar.model import ANGLE_UNITS, LENGTH_UNITS, unit_spelling
    >>> unit_spelling(" MM ", LENGTH_UNITS), unit_spelling("inch", LENGTH_UNITS)
    ('mm', 'in')
    >>> unit_spelling("Degrees", ANGLE_UNITS), unit_spelling("furlong", LENGTH_UNITS)
    ('deg', None)
    """
    if not isinstance(name, str):
        return None
    key = name.strip().replace("·", "*").replace("²", "^2").replace(" ", "").lower()
    key = _SYNONYMS.get(key, key)
    for unit in allowed:
        if unit.replace(" ", "").lower() == key or unit.lower().replace("*", ".") == key:
            return unit
    return None


@dataclass(frozen=True)
class Units:
    """The units a model was written in (its table's `length_unit`, `inertia_unit`, `moment_unit`).

    Inside, everything is SI; these only convert at the edges: the table reader multiplies by the
    scales, and output in model units (`--units model`) divides by them. `length` applies to every
    length of the table; `inertia` to link and flywheel inertias (kg·m² unless the table says
    otherwise); `moment` to moments (N·m unless the table says otherwise). Masses are kg, forces N.

    Attributes
    ----------
    length : str
        A key of `LENGTH_UNITS` ("m", "cm", "mm", "in"); `length_scale` is its size in metres.
    inertia : str
        "kg*m^2", "kg*cm^2", "kg*mm^2" or "kg*in^2"; `inertia_scale` in kg·m².
    moment : str
        "N*m", "N*cm", "N*mm" or "N*in"; `moment_scale` in N·m.

    Examples
    --------
    >>> from mbplanar.model import read_model
    >>> units = read_model("models/jansen.toml").units
    >>> units.length, units.length_scale
    ('cm', 0.01)
    """

    length: str = "m"
    inertia: str = "kg*m^2"
    moment: str = "N*m"

    @property
    def length_scale(self) -> float:
        """Metres per model length unit."""
        return LENGTH_UNITS[self.length]

    @property
    def inertia_scale(self) -> float:
        """kg·m² per model inertia unit."""
        return INERTIA_UNITS[self.inertia]

    @property
    def moment_scale(self) -> float:
        """N·m per model moment unit."""
        return MOMENT_UNITS[self.moment]


@dataclass(frozen=True)
class Link:
    """A rigid link.

    `lengths`: exact distances ((P, Q, metres), ...) between points of this link (joints or points of
    interest); `length` is the shortcut for a link with two revolute joints. `angle`: the two points whose
    direction is reported as the link's angle (default: its first two revolute joints), plus
    `angle_offset` (rad), so that the reported angle can follow any convention (a body axis at +90° to
    P→Q). Mass data are used by kinetostatics and dynamics: `mass` (kg), `inertia` (kg·m² about the
    centre), `centre` (a point).

    Examples
    --------
    >>> import mbplanar
    >>> mbplanar.read_model("models/fourbar_loaded.toml").links["2"].mass          # kg
    2.0
    """

    name: str
    lengths: tuple[tuple[str, str, float], ...] = ()
    angle: tuple[str, str] | None = None
    mass: float = 0.0
    inertia: float = 0.0
    centre: str | None = None
    angle_offset: float = 0.0


@dataclass(frozen=True)
class Joint:
    """A lower pair between two links, at `at` (x, y) in the drawn pose.

    Revolute (`kind == "R"`): `links = (a, b)`; its value is the angle of b's reference line minus a's.
    Prismatic (`kind == "P"`): `links = (carrier, slider)`; the carrier holds a guide line through `at`
    along `guide_deg` (drawn pose) or through the two carrier points `guide_points`; the slider's point
    at `at` moves on it. Its value is the slider's displacement along the guide from the drawn pose.

    Examples
    --------
    >>> import mbplanar
    >>> joint = mbplanar.read_model("models/fourbar.toml").joints["B"]
    >>> joint.kind, joint.links
    ('R', ('2', '3'))
    """

    name: str
    kind: str
    links: tuple[str, str]
    at: tuple[float, float]
    guide_deg: float | None = None
    guide_points: tuple[str, str] | None = None

    @property
    def carrier(self) -> str:
        return self.links[0]

    @property
    def slider(self) -> str:
        return self.links[1]

    def other(self, link: str) -> str:
        return self.links[1] if self.links[0] == link else self.links[0]


HIGHER_KINDS = ("gear", "rack", "cam", "slot")   # the higher pairs (kinematic pairs of the fourth class)
FOLLOWERS = ("knife", "roller", "flat", "circle")  # a cam's follower elements


@dataclass(frozen=True)
class Curve:
    """A curve drawn on a link: a cam's profile, a slot's path (drawn coordinates, metres).

    `kind` "circle": centre `centre`, radius `radius`, the whole circle or the arc `arc` (rad, from +x
    at the centre, counter-clockwise from the first to the second). `kind` "spline": a smooth spline of
    degree `degree` through `points`, closed (periodic) or open, at the spline parameter values
    `parameter` (default: the cumulative chord length).

    Examples
    --------
    >>> from mbplanar.model import Curve
    >>> Curve("circle", centre=(0.015, 0.0), radius=0.04).moved(lambda p: (p[0] + 1.0, p[1])).centre
    (1.015, 0.0)
    """

    kind: str
    centre: tuple[float, float] | None = None
    radius: float | None = None
    arc: tuple[float, float] | None = None
    points: tuple[tuple[float, float], ...] = ()
    parameter: tuple[float, ...] | None = None
    closed: bool = False
    degree: int = 5

    def moved(self, place) -> "Curve":
        """This curve carried by `place` (drawn (x, y) → new (x, y), a rigid motion of its link)."""
        if self.kind == "circle":
            c = place(self.centre)
            if self.arc is None:
                return replace(self, centre=c)
            turn = _turn_of(place, self.centre)
            return replace(self, centre=c, arc=(self.arc[0] + turn, self.arc[1] + turn))
        return replace(self, points=tuple(place(p) for p in self.points))

    def scaled(self, k: float) -> "Curve":
        """Every length times k (parameters given as chord lengths too)."""
        xy = lambda p: (p[0] * k, p[1] * k)  # noqa: E731
        return replace(self, centre=None if self.centre is None else xy(self.centre),
                       radius=None if self.radius is None else self.radius * k,
                       points=tuple(xy(p) for p in self.points),
                       parameter=self.parameter)


def _turn_of(place, at) -> float:
    """The rotation (rad) of a rigid motion `place`, read at point `at`."""
    a = place(at)
    b = place((at[0] + 1.0, at[1]))
    return math.atan2(b[1] - a[1], b[0] - a[0])


@dataclass(frozen=True)
class HigherPair:
    """A higher pair (a kinematic pair of the fourth class: it takes one degree of freedom) between two
    links, in the drawn pose (metres, radians).

    `kind` "gear": `links` (a, b) in mesh with pitch `radii` (from `teeth` and `module`, or given),
    `internal` when b has the internal teeth; each turns about its centre, a point of the `carrier`
    (None: found from the table); the law r_a(θ_a − θ_c) = ∓r_b(θ_b − θ_c). `at` the pitch point (None:
    from the centres). `kind` "rack": `links` (pinion, rack), pinion pitch radius `radius`, the rack's
    pitch line through `at` along `guide`; the pinion rolls on it. `kind` "cam": `links` (cam, follower),
    the cam's `curve` (its profile) and the follower's element `follower` ("knife", "roller", "flat",
    "circle") at the follower's point `at` (the knife's tip, the roller's or circle's centre, a point of
    the flat face), `radius` (roller, circle), `face` (the flat face's direction). `kind` "slot":
    `links` (slot link, pin link), the slot's `curve` (its centre line) and the pin's centre `at`.
    `point` names the point or joint `at` came from (it then follows that point through the assembly).
    `pressure_angle` (gears, racks): the line of action's angle to the common tangent.

    Examples
    --------
    >>> import mbplanar
    >>> mech = mbplanar.read_model("models/planetary.toml")
    >>> g = mech.higher["G23"]
    >>> g.kind, g.links, g.radii, g.internal, g.carrier, g.equations, g.parameters
    ('gear', ('2', '0'), (0.046, 0.112), True, 'H', 1, 0)
    """

    name: str
    kind: str
    links: tuple[str, str]
    at: tuple[float, float] | None = None
    radii: tuple[float, float] | None = None
    teeth: tuple[int, int] | None = None
    module: float | None = None
    internal: bool = False
    carrier: str | None = None
    pressure_angle: float = math.radians(20.0)
    guide: float | None = None
    follower: str = "knife"
    radius: float = 0.0
    face: float | None = None
    curve: Curve | None = None
    point: str | None = None

    @property
    def equations(self) -> int:
        """Closure equations it adds to a loop: 1 (gear, rack) or 2 (a contact point: cam, slot)."""
        return 1 if self.kind in ("gear", "rack") else 2

    @property
    def parameters(self) -> int:
        """Unknowns it adds besides the links' own: the contact's place along the curve (cam, slot)."""
        return self.equations - 1

    def other(self, link: str) -> str:
        return self.links[1] if self.links[0] == link else self.links[0]


@dataclass(frozen=True)
class Point:
    """A point of interest fixed on a link (centre of mass, tool, coupler point).

    Given by its drawn coordinates `at`, or built on two points of its link: `along = (P, Q)` with
    `fraction` of PQ or `distance` from P, plus `offset` to the left of P→Q (metres).

    Examples
    --------
    >>> import mbplanar
    >>> point = mbplanar.read_model("models/fourbar.toml").points["M"]
    >>> point.link, point.along, point.fraction, point.offset
    ('2', ('A', 'B'), 0.5, 0.05)
    """

    name: str
    link: str
    at: tuple[float, float] | None = None
    along: tuple[str, str] | None = None
    fraction: float | None = None
    distance: float | None = None
    offset: float = 0.0


@dataclass(frozen=True)
class Input:
    """A generalized coordinate driving one joint: joint value = zero + sense·φ.

    `unit` is how φ is written at the edges ("deg" or "rad" for a revolute joint, "m", "cm", "mm" or "in"
    for a prismatic one); `zero` and `drawn_at` are in that unit too (`zero` in the joint's unit: degrees for
    "deg"/"rad" inputs when `zero_deg` is set). Inside, φ is in rad or m. `omega`, `epsilon`: the
    default speed dφ/dt and acceleration d²φ/dt². `drawn_at`: φ in the drawn pose (measured if None).
    `sweep`: default range of φ (in `unit`); `steps`: its default number of intervals.

    Examples
    --------
    >>> import mbplanar
    >>> driven = mbplanar.read_model("models/fourbar.toml").inputs[0]
    >>> driven.joint, driven.unit, driven.to_si(90.0)       # the crank's joint, degrees → rad
    ('O', 'deg', 1.5707963267948966)
    """

    joint: str
    name: str = "phi"
    unit: str = "deg"
    zero: float = 0.0
    sense: float = 1.0
    omega: float = 1.0
    epsilon: float = 0.0
    drawn_at: float | None = None
    sweep: tuple[float, float] | None = None
    steps: int | None = None

    @property
    def scale(self) -> float:
        """SI value of one unit of φ (rad per degree, m per mm, cm or inch, 1 for rad and m)."""
        return ANGLE_UNITS.get(self.unit) or LENGTH_UNITS.get(self.unit, 1.0)

    def to_si(self, value):
        return value * self.scale

    def from_si(self, value):
        return value / self.scale

    def joint_value(self, phi_si):
        """The driven joint's value (rad or m) for φ in SI."""
        return self.zero * self.scale + self.sense * phi_si

    def default_sweep(self) -> tuple[float, float]:
        if self.sweep is not None:
            return self.sweep
        if self.unit in ("deg", "rad"):
            full = 360.0 if self.unit == "deg" else 2 * math.pi
            return (0.0, full)
        raise ModelError("a prismatic input needs a sweep range (sweep = [from, to])",
                         where=f"input '{self.joint}'")


LOAD_TYPES = ("force", "weight", "moment", "resistance", "friction", "spring", "damper", "torque")
ELEMENT_TYPES = ("spring", "damper", "torque")  # act between two links
RHO_STEEL = 7800.0


@dataclass(frozen=True)
class Load:
    """One external load (a `loads` row), checked, in SI units.

    `kind` is one of `LOAD_TYPES`. It acts on `link` at the drawn coordinates `at` (m) of a material
    point of the link, or at the named point or joint `point` (its exact drawn position); one of the
    two is set. `force` (N, force loads), `magnitude` (N: a weight, or a guide force's constant size),
    `moment` (N·m). Guide forces (`resistance`, `friction`) act along prismatic joint `joint`: a
    resistance's size follows the diagram `s` (m, increasing) → `table` (N) when given, `when` it acts
    ("forward", "backward", "always"), `zero_at` the input value (input unit) where s = 0.
    Elements (`ELEMENT_TYPES`) act between `other` (a) and `link` (b): a spring or linear damper between
    its end on a (`other_at` or `other_point`) and its end on b (`at` or `point`), with `stiffness`,
    `free_length`, `preload` or a tension table `s` (lengths, m) → `table` (N), or `damping`; a
    rotational damper in revolute `joint`; a torque `moment` on b (−moment on a). Any row may be
    switched: active while the rate of joint `switch` (or the velocity of point `switch` along
    `switch_direction`) is ≥ 0 (`when` "forward") or ≤ 0 ("backward").

    Examples
    --------
    The shaper's cutting force: a resistance on the ram along its guide F, from a diagram over the
    stroke, on the working stroke only.

    >>> import mbplanar
    >>> cutting = mbplanar.read_model("models/shaper.toml").loads[0]
    >>> cutting.name, cutting.kind, cutting.link, cutting.joint, cutting.when, len(cutting.s) == len(cutting.table)
    ('cutting', 'resistance', '5', 'F', 'forward', True)
    """

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
    point: str | None = None
    other: str | None = None                     # spring, damper, torque: the first link (a)
    other_at: tuple[float, float] | None = None  # ... and its end on it: drawn coordinates (m)
    other_point: str | None = None               # ... or a named point or joint
    stiffness: float = 0.0                       # N/m
    free_length: float | None = None             # m; None: the ends' exact drawn distance
    preload: float = 0.0                         # N
    damping: float = 0.0                         # N·s/m, or N·m·s/rad in a revolute joint
    switch: str | None = None                    # joint or point whose velocity's sign switches the row
    switch_direction: float = 0.0                # rad, for a point

    @property
    def name(self) -> str:
        """The row's `name`, else its place in the table, loads[i]."""
        return self.label or f"loads[{self.index}]"


@dataclass(frozen=True)
class Gravity:
    """Uniform gravity: acceleration `g` (m/s²) along `direction` (rad, default −π/2), the model's
    `[gravity]` (`Mechanism.gravity`); `vector` is the acceleration (2,).

    Examples
    --------
    >>> import mbplanar
    >>> gravity = mbplanar.read_model("models/fourbar_loaded.toml").gravity
    >>> gravity.g, gravity.vector.round(12) + 0.0
    (9.81, array([ 0.  , -9.81]))
    """

    g: float = 9.81
    direction: float = -math.pi / 2

    @property
    def vector(self) -> np.ndarray:
        """The acceleration vector (2,), m/s²."""
        return self.g * np.array([math.cos(self.direction), math.sin(self.direction)])


@dataclass(frozen=True)
class FlywheelSpec:
    """Where the flywheel goes and what is already there: inertia on the crank shaft (kg·m²), the motor
    shaft's speed (rev/min, None: the flywheel sits on the crank shaft), the motor rotor's inertia
    (kg·m²), the flywheel's density (kg/m³); `inertia`: the machine's first group as built, on the crank
    shaft besides the crank's own (kg·m², flywheel included; None: not given), which `simulate` puts on
    the input; or `link`, a link of the model the gears turn at a constant ratio to the crank (the
    flywheel sits on it, the ratio from the gears).

    Examples
    --------
    The shaper's flywheel goes on its motor's shaft (1412.4 rev/min):

    >>> import mbplanar
    >>> fw = mbplanar.read_model("models/shaper.toml").dynamics.flywheel
    >>> fw.shaft_inertia, fw.motor_rpm, fw.motor_inertia, fw.density
    (0.1625, 1412.4, 0.0875, 7800.0)
    """

    shaft_inertia: float = 0.0
    motor_rpm: float | None = None
    motor_inertia: float = 0.0
    density: float = RHO_STEEL
    inertia: float | None = None
    link: str | None = None


@dataclass(frozen=True)
class DynamicsSpec:
    """The machine's dynamics data (`[dynamics]`, `Mechanism.dynamics`): the coefficient of speed
    fluctuation `delta`, the mean speed `omega_mean` ω_m (rad/s), the `driving_moment` (N·m, None: the
    constant that balances the cycle's work), the slope `motor_slope` of the motor characteristic
    (N·m·s/rad) and where the flywheel goes (`flywheel`, a `FlywheelSpec`).

    Examples
    --------
    >>> import mbplanar
    >>> spec = mbplanar.read_model("models/shaper.toml").dynamics
    >>> spec.delta, round(spec.omega_mean, 6), spec.driving_moment, spec.flywheel.motor_rpm
    (0.05, 7.644542, None, 1412.4)
    """

    delta: float
    omega_mean: float
    driving_moment: float | None = None
    motor_slope: float = 0.0
    flywheel: FlywheelSpec = field(default_factory=FlywheelSpec)


@dataclass
class Mechanism:
    """A planar mechanism: ground, links, joints (lower pairs), higher pairs, points of interest,
    inputs; loads, gravity and dynamics data (SI units; `units` records what the table was written in).

    `extras` keeps the table's free sections (`plot`, `description`) raw. `assembly_correction` (m) is
    how far `assemble` moved the farthest joint from the sketch to the exact drawn pose.

    Build it from a TOML table (`mbplanar.read_model`) or in Python::

        m = Mechanism("fourbar")
        m.add_link("1"); m.add_link("2"); m.add_link("3")
        m.add_joint("O", "R", "0", "1", at=(0, 0))
        ...
        m.add_input("O")

    Examples
    --------
    >>> import mbplanar
    >>> mech = mbplanar.Mechanism("crank")
    >>> link = mech.add_link("1")
    >>> joint = mech.add_joint("O", "R", "0", "1", at=(0.0, 0.0))
    >>> point = mech.add_point("A", "1", at=(0.1, 0.0))
    >>> driven = mech.add_input("O")
    >>> mbplanar.Engine(mech).topology.structure.formula
    'I(0,1)'
    """

    name: str = "mechanism"
    ground: str = "0"
    links: dict[str, Link] = field(default_factory=dict)
    joints: dict[str, Joint] = field(default_factory=dict)
    points: dict[str, Point] = field(default_factory=dict)
    inputs: list[Input] = field(default_factory=list)
    title: str = ""
    source: str = "<python>"
    exact: bool = False
    extras: dict = field(default_factory=dict)
    units: Units = field(default_factory=Units)
    loads: tuple[Load, ...] = ()
    higher: dict[str, HigherPair] = field(default_factory=dict)
    gravity: Gravity | None = None
    dynamics: DynamicsSpec | None = None
    assembly_correction: float = 0.0

    # -- building -------------------------------------------------------------------------------
    def add_link(self, name: str, **kw) -> Link:
        name = str(name)
        if name in self.links or name == self.ground:
            raise ModelError(f"link '{name}' is defined twice", source=self.source)
        if "length" in kw:
            kw = dict(kw)
            kw["lengths"] = (("", "", float(kw.pop("length"))),)
        link = Link(name, **kw)
        self.links[name] = link
        return link

    def add_joint(self, name, kind, a, b, at, guide=None, guide_points=None) -> Joint:
        name, a, b = str(name), str(a), str(b)
        if name in self.joints or name in self.higher:
            raise ModelError(f"joint '{name}' is defined twice", source=self.source)
        kind = str(kind).upper()
        joint = Joint(name, kind, (a, b), (float(at[0]), float(at[1])),
                      None if guide is None else float(guide),
                      None if guide_points is None else (str(guide_points[0]), str(guide_points[1])))
        self.joints[name] = joint
        return joint

    def add_higher(self, name, kind, a, b, **kw) -> HigherPair:
        """Add a higher pair (`HigherPair`'s fields as keywords, SI units); the table's rows of type
        gear, rack, cam and slot come here.

        Examples
        --------
        ``m.add_higher("G", "gear", "1", "4", radii=(0.04, 0.08))`` (two cranks in mesh, their carrier the
        link that holds both their pivots), ``m.add_higher("S", "slot", "2", "1", at=(0.0, 0.06),
        curve=Curve("circle", centre=(0.25, 0.31), radius=0.3536))``.
        """
        name, a, b = str(name), str(a), str(b)
        if name in self.joints or name in self.higher or name in self.points:
            raise ModelError(f"joint '{name}' is defined twice (or is a point's name)", source=self.source)
        if kind not in HIGHER_KINDS:
            raise ModelError(f"a higher pair's type is one of {', '.join(HIGHER_KINDS)}, got {kind!r}",
                             source=self.source)
        pair = HigherPair(name, kind, (a, b), **kw)
        self.higher[name] = pair
        return pair

    def add_point(self, name, link, at=None, **kw) -> Point:
        name = str(name)
        if name in self.points or name in self.joints or name in self.higher:
            raise ModelError(f"point '{name}' is defined twice (or is a joint's name)", source=self.source)
        point = Point(name, str(link), None if at is None else (float(at[0]), float(at[1])), **kw)
        self.points[name] = point
        return point

    def add_input(self, joint, **kw) -> Input:
        inp = Input(str(joint), **kw)
        self.inputs.append(inp)
        return inp

    def add_load(self, type: str, **row) -> Load:
        """Add an external load, given as a `loads` row of the table (same keys, checked the same way),
        in the mechanism's `units` (SI for a mechanism built in Python).

        Examples
        --------
        ``m.add_load("force", link="2", at="B", force=[0.0, -100.0])``,
        ``m.add_load("resistance", joint="Bp", force=300.0, when="forward")``.
        """
        from ._table import read_load_row
        load = read_load_row(self, len(self.loads), dict(row, type=type), self.units)
        self.loads = self.loads + (load,)
        return load

    def set_gravity(self, g: float = 9.81, direction: float = -90.0) -> Gravity:
        """Uniform gravity `g` (m/s²) along `direction` (degrees), as the table's `[gravity]`."""
        from ._table import read_gravity_section
        self.gravity = read_gravity_section(self, {"g": g, "direction": direction})
        return self.gravity

    def set_dynamics(self, **section) -> DynamicsSpec:
        """Machine dynamics data, with the keys of the table's `[dynamics]` section (`delta`,
        `omega_mean` or `rpm_mean`, `driving_moment`, `motor_slope`, `flywheel` = {...}), in the
        mechanism's `units`."""
        from ._table import read_dynamics_section
        self.dynamics = read_dynamics_section(self, section)
        return self.dynamics

    # -- queries --------------------------------------------------------------------------------
    @property
    def all_links(self) -> list[str]:
        """Ground first, then the moving links in table order."""
        return [self.ground] + [n for n in self.links if n != self.ground]

    @property
    def moving_links(self) -> list[str]:
        return [n for n in self.links if n != self.ground]

    def joints_of(self, link: str) -> list[Joint]:
        return [j for j in self.joints.values() if link in j.links]

    def kind_of(self, pair: str) -> str:
        """The type of the pair `pair`: "R" or "P" (a joint), or a higher pair's kind (gear, rack, cam, slot)."""
        return self.joints[pair].kind if pair in self.joints else self.higher[pair].kind

    def higher_of(self, link: str) -> list[HigherPair]:
        return [h for h in self.higher.values() if link in h.links]

    def input_for(self, joint: str) -> Input | None:
        return next((i for i in self.inputs if i.joint == joint), None)

    def _repr_html_(self) -> str:
        """Jupyter: the table's summary and, when it assembles, the diagram in the drawn pose."""
        from ._views import view
        return view("html", self)
