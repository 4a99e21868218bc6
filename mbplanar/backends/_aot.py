"""The compiled kernels built ahead of time (``mbplanar compile``): one Python extension module, built
by numba's ``numba.pycc`` from the same kernels and options as the just-in-time path, that later
processes load WITHOUT importing numba (the module needs numpy only).

Why. A process that runs the numba backend pays numba's own start (importing numba, its first dispatch,
loading the kernels from its cache: ~0.8 s of CPU over numpy), and its very first run compiles the
kernels (~8 s). The built module loads in milliseconds: ``mbplanar compile`` compiles once, as the
install step of the ``fast`` extra (``pip install "mbplanar[fast]" && mbplanar compile``), and every
later process, the first included, starts as fast as one on numpy.

What is built. `build` runs a small sample (a loaded four-bar: a sweep with and without rates, its
kinetostatics, one position) with every kernel running as plain Python (`_jit.capture`), which records
the argument types of each kernel's call; it then compiles those kernels for exactly those types
(error model, GIL release and options as their ``numba.njit``) and writes the module with a manifest
(the kernels, the types each takes, the key below).

When it is used. A `_jit.Kernel` asks `function` for its compiled function on its first call with
given argument types: the module's function is returned only when the module is built for this copy
of mbplanar and this machine (the key: every module's size and modification time, Python's and numpy's
versions, numba's version, the CPU) and has the kernel for exactly these types (`_jit.signature`);
anything else (not built, another key, a module that fails to load, a kernel or types it lacks) makes
numba compile the kernel, as without the module, silently: the answers are the same. The module is
only loaded from a folder that only the user can write (it is code), as the engine cache's pickles.
``MBPLANAR_AOT=0`` turns it off.

Where. ``<cache>/kernels/<key>/``, the cache being the engine cache's folder (``MBPLANAR_CACHE_DIR``,
else ``$XDG_CACHE_HOME/mbplanar``, else ``~/.cache/mbplanar``): a new version of mbplanar builds into
another folder; `build` removes the folders of other keys.
"""

from __future__ import annotations

import importlib.machinery
import importlib.util
import json
import os
import platform
import shutil
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

from ..engine._cache import _code_stamp, _digest, _private, cache_dir
from ..errors import MbplanarError

__all__ = ["build", "function", "folder", "enabled", "available", "reset"]

FORMAT = 1  # of the module's manifest; bump when it changes
MODULE = "_mbplanar_kernels"  # the extension module's name (its init function is named after it)
MANIFEST = "manifest.json"


def enabled() -> bool:
    """False when the environment turns the built module off (MBPLANAR_AOT=0)."""
    return os.environ.get("MBPLANAR_AOT", "") in ("", "1")


def folder() -> Path:
    """The folder of the module built for this copy of mbplanar on this machine."""
    return cache_dir() / "kernels" / _key()[:32]


def available() -> bool:
    """Whether a module built for this copy of mbplanar loads (loading it if not yet loaded)."""
    return _module() is not None


def function(name: str, signature: str):
    """The built module's function of the kernel `name` (``module.qualname``) for arguments of the
    types `signature` (`_jit.signature`), or None."""
    loaded = _module()
    if loaded is None:
        return None
    module, kernels = loaded
    entry = kernels.get(name)
    if entry is None or entry["signature"] != signature:
        return None
    return getattr(module, entry["symbol"], None)


_state: dict = {}


def reset() -> None:
    """Forget the module looked up (the next kernel looks again; for tests)."""
    _state.clear()


def _module():
    """(module, kernels) of the built module of this key, loaded once per process; None if none loads."""
    if "loaded" not in _state:
        _state["loaded"] = _load() if enabled() else None
    return _state["loaded"]


def _load():
    try:
        where = folder()
        if not _private(where):
            return None
        manifest = json.loads((where / MANIFEST).read_text(encoding="utf-8"))
        if manifest.get("format") != FORMAT or manifest.get("key") != _key():
            return None
        path = where / manifest["file"]
        if not path.is_file() or (hasattr(os, "getuid") and path.stat().st_uid != os.getuid()):
            return None
        loader = importlib.machinery.ExtensionFileLoader(MODULE, str(path))
        spec = importlib.util.spec_from_file_location(MODULE, str(path), loader=loader)
        module = importlib.util.module_from_spec(spec)
        loader.exec_module(module)
        return module, manifest["kernels"]
    except Exception:  # a missing, partial, foreign or broken module: numba compiles instead
        return None


def _key() -> str:
    """What the built module depends on, as one digest (computed once per process)."""
    if "key" not in _state:
        _state["key"] = _digest(str(FORMAT), sys.implementation.cache_tag, sys.version, np.__version__,
                                _numba_stamp(), _cpu(), _code_stamp())
    return _state["key"]


def _numba_stamp() -> str:
    """numba's version, from its files' size and modification time (numba is not imported)."""
    spec = importlib.util.find_spec("numba")
    if spec is None or not spec.origin:
        return "no numba"
    root = Path(spec.origin).parent
    stamps = []
    for name in ("__init__.py", "_version.py"):
        try:
            info = (root / name).stat()
            stamps.append(f"{name}:{info.st_size}:{info.st_mtime_ns}")
        except OSError:
            stamps.append(f"{name}:-")
    return ";".join(stamps)


def _cpu() -> str:
    """The machine the module is built for (it is compiled for the host CPU)."""
    described = [platform.machine(), platform.system()]
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as file:
            for line in file:
                if line.startswith(("model name", "flags", "Features", "CPU part")):
                    described.append(line.strip())
                if len(described) >= 4:
                    break
    except OSError:
        described.append(platform.processor())
    return "\n".join(described)


# -- the build --------------------------------------------------------------------------------------

def build(stream=None) -> Path:
    """Build the module for this copy of mbplanar (replacing any other key's) and return its folder; one
    line on `stream` says so. An `MbplanarError` when numba or a C compiler is missing."""
    try:
        import numba  # noqa: F401
        import numba.pycc  # noqa: F401
    except ImportError as exc:
        raise MbplanarError("building the compiled kernels needs numba and its numba.pycc: pip install 'mbplanar[fast]' "
                            f"({exc})") from None
    from ._numba_notice import quiet
    if stream is not None:
        stream.write("mbplanar: compiling the numba kernels ahead of time")
        stream.flush()
    try:
        with quiet():
            where, seconds = _build()
    except BaseException:
        if stream is not None:
            stream.write(": failed\n")
        raise
    if stream is not None:
        stream.write(f" ({seconds:.1f} s) into {where}\n")
    return where


def _build() -> tuple[Path, float]:
    """`build`'s work: the folder written and the seconds it took."""
    from numba.pycc import CC
    start = time.perf_counter()
    where = folder()
    root = where.parent
    root.mkdir(mode=0o700, parents=True, exist_ok=True)
    if not _private(root):
        raise MbplanarError(f"{root}: the folder of the built kernels must be the user's own, writable by no one else")
    work = Path(tempfile.mkdtemp(prefix="build-", dir=root))
    try:
        calls = _sample_calls()
        cc = CC(MODULE)
        cc.output_dir, cc.target_cpu, cc.use_nrt, cc.verbose = str(work), "host", False, False
        # numba's C helpers (the arguments' unboxing, ...) compiled with -O1, not -O3: ~0.8 s less of the
        # build here; the kernels are LLVM's code, not theirs
        cc._extra_cflags = {"posix": ["-O1"]}
        kernels = {}
        for i, (name, (kernel, args, result)) in enumerate(sorted(calls.items())):
            symbol = f"k{i}_{kernel.py_func.__name__.lstrip('_')}"
            cc.export(symbol, _numba_signature(args, result))(_forwarder(kernel, len(args)))
            kernels[name] = {"symbol": symbol, "signature": _signature(args)}
        with _kernel_flags(calls), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cc.compile()
        built = [p.name for p in work.iterdir() if p.name.startswith(MODULE) and p.suffix in _suffixes()]
        if len(built) != 1:
            raise MbplanarError(f"building the compiled kernels: numba.pycc wrote {built or 'nothing'}")
        manifest = {"format": FORMAT, "key": _key(), "file": built[0], "kernels": kernels,
                    "built_s": round(time.perf_counter() - start, 3)}
        (work / MANIFEST).write_text(json.dumps(manifest, indent=1), encoding="utf-8")
        os.chmod(work, 0o700)
        for old in root.iterdir():  # other keys' modules and this key's earlier one
            if old != work and not old.name.startswith("build-") or old == where:
                shutil.rmtree(old, ignore_errors=True)
        os.replace(work, where)
    except Exception as exc:
        shutil.rmtree(work, ignore_errors=True)
        if isinstance(exc, MbplanarError):
            raise
        raise MbplanarError(f"building the compiled kernels failed (the numba backend still works, compiling on first use): "
                            f"{type(exc).__name__}: {' '.join(str(exc).split())[:300]}") from exc
    from ._jit import forget
    forget()
    return where, time.perf_counter() - start


def _forwarder(kernel, count: int):
    """A function of `count` arguments that calls `kernel` with them: what the module exports. The kernel
    itself is compiled by numba as on the just-in-time path (or taken from numba's cache), once, whether
    exported or called by another kernel (the one-position kernel calls the sweep kernel), and linked in."""
    names = ", ".join(f"a{i}" for i in range(count))
    scope = {"kernel": kernel}
    exec(f"def forward({names}):\n    return kernel({names})\n", scope)  # (numba takes no *args)
    return scope["forward"]


def _suffixes() -> tuple:
    return tuple(importlib.machinery.EXTENSION_SUFFIXES) + (".so", ".pyd")


def _signature(args) -> str:
    from ._jit import signature
    found = signature(args)
    if found is None:
        raise MbplanarError("building the compiled kernels: a kernel takes an argument of a type it cannot describe")
    return found


def _numba_signature(args, result):
    """The kernel's numba signature: the arguments' types, and its result's type."""
    import numba
    return numba.typeof(result)(*(numba.typeof(a) for a in args)) if result is not None else \
        numba.types.none(*(numba.typeof(a) for a in args))


class _kernel_flags:
    """numba.pycc compiles every function with default flags: here with the kernels' own (numpy's error
    model, the GIL released), for the length of the build. The kernels must agree on them."""

    def __init__(self, calls: dict):
        options = {tuple(sorted((k, str(v)) for k, v in kernel.options.items() if k in _FLAGS))
                   for kernel, _, _ in calls.values()}
        if len(options) != 1:
            raise MbplanarError(f"building the compiled kernels: the kernels disagree on their numba options {options}")
        self.options = dict(next(iter(options)))

    def __enter__(self):
        from numba.core import codegen
        from numba.core.compiler import Flags
        from numba.pycc import compiler
        error_model, release_gil = self.options.get("error_model", "python"), self.options.get("nogil") == "True"

        class KernelFlags(Flags):
            def __init__(self, *args):
                super().__init__(*args)
                if not args:
                    self.error_model, self.release_gil = error_model, release_gil

        self.module, self.saved = compiler, compiler.Flags
        compiler.Flags = KernelFlags
        # the module links the kernels as numba compiled and optimised them (`_forwarder`): optimising the
        # whole module once more would only inline the forwarders (~2 s of the build)
        self.library, self.optimise = codegen.AOTCodeLibrary, codegen.AOTCodeLibrary.__dict__.get("_optimize_final_module")
        codegen.AOTCodeLibrary._optimize_final_module = lambda library: None

    def __exit__(self, *exc):
        self.module.Flags = self.saved
        if self.optimise is None:
            del self.library._optimize_final_module
        else:
            self.library._optimize_final_module = self.optimise


_FLAGS = ("error_model", "nogil", "fastmath", "boundscheck", "_nrt")


def _sample_calls() -> dict:
    """{kernel name: (kernel, arguments, result)} of the kernels' calls on a sample (`SAMPLE`), swept with and without rates, its kinetostatics, and one
    position, every kernel run as plain Python."""
    from ._jit import capture
    from ..engine._solver import Engine
    from ..forces._kinetostatics import kinetostatics
    from ..kinematics._motion import analyse
    from ..kinematics._single import position
    from ..model._table import read_model_text

    engine = Engine(read_model_text(SAMPLE, source="<sample>"), backend="numba", threads=1)
    phi = engine.phi_drawn[0] + np.linspace(0.0, 0.5, 3)
    with capture() as seen, warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        analyse(engine, phi, rates=False).value
        motion = analyse(engine, phi)
        kinetostatics(engine, motion)
        position(engine, float(phi[1]))
    wanted = {"_sweep", "_kernel"}  # the kinematics kernel (one position included) and the kinetostatics kernel
    calls = {name: (kernel, args, seen["results"][name]) for name, (kernel, args) in seen["calls"].items()
             if kernel.py_func.__name__ in wanted}
    if len(calls) != len(wanted):
        raise MbplanarError(f"building the compiled kernels: the sample ran {sorted(seen['calls'])}, not every kernel")
    return calls


#: the sample of `_sample_calls`: a crank-rocker four-bar with masses, gravity and a resisting moment
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
