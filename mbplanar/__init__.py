"""mbplanar: planar linkages analysed from a table of kinematic pairs.

    >>> import mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians([0, 90]))     # batch of input values, SI
    >>> motion.xy[:, motion.point("B")]                             # (B, 2) positions
    >>> engine.topology.structure.formula                           # Assur groups
    >>> mbplanar.check(engine).full_turn                            # motion limits, angles
    >>> mbplanar.kinetostatics(engine, motion).balancing["O"]       # reactions, balancing moment
    >>> mbplanar.machine_dynamics(engine).flywheel                  # flywheel, true ω(φ)

The public API is this module; everything else is private by convention.
"""

from .assembly import assemble
from .check import CheckReport, check
from .dynamics import Dynamics, machine_dynamics
from .errors import MbplanarError, ModelError, MotionError
from .kinematics import Motion, analyse
from .kinetostatics import Kinetostatics, kinetostatics
from .model import Input, Joint, Link, Mechanism, Point
from .solver import Engine, Limit
from .table import parse_model, read_model

__all__ = ["Mechanism", "Link", "Joint", "Point", "Input", "read_model", "parse_model", "assemble",
           "Engine", "Limit", "analyse", "Motion", "MbplanarError", "ModelError", "MotionError",
           "kinetostatics", "Kinetostatics", "check", "CheckReport", "machine_dynamics", "Dynamics"]
__version__ = "0.1.0"
