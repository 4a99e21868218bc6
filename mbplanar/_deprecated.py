"""Old module paths, kept for one release (deprecated in 0.2, removed in 0.3).

The package was 25 modules side by side; they now live in subpackages (see ``docs/architecture.md``). An
old path such as ``mbplanar.solver`` still imports, and every name read from it is forwarded to its new
home with a `DeprecationWarning` that names the new place, as ``scipy.optimize.optimize`` does.

The old paths are served by an import hook (`install`), not by files: a file left at ``mbplanar/solver.py``
would turn git's rename of ``solver.py`` → ``engine/_solver.py`` into a rewrite of ``solver.py``, and edits
made meanwhile to the old file in other branches would conflict instead of following the move.

Three old modules share their name with a new subpackage (``model``, ``structure``, ``kinematics``): the
subpackage keeps the name, exports the old module's public names, and forwards the rest with a warning
(`forwarder`).
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
import warnings

__all__ = ["MOVED", "install", "forwarder"]

#: old module (under ``mbplanar.``) → its new home (or homes, searched in order, for a module split up)
MOVED = {
    "table": "model._table", "assembly": "model._assembly",
    "topology": "structure._topology",
    "solver": ("engine._solver", "engine._tolerances", "engine._atlas", "engine._singular", "engine._blocks"),
    "constraints": "engine._constraints", "_linalg": "engine._linalg",
    "loads": "forces._loads", "kinetostatics": "forces._kinetostatics", "dynamics": "forces._dynamics",
    "_numba_kinematics": "backends._numba_kinematics", "_numba_kinetostatics": "backends._numba_kinetostatics",
    "_threads": "backends._threads",
    "check": "analysis._check",
    "scene": "viz._scene", "plotting": "viz._plotting", "forceplots": "viz._forceplots",
    "animation": "viz._animation", "report": "viz._report",
}
#: old modules whose name is also a public function of `mbplanar` (``mbplanar.check``, ...): loaded at
#: import, so that a later ``import mbplanar.check`` cannot rebind the function to the module
SHADOWED = ("check", "kinetostatics")
REMOVED_IN = "0.3"


def forwarder(old: str, new: str | tuple[str, ...]):
    """A module ``__getattr__`` serving the names of ``new`` (the first of several modules that has the
    name) under ``old``, each with a DeprecationWarning."""
    homes = (new,) if isinstance(new, str) else new

    def __getattr__(name: str):
        if name.startswith("__") and name != "__all__":
            raise AttributeError(f"module {old!r} has no attribute {name!r}")
        for home in homes:
            target = importlib.import_module(home)
            if hasattr(target, name):
                break
        else:
            raise AttributeError(f"module {old!r} has no attribute {name!r}")
        if name != "__all__":
            warnings.warn(_message(old, home, name), DeprecationWarning, stacklevel=2)
        return getattr(target, name)

    return __getattr__


def _message(old: str, new: str, name: str) -> str:
    package = new.rpartition(".")[0]
    if name in getattr(importlib.import_module(package), "__all__", ()):
        advice = f"use {package}.{name}"
    else:
        advice = f"it is private now ({new}.{name})"
    return f"{old}.{name} is deprecated and goes in mbplanar {REMOVED_IN}: {advice}"


# (the finder and the loader follow the import protocol without subclassing importlib.abc's base classes:
# importing importlib.abc costs ~0.5 ms of every `import mbplanar`)
class _ShimLoader:
    def create_module(self, spec):
        return None

    def exec_module(self, module):
        old = module.__name__
        moved = MOVED[old.rpartition(".")[2]]
        homes = tuple("mbplanar." + m for m in ((moved,) if isinstance(moved, str) else moved))
        module.__doc__ = f"Deprecated alias of `{homes[0]}` (goes in mbplanar {REMOVED_IN})."
        module.__getattr__ = forwarder(old, homes)
        module.__dir__ = lambda: sorted(getattr(importlib.import_module(homes[0]), "__all__", ()))


class _ShimFinder:
    def find_spec(self, fullname, path=None, target=None):
        package, _, name = fullname.rpartition(".")
        if package != "mbplanar" or name not in MOVED:
            return None
        return importlib.util.spec_from_loader(fullname, _ShimLoader())


def install() -> None:
    """Serve the old module paths (once per process) and load those that a public function shadows."""
    if not any(isinstance(f, _ShimFinder) for f in sys.meta_path):
        sys.meta_path.insert(0, _ShimFinder())  # before any finder that could see a stale file
    for name in SHADOWED:
        importlib.import_module("mbplanar." + name)
