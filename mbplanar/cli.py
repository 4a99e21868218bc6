"""Command-line interface: `mbplanar COMMAND MODEL ...`.

Exit status: 0 success, 1 a mechanism that cannot move as asked (lock, dead point, cannot assemble),
2 bad input (model file, arguments). Messages go to stderr; no traceback unless --debug.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys

import numpy as np

from .errors import MbplanarError, MotionError
from .forces._loads import has_force_data

__all__ = ["main"]


def _load(args):
    from .engine._solver import Engine
    from .model._table import read_model
    return Engine(read_model(args.model), backend=args.backend, threads=args.threads)


def _positive_int(text) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"a positive integer, not {text!r}")
    return value


def _finite(x):
    x = float(x)
    return x if math.isfinite(x) else None


def _at_values(text) -> list[float]:
    """The finite numbers of a comma-separated --at."""
    try:
        values = [float(v) for v in str(text).split(",")]
    except ValueError:
        values = [math.nan]
    if not all(math.isfinite(v) for v in values):
        raise _ArgError("--at needs finite value(s) separated by commas")
    return values


def _write_csv(path, header, rows):
    """A table as CSV to `path` (standard output when None); non-finite cells are left empty."""
    out = open(path, "w", newline="", encoding="utf-8") if path else sys.stdout
    try:
        writer = csv.writer(out)
        writer.writerow(header)
        for row in rows:
            writer.writerow(["" if not math.isfinite(x) else f"{x:.12g}" for x in row])
    finally:
        if path:
            out.close()


def _input_si(engine, value):
    inp = engine.inputs[0]
    return inp.to_si(value)


# -- info -------------------------------------------------------------------------------------------
def info_document(engine) -> dict:
    mech, topo = engine.mech, engine.topology
    doc = {
        "model": mech.name, "title": mech.title,
        "links": [mech.ground] + mech.moving_links,
        "joints": {j.name: {"type": j.kind, "links": list(j.links), "at": list(j.at),
                            **({"guide_deg": j.guide_deg} if j.kind == "P" else {})}
                   for j in mech.joints.values()},
        "points": {p.name: {"link": p.link, "at": list(p.at)} for p in mech.points.values()},
        "inputs": [{"joint": i.joint, "name": i.name, "unit": i.unit} for i in mech.inputs],
        "dof": topo.dof,
        "loops": len(topo.loops),
        "loop_joints": [list(loop) for loop in topo.loops],
    }
    s = topo.structure
    if s is not None:
        doc["groups"] = [{"class": g.group_class, "order": g.order, "kind": g.kind, "links": list(g.links),
                          "joints": list(g.joints), "external": list(g.external)} for g in s.groups]
        doc["mechanism_class"] = s.mechanism_class
        doc["formula"] = s.formula
    return doc


def cmd_info(args):
    engine = _load(args)
    doc = info_document(engine)
    if args.json:
        print(json.dumps(doc, indent=2))
        return 0
    print(f"{doc['model']}: {doc['title']}")
    print(f"links: {', '.join(doc['links'])} (ground {engine.mech.ground})")
    print(f"DOF = {doc['dof']}, independent loops = {doc['loops']}")
    for name, j in doc["joints"].items():
        extra = f"  guide {j['guide_deg']:.4f}°" if j["type"] == "P" else ""
        print(f"  joint {name:6s} {j['type']}  {j['links'][0]}–{j['links'][1]}  "
              f"at ({j['at'][0]:.6f}, {j['at'][1]:.6f}){extra}")
    for name, p in doc["points"].items():
        print(f"  point {name:6s} on {p['link']}  at ({p['at'][0]:.6f}, {p['at'][1]:.6f})")
    if "groups" in doc:
        for g in doc["groups"]:
            kind = f" {g['kind']}" if g["kind"] else ""
            print(f"  group class {g['class']} order {g['order']}{kind}: links {', '.join(g['links'])}; "
                  f"pairs {', '.join(g['joints'])}")
        print(f"mechanism class {doc['mechanism_class']}: {doc['formula']}")
    return 0


# -- solve ------------------------------------------------------------------------------------------
def _input_documents(engine, motion, row, values=None) -> list[dict]:
    """Each input at `row`: its value in the model's unit (as requested, when given, so that 30° is not
    printed back as 29.999999999999996), in SI, and its speed and acceleration."""
    values = values or [inp.from_si(float(motion.phi[row, k])) for k, inp in enumerate(engine.inputs)]
    return [{"name": inp.name, "joint": inp.joint, "unit": inp.unit, "value": float(values[k]),
             "value_si": float(motion.phi[row, k]), "omega": float(motion.omega[row, k]),
             "epsilon": float(motion.epsilon[row, k])} for k, inp in enumerate(engine.inputs)]


def solve_document(engine, motion, row=0, values=None) -> dict:
    inputs = _input_documents(engine, motion, row, values)
    doc = {"model": engine.mech.name, "input": inputs[0], "inputs": inputs,
           "points": {}, "links": {}, "joints": {}, "instant_centres": {}}
    for k, name in enumerate(motion.point_names):
        (x, y), (vx, vy), (ax, ay) = motion.xy[row, k], motion.v[row, k], motion.a[row, k]
        doc["points"][name] = {"x": x, "y": y, "vx": vx, "vy": vy, "ax": ax, "ay": ay}
    for k, name in enumerate(motion.link_names):
        doc["links"][name] = {"angle": motion.angle[row, k], "omega": motion.w[row, k],
                              "epsilon": motion.e[row, k]}
        ic = motion.ic[row, k]
        doc["instant_centres"][name] = None if not np.all(np.isfinite(ic)) else [ic[0], ic[1]]
    for k, name in enumerate(motion.joint_names):
        doc["joints"][name] = {"type": engine.mech.joints[name].kind, "value": motion.value[row, k],
                               "rate": motion.rate[row, k], "accel": motion.accel[row, k]}
    if motion.vq is not None:
        doc["analogues"] = {
            "points": {n: {"vx": motion.vq[row, k, 0], "vy": motion.vq[row, k, 1],
                           "ax": motion.aq[row, k, 0], "ay": motion.aq[row, k, 1]}
                       for k, n in enumerate(motion.point_names)},
            "links": {n: {"omega": motion.wq[row, k], "epsilon": motion.eq[row, k]}
                      for k, n in enumerate(motion.link_names)},
        }
    return _plain(doc)


def _plain(obj):
    """numpy scalars → float, non-finite → None, for JSON."""
    if isinstance(obj, dict):
        return {k: _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return [_plain(v) for v in obj.tolist()]
    if isinstance(obj, (float, np.floating)):
        return _finite(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    return obj


def _motion(engine, values_si, omega=None, epsilon=None):
    from .kinematics._motion import analyse
    return analyse(engine, values_si, omega, epsilon)


def _speeds(engine, phi, args):
    """ω, ε of the input for solve and sweep: --omega/--epsilon (default 1 and 0: the analogues), or the
    true motion from the machine dynamics with --true-motion (then also the first group's J_I)."""
    if not getattr(args, "true_motion", False):
        return (1.0 if args.omega is None else args.omega), (0.0 if args.epsilon is None else args.epsilon), None
    if args.omega is not None or args.epsilon is not None:
        raise _ArgError("--true-motion computes ω and ε; leave out --omega and --epsilon")
    if len(engine.inputs) != 1 or engine.mech.extras.get("dynamics") is None:
        raise _ArgError(f"{engine.mech.source}: --true-motion needs a model with one input and a [dynamics] section")
    return true_motion(engine, phi)


def cmd_solve(args):
    engine = _load(args)
    values = _at_values(args.at)
    if len(values) != len(engine.inputs):
        raise _ArgError(f"--at needs {len(engine.inputs)} finite value(s) separated by commas")
    phi = np.array([[i.to_si(v) for i, v in zip(engine.inputs, values)]])
    omega, epsilon, _ = _speeds(engine, phi[:, 0], args)
    motion = _motion(engine, phi, omega, epsilon)
    if not motion.success:
        raise MotionError(f"{engine.mech.source}: cannot reach {args.at} on the drawn branch: {motion.message}")
    doc = solve_document(engine, motion, values=values)
    if args.json:
        print(json.dumps(doc, indent=2))
        return 0
    _print_solution(engine, doc)
    return 0


def _print_solution(engine, doc):
    print(f"{doc['model']}: " + "; ".join(f"{i['name']} = {i['value']:g} {i['unit']}  (ω = {i['omega']:g}, "
                                           f"ε = {i['epsilon']:g})" for i in doc["inputs"]))
    size = max([1e-300] + [abs(p[k]) for p in doc["points"].values() for k in ("x", "y")])
    _print_columns(["point", "x [m]", "y [m]", "vx [m/s]", "vy [m/s]", "ax [m/s²]", "ay [m/s²]"],
                   [[name] + [_num(_clean(p[k], 1e-12 * size)) for k in ("x", "y", "vx", "vy", "ax", "ay")]
                    for name, p in doc["points"].items()])
    rows = []
    for name, link in doc["links"].items():
        ic = doc["instant_centres"][name]
        rows.append([name, _num(math.degrees(link["angle"])), _num(link["omega"]), _num(link["epsilon"])]
                    + ([_num(ic[0]), _num(ic[1])] if ic else ["—", "—"]))
    _print_columns(["link", "angle [°]", "ω [rad/s]", "ε [rad/s²]", "IC x", "IC y"], rows)
    rows = []
    for name, j in doc["joints"].items():
        revolute = j["type"] == "R"
        value = _num(math.degrees(j["value"])) + " °" if revolute else _num(j["value"]) + " m"
        rows.append([name, j["type"], value, _num(j["rate"]), _num(j["accel"])])
    _print_columns(["joint", "type", "value", "rate", "accel"], rows)


def _num(v) -> str:
    return f"{v:.6g}"


def _clean(v, tiny):
    """Round-off below `tiny` printed as 0."""
    return 0.0 if abs(v) < tiny else v


def _print_columns(head, rows):
    """A text table: the first column left-aligned, the others right-aligned, two spaces apart."""
    widths = [max(len(str(r[k])) for r in [head] + rows) for k in range(len(head))]
    for r in [head] + rows:
        print("  ".join(str(c).ljust(w) if k == 0 else str(c).rjust(w) for k, (c, w) in enumerate(zip(r, widths))))


# -- sweep ------------------------------------------------------------------------------------------
def sweep_values(engine, steps=None, step=None, start=None, stop=None):
    """Input values (model units) of a sweep: `steps` intervals or a `step`, both ends included."""
    inp = engine.inputs[0]
    lo, hi = inp.default_sweep()
    lo = lo if start is None else start
    hi = hi if stop is None else stop
    if step is not None:
        if not step > 0:
            raise _ArgError("--step must be positive")
        count = int(math.floor(abs(hi - lo) / step + 1e-9))
        return lo + math.copysign(step, hi - lo) * np.arange(count + 1)
    steps = getattr(inp, "steps", None) if steps is None else steps
    steps = 72 if steps is None else steps
    if steps < 1:
        raise _ArgError("--steps must be at least 1")
    return np.linspace(lo, hi, steps + 1)


def sweep_table(engine, motion, angle_unit):
    """Header (quantity[unit]) and rows of a sweep."""
    inp = engine.inputs[0]
    to_angle = (lambda x: np.degrees(x)) if angle_unit == "deg" else (lambda x: x)
    au = "deg" if angle_unit == "deg" else "rad"
    header = [f"{inp.name}[{inp.unit}]"]
    cols = [inp.from_si(motion.phi[:, 0])]
    for k, name in enumerate(motion.link_names[1:], start=1):
        header += [f"{name}.angle[{au}]", f"{name}.omega[rad/s]", f"{name}.epsilon[rad/s^2]"]
        cols += [to_angle(motion.angle[:, k]), motion.w[:, k], motion.e[:, k]]
    for k, name in enumerate(motion.point_names):
        header += [f"{name}.{q}" for q in ("x[m]", "y[m]", "vx[m/s]", "vy[m/s]", "ax[m/s^2]", "ay[m/s^2]")]
        cols += [motion.xy[:, k, 0], motion.xy[:, k, 1], motion.v[:, k, 0], motion.v[:, k, 1],
                 motion.a[:, k, 0], motion.a[:, k, 1]]
    for k, name in enumerate(motion.joint_names):
        if engine.mech.joints[name].kind == "R":
            header += [f"{name}.value[{au}]", f"{name}.rate[rad/s]", f"{name}.accel[rad/s^2]"]
            cols += [to_angle(motion.value[:, k]), motion.rate[:, k], motion.accel[:, k]]
        else:
            header += [f"{name}.value[m]", f"{name}.rate[m/s]", f"{name}.accel[m/s^2]"]
            cols += [motion.value[:, k], motion.rate[:, k], motion.accel[:, k]]
    from .analysis._check import pressure_angles, transmission_angles
    labels, angles = transmission_angles(engine, motion)          # at J between J→P and J→Q: P-J-Q
    header += [f"transmission.{p}-{j}-{q}[{au}]" for p, j, q in labels]
    cols += [to_angle(angles[:, k]) for k in range(len(labels))]
    labels, angles = pressure_angles(engine, motion)              # slider S driven by rod A-B: S.A-B
    header += [f"pressure.{s}.{a}-{b}[{au}]" if a != b else f"pressure.{s}.normal-{a}[{au}]" for a, b, s in labels]
    cols += [to_angle(angles[:, k]) for k in range(len(labels))]
    return header, np.column_stack(cols) if cols else np.zeros((0, 0))


def cmd_sweep(args):
    engine = _load(args)
    if len(engine.inputs) != 1:
        raise _ArgError("sweep drives one input; this model has several (use the Python API)")
    values = sweep_values(engine, args.steps, args.step, args.start, args.stop)
    inp = engine.inputs[0]
    omega, epsilon, inertia = _speeds(engine, inp.to_si(values), args)
    if args.input_inertia is not None:
        inertia = args.input_inertia
    motion = _motion(engine, inp.to_si(values), omega, epsilon)
    angle_unit = args.angles or ("rad" if inp.unit == "rad" else "deg")
    header, rows = sweep_table(engine, motion, angle_unit)
    forces_failed = None
    if args.forces == "yes" or (args.forces == "auto" and has_force_data(engine.mech)):
        f_header, f_rows, forces_failed = forces_table(engine, motion, inertia)
        header, rows = header + f_header, np.column_stack([rows, f_rows]) if len(rows) else rows
    _write_csv(args.output, header, rows)
    if motion.crossings:
        from .kinematics._motion import describe_crossing
        for c in motion.crossings:
            print(f"mbplanar: {engine.mech.source}: note: {describe_crossing(engine, c)}", file=sys.stderr)
    if forces_failed:
        print(f"mbplanar: {engine.mech.source}: {forces_failed} (their force cells are empty)", file=sys.stderr)
        return 1
    if not motion.success:
        print(f"mbplanar: {engine.mech.source}: {motion.message}; wrote the {len(motion.phi)} of "
              f"{motion.requested} positions before it", file=sys.stderr)
        return 1
    return 0


# -- forces -----------------------------------------------------------------------------------------
def forces_table(engine, motion, input_inertia=0.0):
    """Header, columns (B, k) and a failure message (or None) of the reactions and balancing loads."""
    from .forces._kinetostatics import kinetostatics
    result = kinetostatics(engine, motion, input_inertia or 0.0)
    header, cols = [], []
    for name, r in result.reactions.items():
        header += [f"{name}.fx[N]", f"{name}.fy[N]"]
        cols += [r.fx, r.fy]
        if engine.mech.joints[name].kind == "P":
            header.append(f"{name}.moment[N*m]")
            cols.append(r.moment)
    for name, q in result.balancing.items():
        unit = "N*m" if engine.mech.joints[name].kind == "R" else "N"
        header.append(f"{name}.balancing[{unit}]")
        cols.append(q)
    header.append("virtual_power_residual")
    cols.append(result.virtual_power_residual)
    return header, np.column_stack(cols), (None if result.success else result.message)


def forces_document(engine, motion, result, row=0, values=None) -> dict:
    reactions = {}
    for name, r in result.reactions.items():
        fx, fy = float(r.fx[row]), float(r.fy[row])
        reactions[name] = {"type": engine.mech.joints[name].kind, "on": r.on, "from": r.source,
                           "fx": fx, "fy": fy, "moment": float(r.moment[row]),
                           "magnitude": math.hypot(fx, fy), "direction_deg": math.degrees(math.atan2(fy, fx)) % 360}
    doc = {"model": engine.mech.name,
           "input": _input_documents(engine, motion, row, values)[0],
           "reactions": reactions,
           "balancing": {name: float(q[row]) for name, q in result.balancing.items()},
           "virtual_power_residual": float(result.virtual_power_residual[row]),
           "loads": [{"name": ld.name, "link": motion.link_names[ld.link], "fx": ld.force[row, 0],
                      "fy": ld.force[row, 1], "x": ld.point[row, 0], "y": ld.point[row, 1],
                      "moment": ld.moment[row]} for ld in result.loads]}
    return _plain(doc)


def cmd_forces(args):
    from .forces._kinetostatics import kinetostatics
    engine = _load(args)
    if len(engine.inputs) != 1:
        raise _ArgError("forces drives one input; this model has several (use the Python API)")
    value = float(args.at)
    if not math.isfinite(value):
        raise _ArgError("--at must be a finite number")
    if args.input_inertia is not None and not (math.isfinite(args.input_inertia) and args.input_inertia >= 0):
        raise _ArgError("--input-inertia must be a finite number >= 0")
    phi = np.array([_input_si(engine, value)])
    omega, epsilon, inertia, how = args.omega, args.epsilon, args.input_inertia, "given"
    if omega is None and epsilon is None and engine.mech.extras.get("dynamics") is not None:
        omega, epsilon, dyn_inertia = true_motion(engine, phi)
        inertia, how = (dyn_inertia if inertia is None else inertia), "true motion from the machine dynamics"
    motion = _motion(engine, phi, omega, epsilon)
    if not motion.success:
        raise MotionError(f"{engine.mech.source}: cannot reach {args.at} on the drawn branch: {motion.message}")
    inertia = inertia or 0.0
    from .forces._friction import friction_kinetostatics, read_friction
    if args.mu is not None and not (math.isfinite(args.mu) and args.mu >= 0):
        raise _ArgError("--mu must be a finite number >= 0")
    spec = read_friction(engine.mech, args.mu)
    fr = None if spec is None else friction_kinetostatics(engine, motion, spec, inertia)
    result = kinetostatics(engine, motion, inertia) if fr is None else fr.kinetostatics
    if not result.success:
        raise MotionError(f"{engine.mech.source}: {result.message}")
    doc = forces_document(engine, motion, result, values=[value])
    doc["input"]["motion"] = how
    doc["input"]["input_inertia"] = float(inertia)
    if fr is not None:
        doc["friction"] = _plain({"iterations": fr.iterations, "residual": float(fr.residual[0]),
                                  "converged": fr.converged, "losses": float(fr.losses[0]),
                                  "efficiency": float(fr.efficiency[0]),
                                  "balancing_without_friction": {n: float(q[0]) for n, q in
                                                                 fr.ideal.balancing.items()}})
        if not fr.converged:
            raise MotionError(f"{engine.mech.source}: the friction iteration did not converge in "
                              f"{fr.iterations} iterations (residual {fr.residual[0]:.3g}): self-locking?")
    if args.json:
        print(json.dumps(doc, indent=2))
        return 0
    inp = doc["input"]
    print(f"{doc['model']}: {inp['name']} = {inp['value']:g} {inp['unit']}  "
          f"(ω = {inp['omega']:g}, ε = {inp['epsilon']:g}, J_I = {inertia:g}; {how})")
    tiny = 1e-12 * max([1.0] + [r["magnitude"] for r in doc["reactions"].values()])
    rows = []
    for name, r in doc["reactions"].items():
        fx, fy, moment = (_clean(r[k], tiny) for k in ("fx", "fy", "moment"))
        rows.append([name, r["type"], r["on"], r["from"], _num(fx), _num(fy), _num(_clean(r["magnitude"], tiny)),
                     f"{r['direction_deg']:.3f}", _num(moment) if r["type"] == "P" else ""])
    _print_columns(["joint", "type", "on", "from", "Fx [N]", "Fy [N]", "|F| [N]", "dir [°]", "M [N·m]"], rows)
    for name, q in doc["balancing"].items():
        unit = "N·m" if engine.mech.joints[name].kind == "R" else "N"
        q = _clean(q, tiny * (engine.size if unit == "N·m" else 1.0))
        print(f"balancing {'moment' if unit == 'N·m' else 'force'} at {name}: {q:.6g} {unit}")
    print(f"virtual-power residual: {doc['virtual_power_residual']:.3g}")
    if "friction" in doc:
        f = doc["friction"]
        print(f"friction: {f['iterations']} iterations, residual {f['residual']:.3g}; power lost "
              f"{-f['losses']:.6g} W; instantaneous efficiency {f['efficiency']}")
    return 0


def true_motion(engine, phi):
    """ω, ε (B,) of the input at `phi` (SI) from the machine dynamics, and the first group's J_I less the
    input link's own inertia (the constant inertia the force analysis adds on the input link)."""
    from .forces._dynamics import machine_dynamics
    dyn = machine_dynamics(engine, simulate_motion=False)
    state = dyn.state_at(engine, phi)
    return state["omega"], state["epsilon"], dyn.inertia_first_group - dyn.input_link_inertia


# -- dynamics ---------------------------------------------------------------------------------------
def dynamics_document(engine, dyn, at=None) -> dict:
    """The JSON document of `mbplanar dynamics` (values at input values `at`, SI, when given)."""
    inp = engine.inputs[0]
    red, sim = dyn.reduced, dyn.simulation
    doc = {"model": engine.mech.name,
           "input": {"name": inp.name, "joint": inp.joint, "unit": inp.unit},
           "steps": len(dyn.phi) - 1,
           "delta_target": dyn.spec.delta,
           "omega_mean": dyn.omega_mean,
           "driving_moment": dyn.driving_moment,
           "resistance_work": dyn.resistance_work,
           "work_by_kind": dyn.work_by_kind(),
           "inertia_first_group": dyn.inertia_first_group,
           "input_link_inertia": dyn.input_link_inertia,
           "dT_I_max": dyn.dT_I_max, "dT_I_max_at": inp.from_si(dyn.phi_dT_max),
           "dT_I_min": dyn.dT_I_min, "dT_I_min_at": inp.from_si(dyn.phi_dT_min),
           "omega_min": dyn.omega_min, "omega_max": dyn.omega_max,
           "epsilon_min": dyn.epsilon_min, "epsilon_max": dyn.epsilon_max,
           "delta_simulated": dyn.delta_simulated,
           "simulation": None if sim is None else {
               "omega_min": sim.omega_min, "omega_max": sim.omega_max, "omega_time_mean": sim.omega_time_mean,
               "period": sim.period, "success": sim.success, "message": sim.message},
           "flywheel": dyn.flywheel}
    if at is not None:
        state = dyn.state_at(engine, at)
        doc["at"] = [{"value": inp.from_si(float(p)), "J_II": state["J_II"][k], "dJ_II": state["dJ_II"][k],
                      "M_red": state["M_red"][k],
                      "M_red_by_load": {name: m[k] for name, m in state["moments"].items()},
                      "A_c": state["A_c"][k], "dT_I": state["dT_I"][k],
                      "omega": state["omega"][k], "epsilon": state["epsilon"][k]}
                     for k, p in enumerate(state["phi"])]
    return _plain(doc)


def dynamics_table(dyn):
    """Header and columns (N, k) of the cycle table: φ, J_II, dJ_II, M_red per load and in total, A_c,
    A_total, T_II, ΔT_I, ω, ε (energy–mass method) and the simulated ω, ε."""
    red = dyn.reduced
    header = ["phi[rad]", "J_II[kg*m2]", "dJ_II[kg*m2]"] + [f"M_red.{n}[N*m]" for n in red.moments] + \
        ["M_red[N*m]", "A_c[J]", "A_total[J]", "T_II[J]", "dT_I[J]", "omega[rad/s]", "epsilon[rad/s2]"]
    cols = [dyn.phi, dyn.J_II, dyn.dJ_II, *red.moments.values(), dyn.M_red, dyn.A_c, dyn.A_total,
            dyn.T_II, dyn.dT_I, dyn.omega, dyn.epsilon]
    if dyn.simulation is not None:
        header += ["omega_sim[rad/s]", "epsilon_sim[rad/s2]"]
        cols += [dyn.simulation.omega, dyn.simulation.epsilon]
    return header, np.column_stack(cols)


def cmd_dynamics(args):
    from .forces._dynamics import machine_dynamics, read_dynamics
    engine = _load(args)
    if args.steps < 36:
        raise _ArgError("--steps must be at least 36")
    if args.delta is not None and not (math.isfinite(args.delta) and 0 < args.delta < 1):
        raise _ArgError("--delta must be a number between 0 and 1")
    spec = read_dynamics(engine.mech, args.delta)
    if spec is None:
        raise _ArgError(f"{engine.mech.source}: the model has no [dynamics] section; give --delta")
    dyn = machine_dynamics(engine, spec, steps=args.steps)
    at = None if args.at is None else np.array([_input_si(engine, v) for v in _at_values(args.at)])
    doc = dynamics_document(engine, dyn, at)
    if args.output:
        _write_csv(args.output, *dynamics_table(dyn))
    if args.json:
        print(json.dumps(doc, indent=2, ensure_ascii=False))
        return 0
    _print_dynamics(engine, dyn, doc)
    return 0


def _print_dynamics(engine, dyn, doc):
    from .forces._dynamics import summary
    inp = doc["input"]
    print(f"{doc['model']}: machine dynamics over one cycle of {inp['name']} ({doc['steps']} steps)")
    for label, value, unit in summary(dyn, engine.inputs[0]):
        value = f"{value:.6g}" if isinstance(value, float) else str(value)
        print(f"  {label:38s} {value:>24s} {unit}")
    for at in doc.get("at", []):
        print(f"at {inp['name']} = {at['value']:g} {inp['unit']}: J_II = {at['J_II']:.6g} kg·m², "
              f"dJ_II = {at['dJ_II']:.6g} kg·m², M_red = {at['M_red']:.6g} N·m, ΔT_I = {at['dT_I']:.6g} J, "
              f"ω = {at['omega']:.6g} rad/s, ε = {at['epsilon']:.6g} rad/s²")
        for name, m in at["M_red_by_load"].items():
            print(f"    M_red of {name}: {m:.6g} N·m")


# -- motion under given forces ---------------------------------------------------------------------
def simulate_document(engine, tr) -> dict:
    """The simulated motion: per time, the inputs' φ, ω, ε, every link's angle, ω, ε, every joint's
    value, rate, acceleration and reaction (on `on` from `from`), the balancing load at each input (it
    equals the drive), the energies; and the solver's settings and statistics."""
    m, ks, spec = tr.motion, tr.kinetostatics, tr.spec
    doc = {"model": engine.mech.name, "t": tr.t,
           "solver": {"method": spec.method, "rtol": spec.rtol, "atol": spec.atol, "evaluations": tr.nfev,
                      "success": tr.success, "message": tr.message},
           "inputs": {inp.name: {"joint": inp.joint, "phi": tr.phi[:, k], "omega": tr.omega[:, k],
                                 "epsilon": tr.epsilon[:, k], "drive": tr.drive[:, k],
                                 "balancing": ks.balancing[inp.joint]}
                      for k, inp in enumerate(engine.inputs)},
           "links": {name: {"angle": m.angle[:, k], "omega": m.w[:, k], "epsilon": m.e[:, k]}
                     for k, name in enumerate(m.link_names) if name != engine.mech.ground},
           "joints": {}, "energy": tr.energy}
    for k, name in enumerate(m.joint_names):
        r = ks.reactions[name]
        doc["joints"][name] = {"value": m.value[:, k], "rate": m.rate[:, k], "accel": m.accel[:, k],
                               "on": r.on, "from": r.source, "fx": r.fx, "fy": r.fy, "moment": r.moment}
    return _plain(doc)


def simulate_table(doc) -> tuple[list, np.ndarray]:
    """Header and columns (N, k) of the simulated motion for CSV."""
    header, cols = ["t[s]"], [doc["t"]]
    for name, d in doc["inputs"].items():
        header += [f"{name}", f"{name}.omega", f"{name}.epsilon", f"{name}.drive"]
        cols += [d["phi"], d["omega"], d["epsilon"], d["drive"]]
    for name, d in doc["links"].items():
        header += [f"angle.{name}[rad]", f"omega.{name}[rad/s]", f"epsilon.{name}[rad/s2]"]
        cols += [d["angle"], d["omega"], d["epsilon"]]
    for name, d in doc["joints"].items():
        header += [f"{name}.value", f"F{name}.x[N]", f"F{name}.y[N]"]
        cols += [d["value"], d["fx"], d["fy"]]
    header += ["kinetic[J]", "potential[J]", "drive_work[J]"]
    cols += [doc["energy"]["kinetic"], doc["energy"]["potential"], doc["energy"]["drive_work"]]
    return header, np.column_stack([np.asarray(c, float) for c in cols])


def _from_state(path, engine) -> tuple[list, list]:
    """φ and ω of every input at the last time of a previous `simulate --json` output."""
    try:
        with open(path, encoding="utf-8") as fh:
            doc = json.load(fh)
        ins = [doc["inputs"][inp.name] for inp in engine.inputs]
        return [float(d["phi"][-1]) for d in ins], [float(d["omega"][-1]) for d in ins]
    except (KeyError, IndexError, TypeError, json.JSONDecodeError) as exc:
        raise _ArgError(f"{path}: not the JSON output of 'mbplanar simulate' for this model ({exc})") from None


def cmd_simulate(args):
    from .forces._simulation import read_simulate, simulate_motion
    engine = _load(args)
    over = {"t": args.t, "rtol": args.rtol, "atol": args.atol, "method": args.method, "steps": args.steps}
    for key, text in (("torque", args.torque), ("motor_slope", args.motor_slope), ("omega", args.omega),
                      ("input_inertia", args.input_inertia)):
        over[key] = None if text is None else _at_values(text)
    if args.start is not None:
        over["phi"], over["omega"] = _from_state(args.start, engine)
    spec = read_simulate(engine.mech, **over)
    tr = simulate_motion(engine, spec)
    doc = simulate_document(engine, tr)
    if args.output:
        _write_csv(args.output, *simulate_table(doc))
    if args.json:
        print(json.dumps(doc, indent=2, ensure_ascii=False))
        return 0 if tr.success else 1
    last = -1
    print(f"{doc['model']}: motion under the given forces from t = 0 to {tr.t[-1]:g} s "
          f"({spec.method}, rtol {spec.rtol:g}, {tr.nfev} evaluations): {tr.message}")
    for name, d in doc["inputs"].items():
        print(f"  {name}: {d['phi'][last]:.12g}, speed {d['omega'][last]:.12g}, acceleration "
              f"{d['epsilon'][last]:.12g}; drive {d['drive'][last]:.6g}, balancing {d['balancing'][last]:.6g}")
    e = doc["energy"]
    print(f"  energy: kinetic {e['kinetic'][last]:.9g} J, potential {e['potential'][last]:.9g} J, "
          f"work of the drive {e['drive_work'][last]:.9g} J")
    return 0 if tr.success else 1


def balance_document(engine, bal, count: int = 360) -> dict:
    """Counterweights, and before/after at the model's speed over a turn: the RMS and largest shaking
    force, the largest reaction in every pair, the largest balancing moment (or force)."""
    from .forces._shaking import shaking
    from .engine._solver import Engine
    from .forces._kinetostatics import kinetostatics
    from .kinematics._motion import analyse
    doc = {"model": engine.mech.name, "counterweights": [vars(cw) for cw in bal.counterweights],
           "rms_unit_speed": {"before": bal.rms_before, "after": bal.rms_after}}
    phi = engine.phi_drawn[0] + np.linspace(0.0, 2 * math.pi, count, endpoint=False)
    balanced = Engine(bal.mechanism, backend=engine.backend, threads=engine.threads)
    for when, eng in (("before", engine), ("after", balanced)):
        ks = kinetostatics(eng, analyse(eng, phi))
        sh = shaking(eng, ks)
        doc[when] = {"shaking_force_max": float(np.max(sh.magnitude)),
                     "shaking_force_rms": float(np.sqrt(np.mean(sh.magnitude ** 2))),
                     "shaking_moment_max": float(np.max(np.abs(sh.moment))),
                     "reaction_max": {n: float(np.max(r.magnitude)) for n, r in ks.reactions.items()},
                     "balancing_max": {n: float(np.max(np.abs(q))) for n, q in ks.balancing.items()}}
    return _plain(doc)


def cmd_balance(args):
    from .forces._shaking import balance
    engine = _load(args)
    links = [n.strip() for n in args.links.split(",") if n.strip()]
    radius = None if args.radius is None else _at_values(args.radius)
    if radius is not None and not all(r > 0 for r in radius):
        raise _ArgError("--radius must be positive")
    bal = balance(engine, links, radius)
    doc = balance_document(engine, bal)
    if args.json:
        print(json.dumps(doc, indent=2, ensure_ascii=False))
        return 0
    print(f"{doc['model']}: counterweights on {', '.join(links)} (shaking force RMS at 1 rad/s: "
          f"{bal.rms_before:.6g} -> {bal.rms_after:.3g} N)")
    for cw in bal.counterweights:
        print(f"  link {cw.link}: {cw.mass:.6g} kg at ({cw.at[0]:.6g}, {cw.at[1]:.6g}) m, first moment "
              f"{cw.first_moment:.6g} kg·m about {cw.about} at {cw.angle_deg:.4f}° to the link's line")
    for when in ("before", "after"):
        d = doc[when]
        print(f"  {when}: shaking force max {d['shaking_force_max']:.6g} N, RMS {d['shaking_force_rms']:.6g} N, "
              f"shaking moment max {d['shaking_moment_max']:.6g} N·m; balancing max "
              + ", ".join(f"{n} {q:.6g}" for n, q in d["balancing_max"].items()))
        print("    largest reactions: " + ", ".join(f"{n} {f:.6g} N" for n, f in d["reaction_max"].items()))
    return 0


# -- pictures ---------------------------------------------------------------------------------------
def _suffix(path, allowed):
    suffix = str(path).rsplit(".", 1)[-1].lower() if "." in str(path) else ""
    if suffix not in allowed:
        raise _ArgError(f"{path}: the output must end in {' or '.join('.' + a for a in allowed)}")
    return suffix


def cmd_plot(args):
    from .viz import _plotting as plotting
    _suffix(args.output, ("png", "svg", "pdf"))
    if args.what not in plotting.FIGURES:
        raise _ArgError(f"unknown picture '{args.what}'; choose one of: {', '.join(plotting.FIGURES)}")
    if args.show is not None and args.what != "diagram":
        raise _ArgError(f"--show applies to the diagram, not to '{args.what}'")
    if args.points is not None and args.what != "trajectories":
        raise _ArgError(f"--points applies to the trajectories, not to '{args.what}'")
    if args.at is not None and not math.isfinite(args.at):
        raise _ArgError("--at must be a finite number")
    options = plotting.show_options(args.show) if args.what == "diagram" else {}
    if args.points is not None:
        options["points"] = [n.strip() for n in args.points.split(",") if n.strip()]
        if not options["points"]:
            raise _ArgError("--points needs names of pairs or points separated by commas")
    plotting.require_matplotlib()
    engine = _load(args)
    plotting.save_figure(plotting.make_figure(engine, args.what, args.at, **options), args.output, dpi=args.dpi)
    return 0


def cmd_animate(args):
    from .viz import _plotting as plotting
    kind = _suffix(args.output, ("gif", "html"))
    if args.frames < 2:
        raise _ArgError("--frames must be at least 2")
    if kind == "gif":
        plotting.require_matplotlib()
    engine = _load(args)
    if kind == "gif":
        motion = plotting.write_gif(engine, args.output, args.frames, dpi=args.dpi)
    else:
        from .viz._animation import write_html_animation
        write_html_animation(engine, args.output, args.frames)
        motion = plotting.cycle_motion(engine, args.frames)
    if motion.limits:
        from .kinematics._motion import describe_limit
        print(f"mbplanar: {engine.mech.source}: the animation stops at the motion limit: "
              + "; ".join(describe_limit(engine, lim) for lim in motion.limits), file=sys.stderr)
    return 0


def cmd_report(args):
    from .viz import _plotting as plotting
    from .viz._report import write_report
    _suffix(args.output, ("html",))
    plotting.require_matplotlib()
    engine = _load(args)
    write_report(engine, args.output, frames=args.frames)
    return 0


# -- check ------------------------------------------------------------------------------------------
def cmd_check(args):
    from .analysis._check import check, format_report
    engine = _load(args)
    report = check(engine)
    if args.json:
        print(json.dumps(_plain(report.as_dict()), indent=2, ensure_ascii=False))
    else:
        print(format_report(report))
    return 0


# -- main -------------------------------------------------------------------------------------------
def _located(exc, args) -> str:
    """One-line message that names the model file (some engine messages do not)."""
    msg = " ".join(str(exc).split())
    model = getattr(args, "model", None)
    return msg if model is None or str(model) in msg else f"{model}: {msg}"


class _ArgError(MbplanarError):
    exit_code = 2


def _speed_options(s):
    """--omega, --epsilon or --true-motion of solve and sweep (see `_speeds`)."""
    s.add_argument("--omega", type=float, help="input speed dφ/dt in rad/s or m/s (default 1: the analogues)")
    s.add_argument("--epsilon", type=float, help="input acceleration (default 0)")
    s.add_argument("--true-motion", action="store_true",
                   help="ω(φ), ε(φ) from the machine dynamics (models with [dynamics]); in a sweep also J_I "
                        "on the input link in the force columns")


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="mbplanar", description="Planar linkage analysis from a table of pairs.")
    p.add_argument("--debug", action="store_true", help="show tracebacks")
    p.add_argument("--backend", choices=("numpy", "numba"), default="numpy",
                   help="numba: compiled kinematics and forces for long sweeps (pip install 'mbplanar[fast]'; "
                        "importing it and loading the compiled code take ~1 s, the very first run compiles for "
                        "~30 s)")
    p.add_argument("--threads", type=_positive_int, default=None, metavar="N",
                   help="cores the numba backend splits a long sweep over (default: all available, or "
                        "MBPLANAR_THREADS)")
    sub = p.add_subparsers(dest="command", required=True)

    s = sub.add_parser("info", help="links, joints, DOF, loops, Assur groups")
    s.add_argument("model")
    s.add_argument("--json", action="store_true")
    s.set_defaults(func=cmd_info)

    s = sub.add_parser("solve", help="one position: positions, velocities, accelerations")
    s.add_argument("model")
    s.add_argument("--at", required=True, help="generalized coordinate in the model's unit")
    _speed_options(s)
    s.add_argument("--json", action="store_true")
    s.set_defaults(func=cmd_solve)

    s = sub.add_parser("sweep", help="the whole cycle as a CSV table")
    s.add_argument("model")
    g = s.add_mutually_exclusive_group()
    g.add_argument("--steps", type=int, help="number of equal intervals (both ends included)")
    g.add_argument("--step", type=float, help="spacing in the model's unit")
    s.add_argument("--from", dest="start", type=float, help="first value (default: the model's sweep)")
    s.add_argument("--to", dest="stop", type=float, help="last value")
    _speed_options(s)
    s.add_argument("--angles", choices=("deg", "rad"), help="unit of angles in the table")
    s.add_argument("-o", "--output", help="CSV file (default: standard output)")
    s.add_argument("--forces", choices=("auto", "yes", "no"), default="auto",
                   help="reaction and balancing columns: auto = when the model has loads or masses")
    s.add_argument("--input-inertia", type=float, help="J_I on the input link for the force columns")
    s.set_defaults(func=cmd_sweep)

    s = sub.add_parser("forces", help="one position: every joint reaction and the balancing moment")
    s.add_argument("model")
    s.add_argument("--at", required=True, help="generalized coordinate in the model's unit")
    s.add_argument("--omega", type=float, help="input speed dφ/dt (default: the model's omega)")
    s.add_argument("--epsilon", type=float, help="input acceleration (default: the model's, else 0)")
    s.add_argument("--input-inertia", type=float, help="reduced inertia J_I on the input link (kg·m²)")
    s.add_argument("--mu", type=float, help="friction coefficient of every pair (overrides [friction] mu)")
    s.add_argument("--json", action="store_true")
    s.set_defaults(func=cmd_forces)

    s = sub.add_parser("dynamics", help="reduced inertia and moments, flywheel, true ω(φ) and ε(φ)")
    s.add_argument("model")
    s.add_argument("--at", help="also the values at these input values (model's unit, comma-separated)")
    s.add_argument("--steps", type=int, default=3600, help="intervals over the cycle (default 3600)")
    s.add_argument("--delta", type=float, help="coefficient of speed fluctuation (default: the model's)")
    s.add_argument("-o", "--output", help="CSV file of the cycle table")
    s.add_argument("--json", action="store_true")
    s.set_defaults(func=cmd_dynamics)

    s = sub.add_parser("simulate", help="motion under given forces: integrate the equations of motion in time")
    s.add_argument("model")
    s.add_argument("--t", type=float, help="end time in s (default: the model's [simulate] t)")
    s.add_argument("--torque", help="drive on each input along its coordinate, N·m or N (comma list; default: the model's, else 0)")
    s.add_argument("--motor-slope", help="motor characteristic: drive = torque − slope·speed (N·m·s/rad)")
    s.add_argument("--omega", help="start speed of each input (default 0)")
    s.add_argument("--input-inertia", help="kg·m² (kg) on each input link besides the links' own (default 0)")
    s.add_argument("--from", dest="start", help="start from the last state of a previous --json output")
    s.add_argument("--rtol", type=float, help="relative tolerance of solve_ivp (default 1e-10)")
    s.add_argument("--atol", type=float, help="absolute tolerance (default 1e-12)")
    s.add_argument("--method", help="solve_ivp method (default DOP853)")
    s.add_argument("--steps", type=int, help="output intervals (default 100)")
    s.add_argument("-o", "--output", help="CSV file of the motion")
    s.add_argument("--json", action="store_true")
    s.set_defaults(func=cmd_simulate)

    s = sub.add_parser("balance", help="counterweights that cancel the shaking force (or minimise its RMS)")
    s.add_argument("model")
    s.add_argument("--links", required=True, help="comma list of the links that get a counterweight")
    s.add_argument("--radius", help="counterweight radius on links turning about a frame pivot, m (one or per link)")
    s.add_argument("--json", action="store_true")
    s.set_defaults(func=cmd_balance)

    s = sub.add_parser("plot", help="a picture: diagram, vectors, trajectories, kinematics, analogues, "
                                    "transmission, forces, ...")
    s.add_argument("model")
    s.add_argument("what", help="diagram, vectors, trajectories, kinematics, analogues, transmission, forces, ...")
    s.add_argument("--at", type=float, help="generalized coordinate in the model's unit (default: drawn pose)")
    s.add_argument("--show", help="on the diagram: a comma list of velocities, accelerations, reactions, "
                                  "centres (or all)")
    s.add_argument("--points", help="trajectories of these pairs or points only (comma list, e.g. B,S3)")
    s.add_argument("--dpi", type=int, default=120)
    s.add_argument("-o", "--output", required=True, help="FILE.png, .svg or .pdf")
    s.set_defaults(func=cmd_plot)

    s = sub.add_parser("animate", help="animation of a cycle: GIF or a browser page (SVG)")
    s.add_argument("model")
    s.add_argument("--frames", type=int, default=36)
    s.add_argument("--dpi", type=int, default=80)
    s.add_argument("-o", "--output", required=True, help="FILE.gif or FILE.html")
    s.set_defaults(func=cmd_animate)

    s = sub.add_parser("report", help="one self-contained HTML report of the model")
    s.add_argument("model")
    s.add_argument("--frames", type=int, default=36, help="frames of the animation in the report")
    s.add_argument("-o", "--output", required=True, help="FILE.html")
    s.set_defaults(func=cmd_report)

    s = sub.add_parser("check", help="full turn?, dead points, extreme positions, transmission angles")
    s.add_argument("model")
    s.add_argument("--json", action="store_true")
    s.set_defaults(func=cmd_check)
    return p


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except MbplanarError as exc:
        if args.debug:
            raise
        print(f"mbplanar: {_located(exc, args)}", file=sys.stderr)
        return exc.exit_code
    except (OSError, ValueError) as exc:
        if args.debug:
            raise
        print(f"mbplanar: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
