"""The units a command shows its numbers in: SI (the default) or the model's own (`--units model`).

Inside mbplanar every number is SI. On output, `DisplayUnits` divides each quantity by the size of
its shown unit: lengths (and so velocities, accelerations) by the table's `length_unit`, moments by
its `moment_unit`, inertias by its `inertia_unit`; forces (N), masses (kg), energy and work (J),
angles and their rates stay as they are. `convert_table` converts a CSV table whose headers end in
[unit]; `add_units_option` gives a command its `--units` option. (The documents of the core commands
are converted in `mbplanar.io._units`.)
"""

from __future__ import annotations

from dataclasses import dataclass

from ._model import INERTIA_UNITS, LENGTH_UNITS, MOMENT_UNITS

__all__ = ["DisplayUnits", "display_units", "SYSTEMS", "convert_table", "add_units_option"]

SYSTEMS = ("si", "model")


@dataclass(frozen=True)
class DisplayUnits:
    """The shown unit of each kind of quantity (see `name`), and its size in SI (`scale`)."""

    system: str = "si"
    length: str = "m"
    moment: str = "N*m"
    inertia: str = "kg*m^2"

    def scale(self, kind: str) -> float:
        """SI value of one shown unit of `kind` (1 for the kinds that are always SI)."""
        length = LENGTH_UNITS[self.length]
        return {"length": length, "velocity": length, "acceleration": length,
                "moment": MOMENT_UNITS[self.moment], "inertia": INERTIA_UNITS[self.inertia]}.get(kind, 1.0)

    def name(self, kind: str) -> str:
        """The unit's name as the outputs write it ("mm/s^2", "N*mm", ...)."""
        return {"length": self.length, "velocity": f"{self.length}/s", "acceleration": f"{self.length}/s^2",
                "force": "N", "moment": self.moment, "inertia": self.inertia, "mass": "kg", "energy": "J",
                "angle": "rad", "angular_velocity": "rad/s", "angular_acceleration": "rad/s^2"}[kind]

    def show(self, value, kind: str):
        """`value` (SI, a number or an array) in the shown unit of `kind`."""
        return value / self.scale(kind)

    def document(self, angle: str = "rad") -> dict:
        """The JSON ``"units"`` object: the system and the unit of every kind of quantity."""
        kinds = ("length", "velocity", "acceleration", "force", "moment", "inertia", "mass", "energy",
                 "angle", "angular_velocity", "angular_acceleration")
        doc = {"system": self.system, **{k: self.name(k) for k in kinds}}
        doc["angle"] = angle
        return doc


def display_units(mech, system: str = "si") -> DisplayUnits:
    """SI units, or the units the model `mech` was written in (`system="model"`)."""
    if system == "si":
        return DisplayUnits()
    if system != "model":
        raise ValueError(f"units must be one of {', '.join(SYSTEMS)}, got {system!r}")
    u = mech.units
    return DisplayUnits("model", u.length, u.moment, u.inertia)


def add_units_option(parser, what: str = "the output"):
    """The `--units si|model` option of a command (`what` says what it applies to)."""
    parser.add_argument("--units", choices=SYSTEMS, default="si",
                        help=f"units of {what}: si (m, N·m, kg·m²; the default) or model (the table's "
                             "length_unit, moment_unit, inertia_unit)")


_BRACKETS = {"m": "length", "m/s": "velocity", "m/s^2": "acceleration", "N*m": "moment", "kg*m2": "inertia",
             "kg*m^2": "inertia"}


def convert_table(header: list[str], rows, display: DisplayUnits, skip: int = 1):
    """A CSV table whose headers end in [unit] (SI), in `display` units; the first `skip` columns (the
    input, in its own unit) are left alone. Returns the new header and rows (N, k)."""
    if display.system == "si" or not len(rows):
        return header, rows
    rows = rows.copy()
    header = list(header)
    for k, head in enumerate(header[skip:], start=skip):
        if not head.endswith("]") or "[" not in head:
            continue
        base, unit = head[:-1].rsplit("[", 1)
        kind = _BRACKETS.get(unit)
        if kind is not None:
            rows[:, k] = rows[:, k] / display.scale(kind)
            header[k] = f"{base}[{display.name(kind)}]"
    return header, rows
