"""The files a workbench may touch: the models of the folder it serves, and the bundled gallery (the
examples of `mbplanar.formats`).

Every name the page sends is a path relative to the served folder (or ``gallery/NAME`` for a bundled
model). `Folder.resolve` refuses anything else with a `Refused` naming the path: an absolute path, a
``..`` that leaves the folder, a symbolic link that points outside it, a file type the workbench does
not read or write.
"""

from __future__ import annotations

import os
from pathlib import Path, PurePosixPath

__all__ = ["Folder", "Refused", "gallery", "READABLE", "WRITABLE", "MAX_UPLOAD"]

READABLE = (".toml", ".csv")      # models, cam files, synthesis inputs, variant tables
WRITABLE = (".toml",)             # a save writes a model, nothing else
MAX_UPLOAD = 1 << 20              # bytes of a model sent by the page (an upload, an edited text)
GALLERY = "gallery"


class Refused(Exception):
    """A path or a request the workbench will not serve; its message says why (HTTP status `status`)."""

    def __init__(self, message: str, status: int = 403):
        super().__init__(message)
        self.status = status


def gallery() -> dict:
    """The bundled examples (`mbplanar.formats.list_examples`) by file: "fourbar.toml" → its `Example`."""
    from ..formats import list_examples
    return {e.file: e for e in list_examples()}


class Folder:
    """The folder a server was given.

    Parameters
    ----------
    root : path
        The folder; its files (and those of its subfolders) are served.
    """

    def __init__(self, root):
        self.root = Path(root).resolve()
        if not self.root.is_dir():
            raise Refused(f"{root}: not a folder", 400)

    def files(self) -> list[dict]:
        """Every readable file under the folder (hidden folders left out), then the gallery's."""
        out = []
        for dirpath, dirnames, filenames in os.walk(self.root):
            dirnames[:] = sorted(d for d in dirnames if not d.startswith(".") and d not in ("__pycache__",))
            for name in sorted(filenames):
                path = Path(dirpath) / name
                if path.suffix in READABLE and self.contains(path.resolve()):
                    out.append({"path": path.relative_to(self.root).as_posix(), "where": "folder"})
        out += [{"path": f"{GALLERY}/{e.file}", "where": "gallery", "kind": e.kind, "title": e.title}
                for e in gallery().values()]
        return out

    def read(self, name) -> tuple[str, str | None]:
        """The text of file `name` and its path in the folder (None for the gallery's), or `Refused`."""
        found = self.resolve(name)
        if not isinstance(found, Path):
            return found.text(), None
        size = found.stat().st_size
        if size > MAX_UPLOAD:
            raise Refused(f"{name}: {size} bytes; the workbench opens files of at most 1 MB", 413)
        try:
            return found.read_text(encoding="utf-8"), self.relative(found)
        except UnicodeDecodeError as exc:
            raise Refused(f"{name} is not UTF-8 text ({exc.reason} at byte {exc.start})", 400) from None

    def copy_into(self, name, folder: Path) -> Path:
        """File `name` (and, for a bundled example, the files it needs) copied into `folder` for a command
        to read; its path there."""
        found = self.resolve(name)
        if not isinstance(found, Path):
            from ..formats import copy_examples
            copy_examples([found.file], folder, overwrite=True)
            return folder / found.file
        target = folder / found.name
        if not target.exists():
            target.write_bytes(found.read_bytes())
        return target

    def resolve(self, name, *, write: bool = False):
        """The file `name` (relative to the folder) names, or the bundled `Example` gallery/NAME names, or
        `Refused`."""
        if not isinstance(name, str) or not name.strip() or "\0" in name:
            raise Refused("a file name is needed", 400)
        pure = PurePosixPath(name.replace("\\", "/"))
        if pure.is_absolute() or (len(name) > 1 and name[1] == ":"):
            raise Refused(f"{name}: an absolute path; give a path inside the served folder")
        allowed = WRITABLE if write else READABLE
        if pure.suffix not in allowed:
            raise Refused(f"{name}: the workbench {'writes' if write else 'reads'} only "
                          f"{' and '.join(allowed)} files", 400)
        if pure.parts and pure.parts[0] == GALLERY and not (self.root / GALLERY).exists():
            if write:
                raise Refused(f"{name}: the gallery is read-only; save the model into the folder")
            found = gallery().get(PurePosixPath(*pure.parts[1:]).as_posix()) if len(pure.parts) > 1 else None
            if found is None:
                raise Refused(f"{name}: no such model in the gallery", 404)
            return found
        path = (self.root / pure).resolve()
        if not self.contains(path):
            raise Refused(f"{name}: outside the served folder {self.root}")
        if not write and not path.is_file():
            raise Refused(f"{name}: no such file in the served folder", 404)
        if write and not path.parent.is_dir():
            raise Refused(f"{name}: no such folder in the served folder", 404)
        return path

    def relative(self, path: Path) -> str:
        path = Path(path).resolve()
        return path.relative_to(self.root).as_posix() if self.contains(path) else path.name

    def contains(self, path: Path) -> bool:
        return path == self.root or self.root in path.parents
