"""The bundled examples: the repository's `models/` folder, shipped inside the package.

The repository keeps one copy of the models, in `models/`; the build maps that folder into the package as
`mbplanar/examples` (package data, `setup.py`), so a wheel carries them and an editable install finds the
folder itself. `list_examples()` lists them (the workbench's gallery reads it), `example_text(name)` gives
one, `copy_examples(names, directory)` writes them out (what ``mbplanar examples`` does).
"""

from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from ..errors import ModelError

__all__ = ["Example", "list_examples", "example", "example_text", "copy_examples", "examples_folder"]

SUFFIXES = (".toml", ".csv")


@dataclass(frozen=True)
class Example:
    """One bundled example file.

    Attributes
    ----------
    name : str
        Its path under the examples without the suffix ("fourbar", "synthesis/motion_3poses").
    file : str
        The path with the suffix.
    kind : str
        "model": a linkage; "cam": a cam file; "variants": a design study's table; "profile": a
        cam's profile a model reads; "synthesis": a target of ``mbplanar synth``.
    title : str
        The model's title, else the file's first comment line.

    `text()` gives the file's text.

    Examples
    --------
    >>> from mbplanar.formats import list_examples
    >>> fourbar = next(e for e in list_examples() if e.name == "fourbar")
    >>> fourbar.file, fourbar.kind, fourbar.title
    ('fourbar.toml', 'model', 'Crank-rocker four-bar')
    """

    name: str
    file: str
    kind: str
    title: str

    def text(self) -> str:
        """The file's text."""
        return examples_folder().joinpath(self.file).read_text(encoding="utf-8")


def examples_folder():
    """The folder the bundled examples are read from.

    The package's `mbplanar.examples` (a wheel's copy, or an editable install's `models/`), else, run
    from a checkout that is not installed, the repository's `models/`.

    Returns
    -------
    importlib.resources.abc.Traversable or Path
        The folder (`joinpath`, `iterdir`, `read_text` work on either).

    Raises
    ------
    OSError
        Never here; reading from a broken install fails where a file is read.

    Examples
    --------
    >>> from mbplanar.formats import examples_folder
    >>> examples_folder().joinpath("fourbar.toml").read_text(encoding="utf-8").splitlines()[2]
    'name = "fourbar"'
    """
    try:
        return resources.files("mbplanar.examples")
    except ModuleNotFoundError:
        return Path(__file__).resolve().parents[2] / "models"


def _files(folder, prefix=""):
    for entry in sorted(folder.iterdir(), key=lambda e: e.name):
        if entry.is_dir() and not entry.name.startswith(("_", ".")):
            yield from _files(entry, f"{prefix}{entry.name}/")
        elif entry.name.endswith(SUFFIXES):
            yield f"{prefix}{entry.name}", entry


def _describe(file: str, text: str) -> tuple[str, str]:
    """(kind, title) of a bundled file."""
    lines = text.splitlines()
    head = " ".join(line.lstrip("#").strip() for line in lines[:next(
        (k for k, line in enumerate(lines) if not line.startswith("#")), len(lines))])
    comment = re.split(r"\.\s+(?=[A-Z`])", head)[0].rstrip(".")   # the leading comment's first sentence
    if file.startswith("synthesis/"):
        return "synthesis", comment
    if file.endswith(".csv"):
        return ("profile" if "profile_x[mm]" in text else "variants"), comment
    data = tomllib.loads(text)
    kind = "model" if "joints" in data else "cam" if "cam" in data else "other"
    return kind, str(data.get("title") or comment)


def list_examples() -> tuple[Example, ...]:
    """Every bundled example (the repository's `models/`, shipped in the package), in file order.

    Returns
    -------
    tuple of Example
        Models first, then the synthesis targets; each with its kind and title.

    Raises
    ------
    OSError
        The examples' folder cannot be read (a broken install).

    Examples
    --------
    >>> from mbplanar.formats import list_examples
    >>> [e.name for e in list_examples() if e.kind == "model"][:2]
    ['cam_eccentric', 'cam_follower']
    >>> sorted({e.kind for e in list_examples()})
    ['cam', 'model', 'profile', 'synthesis', 'variants']
    """
    out = []
    for file, entry in _files(examples_folder()):
        kind, title = _describe(file, entry.read_text(encoding="utf-8"))
        out.append(Example(file.rsplit(".", 1)[0], file, kind, title))
    return tuple(sorted(out, key=lambda e: (e.kind == "synthesis", e.file)))


def example(name: str) -> Example:
    """The example called `name` (with or without its suffix), else a `ModelError` listing them."""
    found = {e.name: e for e in list_examples()}
    key = name.rsplit(".", 1)[0] if name.endswith(SUFFIXES) else name
    if key not in found:
        raise ModelError(f"no bundled example '{name}' (mbplanar examples lists them: "
                         f"{', '.join(e.name for e in found.values() if e.kind in ('model', 'cam'))}, ...)")
    return found[key]


def example_text(name: str) -> str:
    """The text of one bundled example.

    Parameters
    ----------
    name : str
        Its name: the path under the examples without the suffix ("fourbar",
        "synthesis/motion_3poses"), or with it.

    Returns
    -------
    str
        The file's text.

    Raises
    ------
    ModelError
        An unknown name (the message gives the closest).

    Examples
    --------
    >>> from mbplanar.formats import example_text
    >>> example_text("fourbar").splitlines()[2]
    'name = "fourbar"'
    """
    return example(name).text()


def _companions(ex: Example) -> list[Example]:
    """The files an example needs beside it: a cam file's model, a study model's variants table, the CSV
    profile or path a higher pair's curve names."""
    out = []
    names = {e.file: e for e in list_examples()}
    if ex.kind == "cam":
        model = tomllib.loads(ex.text())["cam"].get("model")
        if isinstance(model, str) and model in names:
            out.append(names[model])
    if ex.file.endswith(".toml"):
        joints = tomllib.loads(ex.text()).get("joints", [])
        for row in joints if isinstance(joints, list) else []:
            for key in ("profile", "path"):
                curve = row.get(key) if isinstance(row, dict) else None
                file = curve.get("file") if isinstance(curve, dict) else None
                if isinstance(file, str) and file in names:
                    out.append(names[file])
    variants = ex.name + "_variants.csv"
    if variants in names:
        out.append(names[variants])
    return out


def copy_examples(names=(), directory=".", overwrite: bool = False) -> list[Path]:
    """Write bundled examples, with the files they need, into a folder (``mbplanar examples``).

    A cam file's model, a study model's variant table and a curve's CSV profile come along;
    subfolders are kept.

    Parameters
    ----------
    names : sequence of str
        The examples (every one when empty).
    directory : str or Path
        Where to write them (made if missing).
    overwrite : bool
        Replace existing files.

    Returns
    -------
    list of Path
        The files written.

    Raises
    ------
    ModelError
        An unknown name, or a file that exists already without `overwrite` (nothing is written then).
    OSError
        The folder cannot be written.

    Examples
    --------
    >>> import tempfile
    >>> from mbplanar.formats import copy_examples
    >>> folder = tempfile.mkdtemp()
    >>> sorted(p.name for p in copy_examples(["shaper_cam"], folder))      # the cam and its linkage
    ['shaper.toml', 'shaper_cam.toml']
    >>> copy_examples(["shaper_cam"], folder)                               # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    mbplanar.errors.ModelError: not overwriting ... (--force to replace)
    """
    chosen = list(list_examples()) if not names else [example(n) for n in names]
    todo = {}
    for ex in chosen:
        for e in [ex] + _companions(ex):
            todo[e.file] = e
    directory = Path(directory)
    targets = {file: directory / file for file in todo}
    clash = [str(p) for p in targets.values() if p.exists()]
    if clash and not overwrite:
        raise ModelError(f"not overwriting {', '.join(clash)} (--force to replace)")
    for file, path in targets.items():
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(todo[file].text(), encoding="utf-8")
    return list(targets.values())
