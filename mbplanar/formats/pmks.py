"""PMKS+ (the Planar Mechanism Kinematic Simulator Plus, pmksplus.com): its linkage files and links.

PMKS+ has written a linkage three ways, all read here:

- the CSV file of "Download linkage" (2022–2023): sections `joints`, `links`, `forces`, `settings`,
  each a line with its name, a header line, then one line per row::

      joints
      id,x,y,links,type,ground,angle,input
      a,-1.24,-0.89,ab,R,true,Null,true
      ...
      links
      id,type,mass,mass_moi,center_of_mass_x,center_of_mass_y,joints,forces,shape,...
      ab,R,1,1,-0.67,0.56,"a,b","",

- the same tables in a link's query (``?j=...&l=...&f=...&s=...``, rows on lines, a joint's links and a
  link's joints separated by ``|``, booleans ``t``/``f``);
- the compact link of later versions (and their ``.pmks`` files): fields in base 64, a checksum last.

A joint is a point of its links: revolute (`R`) or a slider on the ground (`P`, its guide at `angle`,
radians); `ground` pins it to the frame; `input` drives it. Lengths are in the file's unit (cm, m or
inches; inches become mm), masses in g (cm) or kg (m), inertias in kg·cm² or kg·m². A force fixed in
direction becomes a `force` load; a force that turns with its link has no equivalent and is left out.
"""

from __future__ import annotations

import csv
import io
import math
from urllib.parse import unquote

from ..errors import ModelError
from ._sketch import Sketch, Slide

__all__ = ["read_csv", "read_link", "looks_like_link"]

_UNITS = {"cm": ("cm", 1.0), "m": ("m", 1.0), "mm": ("mm", 1.0), "in": ("mm", 25.4), "inch": ("mm", 25.4),
          "ft": ("mm", 304.8)}
_BASE64 = "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz_-"
_CHECKSUM = _BASE64[:62]


def _flag(text: str, what: str, source: str) -> bool:
    value = text.strip().lower()
    if value in ("t", "true"):
        return True
    if value in ("f", "false"):
        return False
    raise ModelError(f"PMKS+ {what}: expected true or false, got {text!r}", source=source)


def _number(text: str, what: str, source: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise ModelError(f"PMKS+ {what}: expected a number, got {text!r}", source=source)
    return value


class _Rows:
    """The joints, links and forces of a file as plain rows (strings), whichever way it was written."""

    def __init__(self, source):
        self.source = source
        self.joints, self.links, self.forces = [], [], []
        self.unit, self.cw, self.speed, self.gravity = "cm", False, None, False

    def sketch(self, name: str) -> Sketch:
        unit, scale = _UNITS.get(self.unit, (None, None))
        if unit is None:
            raise ModelError(f"PMKS+ settings: unknown length unit {self.unit!r} (cm, m or in)", source=self.source)
        sk = Sketch(self.source, name, title=f"{name} (imported from PMKS+)", unit=unit, ground="ground")
        if scale != 1.0:
            sk.notes.append(f"lengths in {self.unit} written in mm (×{scale:g})")
        kinds, slides = {}, {}
        for j in self.joints:
            jid = j["id"]
            if jid in sk.points:
                raise ModelError(f"PMKS+ joint '{jid}' is listed twice", source=self.source)
            sk.points[jid] = (j["x"] * scale, j["y"] * scale)
            kinds[jid] = j
        for link in self.links:
            if link["id"] == "ground" or link["id"] in sk.bodies:
                raise ModelError(f"PMKS+ link '{link['id']}' is listed twice (or is called ground)", source=self.source)
            for jid in link["joints"]:
                if jid not in kinds:
                    raise ModelError(f"PMKS+ link '{link['id']}': joint '{jid}' is not in the joints", source=self.source)
            sk.bodies[link["id"]] = list(dict.fromkeys(link["joints"]))
        sk.bodies["ground"] = []
        for jid, j in kinds.items():
            on = [b for b, pts in sk.bodies.items() if jid in pts]
            if j["type"] == "P":
                if not j["ground"]:
                    raise ModelError(f"PMKS+ joint '{jid}': a prismatic joint off the ground (PMKS+ slides on the "
                                     "ground only; which link carries this guide?)", source=self.source)
                if not on:
                    raise ModelError(f"PMKS+ joint '{jid}': a prismatic joint on no link", source=self.source)
                slides[jid] = len(sk.slides)
                sk.slides.append(Slide(jid, "ground", on, guide_deg=math.degrees(j["angle"]), name=jid))
            elif j["type"] == "R":
                if j["ground"]:
                    sk.bodies["ground"].append(jid)
            else:
                raise ModelError(f"PMKS+ joint '{jid}': unknown joint type {j['type']!r} (R or P)", source=self.source)
        inputs = [jid for jid, j in kinds.items() if j["input"]]
        if len(inputs) > 1:
            sk.notes.append(f"PMKS+ marks {len(inputs)} inputs ({', '.join(inputs)}): all are driven")
        for jid in inputs:
            if jid in slides:
                sk.inputs.append(("P", slides[jid]))
                continue
            moving = [b for b, pts in sk.bodies.items() if jid in pts and b != "ground"]
            if not kinds[jid]["ground"] or not moving:
                raise ModelError(f"PMKS+ input joint '{jid}' is not a ground pivot of a link: mbplanar drives a "
                                 "crank on the ground", source=self.source)
            sk.inputs.append(("R", jid, moving[0]))
        if not inputs:
            raise ModelError("PMKS+ file: no joint is marked as the input", source=self.source)
        if self.speed is not None:
            sk.omega = self.speed
            sk.notes.append(f"the input speed {self.speed:g} taken as rad/s (PMKS+ does not say its unit)")
        if self.cw:
            sk.sense = "cw"
        self._masses(sk, scale)
        self._forces(sk, scale)
        if self.gravity:
            sk.extra["gravity"] = {"g": 9.81, "direction": -90.0}
        return sk

    def _masses(self, sk: Sketch, scale: float):
        grams = self.unit == "cm"
        sk.inertia_unit = "kg*cm^2" if self.unit == "cm" else "kg*m^2"
        for link in self.links:
            mass = link.get("mass")
            if mass is None:
                continue
            if link.get("com") is None:                 # a piston: its mass at its first joint
                com = sk.points[link["joints"][0]] if link["joints"] else None
                if com is None:
                    continue
                sk.notes.append(f"piston {link['id']}: its mass placed at its joint {link['joints'][0]}")
            else:
                com = (link["com"][0] * scale, link["com"][1] * scale)
            sk.masses[link["id"]] = (mass / 1000.0 if grams else mass, link.get("moi") or 0.0, com)
        if sk.masses:
            sk.notes.append("link masses, inertias and centres as PMKS+ holds them" +
                            (" (g → kg)" if grams else "") + ": PMKS+ gives every new link mass 1 and inertia 1")
        if self.unit not in ("cm", "m") and sk.masses:
            sk.notes.append(f"masses in a {self.unit} file taken as kg and kg·m²")

    def _forces(self, sk: Sketch, scale: float):
        for f in self.forces:
            if f["local"]:
                sk.notes.append(f"force {f['id']} turns with link {f['link']}: mbplanar's forces keep their "
                                "direction; left out")
                continue
            (sx, sy), (ex, ey) = f["start"], f["end"]
            d = math.hypot(ex - sx, ey - sy)
            if d == 0:
                sk.notes.append(f"force {f['id']} has no direction (start = end): left out")
                continue
            sign = 1.0 if f["outward"] else -1.0
            sk.loads.append({"name": f"force {f['id']}", "type": "force", "link": f["link"],
                             "at": [sx * scale, sy * scale],
                             "force": [sign * f["mag"] * (ex - sx) / d, sign * f["mag"] * (ey - sy) / d]})
        if sk.loads:
            sk.notes.append("force magnitudes taken as N")


def _joint_row(cells, what, src) -> dict:
    if len(cells) < 8:
        raise ModelError(f"PMKS+ {what}: expected id,x,y,links,type,ground,angle,input, got {','.join(cells)!r}",
                         source=src)
    jid, x, y, _, kind, ground, angle, inp = (c.strip() for c in cells[:8])
    return {"id": jid, "x": _number(x, f"joint '{jid}' x", src), "y": _number(y, f"joint '{jid}' y", src),
            "type": kind, "ground": _flag(ground, f"joint '{jid}' ground", src),
            "angle": 0.0 if angle in ("Null", "") else _number(angle, f"joint '{jid}' angle", src),
            "input": _flag(inp, f"joint '{jid}' input", src)}


def _link_row(cells, joints_sep, what, src) -> dict:
    if len(cells) < 7:
        raise ModelError(f"PMKS+ {what}: expected id,type,mass,mass_moi,center_of_mass_x,center_of_mass_y,joints,"
                         f"..., got {','.join(cells)!r}", source=src)
    lid, kind, mass, moi, cx, cy, joints = (c.strip() for c in cells[:7])
    row = {"id": lid, "joints": [j.strip() for j in joints.split(joints_sep) if j.strip()]}
    if kind not in ("R", "P"):
        raise ModelError(f"PMKS+ link '{lid}': unknown link type {kind!r} (R or P)", source=src)
    if mass not in ("Null", ""):
        row["mass"] = _number(mass, f"link '{lid}' mass", src)
    if kind == "R" and "Null" not in (moi, cx, cy):
        row["moi"] = _number(moi, f"link '{lid}' mass_moi", src)
        row["com"] = (_number(cx, f"link '{lid}' centre of mass", src), _number(cy, f"link '{lid}' centre of mass", src))
    return row


def _force_row(cells, fixed_means_global, what, src) -> dict:
    if len(cells) < 9:
        raise ModelError(f"PMKS+ {what}: expected id,link,startx,starty,endx,endy,fixed,direction,mag, got "
                         f"{','.join(cells)!r}", source=src)
    fid, link, sx, sy, ex, ey, fixed, outward, mag = (c.strip() for c in cells[:9])
    n = lambda v, k: _number(v, f"force '{fid}' {k}", src)  # noqa: E731
    return {"id": fid, "link": link, "start": (n(sx, "startx"), n(sy, "starty")), "end": (n(ex, "endx"), n(ey, "endy")),
            "local": not _flag(fixed, f"force '{fid}' fixed", src) if fixed_means_global else False,
            "outward": _flag(outward, f"force '{fid}' direction", src), "mag": n(mag, "mag")}


def _settings(rows: _Rows, cells, src):
    if len(cells) >= 4:
        rows.speed = _number(cells[0], "settings input_speed_mag", src)
        rows.cw = _flag(cells[1], "settings clockwise", src)
        rows.gravity = _flag(cells[2], "settings gravity", src)
        rows.unit = cells[3].strip()


def read_csv(text: str, source: str, name: str) -> Sketch:
    """The sketch of a PMKS+ CSV linkage file."""
    rows = _Rows(source)
    section, header = None, False
    for n, cells in enumerate(csv.reader(io.StringIO(text)), 1):
        if not cells or not "".join(cells).strip():
            continue
        if len(cells) == 1 and cells[0].strip() in ("joints", "links", "forces", "settings", "pathPoints",
                                                     "threePositions", "gearSynthesis"):
            section, header = cells[0].strip(), True
            continue
        if header:
            header = False
            continue
        what = f"{section or 'file'} line {n}"
        if section == "joints":
            rows.joints.append(_joint_row(cells, what, source))
        elif section == "links":
            rows.links.append(_link_row(cells, ",", what, source))
        elif section == "forces":
            rows.forces.append(_force_row(cells, True, what, source))
        elif section == "settings":
            _settings(rows, cells, source)
        elif section is None:
            raise ModelError(f"PMKS+ CSV line {n}: expected a section name (joints, links, forces, settings), got "
                             f"{','.join(cells)!r}", source=source)
    if not rows.joints:
        raise ModelError("PMKS+ CSV: no joints section", source=source)
    return rows.sketch(name)


def looks_like_link(text: str) -> bool:
    """Whether `text` is a PMKS+ link (a URL or its query): the tables form or the compact one."""
    body = unquote(text.strip())
    query = body.split("?", 1)[1] if "?" in body else body
    return query.startswith("j=") or _compact_ok(query)


def _compact_ok(query: str) -> bool:
    return len(query) > 8 and query.count(".") >= 7 and _CHECKSUM.find(query[-1]) == (len(query) - 1) % 62


def read_link(text: str, source: str, name: str) -> Sketch:
    """The sketch of a PMKS+ link (a full URL or its query, in a text file or a .pmks file)."""
    body = unquote(text.strip())
    query = body.split("?", 1)[1] if "?" in body else body
    if query.startswith("j="):
        return _read_tables_query(query, source, name)
    if _compact_ok(query):
        return _read_compact(query, source, name)
    raise ModelError("not a PMKS+ link: expected '?j=...&l=...' or PMKS+'s compact link (its checksum does not "
                     "match)", source=source)


def _part(query: str, key: str, end_keys) -> str:
    start = query.find(key)
    if start < 0:
        return ""
    start += len(key)
    ends = [query.find(k, start) for k in end_keys]
    ends = [e for e in ends if e >= 0]
    return query[start:min(ends) if ends else len(query)]


def _read_tables_query(query: str, source: str, name: str) -> Sketch:
    rows = _Rows(source)
    parts = {k: _part(query, k, ("&l=", "&f=", "&s=")) for k in ("j=", "&l=", "&f=")}
    parts["&s="] = _part(query, "&s=", ())
    for n, line in enumerate(p for p in parts["j="].splitlines() if p.strip()):
        cells = line.split(",")
        row = _joint_row(cells, f"link's joint {n + 1}", source)
        rows.joints.append(row)
    for n, line in enumerate(p for p in parts["&l="].splitlines() if p.strip()):
        cells = line.split(",")
        rows.links.append(_link_row(cells, "|", f"link's link {n + 1}", source))
    for n, line in enumerate(p for p in parts["&f="].splitlines() if p.strip()):
        rows.forces.append(_force_row(line.split(","), True, f"link's force {n + 1}", source))
    if parts["&s="].strip():
        _settings(rows, parts["&s="].strip().split(","), source)
    if not rows.joints:
        raise ModelError("PMKS+ link: no joints (j=...)", source=source)
    return rows.sketch(name)


# -- the compact link --------------------------------------------------------------------------------
def _integer(text: str, force_positive: bool = False) -> int:
    negative = not force_positive and text.startswith("0") and len(text) > 1
    digits = text[1:] if negative else text
    value = 0
    for c in digits:
        k = _BASE64.find(c)
        if k < 0:
            raise ValueError(c)
        value = value * 64 + k
    return -value if negative else value


def _decimal(text: str) -> float:
    return _integer(text) / 1000.0


def _flags(text: str, count: int) -> list[bool]:
    packed = _integer(text, force_positive=True)
    return [bool(packed & (1 << i)) for i in range(count)]


def _read_compact(query: str, source: str, name: str) -> Sketch:
    """Settings (booleans, decimals, integers, enums), joints, links, forces, the selection; a checksum."""
    body = query[:-1]
    rows = _Rows(source)
    try:
        fields = body.split(".")
        bools = _flags(fields[0], 8)
        ints = fields[2].split(",")
        enums = fields[3]
        rest = ".".join(fields[4:])
        joints_part, rest = rest.split("..", 1) if not rest.startswith(".") else ("", rest[1:])
        links_part, rest = rest.split("..", 1) if not rest.startswith(".") else ("", rest[1:])
        forces_part, _ = rest.split("..", 1) if not rest.startswith(".") else ("", rest[1:])
        for token in filter(None, joints_part.split(".")):
            flags = _flags(token[0], 5)
            jid, _, x, y, angle = token[1:].split(",")[:5]
            rows.joints.append({"id": jid, "x": _decimal(x), "y": _decimal(y), "type": "P" if flags[0] else "R",
                                "input": flags[1], "ground": flags[2], "angle": _decimal(angle)})
        for token in filter(None, links_part.split(".")):
            root, kind = token[0] == "Y", token[1]
            cells = token[2:].split(",")
            lid, mass, moi, cx, cy = cells[0], cells[2], cells[3], cells[4], cells[5]
            joint_ids = []
            for c in cells[7:]:
                if c == "":
                    break
                joint_ids.append(c)
            if not root:
                continue
            row = {"id": lid, "joints": joint_ids, "mass": _decimal(mass)}
            if kind == "R":
                row.update(moi=_decimal(moi), com=(_decimal(cx), _decimal(cy)))
            rows.links.append(row)
        for token in filter(None, forces_part.split(".")):
            flags = _flags(token[0], 2)
            fid, link, _, sx, sy, ex, ey, mag = token[1:].split(",")[:8]
            rows.forces.append({"id": fid, "link": link, "start": (_decimal(sx), _decimal(sy)),
                                "end": (_decimal(ex), _decimal(ey)), "local": flags[0], "outward": flags[1],
                                "mag": _decimal(mag)})
        rows.cw, rows.gravity = bools[0], bools[1]
        rows.speed = float(_integer(ints[0])) if ints and ints[0] else None
        rows.unit = {0: "in", 1: "cm", 2: "m"}.get(_integer(enums[0]) if enums else 1, "cm")
    except (ValueError, IndexError):
        raise ModelError("PMKS+ compact link: a field does not read (a cut or edited link?)", source=source) from None
    if not rows.joints:
        raise ModelError("PMKS+ compact link: no joints", source=source)
    return rows.sketch(name)
