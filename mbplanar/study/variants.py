"""Variant tables: one design per row, one column per parameter (CSV), read into arrays.

A variant table is a CSV file whose header names parameters of the model (see `mbplanar.model._parameters`);
an optional first column `variant` (or `name`) names each row. Lines starting with `#` are comments.
Every cell must be a finite number; the error names the file, the row and the column at fault.
Parameters the table leaves out keep the model's declared values.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ModelError, closest_names, did_you_mean
from ..model._parameters import Template

__all__ = ["Variants", "read_variants", "variants_from"]

NAME_COLUMNS = ("variant", "name")


@dataclass(frozen=True)
class Variants:
    """D designs: their names (D,) and the value of every parameter the table sets, arrays (D,) each
    (in the parameter's own unit)."""

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


def variants_from(template: Template, values: dict, names=None, source: str = "<variants>") -> Variants:
    """Variants from arrays of parameter values (each (D,)), checked against the template."""
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
    return Variants(names, arrays)


def read_variants(path, template: Template) -> Variants:
    """Read a CSV variant table for `template` (see the module docstring)."""
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
            values[h].append(value)
    if not names:
        raise ModelError(f"{path}: the variant table has a header but no rows")
    return variants_from(template, values, names, source=str(path))
