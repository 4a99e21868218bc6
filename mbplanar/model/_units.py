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
    """The shown unit of each kind of quantity (see `name`), and its size in SI (`scale`).

    `system` is "si" or "model"; `length`, `moment`, `inertia` the units shown for those kinds (forces,
    masses, energies and angles are always SI). `show` converts a value, `document` writes the JSON
    ``"units"`` object.

    Examples
    --------
    >>> from mbplanar.model import DisplayUnits
    >>> mm = DisplayUnits("model", length="mm", moment="N*mm")
    >>> mm.name("acceleration"), mm.show(0.25, "length"), mm.show(2.0, "moment"), mm.show(3.0, "force")
    ('mm/s^2', 250.0, 2000.0, 3.0)
    """

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
    """The units a command shows a model's numbers in: SI, or the model's own.

    Parameters
    ----------
    mech : Mechanism
        The model (its `Units`).
    system : {"si", "model"}, optional
        SI (the default), or the table's ``length_unit``, ``moment_unit``, ``inertia_unit``.

    Returns
    -------
    DisplayUnits

    Raises
    ------
    ValueError
        Another `system`.

    Examples
    --------
    >>> from mbplanar.model import display_units, read_model
    >>> jansen = read_model("models/jansen.toml")
    >>> display_units(jansen).length, display_units(jansen, "model").length
    ('m', 'cm')
    """
    if system == "si":
        return DisplayUnits()
    if system != "model":
        raise ValueError(f"units must be one of {', '.join(SYSTEMS)}, got {system!r}")
    u = mech.units
    return DisplayUnits("model", u.length, u.moment, u.inertia)


def add_units_option(parser, what: str = "the output"):
    """Give a command its ``--units si|model`` option.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The command's parser.
    what : str, optional
        What the option applies to, for the help.

    Returns
    -------
    None
        The option is added to `parser` (``args.units``: "si" by default).

    Raises
    ------
    argparse.ArgumentError
        The parser has a ``--units`` option already.

    Examples
    --------
    >>> import argparse
    >>> from mbplanar.model import add_units_option
    >>> parser = argparse.ArgumentParser()
    >>> add_units_option(parser, "the table")
    >>> parser.parse_args([]).units, parser.parse_args(["--units", "model"]).units
    ('si', 'model')
    """
    parser.add_argument("--units", choices=SYSTEMS, default="si",
                        help=f"units of {what}: si (m, N·m, kg·m²; the default) or model (the table's "
                             "length_unit, moment_unit, inertia_unit)")


_BRACKETS = {"m": "length", "m/s": "velocity", "m/s^2": "acceleration", "N*m": "moment", "kg*m2": "inertia",
             "kg*m^2": "inertia"}


def convert_table(header: list[str], rows, display: DisplayUnits, skip: int = 1):
    """A CSV table in the units of `display`, its headers' [unit] renamed to match.

    Parameters
    ----------
    header : list of str
        The k column names, each ending in its SI unit in brackets ("x_B[m]") or not (left alone).
    rows : numpy.ndarray
        The values (N, k), SI.
    display : DisplayUnits
        The units to show.
    skip : int, optional
        The first columns (the input, in its own unit) that are left alone.

    Returns
    -------
    header : list of str
        The names with the shown units.
    rows : numpy.ndarray
        (N, k), a copy (the input itself for SI or an empty table).

    Raises
    ------
    Nothing on a table as described; rows that are not a 2-D array give numpy's error.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.model import DisplayUnits, convert_table
    >>> header, rows = convert_table(["phi[deg]", "x_B[m]", "v_B[m/s]", "F[N]"], np.array([[30.0, 0.25, 1.5, 7.0]]),
    ...                              DisplayUnits("model", length="mm"))
    >>> header, rows.tolist()
    (['phi[deg]', 'x_B[mm]', 'v_B[mm/s]', 'F[N]'], [[30.0, 250.0, 1500.0, 7.0]])
    """
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
