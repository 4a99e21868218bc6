"""The mechanism model: links, joints, points of interest and inputs, as written in a table of pairs.

A `Mechanism` holds what the user wrote: coordinates of every joint and point in one drawn pose (metres),
optionally link dimensions that make that pose a sketch. `mbplanar.model.assemble` turns it into an
exact model (same type, `exact=True`) that the engine uses. Everything here is plain data in SI units;
angles are radians except where a name ends in `_deg`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..errors import ModelError

__all__ = ["Link", "Joint", "Point", "Input", "Mechanism"]


@dataclass(frozen=True)
class Link:
    """A rigid link.

    `lengths`: exact distances ((P, Q, metres), ...) between points of this link (joints or points of
    interest); `length` is the shortcut for a link with two revolute joints. `angle`: the two points whose
    direction is reported as the link's angle (default: its first two revolute joints), plus
    `angle_offset` (rad), so that the reported angle can follow any convention (a body axis at +90° to
    P→Q). Mass data are used by kinetostatics and dynamics: `mass` (kg), `inertia` (kg·m² about the
    centre), `centre` (a point).
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


@dataclass(frozen=True)
class Point:
    """A point of interest fixed on a link (centre of mass, tool, coupler point).

    Given by its drawn coordinates `at`, or built on two points of its link: `along = (P, Q)` with
    `fraction` of PQ or `distance` from P, plus `offset` to the left of P→Q (metres).
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

    `unit` is how φ is written at the edges ("deg" or "rad" for a revolute joint, "m" or "mm" for a
    prismatic one); `zero` and `drawn_at` are in that unit too (`zero` in the joint's unit: degrees for
    "deg"/"rad" inputs when `zero_deg` is set). Inside, φ is in rad or m. `omega`, `epsilon`: the
    default speed dφ/dt and acceleration d²φ/dt². `drawn_at`: φ in the drawn pose (measured if None).
    `sweep`: default range of φ (in `unit`); `steps`: its default number of intervals.
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
        """SI value of one unit of φ (rad per degree, m per mm, 1 otherwise)."""
        return {"deg": math.pi / 180.0, "mm": 1e-3}.get(self.unit, 1.0)

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
        raise ModelError(f"input '{self.joint}': a prismatic input needs a sweep range (sweep = [from, to])")


@dataclass
class Mechanism:
    """A planar mechanism: ground, links, joints, points of interest, inputs (and, later, loads).

    Build it from a TOML table (`mbplanar.read_model`) or in Python::

        m = Mechanism("fourbar")
        m.add_link("1"); m.add_link("2"); m.add_link("3")
        m.add_joint("O", "R", "0", "1", at=(0, 0))
        ...
        m.add_input("O")
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

    # -- building -------------------------------------------------------------------------------
    def add_link(self, name: str, **kw) -> Link:
        name = str(name)
        if name in self.links or name == self.ground:
            raise ModelError(f"{self.source}: link '{name}' is defined twice")
        if "length" in kw:
            kw = dict(kw)
            kw["lengths"] = (("", "", float(kw.pop("length"))),)
        link = Link(name, **kw)
        self.links[name] = link
        return link

    def add_joint(self, name, kind, a, b, at, guide=None, guide_points=None) -> Joint:
        name, a, b = str(name), str(a), str(b)
        if name in self.joints:
            raise ModelError(f"{self.source}: joint '{name}' is defined twice")
        kind = str(kind).upper()
        joint = Joint(name, kind, (a, b), (float(at[0]), float(at[1])),
                      None if guide is None else float(guide),
                      None if guide_points is None else (str(guide_points[0]), str(guide_points[1])))
        self.joints[name] = joint
        return joint

    def add_point(self, name, link, at=None, **kw) -> Point:
        name = str(name)
        if name in self.points or name in self.joints:
            raise ModelError(f"{self.source}: point '{name}' is defined twice (or is a joint's name)")
        point = Point(name, str(link), None if at is None else (float(at[0]), float(at[1])), **kw)
        self.points[name] = point
        return point

    def add_input(self, joint, **kw) -> Input:
        inp = Input(str(joint), **kw)
        self.inputs.append(inp)
        return inp

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

    def input_for(self, joint: str) -> Input | None:
        return next((i for i in self.inputs if i.joint == joint), None)
