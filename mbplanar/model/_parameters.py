"""Design parameters of a model: named dimensions that the table refers to, and polar placements.

A model may declare a `[parameters]` table of named numbers, each a plain number (in the unit of the
field that uses it) or ``{ value = ..., unit = "..." }`` with a unit among ``m``, ``mm``, ``cm`` (a
length), ``deg``, ``rad`` (an angle)::

    [parameters]
    l2 = 1.0                                   # metres (the model's length unit)
    phi20 = { value = 0.5, unit = "rad" }      # converted to degrees where an angle is expected

Wherever the table expects one of these numbers, it may give a parameter's name instead:

- ``links[].length``, the third item of ``links[].lengths`` entries, ``links[].mass``, ``inertia``;
- ``joints[].at`` items (the coordinates of ground pivots and of every drawn joint) and ``guide``;
- ``points[].at`` items, ``fraction``, ``distance``, ``offset``;
- ``input.zero``, ``input.drawn_at``, ``input.omega``.

A joint's ``at`` may also be a polar placement relative to another joint,
``at = { from = "A", length = "l2", angle = "phi20" }``: the point ``from + length·(cos a, sin a)``,
the angle ``a`` measured from +x, in degrees (or a parameter, converted from its unit). Placements may
chain; a cycle is an error. Nothing is evaluated as an expression: a value is a number or a name.

`Template` holds the raw table; `Template.bind(values)` gives the plain table (numbers only) for one
design, and `Template.geometry(values)` the drawn coordinates of every joint for arrays of values (one
per design), with the same arithmetic, so that a design batch and one-by-one binding agree exactly.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ._keys import CURVE, HIGHER, INPUT, LINK, PARAMETER, POINT
from ._model import ANGLE_UNITS, LENGTH_UNITS, unit_spelling

__all__ = ["Parameter", "Template", "split_parameters", "higher_rows"]

_UNITS = (*LENGTH_UNITS, *ANGLE_UNITS)


@dataclass(frozen=True)
class Parameter:
    """A named design dimension: its default `value` in `unit` (None: the unit of the field using it).

    One entry of a model's ``[parameters]`` table (`Template.parameters`, by `name`).

    Examples
    --------
    >>> import tomllib
    >>> from mbplanar.model import Template
    >>> with open("models/fourbar_design.toml", "rb") as f:
    ...     template = Template(tomllib.load(f), "models/fourbar_design.toml")
    >>> template.parameters["theta0"]
    Parameter(name='theta0', value=60.0, unit=None)
    """

    name: str
    value: float
    unit: str | None = None


def _number(value, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ModelError(f"{where}: must be a finite number, got {value!r}")
    return float(value)


def split_parameters(data: dict, source: str) -> tuple[dict, dict[str, Parameter]]:
    """The table without its `[parameters]` section, and the parameters it declares."""
    raw = data.get("parameters", {})
    if not isinstance(raw, dict):
        raise ModelError(f"{source}: [parameters] must be a table of name = value")
    params = {}
    for name, spec in raw.items():
        where = f"{source}: parameters.{name}"
        unit = None
        if isinstance(spec, dict):
            unknown = set(spec) - PARAMETER.names
            if unknown:
                raise ModelError(f"{where}: unknown key(s) {', '.join(sorted(unknown))}")
            if "value" not in spec:
                raise ModelError(f"{where}: missing 'value'")
            unit = spec.get("unit")
            if unit is not None:
                unit = unit_spelling(unit, _UNITS)
                if unit is None:
                    raise ModelError(f"{where}: unit must be one of {', '.join(_UNITS)} (in any case), "
                                     f"got {spec.get('unit')!r}")
            spec = spec["value"]
        params[name] = Parameter(name, _number(spec, where), unit)
    rest = {k: v for k, v in data.items() if k != "parameters"}
    return rest, params


# the numeric fields a parameter may stand for, with the kind of number they hold (declared with the keys;
# "dimension": a length that must not be negative, "length": a coordinate or an offset, of any sign)
_LINK_FIELDS = LINK.parameter_fields()
_POINT_FIELDS = POINT.parameter_fields()
_INPUT_FIELDS = INPUT.parameter_fields()
_HIGHER_FIELDS = {kind: section.parameter_fields() for kind, section in HIGHER.items()}
_CURVE_FIELDS = CURVE.parameter_fields()


def _higher_kind(row) -> str | None:
    """The higher pair a joints row is (gear, rack, cam, slot), None for a lower pair."""
    kind = row.get("type") if isinstance(row, dict) else None
    return kind.lower() if isinstance(kind, str) and kind.lower() in HIGHER else None


class Template:
    """A model table with named parameters (see the module docstring).

    Parameters
    ----------
    data : dict
        The TOML document (as `tomllib` gives it), with or without a `[parameters]` table.
    source : str
        The file name, for error messages.

    Attributes
    ----------
    parameters : dict of str to Parameter
        The declared parameters, in the table's order (`names`: their names).
    data : dict
        The table without its ``[parameters]``, rows given as tables of named rows turned into lists.
    uses : dict
        Parameter → {kind of field: the first field using it}.

    Raises
    ------
    ModelError
        A parameter that is not a finite number (or ``{value, unit}``), a reference to an unknown one, a
        cycle of polar placements, a parameter used for numbers of different kinds.

    Examples
    --------
    >>> import tomllib
    >>> from mbplanar.model import Template
    >>> with open("models/fourbar_design.toml", "rb") as f:
    ...     template = Template(tomllib.load(f), "models/fourbar_design.toml")
    >>> template.names
    ('a', 'b', 'd', 'theta0', 'beta', 'm', 'h')
    >>> [round(v, 4) for v in template.bind({"a": 0.12})["joints"][1]["at"]]   # A = O + a·(cos θ0, sin θ0)
    [0.06, 0.1039]
    >>> template.bind({"e": 1.0})
    Traceback (most recent call last):
    mbplanar.errors.ModelError: models/fourbar_design.toml: unknown parameter(s) e (parameters: a, b, ...)
    """

    def __init__(self, data: dict, source: str = "<table>"):
        self.source = source
        self.raw = data
        self.data, self.parameters = split_parameters(data, source)
        for key in ("links", "joints", "points"):  # [links.1] style tables as rows with a name
            if isinstance(self.data.get(key), dict):
                self.data[key] = _row_list(self.data, key)
        self.length_name = unit_spelling(self.data.get("length_unit", "m"), LENGTH_UNITS) or "m"
        self.length_unit = LENGTH_UNITS[self.length_name]
        self.names = tuple(self.parameters)
        self.used: set[str] = set()
        self.uses: dict[str, dict[str, str]] = {}   # parameter → {kind of field: the first field using it}
        self.bind(self.defaults())  # every reference checked once, and `used` and `uses` filled in
        self._check_uses()

    def defaults(self) -> dict[str, float]:
        """The declared value of every parameter, in its own unit."""
        return {name: p.value for name, p in self.parameters.items()}

    @property
    def needs_assembly(self) -> bool:
        """Whether a design's drawn pose is a sketch (dimensions or the input's drawn value given)."""
        links = self.data.get("links", [])
        rows = links.values() if isinstance(links, dict) else links
        inputs = self.data.get("inputs", [self.data.get("input", {})])
        return any(isinstance(r, dict) and ("length" in r or r.get("lengths")) for r in rows) or any(
            isinstance(i, dict) and "drawn_at" in i for i in inputs)

    # -- what each parameter is -----------------------------------------------------------------------
    def _check_uses(self):
        """A parameter used both as a length and as an angle is refused, naming both fields; a
        parameter used as a dimension (a link length, a polar length, a distance) must not be negative."""
        for name, uses in self.uses.items():
            lengths = [w for k, w in uses.items() if k in ("length", "dimension")]
            if lengths and "angle" in uses:
                raise ModelError(f"{self.source}: parameters.{name}: used as a length ({lengths[0]}) and as an "
                                 f"angle ({uses['angle']}); give each its own parameter")
            if "dimension" in uses and self.parameters[name].value < 0:
                raise ModelError(f"{self.source}: parameters.{name}: {self.parameters[name].value:g} is a length "
                                 f"({uses['dimension']}) and must not be negative")

    def kind(self, name: str) -> str | None:
        """What parameter `name` is: "length", "angle", "plain" (a mass, a fraction, a speed), or None
        when no field uses it."""
        uses = self.uses.get(name, {})
        for kind in ("length", "angle", "plain"):
            if kind in uses or (kind == "length" and "dimension" in uses):
                return kind
        return None

    def positive(self, name: str) -> str | None:
        """The field that makes parameter `name` a dimension (a length that must not be negative), or None."""
        return self.uses.get(name, {}).get("dimension")

    def unit(self, name: str) -> str | None:
        """The unit parameter `name`'s values are in: its own `unit`, else the unit of the fields using it
        (the table's `length_unit` for a length, degrees for an angle); None for a plain number."""
        p = self.parameters[name]
        if p.unit is not None:
            return p.unit
        kind = self.kind(name)
        return self.length_name if kind == "length" else "deg" if kind == "angle" else None

    # -- values ---------------------------------------------------------------------------------------
    def _value(self, raw, kind: str, values: dict, where: str, input_unit: str | None = None):
        """A field's number: `raw` itself, or the parameter it names converted to the field's unit
        (`kind`: "length", "dimension" (a positive length), "angle", "input" or "plain")."""
        if not isinstance(raw, str):
            if isinstance(raw, bool) or not isinstance(raw, (int, float, np.ndarray)):
                raise ModelError(f"{self.source}: {where}: {raw!r} is not a number nor a parameter's name")
            return raw
        if raw not in self.parameters:
            known = ", ".join(self.names) or "none declared"
            raise ModelError(f"{self.source}: {where}: '{raw}' is not a number nor a parameter "
                             f"(parameters: {known})")
        self.used.add(raw)
        unit = self.parameters[raw].unit
        value = values[raw]
        if kind == "input":
            input_unit = unit_spelling(input_unit, _UNITS) or input_unit
            kind = "angle_" + input_unit if input_unit in ANGLE_UNITS else "length"
        self.uses.setdefault(raw, {}).setdefault(kind.split("_")[0], where)
        kind = "length" if kind == "dimension" else kind
        if unit is None:
            return value
        if kind == "length" and unit in LENGTH_UNITS:
            return value * (LENGTH_UNITS[unit] / self.length_unit)
        if kind.startswith("angle") and unit in ANGLE_UNITS:
            target = kind.split("_")[1] if "_" in kind else "deg"
            if unit == target:
                return value
            return value * (180.0 / math.pi) if target == "deg" else value * (math.pi / 180.0)
        raise ModelError(f"{self.source}: {where}: parameter '{raw}' is in {unit}, which does not fit "
                         f"a {kind.split('_')[0]} here")

    def _radians(self, raw, values: dict, where: str):
        """An angle field written in degrees, in radians: a parameter in radians is taken as it is (no
        round trip through degrees)."""
        if isinstance(raw, str) and self.parameters.get(raw) is not None and self.parameters[raw].unit == "rad":
            self.used.add(raw)
            self.uses.setdefault(raw, {}).setdefault("angle", where)
            return values[raw]
        return self._value(raw, "angle", values, where) * (math.pi / 180.0)  # (np.radians' product; complex too)

    def _check_values(self, values: dict) -> dict:
        unknown = set(values) - set(self.parameters)
        if unknown:
            raise ModelError(f"{self.source}: unknown parameter(s) {', '.join(sorted(unknown))} "
                             f"(parameters: {', '.join(self.names) or 'none declared'})")
        return {**self.defaults(), **values}

    # -- one design -----------------------------------------------------------------------------------
    def bind(self, values: dict | None = None) -> dict:
        """The plain table (numbers only, polar placements resolved) for parameter `values` (each a
        number in its parameter's unit; missing ones take their declared value)."""
        values = self._check_values(values or {})
        data = copy.deepcopy(self.data)
        self._bind_links(data, values)
        joints = self._bind_joints(data, values)
        for i, row in enumerate(_row_list(data, "points")):
            if isinstance(row, dict):
                self._bind_fields(row, _POINT_FIELDS, values, f"points[{i}]")
                if isinstance(row.get("at"), list):
                    row["at"] = [self._value(x, "length", values, f"points[{i}] at") for x in row["at"]]
        for i, row in enumerate(_input_rows(data)):
            if isinstance(row, dict):
                unit = row.get("unit", "deg")
                for key, kind in _INPUT_FIELDS.items():
                    if key in row:
                        row[key] = self._value(row[key], kind, values, f"inputs[{i}] {key}", unit)
        for row, at in joints:
            try:
                row["at"] = [float(at[0]), float(at[1])]
            except (TypeError, ValueError, IndexError):
                pass  # not a pair of numbers: the table reader refuses the row, naming it
        return data

    def _bind_fields(self, row: dict, fields: dict, values: dict, where: str):
        for key, kind in fields.items():
            if key in row:
                row[key] = self._value(row[key], kind, values, f"{where} {key}")

    def _bind_links(self, data: dict, values: dict):
        for i, row in enumerate(_row_list(data, "links")):
            if not isinstance(row, dict):
                continue
            self._bind_fields(row, _LINK_FIELDS, values, f"links[{i}]")
            for k, item in enumerate(row.get("lengths", []) if isinstance(row.get("lengths"), list) else []):
                if isinstance(item, list) and len(item) == 3:
                    item[2] = self._value(item[2], "dimension", values, f"links[{i}] lengths[{k}]")

    def _bind_joints(self, data: dict, values: dict) -> list:
        rows = [r for r in _row_list(data, "joints") if isinstance(r, dict)]
        for i, row in enumerate(rows):
            kind = _higher_kind(row)
            if kind is not None:
                self._bind_higher(row, kind, values, f"joints[{i}]")
            elif isinstance(row.get("guide"), str):
                row["guide"] = self._value(row["guide"], "angle", values, f"joints[{i}] guide")
        at = self.positions(values, rows)
        return [(row, at[row["name"]]) for row in rows if isinstance(row.get("name"), str) and row["name"] in at]

    def _bind_higher(self, row: dict, kind: str, values: dict, where: str):
        """A higher pair's numbers: its declared fields, a gear's radii, its curve's radius and centre."""
        self._bind_fields(row, _HIGHER_FIELDS[kind], values, where)
        if isinstance(row.get("radii"), list):
            row["radii"] = [self._value(x, "dimension", values, f"{where} radii") for x in row["radii"]]
        for key in ("profile", "path"):
            curve = row.get(key)
            if isinstance(curve, dict):
                self._bind_fields(curve, _CURVE_FIELDS, values, f"{where} {key}")
                if isinstance(curve.get("centre"), list):
                    curve["centre"] = [self._value(x, "length", values, f"{where} {key} centre") for x in curve["centre"]]

    # -- coordinates, for one design or a batch ------------------------------------------------------
    def positions(self, values: dict, rows: list | None = None) -> dict:
        """Drawn coordinates (x, y) of every joint, in the file's length unit, for parameter `values`
        (numbers, or arrays with one value per design: the coordinates are then arrays too)."""
        rows = rows if rows is not None else [r for r in _row_list(self.data, "joints") if isinstance(r, dict)]
        # (a higher pair's `at` is optional, or a point's name: only its coordinates are placed)
        specs = {str(r.get("name")): (i, r.get("at")) for i, r in enumerate(rows) if "name" in r
                 and (_higher_kind(r) is None or isinstance(r.get("at"), (list, dict)))}
        out: dict = {}

        def place(name: str, chain: tuple):
            if name in out:
                return out[name]
            if name in chain:
                raise ModelError(f"{self.source}: joints '{name}': polar placements form a cycle "
                                 f"({' → '.join(chain + (name,))})")
            if name not in specs:
                raise ModelError(f"{self.source}: joints '{chain[-1]}': 'from' names no joint '{name}'")
            i, at = specs[name]
            where = f"joints[{i}] '{name}' at"
            if isinstance(at, dict):
                unknown = set(at) - {"from", "length", "angle"}
                if unknown or not {"from", "length", "angle"} <= set(at):
                    raise ModelError(f"{self.source}: {where}: a polar placement is "
                                     "{ from = JOINT, length = L, angle = DEG }")
                base = place(str(at["from"]), chain + (name,))
                length = self._value(at["length"], "dimension", values, where + " length")
                angle = self._radians(at["angle"], values, where + " angle")
                out[name] = (base[0] + length * np.cos(angle), base[1] + length * np.sin(angle))
            elif isinstance(at, list) and len(at) == 2:
                out[name] = tuple(self._value(x, "length", values, where) for x in at)
            else:
                raise ModelError(f"{self.source}: {where}: must be [x, y] or "
                                 "{ from = JOINT, length = L, angle = DEG }")
            return out[name]

        for name in specs:
            place(name, ())
        return out

    def guides(self, values: dict) -> dict:
        """Guide angle (degrees) of every prismatic joint given by an angle, for `values` (numbers or
        arrays, as `positions`)."""
        out = {}
        for i, row in enumerate(r for r in _row_list(self.data, "joints") if isinstance(r, dict)):
            guide = row.get("guide")
            if guide is not None and not isinstance(guide, list) and _higher_kind(row) is None:
                out[str(row.get("name"))] = self._value(guide, "angle", values, f"joints[{i}] guide")
        return out

    def link_lengths(self, values: dict) -> dict:
        """Every declared link length for `values` (numbers or arrays, as `positions`), in the file's length
        unit: (link, P, Q) → value, with P = Q = "" for a link's `length`."""
        out = {}
        for i, row in enumerate(r for r in _row_list(self.data, "links") if isinstance(r, dict)):
            link = str(row.get("name"))
            if "length" in row:
                out[(link, "", "")] = self._value(row["length"], "length", values, f"links[{i}] length")
            items = row.get("lengths") if isinstance(row.get("lengths"), list) else []
            for k, item in enumerate(items):
                if isinstance(item, list) and len(item) == 3:
                    out[(link, str(item[0]), str(item[1]))] = self._value(item[2], "length", values,
                                                                          f"links[{i}] lengths[{k}]")
        return out

    def point_fields(self, values: dict) -> dict:
        """Each point's numbers for `values` (numbers or arrays): "x", "y" of a point given by `at`, or
        "fraction", "distance", "offset" of one built along two others (lengths in the file's unit)."""
        out = {}
        for i, row in enumerate(r for r in _row_list(self.data, "points") if isinstance(r, dict)):
            got = {}
            if isinstance(row.get("at"), list) and len(row["at"]) == 2:
                got["x"], got["y"] = (self._value(x, "length", values, f"points[{i}] at") for x in row["at"])
            for key, kind in _POINT_FIELDS.items():
                if key in row and key != "at":
                    got[key] = self._value(row[key], kind, values, f"points[{i}] {key}")
            out[str(row.get("name"))] = got
        return out

    def parameter_kinds(self) -> dict:
        """The kinds of the fields each parameter stands for: "length", "angle", "input", "plain" (a
        fraction), "mass", "inertia", "omega" or "drawn_at"."""
        out: dict = {}

        def note(raw, kind):
            if isinstance(raw, str) and raw in self.parameters:
                out.setdefault(raw, set()).add(kind)

        for row in (r for r in _row_list(self.data, "links") if isinstance(r, dict)):
            note(row.get("length"), "length")
            note(row.get("mass"), "mass")
            note(row.get("inertia"), "inertia")
            for item in row.get("lengths") if isinstance(row.get("lengths"), list) else []:
                if isinstance(item, list) and len(item) == 3:
                    note(item[2], "length")
        for row in (r for r in _row_list(self.data, "joints") if isinstance(r, dict)):
            at = row.get("at")
            if isinstance(at, list):
                for x in at:
                    note(x, "length")
            elif isinstance(at, dict):
                note(at.get("length"), "length")
                note(at.get("angle"), "angle")
            note(row.get("guide"), "angle")
        for row in (r for r in _row_list(self.data, "points") if isinstance(r, dict)):
            for x in row.get("at") if isinstance(row.get("at"), list) else []:
                note(x, "length")
            note(row.get("fraction"), "plain")
            note(row.get("distance"), "length")
            note(row.get("offset"), "length")
        for row in (r for r in _input_rows(self.data) if isinstance(r, dict)):
            note(row.get("zero"), "input")
            note(row.get("drawn_at"), "drawn_at")
            note(row.get("omega"), "omega")
        return out

    def input_zero(self, values: dict) -> list:
        """Each input's `zero` (in its unit) for `values` (numbers or arrays)."""
        return [self._value(row.get("zero", 0.0), "input", values, f"inputs[{i}] zero", row.get("unit", "deg"))
                for i, row in enumerate(_input_rows(self.data)) if isinstance(row, dict)]


def higher_rows(data: dict) -> list[tuple[str, str, dict]]:
    """The higher pairs among a table's ``joints`` rows, as its reader sees them.

    Parameters
    ----------
    data : dict
        A model's TOML document (as `tomllib` gives it, or `Template.data`); ``joints`` an array of
        tables or a table of tables by name.

    Returns
    -------
    list of (str, str, dict)
        (name, kind, row) of each: the row's ``name`` (``"None"`` when it has none), the pair's kind in
        lower case (``"gear"``, ``"rack"``, ``"cam"`` or ``"slot"``) and the row itself, its numbers
        possibly parameter names.

    Raises
    ------
    Nothing: rows that are not tables, or whose ``type`` is a lower pair's or not a string, are skipped
    (the model's reader reports them).

    Examples
    --------
    >>> import tomllib
    >>> from mbplanar.model import higher_rows
    >>> with open("models/rack_pinion.toml", "rb") as f:
    ...     data = tomllib.load(f)
    >>> [(name, kind) for name, kind, _ in higher_rows(data)]
    [('K', 'rack')]
    """
    return [(str(row.get("name")), kind, row) for row in _row_list(data, "joints")
            if (kind := _higher_kind(row)) is not None]


def _row_list(data: dict, key: str) -> list:
    rows = data.get(key, [])
    if isinstance(rows, dict):
        return [dict(v, name=k) if isinstance(v, dict) else v for k, v in rows.items()]
    return rows if isinstance(rows, list) else []


def _input_rows(data: dict) -> list:
    rows = data.get("inputs")
    if rows is None:
        rows = [data["input"]] if isinstance(data.get("input"), dict) else []
    return rows if isinstance(rows, list) else []
