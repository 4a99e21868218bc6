"""Reading the `[gears]` section: of a model file (the report gains a Gears section) or of a file of its
own (`mbplanar gear pair FILE`, `mbplanar gear planetary FILE`). Lengths in metres, or `length_unit`
("m", "cm", "mm") in `[gears]`; angles in degrees. docs/gears.md lists every key.

    [gears]
    title = "Shaper drive"
    length_unit = "mm"

    [gears.pair]
    module = 10
    teeth = [12, 30]
    shifts = "auto"          # or [x1, x2]
    criterion = "balanced"

    [gears.planetary]
    ratio = 19.348           # the whole reduction (with the pair after the train: stage = true)
    scheme = "B"
    planets = 3
    module = 2
    stage = true

`[gears.train]` is what `mbplanar gear planetary -o` writes into a model: the chosen train, kept as a
record.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

from ..errors import ModelError
from ..model import Key, Section

__all__ = ["PairSpec", "PlanetarySpec", "GearsSpec", "parse_gears", "read_gears", "GEARS", "GEARS_PAIR",
           "GEARS_PLANETARY"]

_UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3}
_LENGTH = "in [gears] length_unit"
_TEETH = {"type": "array", "items": {"type": "integer", "minimum": 1}, "minItems": 2, "maxItems": 2}
_COMMENT = Key("comment", "any", "free text, ignored")

#: the keys of `[gears.pair]`, `[gears.planetary]` and `[gears]`: what `parse_gears` accepts and what the
#: model's JSON Schema (`mbplanar schema`) describes
GEARS_PAIR = Section("gears_pair", "[gears.pair]", "a spur pair with profile shift (docs/gears.md)", (
    Key("module", "number", f"the module, {_LENGTH}", required=True, positive=True),
    Key("teeth", "custom", "[z1, z2]: tooth numbers (internal: gear 2 the ring)", required=True, schema=_TEETH),
    Key("internal", "boolean", "gear 2 has internal teeth", default=False),
    Key("shifts", "custom", '"auto" (chosen by criterion) or [x1, x2]', default="auto",
        schema={"anyOf": [{"const": "auto"}, {"type": "array", "items": {"type": "number"}, "minItems": 2,
                                              "maxItems": 2}]}),
    Key("criterion", "choice", "how \"auto\" chooses", choices=("balanced", "contact", "sum"), default="balanced"),
    Key("shift_sum", "number", "x1 + x2 (internal: x2 − x1) to hold"),
    Key("centre_distance", "number", f"a fixed working centre distance, {_LENGTH}", positive=True),
    Key("pressure_angle", "number", "α of the basic rack", unit="deg", default=20.0, positive=True),
    Key("addendum", "number", "h_a*", default=1.0, positive=True),
    Key("clearance", "number", "c*", default=0.25, minimum=0.0),
    Key("tip_radius", "number", "ρ_f* of the tool's tip round, in modules", minimum=0.0,
        default_doc="c*/(1 − sin α), or the largest that fits"),
    Key("min_tip", "number", "the smallest tip thickness, in modules", default=0.25, minimum=0.0),
    Key("min_contact", "number", "the smallest contact ratio", default=1.2, positive=True),
    Key("ring_tip", "choice", "an internal gear's tip circle: standard, or cut back to meet the pinion on its "
        "involute", choices=("standard", "cut"), default="standard"),
    _COMMENT))

GEARS_PLANETARY = Section("gears_planetary", "[gears.planetary]", "a planetary train by tooth numbers", (
    Key("ratio", "number", "input speed / output speed (with stage: of the whole drive)", required=True,
        nonzero=True),
    Key("scheme", "choice", "the schemes searched", choices=("A", "B", "C", "D", "all"), default="all"),
    Key("planets", "integer", "k, equally spaced", default=3, minimum=1),
    Key("tolerance", "number", "relative tolerance of the ratio", default=0.01, minimum=0.0),
    Key("module", "number", f"the train's module, {_LENGTH}", positive=True, default_doc="1 mm"),
    Key("min_teeth", "integer", "the smallest external gear", minimum=1,
        default_doc="the smallest without undercut at x = 0 (18)"),
    Key("max_teeth", "integer", "the largest gear, rings included", default=150, minimum=1, maximum=400),
    Key("choose", "integer", "which train of the list is written and drawn", default=1, minimum=1),
    Key("stage", "boolean", "the [gears.pair] follows the train's output", default=False),
    _COMMENT))

GEARS = Section("gears", "[gears]", "the drive's gears (docs/gears.md)", (
    Key("title", "text", "a title for the report", default=""),
    Key("length_unit", "choice", "the unit of the modules and the centre distance", choices=tuple(_UNITS),
        default="m"),
    Key("pair", "table", "a spur pair", section=GEARS_PAIR),
    Key("planetary", "table", "a planetary train", section=GEARS_PLANETARY),
    Key("train", "any", "the train mbplanar gear planetary -o chose, kept as a record"),
    _COMMENT))


@dataclass(frozen=True)
class PairSpec:
    """`[gears.pair]` in SI (angles in degrees)."""

    module: float
    teeth: tuple
    internal: bool = False
    shifts: object = "auto"              # "auto" or (x1, x2)
    criterion: str = "balanced"
    shift_sum: float | None = None
    centre_distance: float | None = None
    pressure_angle: float = 20.0
    addendum: float = 1.0
    clearance: float = 0.25
    tip_radius: float | None = None
    min_tip: float = 0.25
    min_contact: float = 1.2
    ring_tip: str = "standard"


@dataclass(frozen=True)
class PlanetarySpec:
    """`[gears.planetary]` in SI."""

    ratio: float
    scheme: str | None = None
    planets: int = 3
    tolerance: float = 0.01
    module: float = 1e-3
    min_teeth: int | None = None
    max_teeth: int = 150
    choose: int = 1
    stage: bool = False


@dataclass(frozen=True)
class GearsSpec:
    """Everything a `[gears]` section says."""

    source: str
    title: str
    pair: PairSpec | None
    planetary: PlanetarySpec | None
    train: dict | None


def _check_keys(table, allowed, where):
    for key in table:
        if key not in allowed:
            raise ModelError(f"unknown key {key!r} (one of {', '.join(sorted(allowed))})", where=where)


def _number(table, key, where, *, positive=False, default=None):
    v = table.get(key, default)
    if v is None:
        return None
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or (positive and v <= 0):
        raise ModelError(f"{key} must be a {'positive ' if positive else ''}number, got {v!r}", where=where)
    return float(v)


def _whole(table, key, where, default=None):
    v = table.get(key, default)
    if v is None:
        return None
    if isinstance(v, bool) or not isinstance(v, int) or v < 1:
        raise ModelError(f"{key} must be a whole number ≥ 1, got {v!r}", where=where)
    return v


def _pair(table, scale, where) -> PairSpec:
    _check_keys(table, GEARS_PAIR.names, where)
    for key in ("module", "teeth"):
        if key not in table:
            raise ModelError(f"missing key {key!r}", where=where)
    teeth = table["teeth"]
    if not (isinstance(teeth, list) and len(teeth) == 2):
        raise ModelError(f"teeth must be [z1, z2], got {teeth!r}", where=where)
    shifts = table.get("shifts", "auto")
    if shifts != "auto":
        if not (isinstance(shifts, list) and len(shifts) == 2
                and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in shifts)):
            raise ModelError(f'shifts must be "auto" or [x1, x2], got {shifts!r}', where=where)
        shifts = tuple(float(x) for x in shifts)
    internal = table.get("internal", False)
    if not isinstance(internal, bool):
        raise ModelError(f"internal must be true or false, got {internal!r}", where=where)
    centre = _number(table, "centre_distance", where, positive=True)
    return PairSpec(_number(table, "module", where, positive=True) * scale, tuple(teeth), internal, shifts,
                    str(table.get("criterion", "balanced")), _number(table, "shift_sum", where),
                    None if centre is None else centre * scale, _number(table, "pressure_angle", where, default=20.0),
                    _number(table, "addendum", where, default=1.0), _number(table, "clearance", where, default=0.25),
                    _number(table, "tip_radius", where), _number(table, "min_tip", where, default=0.25),
                    _number(table, "min_contact", where, default=1.2), str(table.get("ring_tip", "standard")))


def _planetary(table, scale, where) -> PlanetarySpec:
    _check_keys(table, GEARS_PLANETARY.names, where)
    if "ratio" not in table:
        raise ModelError("missing key 'ratio'", where=where)
    stage = table.get("stage", False)
    if not isinstance(stage, bool):
        raise ModelError(f"stage must be true or false, got {stage!r}", where=where)
    scheme = table.get("scheme")
    return PlanetarySpec(_number(table, "ratio", where), None if scheme in (None, "all") else str(scheme),
                         _whole(table, "planets", where, 3), _number(table, "tolerance", where, default=0.01),
                         _number(table, "module", where, positive=True, default=1e-3 / scale) * scale,
                         _whole(table, "min_teeth", where), _whole(table, "max_teeth", where, 150),
                         _whole(table, "choose", where, 1), stage)


def parse_gears(data: dict, source: str = "<table>") -> GearsSpec:
    """The `[gears]` section of a parsed TOML table (the whole file's dict).

    Raises
    ------
    ModelError
        no `[gears]` section, an unknown key or a value of the wrong kind (named with the section).

    Examples
    --------
    >>> from mbplanar.gears.spec import parse_gears
    >>> s = parse_gears({"gears": {"length_unit": "mm", "pair": {"module": 10, "teeth": [12, 30]}}})
    >>> s.pair.module, s.pair.shifts
    (0.01, 'auto')
    """
    if "gears" not in data or not isinstance(data["gears"], dict):
        raise ModelError("no [gears] section", source=source)
    g = data["gears"]
    _check_keys(g, GEARS.names, f"{source}: [gears]")
    unit = g.get("length_unit", "m")
    if unit not in _UNITS:
        raise ModelError(f"length_unit must be one of {', '.join(_UNITS)}, got {unit!r}", where=f"{source}: [gears]")
    scale = _UNITS[unit]
    pair = _pair(g["pair"], scale, f"{source}: [gears.pair]") if "pair" in g else None
    planetary = _planetary(g["planetary"], scale, f"{source}: [gears.planetary]") if "planetary" in g else None
    return GearsSpec(source, str(g.get("title", "")), pair, planetary, g.get("train"))


def read_gears(path) -> GearsSpec:
    """`parse_gears` of a TOML file (a model with a `[gears]` section, or a file of its own)."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ModelError("no such file", source=str(path)) from None
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"not valid TOML: {exc}", source=str(path)) from None
    return parse_gears(data, str(path))
