"""What the peers' files say, in one shape, turned into an mbplanar table.

Pyslvs, PMKS+ and pylinkage all describe a mechanism as points in one drawn pose and rigid bodies that
hold them; a point on two or more bodies is a revolute pair, a slide joins a pin to a body's guide. A
`Sketch` holds that; `to_table` writes the table of pairs: a point shared by bodies gives revolute
joints (from the ground, else from the first body, to each other body: three links at one pin are two
joints at one place), a point of one body gives a `points` row, a slide gives a prismatic joint (with a
slider block and a revolute pin when the pin also turns in its slot). Bodies that share two points are
one rigid body and are merged. The importers build a Sketch and record what they could not carry over
in `notes`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..errors import ModelError

__all__ = ["Slide", "Sketch", "to_table", "unique"]


@dataclass
class Slide:
    """A pin `point` sliding on a guide of body `carrier` through it: along `guide_deg` (the drawn
    direction, degrees) or the line of two points `guide_points` of the carrier. `pins`: the bodies
    carried by the pin. `turns`: the pin turns in its slot (a pin in a slot: a slider block, a prismatic
    and a revolute pair); else the first pin body slides without turning and the others turn on it."""

    point: str
    carrier: str
    pins: list
    guide_deg: float | None = None
    guide_points: tuple | None = None
    turns: bool = False
    name: str | None = None


@dataclass
class Sketch:
    """Points (name → drawn (x, y) in `unit`), bodies (name → point names), slides, inputs and what else
    the file said. An input is ("R", point, body): the revolute pair of `body` with the ground at `point`,
    measured along the line from `point` to `drive` when given; or ("P", slide index)."""

    source: str
    name: str
    title: str = ""
    unit: str = "m"
    ground: str = "ground"
    points: dict = field(default_factory=dict)
    bodies: dict = field(default_factory=dict)
    slides: list = field(default_factory=list)
    inputs: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    masses: dict = field(default_factory=dict)       # body → (mass kg, inertia, centre (x, y))
    inertia_unit: str = "kg*m^2"
    loads: list = field(default_factory=list)        # mbplanar loads rows
    extra: dict = field(default_factory=dict)        # further top-level sections ([gravity], ...)
    omega: float | None = None                       # the input's speed, rad/s
    sense: str | None = None                         # "cw" for a clockwise crank

    def fail(self, message: str):
        raise ModelError(message, source=self.source)


def unique(name: str, taken) -> str:
    """`name`, or `name_2`, `name_3`, ... when taken."""
    if name not in taken:
        return name
    k = 2
    while f"{name}_{k}" in taken:
        k += 1
    return f"{name}_{k}"


def _merge_rigid(sk: Sketch) -> dict:
    """Bodies that share two points or more are one body: the ground absorbs them first, then each
    other body; returns body → the body it became."""
    into = {b: b for b in sk.bodies}
    changed = True
    while changed:
        changed = False
        names = [sk.ground] + [b for b in sk.bodies if b != sk.ground]
        for i, a in enumerate(names):
            for b in names[i + 1:]:
                if a in sk.bodies and b in sk.bodies and len(set(sk.bodies[a]) & set(sk.bodies[b])) >= 2:
                    sk.bodies[a] = sk.bodies[a] + [p for p in sk.bodies[b] if p not in sk.bodies[a]]
                    del sk.bodies[b]
                    for k, v in into.items():
                        if v == b:
                            into[k] = a
                    sk.notes.append(f"bodies {a} and {b} share two points: one rigid link {a}")
                    changed = True
    return into


def to_table(sk: Sketch) -> dict:
    """The mbplanar table (a TOML document as a dict) of the sketch."""
    sk.bodies.setdefault(sk.ground, [])
    into = _merge_rigid(sk)
    for s in sk.slides:
        s.carrier = into.get(s.carrier, s.carrier)
        s.pins = list(dict.fromkeys(into.get(b, b) for b in s.pins))
    g = sk.ground
    taken = set(sk.points) | set(sk.bodies)
    joints, points, on = [], [], {}                  # on[(point, body)]: the name of that spot on the body

    def joint(name, kind, a, b, xy, **kw):
        name = unique(name, {j["name"] for j in joints} | {p["name"] for p in points})
        joints.append({"name": name, "type": kind, "links": [a, b], "at": [float(xy[0]), float(xy[1])], **kw})
        on.setdefault((name, a), name)
        return name

    slid = {s.point for s in sk.slides}
    for p, xy in sk.points.items():
        if p in slid:                                 # (its pairs are the slide's, below)
            continue
        held = [b for b in sk.bodies if p in sk.bodies[b]]
        if not held:
            sk.notes.append(f"point {p} is on no link: left out")
            continue
        if len(held) == 1:
            if held[0] != g:
                points.append({"name": p, "link": held[0], "at": [float(xy[0]), float(xy[1])]})
                on[(p, held[0])] = p
            continue
        hub = g if g in held else held[0]
        for k, b in enumerate(x for x in held if x != hub):
            name = joint(p if k == 0 else f"{p}_{k + 1}", "R", hub, b, xy)
            on[(p, b)] = name
            on.setdefault((p, hub), name)
    blocks = []
    for s in sk.slides:
        xy = sk.points[s.point]
        if s.guide_points is not None and s.carrier == g:   # a fixed guide: its drawn direction
            (ax, ay), (bx, by) = (sk.points[q] for q in s.guide_points)
            s.guide_deg, s.guide_points = math.degrees(math.atan2(by - ay, bx - ax)), None
        guide = {"guide": float(s.guide_deg)} if s.guide_points is None else {"guide": [
            _spot(sk, points, on, q, s.carrier) for q in s.guide_points]}
        if not s.pins:
            sk.fail(f"the slide at point {s.point} carries no link")
        if s.turns:
            block = unique(f"{s.point}_block", taken | set(blocks))
            blocks.append(block)
            joint(s.name or f"{s.point}_slide", "P", s.carrier, block, xy, **guide)
            for k, b in enumerate(s.pins):
                on[(s.point, b)] = joint(s.point if k == 0 else f"{s.point}_{k + 1}", "R", block, b, xy)
        else:
            name = joint(s.name or s.point, "P", s.carrier, s.pins[0], xy, **guide)
            on[(s.point, s.pins[0])] = name
            for k, b in enumerate(s.pins[1:]):
                on[(s.point, b)] = joint(f"{s.point}_{k + 2}", "R", s.pins[0], b, xy)
    links = []
    for b in list(sk.bodies) + blocks:
        if b == g:
            continue
        row = {"name": b}
        if b in sk.masses:
            mass, inertia, centre = sk.masses[b]
            if mass > 0 or inertia > 0:
                row.update(mass=float(mass), inertia=float(inertia), centre=[float(centre[0]), float(centre[1])])
        links.append(row)
    table = {"name": sk.name, "title": sk.title, "ground": g, "length_unit": sk.unit}
    if sk.inertia_unit != "kg*m^2" and any("inertia" in r for r in links):
        table["inertia_unit"] = sk.inertia_unit
    table.update(links=links, joints=joints)
    if points:
        table["points"] = points
    if sk.loads:
        table["loads"] = sk.loads
    inputs = [_input(sk, inp, links, joints, points, on) for inp in sk.inputs]
    if len(inputs) == 1:
        table["input"] = inputs[0]
    elif inputs:
        table["inputs"] = inputs
    table.update(sk.extra)
    return table


def _spot(sk, points, on, q, body) -> str:
    """A name for point `q` on `body`: its joint there, else a new point of interest."""
    if (q, body) in on:
        return on[(q, body)]
    name = unique(f"{q}@{body}", {p["name"] for p in points} | set(on.values()))
    xy = sk.points[q]
    points.append({"name": name, "link": body, "at": [float(xy[0]), float(xy[1])]})
    on[(q, body)] = name
    return name


def _input(sk: Sketch, inp, links, joints, points, on) -> dict:
    """One `[input]` row: a crank's revolute pair with the ground, or a slide's prismatic pair."""
    if inp[0] == "P":
        s = sk.slides[inp[1]]
        name = next(j["name"] for j in joints if j["type"] == "P" and j["at"] == [float(c) for c in sk.points[s.point]]
                    and j["links"][0] == s.carrier)
        spread = [xy for xy in sk.points.values()]
        size = max((math.dist(a, b) for a in spread for b in spread), default=1.0) or 1.0
        sk.notes.append(f"the slide input at {s.point} takes the range ±{0.5 * size:.6g} {sk.unit} (the file gives "
                        "none): change 'sweep' to its stroke")
        row = {"joint": name, "sweep": [-0.5 * size, 0.5 * size]}
    else:
        _, point, body, *rest = inp
        drive = rest[0] if rest else None
        name = on.get((point, body))
        row_j = next((j for j in joints if j["name"] == name), None)
        if row_j is None or row_j["type"] != "R" or sk.ground not in row_j["links"]:
            sk.fail(f"the input at point {point} turns link {body} about a point that is not a ground pivot: "
                    "mbplanar drives a joint with the ground or between two links, not a link's absolute angle "
                    "about a moving point")
        row = {"joint": name}
        if drive is not None and (drive, body) in on:
            link = next(r for r in links if r["name"] == body)
            link["angle"] = [name, on[(drive, body)]]       # φ: the direction from the pivot to the drive point
        if sk.omega is not None:
            row["omega"] = float(sk.omega)
        if sk.sense is not None:
            row["sense"] = sk.sense
    return row
