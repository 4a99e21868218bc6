"""Units of the numbers a command shows: SI (the default) or the model's own (`--units model`).

Inside mbplanar every number is SI. On output, `DisplayUnits` divides each quantity by the size of
its shown unit: lengths (and so velocities, accelerations) by the table's `length_unit`, moments by
its `moment_unit`, inertias by its `inertia_unit`; forces (N), masses (kg), energy and work (J),
angles and their rates stay as they are. Every JSON document carries the result as a top-level
``"units"`` object (`DisplayUnits.document`), every text table names its units in the headers.
`DisplayUnits` and the CSV conversion live in `mbplanar.model._units` (the commands of the packages
before `io` use them too); the documents of the core commands are converted here.
"""

from __future__ import annotations

from ..model import SYSTEMS, DisplayUnits, convert_table, display_units

__all__ = ["DisplayUnits", "display_units", "SYSTEMS", "convert_info", "convert_solution", "convert_forces",
           "convert_dynamics", "convert_check", "convert_simulation", "convert_balance", "convert_table",
           "input_kinds"]


# -- converting finished (SI) documents and tables ---------------------------------------------------
def input_kinds(engine, k: int = 0) -> tuple[str, str, str]:
    """Kinds of input k's rate, acceleration and its J_I: rad/s, rad/s², kg·m² for a revolute input;
    velocity, acceleration, kg for a prismatic input."""
    prismatic = engine.mech.joints[engine.inputs[k].joint].kind == "P"
    return ("velocity", "acceleration", "mass") if prismatic else ("angular_velocity", "angular_acceleration",
                                                                   "inertia")


def _joint_kinds(engine, name, keys=("value", "rate", "accel")) -> dict:
    if engine.mech.joints[name].kind == "P":
        return dict(zip(keys, ("length", "velocity", "acceleration")))
    return {}


def _scale_dict(node: dict, kinds: dict, display: DisplayUnits, factor: dict | None = None):
    """Divide node[key] (a number or a list of numbers) by the shown unit of kinds[key], in place."""
    for key, kind in kinds.items():
        if key not in node or node[key] is None:
            continue
        scale = display.scale(kind) if factor is None else factor[kind]
        value = node[key]
        node[key] = [None if v is None else v / scale for v in value] if isinstance(value, list) else value / scale


_MOTION = {"x": "length", "y": "length", "vx": "velocity", "vy": "velocity", "ax": "acceleration",
           "ay": "acceleration"}


def _inputs(engine, doc_inputs, display):
    for k, node in enumerate(doc_inputs):
        rate, accel, _ = input_kinds(engine, k)
        _scale_dict(node, {"omega": rate, "epsilon": accel}, display)


def convert_info(engine, doc: dict, display: DisplayUnits) -> dict:
    """`info --json` in `display` units, with its ``"units"`` object."""
    for node in list(doc["joints"].values()) + list(doc["points"].values()):
        _scale_dict(node, {"at": "length"}, display)
    for node in doc.get("higher_pairs", {}).values():
        _scale_dict(node, {"at": "length", "contact": "length", "radius": "length", "radii": "length",
                           "centre": "length"}, display)
        if "centres" in node:
            node["centres"] = [[v / display.scale("length") for v in c] for c in node["centres"]]
        for pair in node["equivalent"]:
            _scale_dict(pair, {"at": "length"}, display)
    doc["units"] = display.document()
    return doc


def convert_solution(engine, doc: dict, display: DisplayUnits) -> dict:
    """`solve --json` in `display` units. Analogues are per unit of the input: per rad for a crank,
    per shown length unit for a prismatic input."""
    for node in doc["points"].values():
        _scale_dict(node, _MOTION, display)
    for name, node in doc["instant_centres"].items():
        if node is not None:
            doc["instant_centres"][name] = [v / display.scale("length") for v in node]
    for name, node in doc["joints"].items():
        _scale_dict(node, _joint_kinds(engine, name), display)
    _inputs(engine, doc["inputs"], display)
    doc["input"] = doc["inputs"][0]
    if "analogues" in doc:
        length = display.scale("length")
        per = length if input_kinds(engine)[0] == "velocity" else 1.0   # d/dφ with φ in the shown unit
        first, second = {"length": length / per}, {"length": length / per ** 2}
        for node in doc["analogues"]["points"].values():
            _scale_dict(node, {"vx": "length", "vy": "length"}, display, first)
            _scale_dict(node, {"ax": "length", "ay": "length"}, display, second)
        for node in doc["analogues"]["links"].values():
            _scale_dict(node, {"omega": "first", "epsilon": "second"}, display,
                        {"first": 1.0 / per, "second": 1.0 / per ** 2})
    doc["units"] = display.document()
    return doc


def convert_forces(engine, doc: dict, display: DisplayUnits) -> dict:
    """`forces --json` in `display` units (forces stay in N)."""
    for node in doc["reactions"].values():
        _scale_dict(node, {"moment": "moment"}, display)
    for name in doc["balancing"]:
        if engine.mech.joints[name].kind == "R":
            _scale_dict(doc["balancing"], {name: "moment"}, display)
    for node in doc["loads"]:
        _scale_dict(node, {"x": "length", "y": "length", "moment": "moment"}, display)
    rate, accel, inertia = input_kinds(engine)
    _scale_dict(doc["input"], {"omega": rate, "epsilon": accel, "input_inertia": inertia}, display)
    doc["units"] = display.document()
    return doc


def convert_dynamics(engine, doc: dict, display: DisplayUnits) -> dict:
    """`dynamics --json` in `display` units (energies in J, speeds in rad/s)."""
    _scale_dict(doc, {"driving_moment": "moment", "inertia_first_group": "inertia",
                      "input_link_inertia": "inertia"}, display)
    fly = doc.get("flywheel") or {}
    _scale_dict(fly, {"inertia": "inertia", "inertia_on_crank_shaft": "inertia"}, display)
    for shape in ("rim", "disc"):
        if shape in fly:
            _scale_dict(fly[shape], {"outer_diameter": "length", "inner_diameter": "length",
                                     "diameter": "length", "width": "length"}, display)
    for node in doc.get("at", []):
        _scale_dict(node, {"J_II": "inertia", "dJ_II": "inertia", "M_red": "moment"}, display)
        _scale_dict(node["M_red_by_load"], dict.fromkeys(node["M_red_by_load"], "moment"), display)
    doc["units"] = display.document()
    return doc


def convert_check(engine, doc: dict, display: DisplayUnits) -> dict:
    """`check --json` in `display` units (its angles are in degrees)."""
    for node in doc["extremes"]:
        if node["kind"] == "slider":
            _scale_dict(node, {"minimum": "length", "maximum": "length"}, display)
            for local in node["local"]:  # (the local extremes too, as the text report shows them)
                _scale_dict(local, {"value": "length"}, display)
    if doc.get("grashof"):
        g = doc["grashof"]
        _scale_dict(g, {"s_plus_l": "length", "p_plus_q": "length"}, display)
        _scale_dict(g["lengths"], dict.fromkeys(g["lengths"], "length"), display)
    doc["units"] = display.document(angle="deg")
    return doc


def convert_simulation(engine, doc: dict, display: DisplayUnits) -> dict:
    """`simulate --json` in `display` units: a prismatic input's or joint's values, rates and
    accelerations as lengths, a revolute input's drive and balancing moment and the reactions' moments
    in the moment unit (angles, forces, energies as they are)."""
    for k, node in enumerate(doc["inputs"].values()):
        rate, accel, _ = input_kinds(engine, k)
        prismatic = rate == "velocity"
        kinds = {"phi": "length" if prismatic else "angle", "omega": rate, "epsilon": accel}
        kinds.update(dict.fromkeys(("drive", "balancing"), "force" if prismatic else "moment"))
        _scale_dict(node, kinds, display)
    for name, node in doc["joints"].items():
        _scale_dict(node, {**_joint_kinds(engine, name), "moment": "moment"}, display)
    doc["units"] = display.document()
    return doc


def convert_balance(engine, doc: dict, display: DisplayUnits) -> dict:
    """`balance --json` in `display` units: counterweight positions and radii as lengths, first moments
    in kg·(length unit), shaking and balancing moments in the moment unit."""
    length = display.scale("length")
    for cw in doc["counterweights"]:
        _scale_dict(cw, {"at": "length", "radius": "length"}, display)
        if cw.get("first_moment") is not None:
            cw["first_moment"] = cw["first_moment"] / length
    for when in ("before", "after"):
        _scale_dict(doc[when], {"shaking_moment_max": "moment"}, display)
        revolute = [n for n in doc[when]["balancing_max"] if engine.mech.joints[n].kind == "R"]
        _scale_dict(doc[when]["balancing_max"], dict.fromkeys(revolute, "moment"), display)
    doc["units"] = {**display.document(), "first_moment": f"kg*{display.name('length')}"}
    return doc
