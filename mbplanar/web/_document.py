"""The model's TOML text and its table, two views of one document.

`ModelDocument(text)` parses the text twice: with `tomllib` (what `mbplanar` reads) and with `tomlkit`
(which keeps the author's comments, order and number formats). The table is the tomlkit document seen
as sections of rows; an edit of a cell, a row or a joint's drawn position is made on the tomlkit
document and written back as text, so everything else in the file stays as the author wrote it.

Sections, in the order a table of pairs is read: ``model`` (the top-level values, one row), every list
of rows (``links``, ``joints``, ``points``, ``inputs``, ``loads``, ...), every table (``input``,
``gravity``, ``dynamics``, ``dynamics.flywheel``, ...; one row each). A cell shows a string as it is and
any other value as TOML (``[0.05, 0.0866]``); what is typed into a cell that held a string stays a
string unless it is written as TOML (quoted, a list or a table), otherwise it is read as a TOML value.

`locate(where, message)` maps an error's `where` ("joints[3] 'Ap'", "inputs[0] (joint 'O')",
"links '2'", "dynamics.flywheel") or its message ("joint 'B' ...", "line 7, column 3") to a section and
row of the table or a line of the text.
"""

from __future__ import annotations

import math
import re
import tomllib

import tomlkit
from tomlkit.exceptions import TOMLKitError

from ..errors import ModelError

__all__ = ["ModelDocument", "EditError", "locate", "FIRST_SECTIONS"]

#: sections shown first, in this order; the others follow in the order of the file
FIRST_SECTIONS = ("model", "links", "joints", "points", "input", "inputs", "loads", "gravity", "dynamics")
#: a section's first columns, in this order; the others follow in the order first met
FIRST_COLUMNS = ("name", "type", "link", "links", "joint", "at", "length", "lengths", "along", "fraction",
                 "distance", "offset", "guide")


class EditError(ModelError):
    """An edit that cannot be made (a value that is not TOML, a row that does not exist); `section` and
    `row` locate it in the table."""

    def __init__(self, message: str, section: str | None = None, row: int | None = None):
        super().__init__(message, where=None if section is None else _where(section, row))
        self.section, self.row = section, row


def _where(section, row):
    return section if row is None else f"{section}[{row}]"


class ModelDocument:
    """One state of a model's text: the text, its data as `tomllib` reads it, and the sections of its
    table. Raises `ModelError` (naming the line and column) for text that is not TOML.

    Parameters
    ----------
    text : str
        The TOML text of a model (or of a cam file).
    source : str
        The file's name, used in messages.
    """

    def __init__(self, text: str, source: str = "<table>"):
        self.text, self.source = text, source
        try:
            self.data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise ModelError(f"TOML syntax error: {exc}", source=source) from None
        try:
            self._doc = tomlkit.parse(text)
        except TOMLKitError as exc:          # (tomllib read it: not expected)
            raise ModelError(f"TOML syntax error: {exc}", source=source) from None

    # -- the table ---------------------------------------------------------------------------------
    def sections(self) -> list[dict]:
        """The table: a list of {"name", "kind" ("rows" or "table"), "columns", "rows"} with every cell
        as text ("" where a row lacks the column)."""
        out, scalars = [], {}
        for key, value in self._doc.items():
            if _is_rows(value):
                out.append(_rows_section(key, [dict(r) for r in value]))
            elif isinstance(value, dict):
                out += _table_sections(key, value)
            else:
                scalars[key] = value
        if scalars:
            out.append(_rows_section("model", [scalars], kind="table"))
        rank = {name: k for k, name in enumerate(FIRST_SECTIONS)}
        return sorted(out, key=lambda s: rank.get(s["name"].split(".")[0], len(rank)))

    def _container(self, section: str, row: int | None):
        """The tomlkit table that holds the cells of `section`'s row `row`."""
        if section == "model":
            return self._doc
        head, *rest = section.split(".")
        if head not in self._doc:
            raise EditError(f"no section '{section}'", section)
        node = self._doc[head]
        for part in rest:
            if not isinstance(node, dict) or part not in node:
                raise EditError(f"no section '{section}'", section)
            node = node[part]
        if _is_rows(node):
            if row is None or not 0 <= row < len(node):
                raise EditError(f"no row {row} in '{section}' ({len(node)} rows)", section)
            return node[row]
        if not isinstance(node, dict):
            raise EditError(f"'{section}' is not a table", section)
        return node

    # -- edits (each returns the new text) ------------------------------------------------------------
    def set_cell(self, section: str, row: int | None, key: str, text: str) -> str:
        """The text with cell (`section`, `row`, `key`) set to `text` (read as described in the module's
        docstring); an empty `text` removes the key from the row."""
        key = str(key).strip()
        if not key or not re.fullmatch(r"[A-Za-z0-9_\-]+", key):
            raise EditError(f"a column's name is letters, digits, '_' or '-', not {key!r}", section, row)
        table = self._container(section, row)
        if not str(text).strip():
            if key in table:
                del table[key]
            return self._dumps()
        table[key] = parse_cell(text, was_string=isinstance(table.get(key, ""), str) and key in table,
                                where=(section, row))
        return self._dumps()

    def add_row(self, section: str) -> str:
        """The text with an empty row `{}` appended to the list of rows `section` (a new list if absent)."""
        if section in ("model", "input") or "." in section:
            raise EditError(f"'{section}' is one table, not a list of rows", section)
        if section not in self._doc:
            self._doc[section] = tomlkit.array()
            self._doc[section].multiline(True)
        rows = self._doc[section]
        if not _is_rows(rows) and not (isinstance(rows, list) and len(rows) == 0):
            raise EditError(f"'{section}' is not a list of rows", section)
        if isinstance(rows, tomlkit.items.AoT):
            rows.append(tomlkit.table())
        else:
            rows.append(tomlkit.inline_table())
        return self._dumps()

    def delete_row(self, section: str, row: int) -> str:
        node = self._doc.get(section)
        if not _is_rows(node) or not 0 <= row < len(node):
            raise EditError(f"no row {row} in '{section}'", section)
        del node[row]
        return self._dumps()

    def move_point(self, name: str, xy, *, exact: dict, units: float, input_angles: dict | None = None) -> str:
        """The text with joint or point `name` drawn at `xy` (model units), and every dimension that involves
        it as the model writes it: the `length` of a link with two revolute pairs, the entries of
        `lengths`, and an input's `drawn_at` when the moved pair turns a link the input drives.

        `exact` maps the names of every joint and point to their exact drawn coordinates (SI) and `units`
        is the length unit in metres; `input_angles` maps an input's row (section, row) to a function
        (name, xy SI) → the change of its joint value (model unit) that the move makes."""
        rows = self._doc.get("joints")
        table, kind = _named_row(rows, name), "joints"
        if table is None:
            table, kind = _named_row(self._doc.get("points"), name), "points"
        if table is None:
            raise EditError(f"no joint or point '{name}' to move")
        if kind == "points" and "at" not in table:
            raise EditError(f"point '{name}' is placed along other points, not drawn: edit its row", "points")
        digits = _digits(exact, units)
        new = [round(float(xy[0]), digits), round(float(xy[1]), digits)]
        at = tomlkit.array()
        at.extend(new)
        table["at"] = at
        here = {k: (v[0] / units, v[1] / units) for k, v in exact.items()}
        here[name] = tuple(new)
        for link in self._doc.get("links", []) or []:
            if not isinstance(link, dict):
                continue
            if "lengths" in link:
                for entry in link["lengths"]:
                    if len(entry) == 3 and name in (entry[0], entry[1]) and entry[0] in here and entry[1] in here:
                        entry[2] = _round_length(math.dist(here[entry[0]], here[entry[1]]), digits)
            elif "length" in link:
                ends = _revolute_ends(self.data, str(link.get("name", "")))
                if ends is not None and name in ends and all(e in here for e in ends):
                    link["length"] = _round_length(math.dist(here[ends[0]], here[ends[1]]), digits)
        for (section, row), change in (input_angles or {}).items():
            table = self._container(section, row)
            if "drawn_at" in table:
                delta = change(name, (new[0] * units, new[1] * units))
                if delta:
                    table["drawn_at"] = round(float(table["drawn_at"]) + delta, 6)
        return self._dumps()

    def _dumps(self) -> str:
        return tomlkit.dumps(self._doc)


def parse_cell(text: str, was_string: bool = False, where=(None, None)):
    """A cell's text as a TOML value: a string where the cell held one (unless written as TOML), else a
    TOML value (a number, a list, a table, true/false), else a string."""
    text = str(text).strip()
    structured = text[:1] in ("[", "{", '"', "'")
    if was_string and not structured:
        return text
    try:
        return tomlkit.parse(f"v = {text}")["v"]
    except TOMLKitError:
        if structured:
            raise EditError(f"{text!r} is not a TOML value", *where) from None
        return text


def _is_rows(value) -> bool:
    return isinstance(value, list) and len(value) > 0 and all(isinstance(v, dict) for v in value)


def _cell(value) -> str:
    if isinstance(value, str):
        return str(value)
    if hasattr(value, "as_string"):
        return value.as_string().strip()
    return tomlkit.item(value).as_string().strip()


def _rows_section(name: str, rows: list[dict], kind: str = "rows") -> dict:
    columns = []
    for row in rows:
        columns += [k for k in row if k not in columns]
    rank = {c: k for k, c in enumerate(FIRST_COLUMNS)}
    columns.sort(key=lambda c: rank.get(c, len(rank)))
    cells = [[_cell(row[c]) if c in row else "" for c in columns] for row in rows]
    return {"name": name, "kind": kind, "columns": columns, "rows": cells}


def _table_sections(name: str, table) -> list[dict]:
    """One section for a table's values, one more for each table inside it (dynamics.flywheel)."""
    own = {k: v for k, v in table.items() if not (isinstance(v, dict) and not _inline(v))}
    out = [_rows_section(name, [own], kind="table")] if own or not table else []
    for key, value in table.items():
        if isinstance(value, dict) and not _inline(value):
            out += _table_sections(f"{name}.{key}", value)
    return out


def _inline(value) -> bool:
    return isinstance(value, tomlkit.items.InlineTable)


def _named_row(rows, name):
    if not _is_rows(rows):
        return None
    return next((r for r in rows if str(r.get("name", "")) == name), None)


def _revolute_ends(data: dict, link: str):
    """The two revolute joints of `link` (as the table names them), or None."""
    ends = [str(j.get("name")) for j in data.get("joints", []) if isinstance(j, dict) and str(j.get("type", "R")) == "R"
            and link in [str(x) for x in (j.get("links") or [])]]
    return ends if len(ends) == 2 else None


def _digits(exact: dict, units: float) -> int:
    """Decimals of a dragged coordinate: a ten-thousandth of the drawing's size, in the model's unit."""
    spans = [abs(c) for xy in exact.values() for c in xy] or [1.0]
    size = max(max(spans) / units, 1e-12)
    return max(0, 4 - math.floor(math.log10(size)))


def _round_length(value: float, digits: int) -> float:
    return round(float(value), digits + 1)


# -- where an error belongs ---------------------------------------------------------------------------
_ROW = re.compile(r"^([A-Za-z_]\w*)\[(\d+)\]")
_NAMED = re.compile(r"^(links|joints|points|loads|inputs)\s+'([^']*)'")
_INPUT = re.compile(r"^input '([^']*)'")
_TABLE = re.compile(r"^([A-Za-z_]\w*(?:\.[A-Za-z_]\w*)*)\b")
_MENTION = re.compile(r"\b(joint|link|point|load|input)s? '([^']*)'")
_LINE = re.compile(r"line (\d+), column (\d+)")
_SINGULAR = {"joint": "joints", "link": "links", "point": "points", "load": "loads", "input": "inputs"}


def locate(where: str | None, message: str, data: dict | None) -> dict:
    """{"section", "row"} of the table row an error belongs to, or {"line", "column"} of the text for a
    TOML syntax error, or {} when neither can be told."""
    text = f"{where or ''}"
    match = _LINE.search(message)
    if "TOML syntax error" in message and match:
        return {"line": int(match.group(1)), "column": int(match.group(2))}
    data = data or {}
    if text:
        m = _ROW.match(text)
        if m:
            return _row_of(data, m.group(1), int(m.group(2)))
        m = _NAMED.match(text)
        if m:
            found = _by_name(data, m.group(1), m.group(2))
            if found:
                return found
        m = _INPUT.match(text)
        if m:
            found = _by_name(data, "inputs", m.group(1), key="joint")
            if found:
                return found
        m = _TABLE.match(text)
        if m and _section_exists(data, m.group(1)):
            return {"section": m.group(1), "row": 0}
    for kind, name in _MENTION.findall(message):
        found = _by_name(data, _SINGULAR[kind], name, key="joint" if kind == "input" else "name")
        if found:
            return found
    return {}


def _row_of(data: dict, section: str, row: int) -> dict:
    if section == "inputs" and isinstance(data.get("input"), dict) and "inputs" not in data:
        return {"section": "input", "row": 0}
    if _section_exists(data, section):
        return {"section": section, "row": row}
    return {}


def _by_name(data: dict, section: str, name: str, key: str = "name") -> dict | None:
    if section == "inputs" and isinstance(data.get("input"), dict) and "inputs" not in data:
        return {"section": "input", "row": 0} if str(data["input"].get(key, "")) == name or key == "joint" else None
    rows = data.get(section)
    if isinstance(rows, list):
        for k, row in enumerate(rows):
            if isinstance(row, dict) and str(row.get(key, "")) == name:
                return {"section": section, "row": k}
    return None


def _section_exists(data: dict, section: str) -> bool:
    node = data
    for part in section.split("."):
        if not isinstance(node, dict) or part not in node:
            return False
        node = node[part]
    return True
