"""The engine cache of the command line: an `Engine` built from a model file, kept on disk so that the
next command on the same file skips its build.

Building an engine costs ~10 ms of work but ~0.1 s of start-up, almost all of it importing networkx for
the structure analysis; a command such as ``mbplanar solve`` then spends about half its time there. The
cache stores the engine as built, before it solves anything (its atlas is made on first use), so a
cached engine gives bit for bit the answers of a new one.

An entry is a pickle written by this module, one file per model path and copy of mbplanar, in the
user's cache directory (``MBPLANAR_CACHE_DIR``, else ``$XDG_CACHE_HOME/mbplanar``, else
``~/.cache/mbplanar``). It is used only when its key matches: the model file's bytes, the path as given
(error messages name it), the backend, the tolerances, and the code that built it (the size and
modification time of every module of the package, which a new version or any edit changes, and Python's
and numpy's versions). Anything else (another key, a truncated or unreadable file, a directory other
users can write) means the engine is built again, silently, and the entry rewritten. The warnings the
build gave (a sketch that disagrees with a length, ...) are kept and given again.
``MBPLANAR_NO_CACHE=1`` or ``mbplanar --no-cache`` turns the cache off.
"""

from __future__ import annotations

import os
import pickle
import sys
import warnings
import zlib
from pathlib import Path

from ._solver import Engine
from ._tolerances import Tolerances
from ..model import read_model, read_model_text

__all__ = ["load_engine", "cache_dir", "cache_enabled"]

FORMAT = 2  # of an entry; bump when its layout changes
PACKAGE = Path(__file__).resolve().parent.parent


def cache_enabled() -> bool:
    """False when the environment turns the engine cache off (MBPLANAR_NO_CACHE set and not "0")."""
    return os.environ.get("MBPLANAR_NO_CACHE", "") in ("", "0")


def cache_dir() -> Path:
    """Where the entries live: MBPLANAR_CACHE_DIR, else $XDG_CACHE_HOME/mbplanar, else ~/.cache/mbplanar."""
    given = os.environ.get("MBPLANAR_CACHE_DIR")
    if given:
        return Path(given)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "mbplanar"


def load_engine(path, backend: str = "numpy", threads: int | None = None, use_cache: bool = True) -> Engine:
    """The engine of a model file: from the engine cache when an entry matches, else built (and stored).

    A cached engine gives bit for bit the answers of a new one (see the module's docstring for the key).

    Parameters
    ----------
    path : str or Path
        The model file.
    backend : str, optional
        As in `Engine`.
    threads : int, optional
        As in `Engine`.
    use_cache : bool, optional
        False: always build (as ``mbplanar --no-cache``; ``MBPLANAR_NO_CACHE=1`` too).

    Returns
    -------
    Engine
        The warnings its build gave are given again, cached or not.

    Raises
    ------
    ModelError
        The file cannot be read or its table is wrong, as `read_model`, whether cached or not.
    MotionError
        Its drawn pose cannot be assembled, as `Engine`.

    Examples
    --------
    >>> from mbplanar.engine import load_engine
    >>> engine = load_engine("models/fourbar.toml", use_cache=False)
    >>> engine.mech.name, engine.backend
    ('fourbar', 'numpy')
    >>> load_engine("models/no_such_model.toml", use_cache=False)
    Traceback (most recent call last):
    mbplanar.errors.ModelError: models/no_such_model.toml: cannot read the model file (No such file or directory)
    """
    text = _read(path)
    if not (use_cache and cache_enabled()):
        engine, caught = _build(text, str(path), backend, threads)
    else:
        key = _key(text, str(path), backend)
        entry = cache_dir() / f"{_entry_name(PACKAGE, os.path.abspath(path), str(path), backend)}.pickle"
        cached = _read_entry(entry, key)
        if cached is not None:
            engine, caught = cached
            engine.threads = threads
        else:
            engine, caught = _build(text, str(path), backend, threads)
            _write_entry(entry, key, engine, caught)
    for message in caught:  # (the build's warnings, cached or not)
        warnings.warn(message, stacklevel=2)
    return engine


def _read(path) -> bytes:
    """The model file's bytes; a ModelError as `read_model` gives when it cannot be read."""
    try:
        return Path(path).read_bytes()
    except OSError:
        read_model(path)  # raises the error that names the file
        raise


def _build(text: bytes, source: str, backend: str, threads) -> tuple[Engine, list[Warning]]:
    """A new engine of the model text, and the warnings reading and assembling it gave."""
    try:
        decoded = text.decode("utf-8")
    except UnicodeDecodeError:
        read_model(source)  # raises the error that names the file and the byte
        raise
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            engine = Engine(read_model_text(decoded, source=source), backend=backend, threads=threads)
    except Exception:
        for w in caught:   # (often the cause: a length in another unit than the file's)
            warnings.warn(w.message, stacklevel=3)
        raise
    return engine, [w.message for w in caught]


def _key(text: bytes, source: str, backend: str) -> tuple:
    """What the cached engine depends on, in full: an entry is used only when its key equals this one
    (compared whole rather than as a digest, which would import hashlib, ~4 ms of every command's start)."""
    import numpy as np
    return (FORMAT, sys.implementation.cache_tag, np.__version__, _code_stamp(), source, backend,
            repr(Tolerances()), text)


def _entry_name(*parts) -> str:
    """The file name of the entry of these parts: two 32-bit checksums of them (zlib's, loaded with numpy).
    Two model paths whose names clash share one entry, each rewriting it for the other: the entry's
    whole key tells them apart, so a clash costs a build, never a wrong engine."""
    data = "\0".join(str(part) for part in parts).encode("utf-8", "surrogateescape")
    return f"{zlib.crc32(data):08x}{zlib.adler32(data):08x}"


def _code_stamp() -> str:
    """The size and modification time of every module of the package: any edit changes it (read once per
    process)."""
    if not _stamp:
        _stamp.append(_stamp_of_files())
    return _stamp[0]


_stamp: list = []


def _stamp_of_files(root=PACKAGE) -> str:
    """The path, size and modification time of every module under the folder `root`, one per line."""
    root, stamps = str(root), []
    for folder, dirs, files in os.walk(root):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        relative = folder[len(root) + 1:]  # (os.path.relpath took half the time of a stamp)
        for name in sorted(files):
            if name.endswith(".py"):
                info = os.stat(os.path.join(folder, name))
                stamps.append(f"{os.path.join(relative, name)}:{info.st_size}:{info.st_mtime_ns}")
    return "\n".join(stamps)


def _private(folder: Path) -> bool:
    """Whether `folder` is ours and only we can write into it (pickles are only read from there)."""
    if not hasattr(os, "getuid"):
        return True
    info = os.stat(folder)
    return info.st_uid == os.getuid() and not info.st_mode & 0o022


def _read_entry(entry: Path, key: tuple) -> tuple[Engine, list[Warning]] | None:
    """The engine and warnings of a matching entry, or None (missing, another key, unreadable)."""
    try:
        if not _private(entry.parent):
            return None
        with open(entry, "rb") as file:
            stored = pickle.load(file)
        if stored["key"] != key or not isinstance(stored["engine"], Engine):
            return None
        return stored["engine"], list(stored["warnings"])
    except Exception:  # a missing, truncated or foreign file: build the engine again
        return None


def _write_entry(entry: Path, key: tuple, engine: Engine, caught: list[Warning]) -> None:
    """Store an entry atomically (a whole file or none); any failure only leaves the cache unused."""
    temporary = entry.with_name(f"{entry.name}.{os.getpid()}.tmp")
    try:
        entry.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
        if not _private(entry.parent):
            return
        data = pickle.dumps({"key": key, "engine": engine, "warnings": caught}, protocol=pickle.HIGHEST_PROTOCOL)
        with open(temporary, "wb") as file:
            file.write(data)
        os.replace(temporary, entry)
    except Exception:  # a read-only or full disk, an engine that cannot be pickled: no cache
        try:
            os.remove(temporary)
        except OSError:
            pass
