"""Reading a mechanism from its TOML table of kinematic pairs.

The format (documented in README.md) has a few top-level keys (`name`, `title`, `ground`,
`length_unit`), a `links` list, a `joints` list (one row per pair), a `points` list, one `[input]`
table or an `inputs` list, and optional `loads`. Every problem is reported as a `ModelError` that names
the file and the row ("joints[3] 'Ap'") at fault. Lengths are converted to metres here, at the edge.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

from ..errors import ModelError
from ._model import Input, Mechanism

__all__ = ["read_model", "read_model_text", "parse_model"]

_LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "cm": 1e-2}


def read_model(path) -> Mechanism:
    """Read a TOML model file into an (unassembled) `Mechanism`."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ModelError(f"{path}: cannot read the model file ({exc.strerror or exc})") from None
    except UnicodeDecodeError as exc:
        raise ModelError(f"{path}: the model file is not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    return read_model_text(text, source=str(path))


def read_model_text(text: str, source: str = "<table>") -> Mechanism:
    """Parse the TOML `text` of a model; a syntax error names the line and column."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"{source}: TOML syntax error: {exc}") from None
    return parse_model(data, source=source)


_MISSING = object()


class Row:
    """Typed access to one table row, with errors that name the file and row."""

    def __init__(self, data, where: str):
        if not isinstance(data, dict):
            raise ModelError(f"{where}: expected a table {{...}}, got {type(data).__name__}")
        self.data, self.where = data, where
        self.used: set[str] = set()

    def fail(self, msg: str):
        raise ModelError(f"{self.where}: {msg}")

    def has(self, key) -> bool:
        return key in self.data

    def _value(self, key, required, hint=""):
        """The raw value of `key` (marked as used), `_MISSING` when absent and not required."""
        self.used.add(key)
        if key not in self.data:
            if required:
                self.fail(f"missing '{key}'{hint}")
            return _MISSING
        return self.data[key]

    def text(self, key, default=None, required=False) -> str | None:
        value = self._value(key, required)
        if value is _MISSING:
            return default
        if isinstance(value, bool) or not isinstance(value, (str, int)):
            self.fail(f"'{key}' must be a name (text), got {value!r}")
        return str(value)

    def number(self, key, default=None, required=False, positive=False, nonzero=False) -> float | None:
        value = self._value(key, required)
        return default if value is _MISSING else self._check_number(key, value, positive, nonzero)

    def _check_number(self, key, value, positive=False, nonzero=False) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(f"'{key}' must be a number, got {value!r}")
        value = float(value)
        if not math.isfinite(value):
            self.fail(f"'{key}' must be finite, got {value}")
        if positive and value <= 0:
            self.fail(f"'{key}' must be positive, got {value}")
        if nonzero and value == 0:
            self.fail(f"'{key}' must not be zero")
        return value

    def pair(self, key, required=False) -> tuple[float, float] | None:
        value = self._value(key, required, " (drawn coordinates [x, y])")
        if value is _MISSING:
            return None
        if not isinstance(value, list) or len(value) != 2:
            self.fail(f"'{key}' must be [x, y], got {value!r}")
        return (self._check_number(key, value[0]), self._check_number(key, value[1]))

    def names(self, key, count=2, required=False) -> tuple[str, ...] | None:
        value = self._value(key, required)
        if value is _MISSING:
            return None
        if not isinstance(value, list) or len(value) != count or not all(
                isinstance(v, (str, int)) and not isinstance(v, bool) for v in value):
            self.fail(f"'{key}' must be a list of {count} names, got {value!r}")
        return tuple(str(v) for v in value)

    def check_unknown_keys(self, extra: set[str] = frozenset()):
        unknown = set(self.data) - self.used - set(extra)
        if unknown:
            self.fail(f"unknown key(s) {', '.join(sorted(unknown))}")


def _rows(data, key, source) -> list:
    rows = data.get(key, [])
    if isinstance(rows, dict):  # [links.1] style tables: name = key
        rows = [dict(v, name=k) if isinstance(v, dict) else v for k, v in rows.items()]
    if not isinstance(rows, list):
        raise ModelError(f"{source}: '{key}' must be a list of rows")
    return rows


def parse_model(data: dict | str, source: str = "<table>") -> Mechanism:
    """Build a `Mechanism` from the parsed TOML document `data`, or from TOML text."""
    if isinstance(data, str):
        return read_model_text(data, source)
    top = Row(data, source)
    unit_name = top.text("length_unit", "m")
    if unit_name not in _LENGTH_UNITS:
        top.fail(f"length_unit must be one of {', '.join(_LENGTH_UNITS)}, got '{unit_name}'")
    unit = _LENGTH_UNITS[unit_name]
    mech = Mechanism(name=top.text("name", Path(source).stem), ground=top.text("ground", "0"),
                     title=top.text("title", ""), source=source)
    _read_links(mech, _rows(data, "links", source), unit)
    _read_joints(mech, _rows(data, "joints", source), unit)
    _read_points(mech, _rows(data, "points", source), unit)
    _read_inputs(mech, data, source, unit)
    top.used |= {"links", "joints", "points", "input", "inputs"}
    mech.extras = {k: data[k] for k in data if k not in top.used}
    for key in mech.extras:
        if key not in _EXTRA_SECTIONS:
            top.fail(f"unknown key '{key}'")
    return mech


# Sections read by later stages (loads, dynamics); kept raw in `Mechanism.extras`.
_EXTRA_SECTIONS = {"loads", "gravity", "dynamics", "simulate", "friction", "plot", "description"}


def _read_links(mech: Mechanism, rows, unit):
    for i, raw in enumerate(rows):
        row = Row(raw, f"{mech.source}: links[{i}]")
        name = row.text("name", required=True)
        row.where = f"{mech.source}: links[{i}] '{name}'"
        lengths = []
        if row.has("length"):
            lengths.append(("", "", row.number("length", positive=True) * unit))
        raw_lengths = row.data.get("lengths", [])
        if not isinstance(raw_lengths, list):
            row.fail(f"'lengths' must be a list of [P, Q, length], got {raw_lengths!r}")
        for k, item in enumerate(raw_lengths):
            if not (isinstance(item, list) and len(item) == 3):
                row.fail(f"lengths[{k}] must be [P, Q, length], got {item!r}")
            p, q, value = item
            if not all(isinstance(v, (str, int)) and not isinstance(v, bool) for v in (p, q)):
                row.fail(f"lengths[{k}] must be [P, Q, length] with P, Q point names, got {item!r}")
            length = row._check_number(f"lengths[{k}]", value, positive=True) * unit
            lengths.append((str(p), str(q), length))
        row.used.add("lengths")
        angle = row.names("angle")
        angle_offset = math.radians(row.number("angle_offset", 0.0))
        mass = row.number("mass", 0.0)
        inertia = row.number("inertia", 0.0)
        if mass < 0 or inertia < 0:
            row.fail("mass and inertia must not be negative")
        centre, centre_at = _centre(row, name, unit)
        row.check_unknown_keys({"comment"})
        if name == mech.ground:
            if lengths:
                row.fail("the ground's geometry is its drawn coordinates; it takes no lengths")
            continue
        try:
            mech.add_link(name, lengths=tuple(lengths), angle=angle, mass=mass,
                          inertia=inertia * unit * unit, centre=centre, angle_offset=angle_offset)
            if centre_at is not None:
                mech.add_point(centre, name, at=centre_at)
        except ModelError as exc:
            row.fail(str(exc).split(": ", 1)[-1])


def _centre(row: Row, link: str, unit: float) -> tuple[str | None, tuple[float, float] | None]:
    """A link's `centre`: a point's name, or coordinates [x, y] in the drawn pose, which make a point
    of the link named `<link>:centre` (its drawn coordinates in metres)."""
    value = row.data.get("centre")
    if not isinstance(value, list):
        return row.text("centre"), None
    x, y = row.pair("centre")
    return f"{link}:centre", (x * unit, y * unit)


def _read_joints(mech: Mechanism, rows, unit):
    if not rows:
        raise ModelError(f"{mech.source}: no joints (a 'joints' list of pairs is required)")
    for i, raw in enumerate(rows):
        row = Row(raw, f"{mech.source}: joints[{i}]")
        name = row.text("name", required=True)
        row.where = f"{mech.source}: joints[{i}] '{name}'"
        kind = (row.text("type", required=True) or "").upper()
        if kind not in ("R", "P"):
            row.fail(f"type must be 'R' (revolute) or 'P' (prismatic), got '{kind}'")
        links = row.names("links", required=True)
        if links[0] == links[1]:
            row.fail(f"joins link '{links[0]}' to itself")
        for link in links:
            if link != mech.ground and link not in mech.links:
                row.fail(f"link '{link}' is not in the links list (ground is '{mech.ground}')")
        x, y = row.pair("at", required=True)
        guide = guide_points = None
        carrier = row.text("carrier")
        if kind == "P":
            if carrier is not None:
                if carrier not in links:
                    row.fail(f"carrier '{carrier}' is not one of its links {list(links)}")
                links = (carrier, links[1] if links[0] == carrier else links[0])
            value = row.data.get("guide")
            row.used.add("guide")
            if value is None:
                row.fail("a prismatic pair needs 'guide': an angle in degrees or two points [P, Q] "
                         "of the carrier link")
            if isinstance(value, list):
                guide_points = row.names("guide")
            else:
                guide = row.number("guide")
        else:
            if row.has("guide") or carrier is not None:
                row.fail("'guide' and 'carrier' belong to prismatic (P) pairs only")
        row.check_unknown_keys({"comment"})
        try:
            mech.add_joint(name, kind, links[0], links[1], (x * unit, y * unit), guide, guide_points)
        except ModelError as exc:
            row.fail(str(exc).split(": ", 1)[-1])


def _read_points(mech: Mechanism, rows, unit):
    for i, raw in enumerate(rows):
        row = Row(raw, f"{mech.source}: points[{i}]")
        name = row.text("name", required=True)
        row.where = f"{mech.source}: points[{i}] '{name}'"
        link = row.text("link", required=True)
        if link != mech.ground and link not in mech.links:
            row.fail(f"link '{link}' is not in the links list")
        at = row.pair("at")
        along = row.names("along")
        fraction = row.number("fraction")
        distance = row.number("distance")
        offset = row.number("offset", 0.0)
        if (at is None) == (along is None):
            row.fail("give either 'at' = [x, y] or 'along' = [P, Q] with 'fraction' or 'distance'")
        if along is not None and (fraction is None) == (distance is None):
            row.fail("'along' needs exactly one of 'fraction' or 'distance'")
        row.check_unknown_keys({"comment"})
        try:
            mech.add_point(name, link, None if at is None else (at[0] * unit, at[1] * unit),
                           along=along, fraction=fraction,
                           distance=None if distance is None else distance * unit,
                           offset=offset * unit)
        except ModelError as exc:
            row.fail(str(exc).split(": ", 1)[-1])


def _steps(row: Row) -> int | None:
    steps = row.number("steps")
    if steps is not None and (steps != int(steps) or steps < 1):
        row.fail(f"steps must be a whole number ≥ 1, got {steps:g}")
    return None if steps is None else int(steps)


def _read_inputs(mech: Mechanism, data, source, unit):
    rows = data.get("inputs")
    if rows is None:
        rows = [data["input"]] if "input" in data else []
    elif "input" in data:
        raise ModelError(f"{source}: give either [input] or an 'inputs' list, not both")
    if not isinstance(rows, list):
        raise ModelError(f"{source}: 'inputs' must be a list of tables")
    if not rows:
        raise ModelError(f"{source}: no input: add an [input] table naming the driving joint")
    for i, raw in enumerate(rows):
        row = Row(raw, f"{source}: inputs[{i}]")
        joint_name = row.text("joint", required=True)
        row.where = f"{source}: inputs[{i}] (joint '{joint_name}')"
        joint = mech.joints.get(joint_name)
        if joint is None:
            row.fail(f"'{joint_name}' is not a joint of the table")
        if any(inp.joint == joint_name for inp in mech.inputs):
            row.fail(f"joint '{joint_name}' is driven twice")
        default_unit = "deg" if joint.kind == "R" else "m"
        in_unit = row.text("unit", default_unit)
        allowed = ("deg", "rad") if joint.kind == "R" else ("m", "mm")
        if in_unit not in allowed:
            row.fail(f"unit of a {'revolute' if joint.kind == 'R' else 'prismatic'} input must be "
                     f"one of {', '.join(allowed)}, got '{in_unit}'")
        sense = row.data.get("sense", 1)
        row.used.add("sense")
        if isinstance(sense, str):
            sense = {"ccw": 1.0, "cw": -1.0}.get(sense, sense)
        if isinstance(sense, bool) or sense not in (1, -1, 1.0, -1.0):
            row.fail(f"sense must be 1, -1, 'ccw' or 'cw', got {sense!r}")
        sweep = row.data.get("sweep")
        row.used.add("sweep")
        if sweep is not None:
            if not (isinstance(sweep, list) and len(sweep) == 2):
                row.fail(f"sweep must be [from, to], got {sweep!r}")
            sweep = (row._check_number("sweep", sweep[0]), row._check_number("sweep", sweep[1]))
            if sweep[0] == sweep[1]:
                row.fail("sweep range is empty")
        inp = Input(joint=joint_name, name=row.text("name", "phi"), unit=in_unit,
                    zero=row.number("zero", 0.0), sense=float(sense),
                    omega=row.number("omega", 1.0), epsilon=row.number("epsilon", 0.0),
                    drawn_at=row.number("drawn_at"), sweep=sweep, steps=_steps(row))
        row.check_unknown_keys({"comment"})
        mech.inputs.append(inp)
