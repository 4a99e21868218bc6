"""Variant tables: one design per row, one column per parameter (CSV), read into arrays.

A variant table is a CSV file whose header names parameters of the model (see `mbplanar.model._parameters`);
an optional first column `variant` (or `name`) names each row. Lines starting with `#` are comments.
Every cell must be a finite number; the error names the file, the row and the column at fault.
Parameters the table leaves out keep the model's declared values.

A cell is in its parameter's unit (its declared `unit`, else the table's `length_unit` for a length and
degrees for an angle), or in the unit its header names in brackets: ``l2[mm]``, ``phi20[deg]`` (any
length or angle unit the model accepts, in any case). A length parameter that sizes something (a link
length, a polar length, a distance) must not be negative: the error names the line, the column and the
value. Values far from the parameter's declared one (100 times or more, 1/100 or less: a length in mm
where metres are meant), and angles in radians beyond a turn (degrees typed), warn with the numbers
(`mbplanar.errors.ModelWarning`).
"""

from __future__ import annotations

import csv
import math
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ModelError, ModelWarning, closest_names, did_you_mean
from ..model import ANGLE_UNITS, LENGTH_UNITS, Template, out_of_scale, unit_spelling

__all__ = ["Variants", "read_variants", "variants_from"]

NAME_COLUMNS = ("variant", "name")


@dataclass(frozen=True)
class Variants:
    """D designs of one model: their names and the parameter values a variant table sets.

    Attributes
    ----------
    names : tuple of str
        The designs' names (D,).
    values : dict
        {parameter: (D,) ndarray}, each in its parameter's own unit; parameters left out keep the
        model's declared values.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.study import load_template, variants_from
    >>> v = variants_from(load_template("models/fourbar_design.toml"), {"b": np.array([0.3, 0.35])})
    >>> v.names, v.values["b"].tolist(), len(v)
    (('1', '2'), [0.3, 0.35], 2)
    """

    names: tuple[str, ...]
    values: dict[str, np.ndarray]

    def __len__(self) -> int:
        return len(self.names)

    def row(self, k: int) -> dict[str, float]:
        """Parameter values of design k, as numbers."""
        return {name: float(v[k]) for name, v in self.values.items()}

    def take(self, index) -> "Variants":
        """The designs at `index` (an array of rows or a slice), in that order."""
        names = np.asarray(self.names, dtype=object)[index]
        return Variants(tuple(names), {n: v[index] for n, v in self.values.items()})


def variants_from(template: Template, values: dict, names=None, source: str = "<variants>", check: bool = True,
                  labels=None) -> Variants:
    """Variants from arrays of parameter values, checked against the model's parameters.

    Parameters
    ----------
    template : Template
        The model with its `[parameters]`.
    values : dict
        {parameter: (D,) array_like} in the parameters' units.
    names : sequence of str, optional
        The designs' names (default "1" … "D").
    source : str
        Where the values come from, for the messages.
    check : bool
        A negative length is an error and values far off the declared ones warn (`ModelWarning`:
        100 times or more, 1/100 or less, angles in radians beyond a turn).
    labels : sequence of str, optional
        What names each design in those messages (default "design k").

    Returns
    -------
    Variants
        The designs.

    Raises
    ------
    ModelError
        A name that is no parameter of the model (with the closest), arrays of different lengths, a
        value that is not finite, as many names as designs missing, or (with `check`) a negative length.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.study import load_template, variants_from
    >>> template = load_template("models/fourbar_design.toml")
    >>> variants_from(template, {"b": np.array([0.3, 0.12])}, names=["long", "short"]).names
    ('long', 'short')
    >>> variants_from(template, {"b": np.array([0.3, -0.1])})  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    mbplanar.errors.ModelError: <variants>: design 2: column 'b': -0.1 m is a length (...) and must not be negative
    """
    arrays = {k: np.atleast_1d(np.asarray(v, dtype=float)) for k, v in values.items()}
    unknown = sorted(set(arrays) - set(template.parameters))
    if unknown:
        hints = "; ".join(f"'{u}': {did_you_mean(u, template.names, 'parameters')}" for u in unknown[:3]
                          if closest_names(u, template.names))
        raise ModelError(f"{source}: column(s) {', '.join(unknown)} name no parameter of "
                         f"{template.source} (parameters: {', '.join(template.names) or 'none declared'})"
                         + (f"; {hints}" if hints else ""))
    sizes = {len(v) for v in arrays.values()}
    if len(sizes) > 1:
        raise ModelError(f"{source}: parameter arrays differ in length ({sorted(sizes)})")
    count = sizes.pop() if sizes else 1
    for k, v in arrays.items():
        bad = np.flatnonzero(~np.isfinite(v))
        if len(bad):
            raise ModelError(f"{source}: parameter '{k}' of design {int(bad[0]) + 1} is not finite")
    names = tuple(str(n) for n in names) if names is not None else tuple(str(k + 1) for k in range(count))
    if len(names) != count:
        raise ModelError(f"{source}: {len(names)} names for {count} designs")
    if check:
        check_values(template, arrays, labels or [f"design {k + 1}" for k in range(count)], source)
    return Variants(names, arrays)


def check_values(template: Template, values: dict, labels, source: str):
    """A negative value of a parameter that sizes a length is an error naming its row (`labels[k]`), column
    and value; values 100 times or more (1/100 or less) off the parameter's declared value, and angles in
    radians beyond a turn, warn once per column with the count, the first row and its value."""
    for name, v in values.items():
        kind, unit, declared = template.kind(name), template.unit(name), template.parameters[name].value
        field = template.positive(name)
        if field is not None and np.any(v < 0):
            k = int(np.flatnonzero(v < 0)[0])
            raise ModelError(f"column '{name}': {v[k]:g} {unit} is a length ({field}) and must not be negative",
                             source=source, where=labels[k])
        if kind == "angle" and unit == "rad":
            bad, why = np.abs(v) > 2 * math.pi, "more than a turn in radians: degrees?"
        elif kind in ("length", "angle"):
            bad = np.array([out_of_scale(x, declared) for x in v], bool)
            why = (f"100 times or more, or 1/100 or less, of the parameter's declared {declared:g} {unit}: "
                   "in another unit?")
        else:
            continue
        if np.any(bad):
            k = int(np.flatnonzero(bad)[0])
            other = _likely_unit(unit, v[k], declared)
            warnings.warn(ModelWarning(
                f"{source}: column '{name}' ({kind} in {unit}): {int(np.sum(bad))} of {len(v)} rows are {why} "
                f"(first: {labels[k]}, {v[k]:g} {unit}); a header '{name}[{other}]' gives the column in {other}"),
                stacklevel=3)


def _likely_unit(unit: str, value: float, declared: float) -> str:
    """The unit in which `value` would lie nearest the declared value (given in `unit`)."""
    if unit in ANGLE_UNITS:
        return "deg" if unit == "rad" else "rad"
    if not (value and declared):
        return "mm" if unit != "mm" else "m"
    return min((u for u in LENGTH_UNITS if u != unit),
               key=lambda u: abs(math.log(abs(value * LENGTH_UNITS[u] / LENGTH_UNITS[unit] / declared))))


def _header(path, head: str, template: Template) -> tuple[str, float]:
    """A header cell: the parameter's name, and the factor from the unit it names in brackets
    (``l2[mm]``) to the parameter's own unit (1 without brackets)."""
    if not head.endswith("]") or "[" not in head:
        return head, 1.0
    name, given = head[:-1].split("[", 1)
    name = name.strip()
    if name not in template.parameters:
        return name, 1.0       # refused with the other unknown columns
    unit = template.unit(name)
    known = {**LENGTH_UNITS, **ANGLE_UNITS}
    spelt = unit_spelling(given, known)
    same_kind = unit is not None and spelt is not None and (spelt in LENGTH_UNITS) == (unit in LENGTH_UNITS)
    if not same_kind:
        what = f"a {template.kind(name)} in {unit}" if unit is not None else "a plain number (no unit)"
        raise ModelError(f"{path}: column '{head}': parameter '{name}' is {what}; '{given}' is not a unit for it "
                         f"(lengths: {', '.join(LENGTH_UNITS)}; angles: {', '.join(ANGLE_UNITS)})")
    return name, known[spelt] / known[unit]


def read_variants(path, template: Template) -> Variants:
    r"""Read a CSV variant table for a model: one design per row, one column per parameter.

    An optional first column `variant` (or `name`) names the rows; lines starting with `#` are
    comments; a header may give a column's unit in brackets (``l2[mm]``, ``phi20[deg]``).

    Parameters
    ----------
    path : str or Path
        The CSV file.
    template : Template
        The model with its `[parameters]`.

    Returns
    -------
    Variants
        The designs, in the parameters' own units.

    Raises
    ------
    ModelError
        A file that cannot be read, an empty table or one without rows, a column twice, a column
        naming no parameter or a unit not for it, a row of another width, a cell that is not a finite
        number, or a negative length (each message names the file, line and column).

    Examples
    --------
    >>> import os, tempfile
    >>> from mbplanar.study import load_template, read_variants
    >>> path = os.path.join(tempfile.mkdtemp(), "variants.csv")
    >>> _ = open(path, "w").write("variant,b[mm],beta\nlong,350,30\nshort,250,40\n")
    >>> v = read_variants(path, load_template("models/fourbar_design.toml"))
    >>> v.names, v.values["b"].round(12).tolist(), v.values["beta"].tolist()          # b read in metres
    (('long', 'short'), [0.35, 0.25], [30.0, 40.0])
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise ModelError(f"{path}: cannot read the variant table ({exc})") from None
    lines = [(k + 1, line) for k, line in enumerate(text.splitlines()) if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise ModelError(f"{path}: the variant table is empty (a header of parameter names is needed)")
    rows = list(csv.reader(line for _, line in lines))
    header = [h.strip() for h in rows[0]]
    name_col = 0 if header and header[0].lower() in NAME_COLUMNS else None
    factors = {k: _header(path, h, template) for k, h in enumerate(header) if k != name_col}
    header = [factors[k][0] if k in factors else h for k, h in enumerate(header)]
    columns = [h for k, h in enumerate(header) if k != name_col]
    if len(set(columns)) != len(columns):
        raise ModelError(f"{path}: a column appears twice in the header {header}")
    names, values = [], {h: [] for h in columns}
    for (lineno, _), row in zip(lines[1:], rows[1:]):
        if len(row) != len(header):
            raise ModelError(f"{path}: line {lineno}: {len(row)} cells, the header has {len(header)}")
        names.append(row[name_col].strip() if name_col is not None else str(len(names) + 1))
        for k, (h, cell) in enumerate(zip(header, row)):
            if k == name_col:
                continue
            try:
                value = float(cell)
            except ValueError:
                raise ModelError(f"{path}: line {lineno}, column '{h}': {cell.strip()!r} is not a number") from None
            if not math.isfinite(value):
                raise ModelError(f"{path}: line {lineno}, column '{h}': {cell.strip()!r} is not finite")
            values[h].append(value * factors[k][1])
    if not names:
        raise ModelError(f"{path}: the variant table has a header but no rows")
    labels = [f"line {lineno}" for lineno, _ in lines[1:]]
    return variants_from(template, values, names, source=str(path), labels=labels)
