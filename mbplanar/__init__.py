"""mbplanar: planar linkages analysed from a table of kinematic pairs.

    >>> import numpy as np
    >>> import mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians([0, 90]))        # a batch of input values, SI
    >>> motion.xy[:, motion.point("B")].round(4)                       # (B, 2) positions of B, m
    array([[0.2687, 0.248 ],
           [0.2615, 0.247 ]])
    >>> mbplanar.position(engine, np.radians(30)).xy.shape             # one position, lean: (P, 2)
    (5, 2)
    >>> engine.topology.structure.formula                              # Assur groups
    'I(0,1) → II(2,3)'
    >>> mbplanar.check(engine).full_turn                               # motion limits, angles
    True
    >>> loaded = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> forces = mbplanar.kinetostatics(loaded, mbplanar.analyse(loaded, np.radians([60.0]), omega=10.0))
    >>> round(float(forces.balancing["O"][0]), 5)                      # reactions, balancing moment (N·m)
    2.69865
    >>> shaper = mbplanar.Engine(mbplanar.read_model("models/shaper.toml"))
    >>> round(float(mbplanar.machine_dynamics(shaper).driving_moment), 3)   # flywheel, true ω(φ): N·m
    102.058

The public API is this module. The subpackages (`model`, `structure`, `engine`, `kinematics`, `forces`,
`backends`, `analysis`, `io`, `viz`) export their own documented names; modules whose names start with an
underscore are private. See ``docs/architecture.md``.
"""

from .errors import MbplanarError, ModelError, MotionError

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
                "gears", "study", "accuracy", "synthesis", "formats", "web", "cli", "errors")


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
