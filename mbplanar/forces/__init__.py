"""Forces: loads and their evaluation (`evaluate_loads`), the kinetostatic system (reactions and
balancing moment, `kinetostatics`), and machine dynamics (reduced model, flywheel, true motion,
`machine_dynamics`).

``mbplanar.loads``, ``mbplanar.kinetostatics`` and ``mbplanar.dynamics`` are deprecated aliases of the
modules here.
"""

from ._dynamics import (Dynamics, DynamicsSpec, FlywheelSpec, Reduced, Simulation, flywheel_sizes,
                        machine_dynamics, reduce, simulate, true_motion)
from ._kinetostatics import Kinetostatics, Reaction, inertia_loads, kinetostatics
from ._loads import Gravity, Load, LoadValue, evaluate_loads, has_force_data, load_power

__all__ = ["Load", "Gravity", "LoadValue", "evaluate_loads", "load_power", "has_force_data",
           "Kinetostatics", "Reaction", "kinetostatics", "inertia_loads",
           "Dynamics", "DynamicsSpec", "FlywheelSpec", "Reduced", "Simulation", "machine_dynamics", "true_motion",
           "reduce", "simulate", "flywheel_sizes"]
