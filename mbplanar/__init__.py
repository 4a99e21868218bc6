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

The public API is this module. The subpackages (`model`, `structure`, `engine`, `kinematics`, `forces`,
`backends`, `analysis`, `io`, `viz`) export their own documented names; modules whose names start with an
underscore are private. See ``docs/architecture.md``.
"""

from . import _deprecated

_deprecated.install()  # old module paths (mbplanar.solver, ...) as warning aliases, for one release

from .analysis import CheckReport, check  # noqa: E402
from .engine import Engine, Limit  # noqa: E402
from .errors import MbplanarError, ModelError, MotionError  # noqa: E402
from .forces import Dynamics, Kinetostatics, kinetostatics, machine_dynamics  # noqa: E402
from .kinematics import Motion, Position, analyse, position  # noqa: E402
from .model import Input, Joint, Link, Mechanism, Point, assemble, parse_model, read_model  # noqa: E402

__all__ = ["Mechanism", "Link", "Joint", "Point", "Input", "read_model", "parse_model", "assemble",
           "Engine", "Limit", "analyse", "Motion", "position", "Position", "MbplanarError", "ModelError", "MotionError",
           "kinetostatics", "Kinetostatics", "check", "CheckReport", "machine_dynamics", "Dynamics"]
__version__ = "0.1.0"
