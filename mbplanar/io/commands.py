"""The core commands' work: `mbplanar info`, `solve`, `forces`, `dynamics`, `simulate`, `balance` and `check`.

Each takes the model's engine (loaded by the command line, `mbplanar.cli`) and the parsed arguments, builds
the command's document (`mbplanar.io`), prints it as JSON or as text and returns the exit status: 0, or 1
where the mechanism cannot do what was asked (a simulation that stops). Errors are raised
(`mbplanar.errors`); the command line turns them into one line and an exit status. The JSON keys are a
contract (docs/cli.md). `mbplanar sweep` is in `mbplanar.io.sweep`, the pictures in `mbplanar.viz.command`.
"""

from __future__ import annotations

import math

import numpy as np

from .._progress import Interrupted
from ..errors import ModelError, MotionError
from ._export import dynamics_document, forces_document, info_document, partials_document, plain, solve_document
from ._export import write_csv
from ._tables import dynamics_table
from ._text import clean, dumps, num, print_columns, text_unit
from ._units import (convert_check, convert_dynamics, convert_forces, convert_info, convert_solution, convert_table,
                     display_units, input_kinds)
from .inputs import at_si, inputs_at, motion_of, numbers_of, one_position, speeds, unreachable

__all__ = ["info", "solve", "forces", "dynamics", "simulate", "balance", "check", "NO_FORCE_DATA"]


#: the numpydoc docstring of a command's work, written once (`_documented`): the summary is the function's
#: own, the example runs it on a bundled model and shows what it printed
_DOC = """{summary}

    Parameters
    ----------
    engine : Engine
        The engine of the command's model.
    args : argparse.Namespace
        The parsed arguments of ``mbplanar {name}`` (`mbplanar.cli.build_parser`).

    Returns
    -------
    int
        The exit status: {status}

    Raises
    ------
{raises}

    Examples
    --------
    >>> import contextlib, io, json, mbplanar
    >>> from mbplanar.cli import build_parser
    >>> from mbplanar.io.commands import {name}
    >>> args = build_parser("{name}").parse_args({argv!r})
    >>> with contextlib.redirect_stdout(io.StringIO()) as out:
    ...     code = {name}(mbplanar.Engine(mbplanar.read_model(args.model)), args)
    >>> code
    0
    >>> {shown}
    {result}
    """


def _documented(raises, argv, shown, result, status="0 (the document is printed)."):
    """The command's docstring from `_DOC`: the errors it raises ((name, why) pairs) and its example (the
    command's arguments `argv`, an expression `shown` of what it printed and its value `result`)."""
    def document(work):
        work.__doc__ = _DOC.format(summary=work.__doc__, name=work.__name__, status=status,
                                   argv=[work.__name__, *argv],
                                   raises="\n".join(f"    {error}\n        {why}" for error, why in raises),
                                   shown=shown, result=result)
        return work
    return document


@_documented([("ModelError", "An unknown ``--units``.")], ["models/fourbar.toml"],
             "out.getvalue().splitlines()[2]", "'DOF = 1, independent loops = 1'")
def info(engine, args) -> int:
    """`mbplanar info`: links, joints, DOF, loops and Assur groups, printed as JSON (``--json``) or text."""
    display = display_units(engine.mech, args.units)
    doc = convert_info(engine, info_document(engine), display)
    if args.json:
        print(dumps(doc, indent=2))
        return 0
    length = display.name("length")
    print(f"{doc['model']}: {doc['title']}")
    print(f"links: {', '.join(doc['links'])} (ground {engine.mech.ground})")
    print(f"DOF = {doc['dof']}, independent loops = {doc['loops']}")
    count = doc["count"]
    if count["p4"]:
        print(f"  W = 3·n − 2·p5 − p4 = 3·{count['n']} − 2·{count['p5']} − {count['p4']} = {count['chebyshev']} "
              f"(Chebyshev); the engine: {count['joint_variables']} joint variables + {count['contact_parameters']} "
              f"contact parameter(s) − {count['closure_equations']} closure equations = {count['engine']}")
    for name, j in doc["joints"].items():
        extra = f"  guide {j['guide_deg']:.4f}°" if j["type"] == "P" else ""
        print(f"  joint {name:6s} {j['type']}  {j['links'][0]}–{j['links'][1]}  "
              f"at ({j['at'][0]:.6f}, {j['at'][1]:.6f}) {length}{extra}")
    for name, h in doc.get("higher_pairs", {}).items():
        print(f"  higher pair {name:6s} {h['type']}  {h['links'][0]}–{h['links'][1]}  {_higher_words(h, length)}")
        pairs = "; ".join(f"{e['type']} on {e['link']} at ({e['at'][0]:.6f}, {e['at'][1]:.6f})"
                          + (f" along {e['guide_deg']:.4f}°" if e["type"] == "P" else "") for e in h["equivalent"])
        print(f"      replaced by a link with {pairs}")
    for name, p in doc["points"].items():
        print(f"  point {name:6s} on {p['link']}  at ({p['at'][0]:.6f}, {p['at'][1]:.6f}) {length}")
    if "groups" in doc:
        if doc.get("replaced"):
            print("Assur groups of the equivalent lower-pair mechanism (" + ", ".join(
                f"{link} replaces {pair}" for link, pair in doc["replaced"].items()) + "):")
        for g in doc["groups"]:
            kind = f" {g['kind']}" if g["kind"] else ""
            print(f"  group class {g['class']} order {g['order']}{kind}: links {', '.join(g['links'])}; "
                  f"pairs {', '.join(g['joints'])}")
        print(f"mechanism class {doc['mechanism_class']}: {doc['formula']}")
    return 0


def _higher_words(h: dict, length: str) -> str:
    """A higher pair's data in a line of `info`."""
    at = f"({h['contact'][0]:.6f}, {h['contact'][1]:.6f}) {length}"
    if h["type"] == "gear":
        return (f"{h['mesh']}, pitch radii {h['radii'][0]:.6g}, {h['radii'][1]:.6g} {length}, carrier "
                f"{h['carrier']}, ratio ω_a/ω_b relative to it {h['ratio']:.6g}; pitch point {at}, "
                f"pressure angle {h['pressure_angle_deg']:g}°")
    if h["type"] == "rack":
        return f"pinion radius {h['radius']:.6g} {length}; pitch point {at}, pressure angle {h['pressure_angle_deg']:g}°"
    if h["type"] == "cam":
        size = f" radius {h['radius']:.6g} {length}" if "radius" in h else ""
        return f"{h['follower']} follower{size} on a {h['curve']} profile; contact at {at}"
    return f"pin in a {h['curve']} slot; at {at}"


@_documented([("ModelError", "``--at`` without one finite value per input, contradicting speed options, "
                            "rates out of the floating-point range."),
              ("MotionError", "A position the drawn branch cannot reach (with the range the input moves through).")],
             ["models/fourbar.toml", "--at", "30", "--json"],
             'round(json.loads(out.getvalue())["points"]["A"]["x"], 12)  # 0.1 m · cos 30°', "0.086602540378")
def solve(engine, args) -> int:
    """`mbplanar solve`: one position (``--at``) with its velocities and accelerations, printed as JSON
    (``--json``, with the partial derivatives) or as text tables."""
    values = inputs_at(engine, args.at)
    phi = at_si(engine, values)
    omega, epsilon, _ = speeds(engine, phi[:, 0], args)
    result = one_position(engine, phi, omega, epsilon, args.at)
    display = display_units(engine.mech, args.units)
    doc = convert_solution(engine, solve_document(engine, result, values=values), display)
    if args.json:  # (with one input, "first" and "second" repeat the analogues, by name)
        doc["partials"] = partials_document(engine, phi, result)
    if args.json:
        print(dumps(doc, indent=2))
        return 0
    _print_solution(engine, doc, display)
    return 0


def _print_solution(engine, doc, display):
    u = {k: text_unit(display.name(k)) for k in ("length", "velocity", "acceleration")}
    kinds = [[text_unit(display.name(kind)) for kind in input_kinds(engine, k)] for k in range(len(doc["inputs"]))]
    print(f"{doc['model']}: " + "; ".join(f"{i['name']} = {i['value']:g} {i['unit']}  (ω = {i['omega']:g} {rate}, "
                                           f"ε = {i['epsilon']:g} {accel})"
                                           for i, (rate, accel, _) in zip(doc["inputs"], kinds)))
    size = max([1e-300] + [abs(p[k]) for p in doc["points"].values() for k in ("x", "y")])
    print_columns(["point", f"x [{u['length']}]", f"y [{u['length']}]", f"vx [{u['velocity']}]",
                    f"vy [{u['velocity']}]", f"ax [{u['acceleration']}]", f"ay [{u['acceleration']}]"],
                   [[name] + [num(clean(p[k], 1e-12 * size)) for k in ("x", "y", "vx", "vy", "ax", "ay")]
                    for name, p in doc["points"].items()])
    rows = []
    for name, link in doc["links"].items():
        ic = doc["instant_centres"][name]
        rows.append([name, num(math.degrees(link["angle"])), num(link["omega"]), num(link["epsilon"])]
                    + ([num(ic[0]), num(ic[1])] if ic else ["—", "—"]))
    print_columns(["link", "angle [°]", "ω [rad/s]", "ε [rad/s²]", f"IC x [{u['length']}]",
                    f"IC y [{u['length']}]"], rows)
    rows = []
    for name, j in doc["joints"].items():
        if j["type"] == "R":
            cells = [num(math.degrees(j["value"])) + " °", num(j["rate"]) + " rad/s", num(j["accel"]) + " rad/s²"]
        else:
            cells = [num(j["value"]) + f" {u['length']}", num(j["rate"]) + f" {u['velocity']}",
                     num(j["accel"]) + f" {u['acceleration']}"]
        rows.append([name, j["type"], *cells])
    print_columns(["joint", "type", "value", "rate", "accel"], rows)


NO_FORCE_DATA = ("the model has no loads, gravity or masses, so every reaction and the balancing moment would "
                 "be zero; add [[loads]], [gravity] or link masses")


@_documented([("ModelError", "A model without loads, gravity or masses, a bad ``--at`` or ``--mu``, friction out "
                            "of scale."),
              ("MotionError", "A position the drawn branch cannot reach, or a kinetostatic system (or friction) "
                              "without a solution there.")],
             ["models/fourbar_loaded.toml", "--at", "30", "--json"],
             'round(json.loads(out.getvalue())["reactions"]["O"]["magnitude"], 4)', "71.0255")
def forces(engine, args) -> int:
    """`mbplanar forces`: one position's reactions and balancing loads, with friction where the model or
    ``--mu`` asks for it; at the true motion where the model has ``[dynamics]`` and no speed is given."""
    from ..forces import has_force_data, kinetostatics, true_motion
    values = inputs_at(engine, args.at)
    if not has_force_data(engine.mech):
        raise ModelError(NO_FORCE_DATA, source=engine.mech.source)
    phi = at_si(engine, values)
    phi = phi[:, 0] if len(engine.inputs) == 1 else phi
    omega, epsilon, inertia, how = args.omega, args.epsilon, args.input_inertia, "given"
    if omega is None and epsilon is None and engine.mech.dynamics is not None \
            and len(engine.inputs) == 1:
        omega, epsilon, dyn_inertia = true_motion(engine, phi)
        inertia, how = (dyn_inertia if inertia is None else inertia), "true motion from the machine dynamics"
    motion = motion_of(engine, phi, omega, epsilon)
    if not motion.success:
        raise unreachable(engine, args.at, motion)
    inertia = inertia or 0.0
    from ..forces import friction_kinetostatics, read_friction
    if args.mu is not None and not (math.isfinite(args.mu) and args.mu >= 0):
        raise ModelError("--mu must be a finite number >= 0")
    spec = read_friction(engine.mech, args.mu)
    fr = None if spec is None else friction_kinetostatics(engine, motion, spec, inertia)
    result = kinetostatics(engine, motion, inertia) if fr is None else fr.kinetostatics
    if not result.success:
        raise MotionError(f"{result.message}", source=engine.mech.source)
    doc = forces_document(engine, motion, result, values=values)
    doc["input"]["motion"] = how
    doc["input"]["input_inertia"] = float(inertia)
    if fr is not None:
        doc["friction"] = plain({"iterations": fr.iterations, "residual": float(fr.residual[0]),
                                  "converged": fr.converged, "losses": float(fr.losses[0]),
                                  "efficiency": float(fr.efficiency[0]),
                                  "balancing_without_friction": {n: float(q[0]) for n, q in
                                                                 fr.ideal.balancing.items()}})
        if not fr.converged:  # bad input (2) when the friction is out of scale, else a mechanism that locks (1)
            from ..forces import implausible_friction, not_converged
            at = "at " + ", ".join(f"{i.name} = {v:g} {i.unit}" for i, v in zip(engine.inputs, values))
            error = ModelError if implausible_friction(engine.mech, spec) else MotionError
            raise error(not_converged(engine, spec, fr, at), source=engine.mech.source)
    display = display_units(engine.mech, args.units)
    doc = convert_forces(engine, doc, display)
    if args.json:
        print(dumps(doc, indent=2))
        return 0
    rate, accel, inertia_kind = (text_unit(display.name(k)) for k in input_kinds(engine))
    moment_unit = text_unit(display.name("moment"))
    print(f"{doc['model']}: " + "); ".join(f"{i['name']} = {i['value']:g} {i['unit']}  (ω = {i['omega']:g} {rate}, "
                                            f"ε = {i['epsilon']:g} {accel}" for i in doc["inputs"])
          + f", J_I = {doc['input']['input_inertia']:g} {inertia_kind}; {how})")
    tiny = 1e-12 * max([0.0] + [r["magnitude"] for r in doc["reactions"].values()])  # (relative: any scale)
    rows = []
    for name, r in doc["reactions"].items():
        fx, fy, moment = (clean(r[k], tiny) for k in ("fx", "fy", "moment"))
        rows.append([name, r["type"], r["on"], r["from"], num(fx), num(fy), num(clean(r["magnitude"], tiny)),
                     f"{r['direction_deg']:.3f}", num(moment) if r["type"] == "P" else ""])
    print_columns(["joint", "type", "on", "from", "Fx [N]", "Fy [N]", "|F| [N]", "dir [°]", f"M [{moment_unit}]"],
                   rows)
    for name, q in doc["balancing"].items():
        revolute = engine.mech.joints[name].kind == "R"
        unit = moment_unit if revolute else "N"
        q = clean(q, tiny * (engine.size / display.scale("moment") if revolute else 1.0))
        print(f"balancing {'moment' if revolute else 'force'} at {name}: {q:.6g} {unit}")
    print(f"virtual-power residual: {doc['virtual_power_residual']:.3g}")
    if "friction" in doc:
        f = doc["friction"]
        print(f"friction: {f['iterations']} iterations, residual {f['residual']:.3g}; power lost "
              f"{-f['losses']:.6g} W; instantaneous efficiency {f['efficiency']}")
    return 0


@_documented([("ModelError", "A model of several inputs or driven by a slider, without ``[dynamics]`` and "
                            "``--delta``, or a ``--steps`` or ``--delta`` out of range.")],
             ["models/shaper.toml", "--steps", "36"],
             "out.getvalue().splitlines()[0]", "'shaper: machine dynamics over one cycle of f (36 steps)'")
def dynamics(engine, args) -> int:
    """`mbplanar dynamics`: the reduced model, the flywheel and the true motion over a cycle, printed as
    JSON or text, the cycle's table written to ``-o``."""
    from ..forces import machine_dynamics, read_dynamics
    if args.steps < 36:
        raise ModelError("--steps must be at least 36")
    if args.delta is not None and not (math.isfinite(args.delta) and 0 < args.delta < 1):
        raise ModelError("--delta must be a number between 0 and 1")
    from ..model import crank_input
    crank_input(engine.mech)  # (a machine of several inputs, or driven by a slider, says so first)
    spec = read_dynamics(engine.mech, args.delta)
    if spec is None:
        raise ModelError("the model has no [dynamics] section; give --delta", source=engine.mech.source)
    dyn = machine_dynamics(engine, spec, steps=args.steps)
    at = None if args.at is None else np.array([engine.inputs[0].to_si(v) for v in numbers_of(args.at, "--at")])
    display = display_units(engine.mech, args.units)
    doc = convert_dynamics(engine, dynamics_document(engine, dyn, at), display)
    if args.output:
        write_csv(args.output, *convert_table(*dynamics_table(dyn), display))
    if args.json:
        print(dumps(doc, indent=2, ensure_ascii=False))
        return 0
    _print_dynamics(engine, dyn, doc, display)
    return 0


def _print_dynamics(engine, dyn, doc, display):
    from ..forces import summary
    inp = doc["input"]
    inertia, moment = text_unit(display.name("inertia")), text_unit(display.name("moment"))
    shown = {"N·m": ("moment", moment), "kg·m²": ("inertia", inertia)}
    print(f"{doc['model']}: machine dynamics over one cycle of {inp['name']} ({doc['steps']} steps)")
    for label, value, unit in summary(dyn, engine.inputs[0]):
        head = unit.split(" ", 1)[0]
        if isinstance(value, float) and head in shown:
            kind, name = shown[head]
            value, unit = display.show(value, kind), name + unit[len(head):]
        value = f"{value:.6g}" if isinstance(value, float) else str(value)
        print(f"  {label:38s} {value:>24s} {unit}")
    for at in doc.get("at", []):
        print(f"at {inp['name']} = {at['value']:g} {inp['unit']}: J_II = {at['J_II']:.6g} {inertia}, "
              f"dJ_II = {at['dJ_II']:.6g} {inertia}, M_red = {at['M_red']:.6g} {moment}, "
              f"ΔT_I = {at['dT_I']:.6g} J, ω = {at['omega']:.6g} rad/s, ε = {at['epsilon']:.6g} rad/s²")
        for name, m in at["M_red_by_load"].items():
            print(f"    M_red of {name}: {m:.6g} {moment}")


def _from_state(path, engine) -> tuple[list, list]:
    """φ and ω of every input at the last time of a previous `simulate --json` output."""
    import json
    try:
        with open(path, encoding="utf-8-sig") as fh:
            doc = json.load(fh)
        ins = [doc["inputs"][inp.name] for inp in engine.inputs]
        return [float(d["phi"][-1]) for d in ins], [float(d["omega"][-1]) for d in ins]
    except (KeyError, IndexError, TypeError, json.JSONDecodeError) as exc:
        raise ModelError(f"{path}: not the JSON output of 'mbplanar simulate' for this model ({exc})") from None


@_documented([("ModelError", "Options that are not finite numbers, one per input, or a ``--from`` file that is "
                            "not a simulation of this model."),
              ("Interrupted", "Ctrl-C, or a run refused as too long.")],
             ["models/squeezer.toml", "--t", "0.001", "--steps", "2"],
             "out.getvalue().splitlines()[2]",
             "'  energy: kinetic 0.000252660316 J, potential 1.43578281 J, work of the drive 0.000239071109 J'",
             status="0, or 1 where the integration stops before the end time.")
def simulate(engine, args) -> int:
    """`mbplanar simulate`: the motion under given forces, integrated in time, printed as JSON or as the
    last state, the motion written to ``-o`` (also the part done when interrupted)."""
    from .._progress import Progress
    from ..forces import read_simulate, simulate_motion
    from ._documents import simulate_document, simulate_table
    from ._units import convert_simulation
    over = {"t": args.t, "rtol": args.rtol, "atol": args.atol, "method": args.method, "steps": args.steps}
    for key, text in (("torque", args.torque), ("motor_slope", args.motor_slope), ("omega", args.omega),
                      ("input_inertia", args.input_inertia)):
        over[key] = None if text is None else numbers_of(text, "--" + key.replace("_", "-"))
    if args.start is not None:
        over["phi"], over["omega"] = _from_state(args.start, engine)
    spec = read_simulate(engine.mech, **over)
    display = display_units(engine.mech, args.units)
    total = spec.t or 1.0
    with Progress(total, "s of motion", show=args.progress, what=f"simulating {total:g} s of motion",
                  yes=args.yes, source=engine.mech.source) as bar:
        try:
            tr = simulate_motion(engine, spec, progress=bar.update)
        except Interrupted as exc:
            if exc.partial is not None and args.output:
                write_csv(args.output, *convert_table(*simulate_table(simulate_document(engine, exc.partial), engine),
                                                      display))
                exc.message += f"; wrote the motion up to t = {exc.partial.t[-1]:.6g} s to {args.output}"
            raise
    doc = simulate_document(engine, tr)
    if args.output:
        write_csv(args.output, *convert_table(*simulate_table(doc, engine), display))
    doc = convert_simulation(engine, doc, display)
    if args.json:
        print(dumps(doc, indent=2, ensure_ascii=False))
        return 0 if tr.success else 1
    last = -1
    machine = spec.torque is None and engine.mech.dynamics is not None
    spec = tr.spec
    forces = "the drive of [dynamics] (M_dr − slope·(ω − ω_m))" if machine else "the given forces"
    print(f"{doc['model']}: motion under {forces} from t = 0 to {tr.t[-1]:g} s "
          f"({spec.method}, rtol {spec.rtol:g}, {tr.nfev} evaluations): {tr.message}")
    for k, (name, d) in enumerate(doc["inputs"].items()):
        rate, accel, _ = input_kinds(engine, k)
        kinds = (("length", rate, accel, "force") if rate == "velocity" else ("angle", rate, accel, "moment"))
        unit = [text_unit(display.name(kind)) for kind in kinds]
        print(f"  {name}: {d['phi'][last]:.12g} {unit[0]}, speed {d['omega'][last]:.12g} {unit[1]}, acceleration "
              f"{d['epsilon'][last]:.12g} {unit[2]}; drive {d['drive'][last]:.6g} {unit[3]}, balancing "
              f"{d['balancing'][last]:.6g} {unit[3]}")
    e = doc["energy"]
    print(f"  energy: kinetic {e['kinetic'][last]:.9g} J, potential {e['potential'][last]:.9g} J, "
          f"work of the drive {e['drive_work'][last]:.9g} J")
    return 0 if tr.success else 1


@_documented([("ModelError", "Unknown links, a ``--radius`` that is not positive, a model of several inputs.")],
             ["models/fourbar_loaded.toml", "--links", "1,3"], "out.getvalue().splitlines()[1][:39]",
             "'  link 1: 1 kg at (-0.05, -0.0866025) m'")
def balance(engine, args) -> int:
    """`mbplanar balance`: counterweights on ``--links`` and the shaking force, moment, reactions and
    balancing loads before and after, printed as JSON or text."""
    from ..forces import balance as counterweights
    from ..model import drawing_size, warn_scale
    from ._documents import balance_document
    from ._units import convert_balance
    display = display_units(engine.mech, args.units)
    length = display.scale("length")
    links = [n.strip() for n in args.links.split(",") if n.strip()]
    radius = None if args.radius is None else [r * length for r in numbers_of(args.radius, "--radius")]
    if radius is not None and not all(r > 0 for r in radius):
        raise ModelError("--radius must be positive")
    for r in radius or ():
        warn_scale("--radius", r, drawing_size(engine.mech), display.name("length"), length,
                   source=engine.mech.source)
    bal = counterweights(engine, links, radius)
    doc = convert_balance(engine, balance_document(engine, bal), display)
    if args.json:
        print(dumps(doc, indent=2, ensure_ascii=False))
        return 0
    u = doc["units"]
    lu, mu, fu = u["length"], text_unit(u["moment"]), text_unit(u["first_moment"])
    print(f"{doc['model']}: counterweights on {', '.join(links)} (shaking force RMS at 1 rad/s: "
          f"{bal.rms_before:.6g} -> {bal.rms_after:.3g} N)")
    for cw in doc["counterweights"]:
        print(f"  link {cw['link']}: {cw['mass']:.6g} kg at ({cw['at'][0]:.6g}, {cw['at'][1]:.6g}) {lu}, first moment "
              f"{cw['first_moment']:.6g} {fu} about {cw['about']} at {cw['angle_deg']:.4f}° to the link's line")
    for when in ("before", "after"):
        d = doc[when]
        print(f"  {when}: shaking force max {d['shaking_force_max']:.6g} N, RMS {d['shaking_force_rms']:.6g} N, "
              f"shaking moment max {d['shaking_moment_max']:.6g} {mu}; balancing max "
              + ", ".join(f"{n} {q:.6g}" for n, q in d["balancing_max"].items()))
        print("    largest reactions: " + ", ".join(f"{n} {f:.6g} N" for n, f in d["reaction_max"].items()))
    return 0


@_documented([("ModelError", "An unknown ``--units``.")], ["models/fourbar.toml"], "out.getvalue().splitlines()[2]",
             "'the input turns fully (numerically: a whole turn without a motion limit)'")
def check(engine, args) -> int:
    """`mbplanar check`: full turn, dead points, extreme positions, transmission angles (for two inputs,
    the region they reach), printed as JSON or text."""
    from ..analysis import check as check_motion, check_region, format_region, format_report
    if len(engine.inputs) == 2:
        region = check_region(engine)
        if args.json:
            print(dumps(plain(region.as_dict()), indent=2, ensure_ascii=False))
        else:
            print(format_region(region))
        return 0
    report = check_motion(engine)
    display = display_units(engine.mech, args.units)
    if args.json:
        print(dumps(convert_check(engine, plain(report.as_dict()), display), indent=2, ensure_ascii=False))
    else:
        print(format_report(report, length=(display.name("length"), display.scale("length"))))
    return 0
