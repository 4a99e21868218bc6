"""Synthesised designs written as mbplanar models (TOML text) and read back as `Mechanism`.

Every design leaves the synthesis as the TOML text of an ordinary model, drawn exactly (no lengths, so
the coordinates are the design) in its first precision position; the errors reported for it are
computed by mbplanar's analysis of the `Mechanism` read back from that very text.
"""

from __future__ import annotations

import math

import numpy as np

from ..model import parse_model

__all__ = ["model_toml", "table_toml", "read_design", "guiding_slider_toml", "fourbar_toml", "slider_crank_toml"]


def _value(v) -> str:
    """One TOML value: floats to the last digit (repr), strings quoted, lists and inline tables."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        v = float(v)
        if not math.isfinite(v):
            raise ValueError(f"not a finite number: {v}")
        return repr(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }"
    return "[" + ", ".join(_value(x) for x in v) + "]"


def model_toml(name: str, title: str, links: list, joints: list, points: list, inputs: dict,
               comment: str = "") -> str:
    """The TOML text of a model from its rows (dicts in the table format's keys)."""
    lines = [f"# {c}" if c else "#" for c in comment.splitlines()]
    lines += [f"name = {_value(name)}", f"title = {_value(title)}", 'ground = "0"', ""]
    for key, rows in (("links", links), ("joints", joints), ("points", points)):
        if rows:
            lines.append(f"{key} = [")
            lines += [f"  {_value(r)}," for r in rows]
            lines += ["]", ""]
    lines.append("[input]")
    lines += [f"{k} = {_value(v)}" for k, v in inputs.items()]
    return "\n".join(lines) + "\n"


def table_toml(data: dict, comment: str = "") -> str:
    """The TOML text of a model's table, as `tomllib` reads it back.

    Top-level values first (lists of rows as inline tables, one per line), then one `[section]` per
    sub-table; floats are written to the last digit (`repr`), so the text reads back to the same
    numbers: e.g. a model with new parameter values, or a model imported from another format.

    Parameters
    ----------
    data : dict
        The table: {key: value}, values numbers, strings, booleans, lists, dicts of rows or sections.
    comment : str
        Text for the comment lines at the top (one "# " line per line).

    Returns
    -------
    str
        The TOML text, ending with a newline.

    Raises
    ------
    ValueError
        A float that is not finite (TOML's inf and nan are not model values).

    Examples
    --------
    >>> import tomllib
    >>> from mbplanar.synthesis import table_toml
    >>> data = tomllib.load(open("models/fourbar.toml", "rb"))
    >>> text = table_toml(data, "the four-bar, written back")
    >>> print(text.splitlines()[0])
    # the four-bar, written back
    >>> tomllib.loads(text) == data
    True
    """
    lines = [f"# {c}" if c else "#" for c in comment.splitlines()]
    plain = {k: v for k, v in data.items() if not isinstance(v, dict)}
    for key, v in plain.items():
        if isinstance(v, list) and v and all(isinstance(r, dict) for r in v):
            lines += [f"{key} = ["] + [f"  {_value(r)}," for r in v] + ["]"]
        else:
            lines.append(f"{key} = {_value(v)}")
    for key, table in data.items():
        if isinstance(table, dict):
            lines += ["", f"[{key}]"] + [f"{_key(k)} = {_value(v)}" for k, v in table.items()]
    return "\n".join(lines) + "\n"


def _key(k: str) -> str:
    return k if k.replace("_", "").replace("-", "").isalnum() and k.isascii() else _value(k)


def read_design(text: str, source: str = "<synthesis>"):
    """The `Mechanism` of a model's TOML text (what the rest of mbplanar analyses)."""
    return parse_model(text, source=source)


def _xy(p) -> list:
    return [float(p[0]), float(p[1])]


def guiding_slider_toml(pivot, b_point, c_point, e_point, guide_deg: float, sense: int = 1,
                        name: str = "guiding_slider", comment: str = "") -> str:
    """Seed 001's guiding crank-slider: crank 1 (A–B), rod 2 (B, C, foot E), slider 3 at C on a line.

    Points are the drawn (first node's) coordinates; `guide_deg` the line's direction in degrees. The
    input φ is the crank angle (direction of A→B) in degrees, counter-clockwise for `sense` 1, clockwise
    (φ = −angle) for −1.
    """
    links = [{"name": "1", "angle": ["A", "B"]}, {"name": "2", "angle": ["B", "E"]}, {"name": "3"}]
    joints = [{"name": "A", "type": "R", "links": ["0", "1"], "at": _xy(pivot)},
              {"name": "B", "type": "R", "links": ["1", "2"], "at": _xy(b_point)},
              {"name": "C", "type": "R", "links": ["2", "3"], "at": _xy(c_point)},
              {"name": "Cp", "type": "P", "links": ["0", "3"], "at": _xy(c_point), "guide": float(guide_deg)}]
    points = [{"name": "E", "link": "2", "at": _xy(e_point)}]
    inputs = {"joint": "A", "name": "phi1", "unit": "deg", "zero": 0.0, "sense": int(sense)}
    return model_toml(name, "Guiding crank-slider of a walking leg (seed 001 synthesis)", links, joints,
                      points, inputs, comment)


def fourbar_toml(a0, a1, b1, b0, points: dict, name: str = "fourbar", title: str = "Synthesised four-bar",
                 zero_deg: float = 0.0, sense: int = 1, comment: str = "") -> str:
    """A four-bar: crank 1 (A0–A), coupler 2 (A–B, with `points` {name: (x, y)}), rocker 3 (B–B0).

    Coordinates are the drawn pose. The input φ (degrees, counter-clockwise) is the crank's direction
    A0→A minus `zero_deg` (times −1 for `sense` −1).
    """
    links = [{"name": "1", "angle": ["A0", "A"]}, {"name": "2", "angle": ["A", "B"]},
             {"name": "3", "angle": ["B0", "B"]}]
    joints = [{"name": "A0", "type": "R", "links": ["0", "1"], "at": _xy(a0)},
              {"name": "A", "type": "R", "links": ["1", "2"], "at": _xy(a1)},
              {"name": "B", "type": "R", "links": ["2", "3"], "at": _xy(b1)},
              {"name": "B0", "type": "R", "links": ["0", "3"], "at": _xy(b0)}]
    rows = [{"name": n, "link": "2", "at": _xy(p)} for n, p in points.items()]
    inputs = {"joint": "A0", "name": "phi", "unit": "deg", "zero": float(zero_deg), "sense": int(sense)}
    return model_toml(name, title, links, joints, rows, inputs, comment)


def slider_crank_toml(a0, a1, b1, guide_deg: float, points: dict, name: str = "slider_crank",
                      title: str = "Synthesised crank and slider", sense: int = 1, comment: str = "") -> str:
    """A crank 1 (A0–A), a coupler 2 (A–B, with `points`) and a slider 3 at B on the fixed line through
    B along `guide_deg` (degrees). Coordinates are the drawn pose; the input φ is the crank's direction."""
    links = [{"name": "1", "angle": ["A0", "A"]}, {"name": "2", "angle": ["A", "B"]}, {"name": "3"}]
    joints = [{"name": "A0", "type": "R", "links": ["0", "1"], "at": _xy(a0)},
              {"name": "A", "type": "R", "links": ["1", "2"], "at": _xy(a1)},
              {"name": "B", "type": "R", "links": ["2", "3"], "at": _xy(b1)},
              {"name": "Bp", "type": "P", "links": ["0", "3"], "at": _xy(b1), "guide": float(guide_deg)}]
    rows = [{"name": n, "link": "2", "at": _xy(p)} for n, p in points.items()]
    inputs = {"joint": "A0", "name": "phi", "unit": "deg", "zero": 0.0, "sense": int(sense)}
    return model_toml(name, title, links, joints, rows, inputs, comment)
