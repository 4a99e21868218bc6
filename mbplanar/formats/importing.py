"""`mbplanar import`: a peer's file (or a live pylinkage object) as an mbplanar model.

`import_model` reads the file by its kind (`FORMATS`; guessed from the suffix and the text), builds the
table of pairs, checks it the way every model is checked (`parse_model`, then the engine: structure,
degrees of freedom against the inputs, assembly) and returns an `Imported` record: the table, its TOML
text (what it could not carry over written as comments at the top) and the notes. A file that cannot be
read, a malformed expression, or a joint mbplanar cannot represent is a `ModelError` naming the file and
the place; nothing is written then.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from ..errors import MbplanarError, ModelError

__all__ = ["Imported", "FORMATS", "import_model", "import_object", "detect_format"]

#: format → (what the model's header calls it, what it is); ``--from`` takes these names
FORMATS = {
    "pyslvs": ("a Pyslvs expression", "a Pyslvs mechanism expression M[J[...], ...] in a text file"),
    "pyslvs-yaml": ("a Pyslvs project", "a Pyslvs YAML project (.pyslvs, .yml, .yaml)"),
    "pmks-csv": ("a PMKS+ CSV file", "a PMKS+ CSV linkage file (.csv)"),
    "pmks-link": ("a PMKS+ link", "a PMKS+ link: a URL or its query (.txt, .url, .pmks)"),
    "pylinkage": ("a pylinkage JSON file", "a pylinkage JSON file: Linkage.to_json or mechanism_to_json (.json)"),
}


@dataclass(frozen=True)
class Imported:
    """An imported model: `table` (the TOML document as a dict), `text` (its TOML text), `notes` (what
    could not be carried over, what was guessed), `format` and `source` (where it came from)."""

    table: dict
    text: str
    notes: tuple
    format: str
    source: str


def detect_format(path, text: str) -> str:
    """The format of a file from its suffix and, for text files, its first characters."""
    suffix = Path(path).suffix.lower()
    head = re.sub(r"#[^\n]*", "", re.sub(r"#\[[\s\S]*?#\]", "", text)).lstrip()   # (Pyslvs' comments)
    if suffix in (".pyslvs", ".yml", ".yaml"):
        return "pyslvs-yaml"
    if suffix == ".csv":
        return "pmks-csv"
    if suffix == ".json":
        return "pylinkage"
    if suffix == ".pmks":
        return "pmks-link"
    if suffix in ("", ".txt", ".url", ".expr", ".expression"):
        from .pmks import looks_like_link
        if head.startswith("M["):
            return "pyslvs"
        if looks_like_link(text):
            return "pmks-link"
        if head.startswith("mechanism:") or "\nmechanism:" in text or head.startswith("{"):
            return "pyslvs-yaml" if not head.startswith("{") or "mechanism" in head else "pylinkage"
        if head.startswith("joints"):
            return "pmks-csv"
        raise ModelError("cannot tell what this file is: not a Pyslvs expression (M[...]), a PMKS+ link or "
                         f"CSV, a Pyslvs project or a pylinkage JSON file ({', '.join(FORMATS)})", source=str(path))
    raise ModelError(f"unknown file type '{suffix}': mbplanar imports Pyslvs expressions (.txt) and projects "
                     "(.pyslvs, .yml), PMKS+ CSV files (.csv) and links (.txt, .pmks), pylinkage JSON (.json); "
                     "--from names the format", source=str(path))


def _sketch_of(fmt: str, text: str, source: str, name: str):
    if fmt == "pyslvs":
        from .pyslvs import read_expression
        return read_expression(text, source, name)
    if fmt == "pyslvs-yaml":
        from .pyslvs import read_project
        return read_project(text, source, name)
    if fmt == "pmks-csv":
        from .pmks import read_csv
        return read_csv(text, source, name)
    if fmt == "pmks-link":
        from .pmks import read_link
        return read_link(text, source, name)
    if fmt == "pylinkage":
        from .pylinkage import read_json
        return read_json(text, source, name)
    raise ModelError(f"unknown format '{fmt}' (one of {', '.join(FORMATS)})", source=source)


def _model_name(path) -> str:
    stem = re.sub(r"[^A-Za-z0-9_\-]+", "_", Path(path).stem).strip("_")
    return stem or "imported"


def import_model(path, fmt: str | None = None) -> Imported:
    """The model of the peer's file `path` (its format `fmt`, else detected).

    Examples
    --------
    >>> from mbplanar.formats import import_model
    >>> imp = import_model("tests/data/peers/fourbar.pyslvs")
    >>> imp.table["input"]["joint"], imp.table["length_unit"]
    ('P0', 'mm')
    """
    from ..model import read_text
    path = Path(path)
    text = read_text(path, "the file")
    fmt = fmt or detect_format(path, text)
    sketch = _sketch_of(fmt, text, str(path), _model_name(path))
    return _finish(sketch, fmt)


def import_object(obj, name: str | None = None) -> Imported:
    """The model of a live pylinkage object (`pylinkage.simulation.Linkage` or `pylinkage.mechanism.Mechanism`)."""
    from .pylinkage import read_object
    return _finish(read_object(obj, name), "pylinkage")


def _finish(sketch, fmt: str) -> Imported:
    from ..synthesis._models import table_toml
    from ._sketch import to_table
    table = to_table(sketch)
    notes = tuple(dict.fromkeys(sketch.notes))
    _check(table, sketch.source)
    head = [f"Imported from {Path(sketch.source).name} ({FORMATS[fmt][0]}) by mbplanar import."]
    if notes:
        head.append("Not carried over, or guessed:")
        head += [f"- {n}" for n in notes]
    return Imported(table, table_toml(table, "\n".join(head)), notes, fmt, sketch.source)


def _check(table: dict, source: str):
    """The table read and compiled as any model is: a refusal names the file it came from."""
    from ..engine import Engine
    from ..model import parse_model
    try:
        Engine(parse_model(table, source=source))
    except MbplanarError as exc:
        said = ": ".join(p for p in (exc.where, exc.message) if p)
        raise ModelError(f"the mechanism it describes is refused: {' '.join(said.split())}", source=source) from None
