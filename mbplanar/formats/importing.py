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
    """A model imported from a peer's file or object.

    Attributes
    ----------
    table : dict
        The model's TOML document as a dict (what `mbplanar.parse_model` reads).
    text : str
        Its TOML text, headed by comments on where it came from and what was guessed.
    notes : tuple of str
        What could not be carried over, and what was guessed.
    format : str
        The format read ("pyslvs", "pmks-csv", "pylinkage", ...).
    source : str
        Where it came from.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.formats import import_model
    >>> imp = import_model("tests/data/peers/fourbar.pyslvs")
    >>> imp.text.splitlines()[0]
    '# Imported from fourbar.pyslvs (a Pyslvs project) by mbplanar import.'
    >>> sorted(mbplanar.parse_model(imp.table, "fourbar.toml").joints)
    ['P0', 'P1', 'P2', 'P4']
    """

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
    """A peer's mechanism file as an mbplanar model: Pyslvs, PMKS+ or pylinkage.

    Parameters
    ----------
    path : str or Path
        A Pyslvs expression (.txt) or project (.pyslvs), a PMKS+ CSV file or link (.csv, .txt), a
        pylinkage JSON file (.json).
    fmt : str, optional
        The format ("pyslvs", "pyslvs-project", "pmks-csv", "pmks-link", "pylinkage", ...); default:
        detected from the suffix and the text.

    Returns
    -------
    Imported
        The model's table and TOML text, and notes on what could not be carried over.

    Raises
    ------
    ModelError
        An unreadable file, a format that cannot be told or is unknown, a syntax error (naming the
        line and column), or a mechanism mbplanar refuses (the message says why).

    Examples
    --------
    >>> from mbplanar.formats import import_model
    >>> imp = import_model("tests/data/peers/fourbar.pyslvs")
    >>> imp.table["input"]["joint"], imp.table["length_unit"]
    ('P0', 'mm')
    >>> imp = import_model("tests/data/peers/slider_crank_pmks.csv")
    >>> imp.format, imp.notes[0]
    ('pmks-csv', 'the input speed 10 taken as rad/s (PMKS+ does not say its unit)')
    """
    from ..model import read_text
    path = Path(path)
    text = read_text(path, "the file")
    fmt = fmt or detect_format(path, text)
    sketch = _sketch_of(fmt, text, str(path), _model_name(path))
    return _finish(sketch, fmt)


def import_object(obj, name: str | None = None) -> Imported:
    """A live pylinkage object as an mbplanar model.

    Parameters
    ----------
    obj : pylinkage.simulation.Linkage or pylinkage.mechanism.Mechanism
        The linkage, as built in Python.
    name : str, optional
        The model's name (default: the linkage's).

    Returns
    -------
    Imported
        The model's table and TOML text, and notes.

    Raises
    ------
    ModelError
        An object of another type, a part mbplanar has no counterpart for, or a mechanism it refuses.

    Examples
    --------
    With pylinkage installed (``pip install "mbplanar[bench]"``), a `Linkage` built in Python, e.g.
    ``Linkage([o1, o2, crank, rocker])`` of two `Ground`s, a `Crank` and an `RRRDyad`, comes back as
    the model whose analysis moves as pylinkage moves it; anything else is refused:

    >>> from mbplanar.formats import import_object
    >>> import_object(42)
    Traceback (most recent call last):
    ...
    mbplanar.errors.ModelError: <pylinkage int>: not a pylinkage Linkage or Mechanism: int
    """
    from .pylinkage import read_object
    return _finish(read_object(obj, name), "pylinkage")


def _finish(sketch, fmt: str) -> Imported:
    from ..synthesis import table_toml
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
