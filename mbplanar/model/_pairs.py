"""Reading the higher pairs of a table: the `joints` rows of type gear, rack, cam and slot, and the curves
(a cam's profile, a slot's path) they carry.

Each row is read through its own section (`mbplanar.model._keys.HIGHER`, the curve's `CURVE`) into a
`HigherPair` in SI units. What the row alone can check is checked here (tooth numbers, radii, which
keys a follower takes, the curve's data); whether the pair fits the drawing (gears that mesh, a follower
on its cam, a pin in its slot) is checked by the engine on the assembled pose (`engine._higher`).
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

from ._keys import CURVE
from ._model import Curve, Mechanism

__all__ = ["read_higher_row"]


def read_higher_row(mech: Mechanism, row, kind: str, unit: float, folder=None):
    """Add the higher pair of `row` (a `_table.Row` of section `HIGHER[kind]`, `unit` metres per length
    unit) to `mech`; a curve's `file` is read from `folder` (None: the folder of the table's source)."""
    from ._table import joined_links
    name = row.get("name")
    row.raw("type")
    links = joined_links(mech, row)
    if kind in ("cam", "slot"):
        fields = {"cam": _cam, "slot": _slot}[kind](mech, row, links, unit, folder)
    else:
        fields = {"gear": _gear, "rack": _rack}[kind](mech, row, links, unit)
    row.check_unknown_keys({"comment"})
    try:
        mech.add_higher(name, kind, links[0], links[1], **fields)
    except Exception as exc:  # (a ModelError of the model: named with the row)
        row.fail(getattr(exc, "message", str(exc)))


def _xy(row, key: str, unit: float):
    at = row.pair(key)
    return None if at is None else (at[0] * unit, at[1] * unit)


def _teeth(row, key: str, count: int):
    """Tooth numbers: whole numbers >= 1."""
    value = row.raw(key)
    if value is None:
        return None
    values = value if isinstance(value, list) else [value]
    if len(values) != count or not all(isinstance(z, (int, float)) and not isinstance(z, bool) for z in values):
        row.fail(f"'{key}' must be {'[z_a, z_b], two tooth numbers' if count == 2 else 'a tooth number'}, "
                 f"got {value!r}")
    for z in values:
        if not (math.isfinite(z) and z == int(z) and z >= 1):
            row.fail(f"a tooth number must be a whole number >= 1, got {z!r}")
    return tuple(int(z) for z in values)


def _gear(mech, row, links, unit) -> dict:
    teeth = _teeth(row, "teeth", 2)
    module = row.get("module")
    radii = row.raw("radii")
    if radii is not None:
        if not (isinstance(radii, list) and len(radii) == 2):
            row.fail(f"'radii' must be [r_a, r_b], got {radii!r}")
        radii = tuple(row._check_number("radii", r, positive=True) * unit for r in radii)
    elif teeth is not None and module is not None:
        radii = (module * teeth[0] / 2 * unit, module * teeth[1] / 2 * unit)
    else:
        row.fail("a gear pair needs its pitch radii: 'radii' = [r_a, r_b], or 'teeth' = [z_a, z_b] and 'module'")
    internal = row.get("mesh") == "internal"
    if internal and radii[0] == radii[1]:
        row.fail(f"an internal pair's gears differ in size (the larger has the internal teeth): radii "
                 f"{radii[0] / unit:g} and {radii[1] / unit:g}")
    carrier = row.get("carrier")
    if carrier is not None and carrier != mech.ground and carrier not in mech.links:
        row.fail(f"carrier '{carrier}' is not a link of the model")
    if carrier is not None and carrier in links:
        row.fail(f"carrier '{carrier}' is one of the gears; it is the link that holds both gears' centres")
    return dict(radii=radii, teeth=teeth, module=None if module is None else module * unit, internal=internal,
                carrier=carrier, pressure_angle=math.radians(row.get("pressure_angle")), at=_xy(row, "at", unit))


def _rack(mech, row, links, unit) -> dict:
    radius = row.get("radius")
    teeth, module = _teeth(row, "teeth", 1), row.get("module")
    if radius is None:
        if teeth is None or module is None:
            row.fail("a rack pair needs the pinion's pitch radius: 'radius', or 'teeth' and 'module'")
        radius = module * teeth[0] / 2
    elif teeth is not None and module is not None and not math.isclose(radius, module * teeth[0] / 2):
        row.fail(f"'radius' = {radius:g} differs from module·teeth/2 = {module * teeth[0] / 2:g}: give one of them")
    guide = row.get("guide")
    at = row.pair("at", required=True)
    return dict(radius=radius * unit, teeth=None if teeth is None else (teeth[0], 0),
                module=None if module is None else module * unit,
                guide=None if guide is None else math.radians(guide),
                pressure_angle=math.radians(row.get("pressure_angle")), at=(at[0] * unit, at[1] * unit))


def _point_of(mech, row, link: str, unit) -> dict:
    """The follower's or pin's point `at`: a point or joint of `link` (its drawn place; `point` keeps the
    name, followed through the assembly), or [x, y]."""
    value = row.raw("at")
    if isinstance(value, list):
        return {"at": _xy(row, "at", unit)}
    name = row.text("at", required=True)
    if name in mech.points:
        if mech.points[name].link != link:
            row.fail(f"point '{name}' is on link '{mech.points[name].link}', not on '{link}'")
        return {"at": mech.points[name].at, "point": name}
    if name in mech.joints:
        j = mech.joints[name]
        if link not in j.links:
            row.fail(f"joint '{name}' does not belong to link '{link}'")
        return {"at": j.at, "point": name}
    row.fail(f"'at' = '{name}' is neither a point nor a joint (listed before this row) of the model, nor [x, y]")


def _cam(mech, row, links, unit, folder) -> dict:
    follower = row.get("follower")
    where = _point_of(mech, row, links[1], unit)
    radius = row.get("radius")
    if follower in ("roller", "circle"):
        if radius is None:
            row.fail(f"a {follower} follower needs its 'radius'")
    elif radius is not None:
        row.fail(f"a {follower} follower takes no 'radius'")
    face = row.get("face")
    if face is not None and follower != "flat":
        row.fail("'face' is the direction of a flat face (follower = \"flat\")")
    curve = read_curve(mech, row, "profile", unit, closed=True, folder=folder)
    return dict(follower=follower, radius=0.0 if radius is None else radius * unit,
                face=None if face is None else math.radians(face), curve=curve, **where)


def _slot(mech, row, links, unit, folder) -> dict:
    where = _point_of(mech, row, links[1], unit)
    curve = read_curve(mech, row, "path", unit, closed=False, pin=where["at"], folder=folder)
    return dict(curve=curve, **where)


def read_curve(mech, row, key: str, unit: float, closed: bool, pin=None, folder=None) -> Curve:
    """The curve in table `key` of `row` (section `CURVE`) in SI: a circle (its radius by default the
    pin's distance from the centre), a spline through points, or the points of a CSV file (in `folder`,
    None: the folder of the table's source)."""
    from ._table import Row
    raw = row.raw(key)
    sub = Row(raw, f"{row.where}: {key}", row.source, CURVE)
    given = [k for k in ("centre", "points", "file") if sub.has(k)]
    if len(given) != 1:
        sub.fail("give one of 'centre' (a circle), 'points' (a spline) or 'file' (a CSV of points)")
    if given[0] == "centre":
        out = _circle(sub, unit, pin)
    else:
        out = _spline(mech, sub, unit, closed, given[0], folder)
    sub.check_unknown_keys({"comment"})
    return out


def _circle(sub, unit, pin) -> Curve:
    centre = _xy(sub, "centre", unit)
    radius = sub.get("radius")
    if radius is not None:
        radius *= unit
    elif pin is not None:
        radius = math.dist(centre, pin)
        if radius == 0:
            sub.fail("the pin is drawn at the circle's centre: give the slot's 'radius'")
    else:
        sub.fail("a circle needs its 'radius'")
    arc = sub.pair("arc")
    if arc is not None:
        lo = math.radians(arc[0])
        span = (arc[1] - arc[0]) % 360.0 or 360.0
        arc = (lo, lo + math.radians(span))
    for key in ("closed", "parameter", "degree", "column", "offset", "rotate"):
        if sub.has(key):
            sub.fail(f"'{key}' belongs to a spline, not a circle")
    return Curve("circle", centre=centre, radius=radius, arc=arc)


def _spline(mech, sub, unit, closed_default: bool, source: str, folder) -> Curve:
    if sub.has("radius") or sub.has("arc"):
        sub.fail("'radius' and 'arc' belong to a circle ('centre'), not a spline")
    parameter = sub.get("parameter")
    if source == "points":
        for key in ("column", "offset", "rotate"):
            if sub.has(key):
                sub.fail(f"'{key}' goes with 'file'")
        points = _point_list(sub, unit)
    else:
        points, from_file = _points_from_file(mech, sub, unit, folder)
        if parameter is None:
            parameter = from_file
    closed = sub.raw("closed", closed_default)
    if not isinstance(closed, bool):
        sub.fail(f"'closed' must be true or false, got {closed!r}")
    if source == "file" and not closed and parameter is not None and len(parameter) == len(points) + 1:
        parameter = parameter[:-1]             # (the cam's angle where it closes: not for an open curve)
    degree = sub.raw("degree", CURVE["degree"].default)
    if degree not in CURVE["degree"].choices or isinstance(degree, bool):
        sub.fail(f"'degree' must be 3 or 5, got {degree!r}")
    return Curve("spline", points=tuple(points), parameter=parameter, closed=closed, degree=int(degree))


def _point_list(sub, unit) -> list:
    value = sub.raw("points")
    if not isinstance(value, list):
        sub.fail(f"'points' must be a list of [x, y], got {value!r}")
    out = []
    for k, p in enumerate(value):
        if not (isinstance(p, list) and len(p) == 2):
            sub.fail(f"points[{k}] must be [x, y], got {p!r}")
        out.append(tuple(sub._check_number(f"points[{k}]", v) * unit for v in p))
    return out


def _points_from_file(mech, sub, unit, folder):
    """The points of a CSV file: `mbplanar cam`'s profile (mm; its cam angles, in radians, become the
    spline's parameter) or two columns x, y in the table's length unit; moved by `rotate` and `offset`."""
    name = sub.get("file")
    if folder is not None:
        base = folder
    else:
        base = Path(mech.source).parent if mech.source and not mech.source.startswith("<") else Path.cwd()
    path = base / name
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        sub.fail(f"cannot read the curve's file '{path}' ({exc.strerror or exc})")
    rows = [r for r in csv.reader(text.splitlines()) if r and not r[0].lstrip().startswith("#")]
    if not rows:
        sub.fail(f"'{path}' holds no points")
    header, parameter = rows[0], None
    column = sub.get("column")
    try:
        if "profile_x[mm]" in header:          # mbplanar cam's CSV: one row per cam angle
            ix, iy = header.index(f"{column}_x[mm]"), header.index(f"{column}_y[mm]")
            data = [(float(r[ix]) * 1e-3, float(r[iy]) * 1e-3, math.radians(float(r[0]))) for r in rows[1:]]
            if not data or any(not math.isfinite(v) for r in data for v in r):
                sub.fail(f"'{path}' has no {column} curve (a flat face's cam has no pitch curve)")
            points = [(x, y) for x, y, _ in data]
            angles = [a for _, _, a in data]
            parameter = tuple(angles) + (angles[0] + 2 * math.pi,)
        else:
            try:
                float(header[0])
                body = rows
            except ValueError:
                body = rows[1:]                # a header line
            points = [(float(r[0]) * unit, float(r[1]) * unit) for r in body]
    except (ValueError, IndexError) as exc:
        sub.fail(f"'{path}' is not a CSV of points ({exc})")
    turn = math.radians(sub.get("rotate"))
    off = _xy(sub, "offset", unit) or (0.0, 0.0)
    c, s = math.cos(turn), math.sin(turn)
    points = [(off[0] + c * x - s * y, off[1] + s * x + c * y) for x, y in points]
    return points, parameter
