"""The kernels compiled ahead of time (``mbplanar compile``): numba's own on-disk cache, filled once, and an
index that tells mbplanar whether that cache holds the kernels of these sources.

Why. The first process that runs the numba backend compiles its kernels (~10 to 20 s of CPU). numba keeps
them in its on-disk cache (``numba.njit(cache=True)``, numba's documented cache), so later processes load
them (numba's own start, importing numba and its target context, is what they pay). ``mbplanar compile``,
the install step of the ``fast`` extra (``pip install "mbplanar[fast]" && mbplanar compile``), runs a
small sample through every kernel, the design batch's included, so that no process compiles.

Where. Where numba puts a cache (`numba's documentation
<https://numba.readthedocs.io/en/stable/developer/caching.html>`_): ``NUMBA_CACHE_DIR`` when it is set,
else the ``__pycache__`` folder beside the kernels' modules (``mbplanar/backends/__pycache__``), else
numba's folder in the user's cache. The index, ``mbplanar-kernels.json``, lies beside numba's files.

The index. numba checks a cached kernel against its own module's source only, while a kernel inlines
the building blocks of the other kernel modules, and freezes their constants. So mbplanar keeps its
own record: the digest of every module of the kernels (`sources`: their content, numba's version and
Python's) for which numba's files there were written. Before the first kernel of a process is loaded
or compiled (`prepare`, from `_jit`), the index is read; when it names other sources (an upgrade, an
edit of an editable install, numba upgraded) or is missing, the kernels' cache files in that folder are
removed and a new index is written, so a kernel compiled from other code is never loaded. `build`
(``mbplanar compile``) adds to the index which kernels it compiled (`status`).
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
import time
import warnings
from pathlib import Path

from ..errors import MbplanarError

__all__ = ["build", "prepare", "status", "sources", "digest", "INDEX", "KERNEL_MODULES"]

FORMAT = 1  # of the index; bump when it changes
INDEX = "mbplanar-kernels.json"
#: the modules holding kernels (`_jit.njit`), imported by `build` so that every kernel is known
KERNEL_MODULES = ("_numba_blocks", "_numba_higher", "_numba_kinematics", "_numba_kinetostatics", "_numba_design")
HERE = Path(__file__).resolve().parent
#: the engine's modules the kernels read: the continuation's rules they compile (`_numba_blocks`), the named
#: tuples of their tables and bundles, and of their tolerances
ENGINE_SOURCES = ("_continuation", "_higher_tables", "_tables", "_tolerances")
#: numba's cache files of a kernel (index and data), named after the kernel's module
SUFFIXES = (".nbi", ".nbc")


def sources() -> list[Path]:
    """The files a compiled kernel depends on: the kernel modules (the kernels, the building blocks they
    inline, the constants they freeze), the decorator (`_jit`: the pipeline), the names old cache indexes
    hold (`_tables`) and the engine's modules of `ENGINE_SOURCES`. A kernel reads nothing else at compile time
    (`tests/test_aot.py` checks that the globals the kernels read are defined in these modules)."""
    return ([HERE / f"{name}.py" for name in sorted(KERNEL_MODULES + ("_jit", "_tables"))]
            + [HERE.parent / "engine" / f"{name}.py" for name in ENGINE_SOURCES])


def digest() -> str:
    """The SHA-256 of the kernels' sources (`sources`, by content), numba's version and Python's (read
    once per process, numba imported)."""
    if not _digest:
        import numba
        h = hashlib.sha256()
        for part in (str(FORMAT), sys.implementation.cache_tag, sys.version, numba.__version__):
            h.update(part.encode() + b"\0")
        for path in sources():
            h.update(f"{path.parent.name}/{path.name}".encode() + b"\0" + path.read_bytes() + b"\0")
        _digest.append(h.hexdigest())
    return _digest[0]


_digest: list = []
_prepared: dict = {}  # cache folder → its index, as this process found or wrote it


def prepare(cache_path: str | os.PathLike) -> dict:
    """Make numba's cache folder `cache_path` safe to load from (once per process and folder): when its
    index names other sources than these (`digest`), or there is none, remove the kernels' cache files
    and write a new index. Returns the index."""
    folder = Path(cache_path)
    found = _prepared.get(folder)
    if found is None:
        found = _prepared[folder] = _checked(folder, digest())
    return found


def _checked(folder: Path, current: str) -> dict:
    """`prepare`'s work on `folder` for the sources' digest `current`."""
    index = _read(folder)
    if index.get("format") == FORMAT and index.get("digest") == current:
        return index
    for path in _kernel_files(folder):
        try:
            path.unlink()
        except FileNotFoundError:
            pass
    index = {"format": FORMAT, "digest": current, "kernels": None}
    _write(folder, index)
    return index


def _kernel_files(folder: Path) -> list[Path]:
    """numba's cache files of the kernels in `folder`: named after a module of this folder."""
    try:
        names = os.listdir(folder)
    except OSError:
        return []
    modules = tuple(f"{path.stem}." for path in sources())
    return [folder / name for name in names if name.endswith(SUFFIXES) and name.startswith(modules)]


def _read(folder: Path) -> dict:
    try:
        index = json.loads((folder / INDEX).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return index if isinstance(index, dict) else {}


def _write(folder: Path, index: dict) -> None:
    """Write the index atomically (a process reading it sees the old one or the new one)."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        temporary = folder / f"{INDEX}.{os.getpid()}.tmp"
        temporary.write_text(json.dumps(index, indent=1), encoding="utf-8")
        os.replace(temporary, folder / INDEX)
    except OSError:  # a folder numba can read but we cannot write: numba's own check still applies
        pass


def status() -> dict | None:
    """The index of numba's cache folder of the kernels (numba imported), or None when numba is missing:
    ``kernels`` names the kernels that `build` left compiled there for these sources (None when it has
    not run since they changed: a first use compiles)."""
    try:
        import numba  # noqa: F401
    except ImportError:
        return None
    from ._jit import cache_path
    return prepare(cache_path())


# -- the build --------------------------------------------------------------------------------------

def build(stream=None, samples=()) -> Path:
    """Compile every kernel into numba's on-disk cache: ``mbplanar compile``, once after installing.

    Those already there for these sources are loaded, not compiled again; the index beside numba's files
    records them, so that later processes load them and none compiles.

    Parameters
    ----------
    stream : file-like, optional
        Where one line says what was compiled, how long it took and where (``sys.stderr`` for the
        command); None: silent.
    samples : sequence of callable, optional
        Functions that run the kernels this module cannot reach itself (the design batch's,
        `mbplanar.study.batch.compile_sample`, from a layer above).

    Returns
    -------
    pathlib.Path
        numba's cache folder of the kernels.

    Raises
    ------
    MbplanarError
        numba is missing (the message names the extra), a kernel fails to compile, or a kernel that
        Python calls (`entries`) was reached by no sample.

    Examples
    --------
    The kernels it compiles are the numba backend's (`NUMBA`); compiling them takes 10 to 20 s of CPU:

    >>> import sys
    >>> from mbplanar.backends import NUMBA, build
    >>> NUMBA.name, NUMBA.should_run("design", 10)
    ('numba', True)
    >>> from mbplanar.study.batch import compile_sample
    >>> folder = build(sys.stderr, samples=(compile_sample,))     # doctest: +SKIP
    """
    try:
        import numba  # noqa: F401
    except ImportError as exc:
        raise MbplanarError(f"compiling the kernels needs numba: pip install 'mbplanar[fast]' ({exc})") from None
    from ._jit import kernels
    from ._numba_notice import quiet
    if stream is not None:
        stream.write("mbplanar: compiling the numba kernels into numba's cache")
        stream.flush()
    start = time.perf_counter()
    try:
        with quiet():
            folder = _build(samples)
    except BaseException:
        if stream is not None:
            stream.write(": failed\n")
        raise
    made = [kernel for kernel in kernels() if kernel.made]
    compiled = sum(kernel.dispatcher.stats.cache_misses.total() for kernel in made)
    loaded = sum(kernel.dispatcher.stats.cache_hits.total() for kernel in made)
    if stream is not None:
        stream.write(f": {compiled} compiled, {loaded} already there ({time.perf_counter() - start:.1f} s) in {folder}\n")
    index = dict(prepare(folder), kernels=sorted(kernel.name for kernel in entries(kernels())))
    _prepared[folder] = index
    _write(folder, index)
    return folder


def _build(samples) -> Path:
    """`build`'s work: run the samples, check that every kernel Python calls ran; numba's cache folder."""
    import importlib
    for module in KERNEL_MODULES:
        importlib.import_module(f"{__package__}.{module}")
    from ._jit import cache_path, kernels
    folder = Path(cache_path())
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for sample in (_run_sample, *samples):
                sample()
    except MbplanarError:
        raise
    except Exception as exc:
        raise MbplanarError(f"compiling the kernels failed (the numba backend still works, numpy taking what "
                            f"it cannot): {type(exc).__name__}: {' '.join(str(exc).split())[:300]}") from exc
    missing = [kernel.name for kernel in entries(kernels()) if not kernel.dispatcher.signatures]
    if missing:
        raise MbplanarError(f"compiling the kernels: the sample did not reach {', '.join(missing)}")
    return folder


def entries(found: list) -> list:
    """The kernels of `found` that Python calls: those no other kernel calls and numba does not inline
    (a kernel called by another is compiled, and cached, with its caller)."""
    called = {id(kernel.py_func.__globals__.get(name)) for kernel in found for name in kernel.py_func.__code__.co_names}
    return [kernel for kernel in found if id(kernel) not in called and kernel.options.get("inline") != "always"]


def _run_sample() -> None:
    """Run the linkage kernels on `SAMPLE` (a loaded four-bar) with the argument types the library's paths
    pass: sweeps with and without rates, of every point and of one, the kinetostatics, one position."""
    import numpy as np
    from ..engine import Engine
    from ..forces import kinetostatics
    from ..kinematics import analyse, position
    from ..model import read_model_text

    engine = Engine(read_model_text(SAMPLE, source="<sample>"), backend="numba", threads=1)
    phi = engine.phi_drawn[0] + np.linspace(0.0, 0.5, 3)
    analyse(engine, phi, rates=False)
    analyse(engine, phi, points=["S2"])
    kinetostatics(engine, analyse(engine, phi, 2.0, 1.0))
    position(engine, float(phi[1]), omega=2.0, epsilon=1.0)


#: the sample of `_run_sample`: a crank-rocker four-bar with masses, gravity and a resisting moment
SAMPLE = """
name = "sample"
ground = "0"
links = [{ name = "1", length = 0.10 },
         { name = "2", length = 0.30, mass = 2.0, inertia = 0.015, centre = "S2" },
         { name = "3", length = 0.25, mass = 1.5, inertia = 0.008, centre = "S3" }]
joints = [{ name = "O", type = "R", links = ["0", "1"], at = [0.0, 0.0] },
          { name = "A", type = "R", links = ["1", "2"], at = [0.05, 0.0866] },
          { name = "B", type = "R", links = ["2", "3"], at = [0.3016, 0.25] },
          { name = "C", type = "R", links = ["3", "0"], at = [0.30, 0.0] }]
points = [{ name = "S2", link = "2", along = ["A", "B"], fraction = 0.5 },
          { name = "S3", link = "3", along = ["C", "B"], fraction = 0.5 }]
loads = [{ name = "resistance", type = "moment", link = "3", moment = -5.0 }]
[gravity]
g = 9.81
[input]
joint = "O"
drawn_at = 60.0
omega = 10.0
"""
