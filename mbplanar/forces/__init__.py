"""Forces: loads and their evaluation (`evaluate_loads`; springs, dampers, torques, switched rows), the
kinetostatic system (reactions and balancing moment, `kinetostatics`), friction in the pairs and the
efficiency (`friction_kinetostatics`), the shaking force and balancing (`shaking`, `balance`), machine
dynamics (reduced model, flywheel, true motion, `machine_dynamics`), and the motion under given forces
(`simulate_motion`).

``mbplanar.loads``, ``mbplanar.kinetostatics`` and ``mbplanar.dynamics`` are deprecated aliases of the
modules here.
"""

from ._dynamics import (Dynamics, DynamicsSpec, FlywheelSpec, Reduced, Simulation, flywheel_sizes,
                        machine_dynamics, reduce, simulate, true_motion)
from ._friction import FrictionResult, FrictionSpec, PairFriction, friction_kinetostatics, read_friction
from ._kinetostatics import Kinetostatics, Reaction, inertia_loads, kinetostatics
from ._loads import Gravity, Load, LoadValue, evaluate_loads, has_force_data, load_power
from ._shaking import Balancing, Counterweight, Shaking, balance, shaking, shaking_from_loads
from ._simulation import SimulateSpec, Trajectory, read_simulate, simulate_motion

__all__ = ["Load", "Gravity", "LoadValue", "evaluate_loads", "load_power", "has_force_data",
           "Kinetostatics", "Reaction", "kinetostatics", "inertia_loads",
           "Dynamics", "DynamicsSpec", "FlywheelSpec", "Reduced", "Simulation", "machine_dynamics", "true_motion",
           "reduce", "simulate", "flywheel_sizes",
           "PairFriction", "FrictionSpec", "FrictionResult", "read_friction", "friction_kinetostatics",
           "Shaking", "shaking", "shaking_from_loads", "Counterweight", "Balancing", "balance",
           "SimulateSpec", "Trajectory", "read_simulate", "simulate_motion"]
