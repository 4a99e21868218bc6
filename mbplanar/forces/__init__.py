"""Forces: loads and their evaluation (`evaluate_loads`; springs, dampers, torques, switched rows), the
kinetostatic system (reactions and balancing moment, `kinetostatics`), friction in the pairs and the
efficiency (`friction_kinetostatics`), the shaking force and balancing (`shaking`, `inertia_shaking`,
`balance`), machine dynamics (reduced model, flywheel, true motion, `machine_dynamics`), and the motion
under given forces (`simulate_motion`).
"""

from .._lazy import lazy_attributes

#: name → the module that defines it, imported on first use (PEP 562), so that a command reading one
#: result type (``mbplanar solve`` reaches `Kinetostatics` and `Dynamics` through `mbplanar.io`) does not
#: load friction, shaking and the simulation
_HOME = {**dict.fromkeys(["Dynamics", "DynamicsSpec", "FlywheelSpec", "Reduced", "Simulation", "flywheel_sizes",
                          "machine_dynamics", "read_dynamics", "reduce", "simulate", "stall_ahead", "summary",
                          "true_motion"], "_dynamics"),
         **dict.fromkeys(["FrictionResult", "FrictionSpec", "PairFriction", "friction_kinetostatics", "read_friction",
                          "implausible_friction", "not_converged", "FRICTION", "FRICTION_PAIR"], "_friction"),
         **dict.fromkeys(["Kinetostatics", "Reaction", "inertia_loads", "kinetostatics", "plan_of", "solve_blocks",
                          "input_link", "reported_on"], "_kinetostatics"),
         **dict.fromkeys(["Gravity", "Load", "LoadValue", "evaluate_loads", "has_force_data", "load_power",
                          "warn_idle_resistances", "read_loads", "heavy_links", "constant_parts", "world_points",
                          "drawn_end", "ELEMENT_TYPES"], "_loads"),
         **dict.fromkeys(["Balancing", "Counterweight", "Shaking", "balance", "shaking", "shaking_from_loads",
                          "inertia_shaking"], "_shaking"),
         **dict.fromkeys(["SimulateSpec", "Trajectory", "read_simulate", "simulate_motion", "SIMULATE"], "_simulation")}


__getattr__, __dir__ = lazy_attributes(__name__, _HOME)

__all__ = ["Load", "Gravity", "LoadValue", "read_loads", "evaluate_loads", "load_power", "has_force_data",
           "warn_idle_resistances", "heavy_links", "constant_parts", "world_points", "drawn_end", "ELEMENT_TYPES",
           "Kinetostatics", "Reaction", "kinetostatics", "inertia_loads", "plan_of", "solve_blocks", "input_link",
           "reported_on",
           "Dynamics", "DynamicsSpec", "FlywheelSpec", "Reduced", "Simulation", "machine_dynamics", "true_motion",
           "reduce", "simulate", "stall_ahead", "flywheel_sizes", "read_dynamics", "summary",
           "PairFriction", "FrictionSpec", "FrictionResult", "read_friction", "friction_kinetostatics", "implausible_friction",
           "not_converged", "FRICTION", "FRICTION_PAIR",
           "Shaking", "shaking", "shaking_from_loads", "inertia_shaking", "Counterweight", "Balancing", "balance",
           "SimulateSpec", "Trajectory", "read_simulate", "simulate_motion", "SIMULATE"]
