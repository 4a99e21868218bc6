"""pylinkage: its JSON files and its live objects.

pylinkage has saved a linkage two ways, both read here:

- `Linkage.to_json` (pylinkage 0.6 to 0.9): ``{"name", "joints": [...], "solve_order"}``, each joint a
  `Static` (a ground point), a `Crank` (turning about `joint0` at `distance`), a `Revolute` (at
  `distance0` from `joint0` and `distance1` from `joint1`: two binary links), a `Fixed` (rigid with
  `joint0` and `joint1`: a ternary link) or a `Prismatic` / `Linear` (at `revolute_radius` from
  `joint0`, its pin sliding on the line through `joint1` and `joint2`); a parent is ``{"ref": name}``
  or an inline static point;
- `mechanism_to_json` (pylinkage 0.7 and later, the `Mechanism` model): ``{"name", "joints", "links",
  "ground"}``, joints `ground`, `revolute`, `prismatic` (sliding on the fixed line through `line_point`
  along `axis`) or `tracker` (a point of a link), links `ground`, `link`, `driver` (a crank about its
  `motor_joint`) or `arc_driver` (a crank between `arc_start` and `arc_end`).

A live `pylinkage.simulation.Linkage` (pylinkage 0.10 and later: `Ground`, `Crank`, `ArcCrank`,
`RRRDyad`, `RRPDyad`, `FixedDyad`) or `pylinkage.mechanism.Mechanism` is read as well. The positions
are the drawn pose and pylinkage has no unit: lengths are taken as metres. A crank's speed is an angle
per simulation step, not per second: it is not carried over.
"""

from __future__ import annotations

import math

from ..errors import ModelError
from ._sketch import Sketch, Slide, unique

__all__ = ["read_json", "read_object", "legacy_sketch", "mechanism_sketch"]


def _xy(item, what, source) -> tuple[float, float]:
    x, y = item
    if isinstance(x, bool) or isinstance(y, bool) or not all(isinstance(v, (int, float)) and math.isfinite(v)
                                                             for v in (x, y)):
        raise ModelError(f"pylinkage {what} has no position ({x!r}, {y!r}): save it after the linkage is built",
                         source=source)
    return float(x), float(y)


def _check_distances(sk: Sketch, pairs):
    """Note where the file's distances and its drawn positions disagree (the positions are kept)."""
    worst = max((abs(math.dist(sk.points[a], sk.points[b]) - d) for a, b, d in pairs if d is not None), default=0.0)
    spread = list(sk.points.values())
    size = max((math.dist(a, b) for a in spread for b in spread), default=1.0) or 1.0
    if worst > 1e-9 * size:
        sk.notes.append(f"the file's distances and its drawn positions differ by up to {worst:.3g} m: the positions "
                        "are kept")


def legacy_sketch(data: dict, source: str, name: str) -> Sketch:
    """The sketch of a `Linkage.to_json` document (pylinkage 0.6–0.9)."""
    joints = data.get("joints")
    if not isinstance(joints, list) or not joints:
        raise ModelError("pylinkage linkage: no 'joints' list", source=source)
    sk = Sketch(source, name, title=f"{data.get('name') or name} (imported from pylinkage)")
    sk.notes.append("pylinkage has no unit: lengths taken as m")
    rows = {}
    for k, j in enumerate(joints):
        if not isinstance(j, dict) or not isinstance(j.get("name"), str) or not j.get("type"):
            raise ModelError(f"pylinkage joints[{k}]: expected a joint with a type and a name, got {j!r}",
                             source=source)
        if j["name"] in rows:
            raise ModelError(f"pylinkage joint '{j['name']}' is listed twice", source=source)
        rows[j["name"]] = j
        sk.points[j["name"]] = _xy((j.get("x"), j.get("y")), f"joint '{j['name']}'", source)

    def parent(j, key) -> str:
        ref = j.get(key)
        what = f"joint '{j['name']}' ({j['type']})"
        if not isinstance(ref, dict):
            raise ModelError(f"pylinkage {what}: '{key}' missing", source=source)
        if ref.get("inline"):
            p = unique(str(ref.get("name") or f"{j['name']}_{key}"), sk.points)
            sk.points[p] = _xy((ref.get("x"), ref.get("y")), f"{what} {key}", source)
            sk.bodies.setdefault(sk.ground, []).append(p)
            return p
        if ref.get("ref") not in rows:
            raise ModelError(f"pylinkage {what}: {key} names no joint {ref.get('ref')!r}", source=source)
        return ref["ref"]

    ground = sk.bodies.setdefault(sk.ground, [])
    distances, slides = [], []
    for jn, j in rows.items():
        kind = j["type"]
        if kind == "Static":
            ground.append(jn)
        elif kind == "Crank":
            a = parent(j, "joint0")
            body = unique(f"{jn}_crank", set(sk.bodies) | set(sk.points))
            sk.bodies[body] = [a, jn]
            sk.inputs.append(("R", a, body, jn))
            distances.append((a, jn, j.get("distance")))
        elif kind == "Revolute":
            for key, d in (("joint0", "distance0"), ("joint1", "distance1")):
                a = parent(j, key)
                sk.bodies[unique(f"{a}-{jn}", set(sk.bodies) | set(sk.points))] = [a, jn]
                distances.append((a, jn, j.get(d)))
        elif kind == "Fixed":
            a, b = parent(j, "joint0"), parent(j, "joint1")
            sk.bodies[unique(f"{a}-{b}-{jn}", set(sk.bodies) | set(sk.points))] = [a, b, jn]
            distances.append((a, jn, j.get("distance")))
        elif kind in ("Prismatic", "Linear"):
            a, p, q = parent(j, "joint0"), parent(j, "joint1"), parent(j, "joint2")
            rod = unique(f"{a}-{jn}", set(sk.bodies) | set(sk.points))
            sk.bodies[rod] = [a, jn]
            slides.append((jn, p, q, rod))
            distances.append((a, jn, j.get("revolute_radius")))
        else:
            raise ModelError(f"pylinkage joint '{jn}': type {kind!r} has no mbplanar equivalent (Static, Crank, "
                             "Revolute, Fixed, Prismatic)", source=source)
    if any(isinstance(j.get("angle"), (int, float)) for j in rows.values() if j["type"] == "Crank"):
        sk.notes.append("a crank's 'angle' (its turn per simulation step) is not carried over: give 'omega' in rad/s")
    _check_distances(sk, [(a, b, d) for a, b, d in distances if isinstance(d, (int, float))])
    _slides(sk, slides)
    return sk


def _slides(sk: Sketch, slides):
    """Slides whose guide is the line of two points: on the body that holds both (after rigid merging)."""
    from ._sketch import _merge_rigid
    into = _merge_rigid(sk)
    for pin, p, q, rod in slides:
        carrier = next((b for b, pts in sk.bodies.items() if p in pts and q in pts), None)
        if carrier is None:
            raise ModelError(f"pylinkage prismatic joint '{pin}': its line runs through {p} and {q}, which no one link "
                             "holds; mbplanar guides lie on a link", source=sk.source)
        sk.slides.append(Slide(pin, carrier, [into.get(rod, rod)], guide_points=(p, q), turns=True))


def mechanism_sketch(data: dict, source: str, name: str) -> Sketch:
    """The sketch of a `mechanism_to_json` document (pylinkage's `Mechanism`)."""
    joints, links = data.get("joints"), data.get("links")
    if not isinstance(joints, list) or not isinstance(links, list):
        raise ModelError("pylinkage mechanism: expected 'joints' and 'links' lists", source=source)
    sk = Sketch(source, name, title=f"{data.get('name') or name} (imported from pylinkage)")
    sk.notes.append("pylinkage has no unit: lengths taken as m")
    kinds = {}
    for k, j in enumerate(joints):
        if not isinstance(j, dict) or not isinstance(j.get("id"), str):
            raise ModelError(f"pylinkage mechanism joints[{k}]: expected a joint with an 'id', got {j!r}",
                             source=source)
        pos = j.get("position")
        if not (isinstance(pos, list) and len(pos) == 2):
            raise ModelError(f"pylinkage joint '{j['id']}': 'position' must be [x, y], got {pos!r}", source=source)
        sk.points[j["id"]] = _xy(pos, f"joint '{j['id']}'", source)
        kinds[j["id"]] = j
    ground_id = data.get("ground")
    ground = sk.bodies.setdefault(sk.ground, [])
    for jid, j in kinds.items():
        if j.get("type") == "ground":
            ground.append(jid)
        elif j.get("type") not in ("revolute", "prismatic", "tracker", None):
            raise ModelError(f"pylinkage joint '{jid}': type {j.get('type')!r} has no mbplanar equivalent",
                             source=source)
    drivers = []
    for k, link in enumerate(links):
        if not isinstance(link, dict) or not isinstance(link.get("id"), str):
            raise ModelError(f"pylinkage mechanism links[{k}]: expected a link with an 'id', got {link!r}",
                             source=source)
        members = [m for m in link.get("joints", []) if m in kinds]
        missing = [m for m in link.get("joints", []) if m not in kinds]
        if missing:
            raise ModelError(f"pylinkage link '{link['id']}': joint(s) {', '.join(map(str, missing))} are not in the "
                             "joints", source=source)
        if link.get("type") == "ground" or link["id"] == ground_id:
            ground.extend(m for m in members if m not in ground)
            continue
        body = link["id"] if link["id"] not in sk.points else unique(link["id"], set(sk.points))
        sk.bodies[body] = [m for m in members if kinds[m].get("type") != "prismatic"]
        for m in members:
            if kinds[m].get("type") == "prismatic":
                sk.bodies[body].append(m)
        if link.get("type") in ("driver", "arc_driver"):
            drivers.append((body, link))
    for jid, j in kinds.items():
        if j.get("type") == "tracker" and not any(jid in pts for pts in sk.bodies.values()):
            refs = (j.get("ref_joint1_id"), j.get("ref_joint2_id"))
            holder = next((b for b, pts in sk.bodies.items() if b != sk.ground and all(r in pts for r in refs)), None)
            if holder is None:
                raise ModelError(f"pylinkage tracker '{jid}': no link holds its joints {refs[0]} and {refs[1]}",
                                 source=source)
            sk.bodies[holder].append(jid)
        if j.get("type") == "prismatic":
            pins = [b for b, pts in sk.bodies.items() if jid in pts and b != sk.ground]
            axis = j.get("axis", [1.0, 0.0])
            if not pins:
                raise ModelError(f"pylinkage prismatic joint '{jid}' is on no link", source=source)
            sk.slides.append(Slide(jid, sk.ground, pins, guide_deg=math.degrees(math.atan2(axis[1], axis[0])),
                                   turns=True))
    for body, link in drivers:
        motor = link.get("motor_joint")
        if motor not in sk.bodies[sk.ground]:
            motor = next((m for m in sk.bodies[body] if m in sk.bodies[sk.ground]), None)
        if motor is None:
            raise ModelError(f"pylinkage driver '{link['id']}' turns about no ground joint", source=source)
        tip = next((m for m in sk.bodies[body] if m != motor), None)
        sk.inputs.append(("R", motor, body, tip) if tip else ("R", motor, body))
        if link.get("type") == "arc_driver":
            sk.notes.append(f"driver '{link['id']}' swings between {link.get('arc_start')} and {link.get('arc_end')} "
                            "rad in pylinkage: give the input's 'sweep'")
    if drivers:
        sk.notes.append("a driver's angular_velocity (its turn per simulation step) is not carried over")
    return sk


def read_json(text: str, source: str, name: str) -> Sketch:
    """The sketch of a pylinkage JSON file, either kind."""
    import json
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ModelError(f"JSON syntax error at line {exc.lineno}, column {exc.colno}: {exc.msg}", source=source) from None
    if not isinstance(data, dict) or not isinstance(data.get("joints"), list):
        raise ModelError("not a pylinkage file: expected an object with a 'joints' list", source=source)
    if "links" in data:
        return mechanism_sketch(data, source, name)
    return legacy_sketch(data, source, name)


# -- live objects -------------------------------------------------------------------------------------
def read_object(obj, name: str | None = None) -> Sketch:
    """The sketch of a live pylinkage object: a `simulation.Linkage` (its components) or a
    `mechanism.Mechanism`."""
    kind = type(obj).__name__
    source = f"<pylinkage {kind} {getattr(obj, 'name', '')}>".replace(" >", ">")
    name = name or str(getattr(obj, "name", None) or "pylinkage")
    if hasattr(obj, "components"):
        return legacy_sketch(_components_document(obj, source), source, name)
    if hasattr(obj, "links") and hasattr(obj, "joints"):
        from pylinkage.mechanism import mechanism_to_dict
        return mechanism_sketch(mechanism_to_dict(obj), source, name)
    raise ModelError(f"not a pylinkage Linkage or Mechanism: {kind}", source=source)


def _components_document(linkage, source) -> dict:
    """A `simulation.Linkage`'s components as the joints of a `Linkage.to_json` document."""
    comps = list(linkage.components)
    if any(getattr(c, "x", None) is None for c in comps):
        list(linkage.step(iterations=1, dt=0))        # (solve the positions, turning nothing)

    def ref(c) -> dict:
        parent = getattr(c, "_parent", c)              # an anchor proxy stands for its component
        return {"ref": parent.name}

    joints = []
    for c in comps:
        kind = type(c).__name__
        row = {"name": c.name, "x": c.x, "y": c.y}
        if kind == "Ground":
            row["type"] = "Static"
        elif kind in ("Crank", "ArcCrank"):
            row.update(type="Crank", joint0=ref(c.anchor), distance=c.radius)
        elif kind == "RRRDyad":
            row.update(type="Revolute", joint0=ref(c.anchor1), joint1=ref(c.anchor2), distance0=c.distance1,
                       distance1=c.distance2)
        elif kind == "FixedDyad":
            row.update(type="Fixed", joint0=ref(c.anchor1), joint1=ref(c.anchor2), distance=c.distance,
                       angle=c.angle)
        elif kind == "RRPDyad":
            row.update(type="Prismatic", joint0=ref(c.revolute_anchor), joint1=ref(c.line_anchor1),
                       joint2=ref(c.line_anchor2), revolute_radius=c.distance)
        else:
            raise ModelError(f"pylinkage component '{c.name}' ({kind}) has no mbplanar equivalent here (Ground, "
                             "Crank, ArcCrank, RRRDyad, RRPDyad, FixedDyad)", source=source)
        joints.append(row)
    return {"name": linkage.name, "joints": joints}
