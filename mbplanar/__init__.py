"""mbplanar: planar linkages analysed from a table of kinematic pairs.

    >>> import mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians([0, 90]))     # batch of input values, SI
    >>> motion.xy[:, motion.point("B")]                             # (B, 2) positions
    >>> mbplanar.position(engine, np.radians(30)).xy                # one position, lean: (P, 2)
    >>> engine.topology.structure.formula                           # Assur groups
    >>> mbplanar.check(engine).full_turn                            # motion limits, angles
    >>> mbplanar.kinetostatics(engine, motion).balancing["O"]       # reactions, balancing moment
    >>> mbplanar.machine_dynamics(engine).flywheel                  # flywheel, true ω(φ)
    >>> mbplanar.widget("models/fourbar.toml")                      # Jupyter: the workbench's diagram and plots

The public API is this module. The subpackages (`model`, `structure`, `engine`, `kinematics`, `forces`,
`backends`, `analysis`, `io`, `viz`) export their own documented names; modules whose names start with an
underscore are private. See ``docs/architecture.md``.
"""

from . import _deprecated
from .errors import MbplanarError, ModelError, MotionError

_deprecated.install()  # old module paths (mbplanar.solver, ...) as warning aliases, for one release
for _old in _deprecated.SHADOWED:  # the old module mbplanar.check gave way to the function, served below
    globals().pop(_old, None)

__all__ = ["Mechanism", "Link", "Joint", "Point", "Input", "read_model", "parse_model", "assemble",
           "Engine", "Limit", "analyse", "Motion", "position", "Position", "MbplanarError", "ModelError", "MotionError",
           "kinetostatics", "Kinetostatics", "check", "CheckReport", "machine_dynamics", "Dynamics", "widget"]
__version__ = "0.1.0"

#: public name → the subpackage that defines it, imported on first use (PEP 562): ``import mbplanar``
#: loads neither numpy nor the analysis code, so that a command or a script pays only for what it uses
_HOME = {**dict.fromkeys(["CheckReport", "check"], "analysis"), **dict.fromkeys(["Engine", "Limit"], "engine"),
         **dict.fromkeys(["Dynamics", "Kinetostatics", "kinetostatics", "machine_dynamics"], "forces"),
         **dict.fromkeys(["Motion", "Position", "analyse", "position"], "kinematics"),
         **dict.fromkeys(["Input", "Joint", "Link", "Mechanism", "Point", "assemble", "parse_model", "read_model"],
                         "model"), "widget": "web"}
_SUBPACKAGES = ("model", "structure", "engine", "kinematics", "forces", "backends", "analysis", "io", "viz", "cam",
                "study", "synthesis", "formats", "web", "cli", "errors")


def __getattr__(name: str):
    """A public name (or a subpackage) imported on first use and kept in the module's namespace."""
    import importlib
    if name in _HOME:
        value = getattr(importlib.import_module(f"{__name__}.{_HOME[name]}"), name)
    elif name in _SUBPACKAGES:
        value = importlib.import_module(f"{__name__}.{name}")
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__) | set(_SUBPACKAGES))
