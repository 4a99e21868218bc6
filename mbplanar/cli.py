"""Command-line interface: `mbplanar COMMAND MODEL ...`.

Exit status: 0 success, 1 a mechanism that cannot move as asked (lock, dead point, cannot assemble),
2 bad input (model file, arguments). Messages go to stderr; no traceback unless --debug.
"""

from __future__ import annotations

import argparse
import gc
import math
import os
import re
import sys
import warnings

#: the variables that set the threads of numpy's BLAS (OpenBLAS reads the first it finds of these)
BLAS_THREADS = ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS")


def _blas_on_one_thread() -> None:
    """Run numpy's BLAS on one thread in a command-line process, unless the user set its threads: the
    commands' matrices are small (no command took less time with more BLAS threads, docs/speed.md), while
    OpenBLAS starts one busy thread per core at numpy's import (~0.06 s of CPU on 2 cores for every
    command). Before numpy is imported, or it has no effect; the library itself sets nothing."""
    if "numpy" not in sys.modules and not any(os.environ.get(name) for name in BLAS_THREADS):
        os.environ["OPENBLAS_NUM_THREADS"] = "1"


_blas_on_one_thread()

import numpy as np  # noqa: E402  (after the BLAS threads are set)

from ._progress import Interrupted, add_long_run_options
from .errors import MbplanarError, ModelError, ModelWarning, MotionError, PrecisionWarning
from .io import (dynamics_document, forces_document, info_document, partials_document, plain, solve_document,
                 write_csv)
from .io._tables import dynamics_table, forces_columns, sweep_table
from .io._units import (input_kinds, convert_check, convert_dynamics, convert_forces, convert_info,
                        convert_solution, convert_table, display_units)

__all__ = ["main", "run"]


def _dumps(doc, **options) -> str:
    """json.dumps, with json imported by the commands that print JSON only."""
    import json
    return json.dumps(doc, **options)


def _load(args):
    """The engine of the command's model file, from the engine cache unless --no-cache (`engine._cache`)."""
    from .engine._cache import load_engine
    engine = load_engine(args.model, backend=args.backend, threads=args.threads,
                         use_cache=not getattr(args, "no_cache", False))
    if args.backend != "numpy":   # kernels that take none of this model's jobs: why, once (the seam logs each)
        from .engine._tables import kernels_decline
        why = kernels_decline(engine.mech)
        if why:
            print(f"mbplanar: note: backend {args.backend}: {why}", file=sys.stderr)
    return engine


def _plan(positions: int) -> None:
    """Tell the backends that this command (one per process) solves `positions` positions: a backend
    whose loading costs more than it saves then declines (`Backend.should_run`; numba's own start is
    ~0.8 s, a position saves ~1 µs); the answers are the same to rounding. `_run` forgets the plan
    when the command ends."""
    from .engine._backend import planned
    planned.positions = positions


def _positive_int(text) -> int:
    """A whole number ≥ 1, also written as 1e6 (argparse type)."""
    try:
        value = int(text)
    except ValueError:
        try:
            number = float(text)
            value = int(number) if number.is_integer() else 0
        except (ValueError, OverflowError):
            value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"a positive integer, not {text!r}")
    return value


def _finite_float(text) -> float:
    """A finite number (argparse type): nan and ±inf are refused at the edge."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"a finite number, not {text!r}")
    return value


DPI_RANGE = (10, 1200)       # a picture of 8 × 6 in at 1200 dpi is ~70 Mpixel (~280 MB in memory)
FRAMES_MAX = 3600


def _bounded_int(lo, hi):
    """An integer in [lo, hi] (argparse type)."""
    def parse(text) -> int:
        try:
            value = int(text)
        except ValueError:
            value = lo - 1
        if not lo <= value <= hi:
            raise argparse.ArgumentTypeError(f"an integer from {lo} to {hi}, not {text!r}")
        return value
    return parse


def _at_values(text) -> list[float]:
    """The finite numbers of a comma-separated --at."""
    try:
        values = [float(v) for v in str(text).split(",")]
    except ValueError:
        values = [math.nan]
    if not all(math.isfinite(v) for v in values):
        raise ModelError("--at needs finite value(s) separated by commas")
    return values


def _numbers_of(text, option) -> list[float]:
    """The finite numbers of a comma-separated option's value."""
    try:
        values = [float(v) for v in str(text).split(",")]
    except ValueError:
        values = [math.nan]
    if not all(math.isfinite(v) for v in values):
        raise ModelError(f"{option} needs finite value(s) separated by commas")
    return values


def _input_si(engine, value):
    inp = engine.inputs[0]
    return inp.to_si(value)


def _at_si(engine, values) -> np.ndarray:
    """--at values (model units) as SI (1, n_in), reduced by whole periods where far (`_at_reduced`)."""
    return np.array([[i.to_si(v) for i, v in zip(engine.inputs, _at_reduced(engine, values))]])


def _at_reduced(engine, values) -> list[float]:
    """--at values (model units), unchanged unless a single revolute input lies far from the drawn
    pose on a periodic branch: then reduced by whole periods in the model's unit, exactly for degrees
    (fmod is exact), with a note (the engine reduces SI values itself, to the float spacing of φ)."""
    from .engine._atlas import FAR_TURNS, LOST_PRECISION
    values = [float(v) for v in values]
    if len(engine.inputs) != 1 or engine.mech.joints[engine.inputs[0].joint].kind != "R":
        return values
    inp, value = engine.inputs[0], values[0]
    if abs(inp.to_si(value) - engine.phi_drawn[0]) <= 2 * math.pi * FAR_TURNS:
        return values
    period = engine.period()
    if period is None:
        return values  # the engine refuses it, naming the range, or stops at a limit
    turns = round(period / (2 * math.pi))
    in_unit = 360.0 * turns if inp.unit == "deg" else period
    reduced = math.fmod(value, in_unit)
    error = 0.0 if inp.unit == "deg" else abs(value / in_unit) * np.spacing(in_unit)
    if error > LOST_PRECISION:
        raise ModelError(f"--at {value:g} {inp.unit}: reducing it by whole turns leaves an uncertainty of "
                         f"{error:.3g} rad; give the value reduced by whole turns", source=engine.mech.source)
    note = f"; the reduction is good to {error:.2g} rad" if error > 1e-15 else ""
    print(f"mbplanar: {engine.mech.source}: note: {inp.name} = {value:g} {inp.unit} lies "
          f"{abs(value) / in_unit:.6g} period(s) from zero; the motion repeats every {turns} turn(s), so it is "
          f"solved at the equivalent {reduced:.15g} {inp.unit}{note}", file=sys.stderr)
    return [reduced]


# -- info -------------------------------------------------------------------------------------------
def cmd_info(args):
    engine = _load(args)
    display = display_units(engine.mech, args.units)
    doc = convert_info(engine, info_document(engine), display)
    if args.json:
        print(_dumps(doc, indent=2))
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


# -- solve ------------------------------------------------------------------------------------------
def _unreachable(engine, at, motion) -> MotionError:
    """The error of an --at the drawn branch cannot reach, with the range a single input can move
    through when a motion limit stopped it."""
    where = ""
    if len(engine.inputs) == 1 and motion.limits:
        inp = engine.inputs[0]
        lo, hi = engine.reach()
        from .kinematics._motion import reach_text
        where = f" (the input moves within {reach_text(inp, lo, hi)})"
    return MotionError(f"{engine.mech.source}: cannot reach {at} on the drawn branch: {motion.message}{where}")


def _motion(engine, values_si, omega=None, epsilon=None):
    from .kinematics._motion import analyse
    motion = analyse(engine, values_si, omega, epsilon)
    _check_overflow(motion)
    return motion


def _one_position(engine, phi, omega, epsilon, at):
    """The position phi (1, n_in) by the lean path (`mbplanar.position`); where the drawn branch does not
    reach it, the batch path says why, with the range the input moves through."""
    from .kinematics._single import position
    try:
        result = position(engine, phi[0], omega, epsilon)
    except MotionError:
        motion = _motion(engine, phi, omega, epsilon)
        if motion.success:
            raise
        raise _unreachable(engine, at, motion) from None
    _check_overflow(result)
    return result


def _check_overflow(motion):
    """Refuse an input speed or acceleration whose real velocities or accelerations leave the
    floating-point range (--omega 1e300 squares to infinity) while their analogues are finite."""
    real = (motion.w, motion.e, motion.v, motion.a)
    if all(np.all(np.isfinite(x)) for x in real):
        return
    analogues = (motion.wq, motion.eq, motion.vq, motion.aq)
    if any(x is not None and not np.all(np.isfinite(x)) for x in analogues):
        return  # a singular position: its rates are infinite whatever the speed
    om, ep = np.max(np.abs(motion.omega)), np.max(np.abs(motion.epsilon))
    raise ModelError(f"input speed {om:g} and acceleration {ep:g}: the velocities or accelerations leave "
                    f"the floating-point range (above {np.finfo(float).max:.3g}); give a smaller --omega "
                    "or --epsilon")


def _speeds(engine, phi, args, cache=None, check_only=False):
    """ω, ε of the input for solve and sweep: --omega/--epsilon (default 1 and 0: the analogues), or the
    true motion from the machine dynamics with --true-motion (then also the first group's J_I). `cache`
    keeps the machine dynamics between the chunks of a sweep; `check_only` only checks the options."""
    if not getattr(args, "true_motion", False):
        return (1.0 if args.omega is None else args.omega), (0.0 if args.epsilon is None else args.epsilon), None
    if args.omega is not None or args.epsilon is not None:
        raise ModelError("--true-motion computes ω and ε; leave out --omega and --epsilon")
    if len(engine.inputs) != 1 or engine.mech.dynamics is None:
        raise ModelError("--true-motion needs a model with one input and a [dynamics] section",
                         source=engine.mech.source)
    from .forces._dynamics import true_motion
    return None if check_only else true_motion(engine, phi, cache)


def _inputs_at(engine, text) -> list[float]:
    """The --at values, one per input of the model."""
    values = _at_values(text)
    if len(values) != len(engine.inputs):
        raise ModelError(f"--at needs {len(engine.inputs)} finite value(s) separated by commas "
                        f"({', '.join(i.name for i in engine.inputs)})")
    return values


def cmd_solve(args):
    engine = _load(args)
    _plan(1)
    values = _inputs_at(engine, args.at)
    phi = _at_si(engine, values)
    omega, epsilon, _ = _speeds(engine, phi[:, 0], args)
    result = _one_position(engine, phi, omega, epsilon, args.at)
    display = display_units(engine.mech, args.units)
    doc = convert_solution(engine, solve_document(engine, result, values=values), display)
    if args.json:  # (with one input, "first" and "second" repeat the analogues, by name)
        doc["partials"] = partials_document(engine, phi, result)
    if args.json:
        print(_dumps(doc, indent=2))
        return 0
    _print_solution(engine, doc, display)
    return 0


def _text_unit(name: str) -> str:
    """A unit name for text tables: N·m, kg·m², m/s²."""
    return name.replace("*", "·").replace("^2", "²")


def _print_solution(engine, doc, display):
    u = {k: _text_unit(display.name(k)) for k in ("length", "velocity", "acceleration")}
    kinds = [[_text_unit(display.name(kind)) for kind in input_kinds(engine, k)] for k in range(len(doc["inputs"]))]
    print(f"{doc['model']}: " + "; ".join(f"{i['name']} = {i['value']:g} {i['unit']}  (ω = {i['omega']:g} {rate}, "
                                           f"ε = {i['epsilon']:g} {accel})"
                                           for i, (rate, accel, _) in zip(doc["inputs"], kinds)))
    size = max([1e-300] + [abs(p[k]) for p in doc["points"].values() for k in ("x", "y")])
    _print_columns(["point", f"x [{u['length']}]", f"y [{u['length']}]", f"vx [{u['velocity']}]",
                    f"vy [{u['velocity']}]", f"ax [{u['acceleration']}]", f"ay [{u['acceleration']}]"],
                   [[name] + [_num(_clean(p[k], 1e-12 * size)) for k in ("x", "y", "vx", "vy", "ax", "ay")]
                    for name, p in doc["points"].items()])
    rows = []
    for name, link in doc["links"].items():
        ic = doc["instant_centres"][name]
        rows.append([name, _num(math.degrees(link["angle"])), _num(link["omega"]), _num(link["epsilon"])]
                    + ([_num(ic[0]), _num(ic[1])] if ic else ["—", "—"]))
    _print_columns(["link", "angle [°]", "ω [rad/s]", "ε [rad/s²]", f"IC x [{u['length']}]",
                    f"IC y [{u['length']}]"], rows)
    rows = []
    for name, j in doc["joints"].items():
        if j["type"] == "R":
            cells = [_num(math.degrees(j["value"])) + " °", _num(j["rate"]) + " rad/s", _num(j["accel"]) + " rad/s²"]
        else:
            cells = [_num(j["value"]) + f" {u['length']}", _num(j["rate"]) + f" {u['velocity']}",
                     _num(j["accel"]) + f" {u['acceleration']}"]
        rows.append([name, j["type"], *cells])
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
    """Input values (model units) of a one-input sweep: `steps` intervals or a `step`, both ends
    included (see `sweep_plan` for the lazy form the CLI streams)."""
    count, values, _ = sweep_plan(engine, steps, step, None if start is None else [start],
                                  None if stop is None else [stop])
    return values(0, count)[:, 0]


def sweep_plan(engine, steps=None, step=None, start=None, stop=None, grid=False):
    """A sweep's positions, generated lazily so that a long one never sits in memory: the number of
    rows, a function values(i, j) → input values (j − i, n_in) (model units) of rows i … j − 1, and the
    grid's shape (or None).

    One input: `steps` intervals or a `step` from `start` to `stop` (default: the model's sweep), both
    ends included; equal ends give one row. Several inputs: `start` and `stop` (one value per input)
    are the ends of a straight path in input space with `steps` intervals; with `grid` the box they
    span, with `steps` intervals per input (one count for all, or one per input), the first input
    varying slowest."""
    n_in = len(engine.inputs)
    if n_in == 1:
        lo, hi = engine.inputs[0].default_sweep()
        lo, hi = (lo if start is None else start[0]), (hi if stop is None else stop[0])
        return _line_plan(lo, hi, steps or [getattr(engine.inputs[0], "steps", None) or 72], step)
    if start is None or stop is None:
        raise ModelError(f"a sweep of {n_in} inputs needs --from and --to with {n_in} values each "
                        "(the ends of a path in input space, or the corners of a grid with --grid)")
    if step is not None:
        raise ModelError("--step applies to one input; give --steps for several")
    lo, hi = np.array(start, float), np.array(stop, float)
    counts = steps or [72]
    if not grid:
        if len(counts) != 1:
            raise ModelError("--steps of a path is one number; several numbers need --grid")
        n = 1 if np.all(lo == hi) else counts[0] + 1
        return n, (lambda i, j: lo + (hi - lo) * (np.arange(i, j)[:, None] / max(n - 1, 1))), None
    if len(counts) not in (1, n_in):
        raise ModelError(f"--steps of a grid is one number or {n_in} numbers")
    axes = [np.linspace(a, b, (1 if a == b else int(c) + 1)) for a, b, c in
            zip(lo, hi, np.broadcast_to(counts, (n_in,)))]
    shape = tuple(len(ax) for ax in axes)

    def values(i, j):
        idx = np.unravel_index(np.arange(i, j), shape)
        return np.stack([ax[k] for ax, k in zip(axes, idx)], axis=1)
    return int(np.prod(shape)), values, shape


def _line_plan(lo, hi, steps, step):
    """`sweep_plan` of one input from lo to hi."""
    if hi == lo:
        return 1, (lambda i, j: np.full((j - i, 1), float(lo))), None  # --from and --to equal
    if step is not None:
        if not step > 0:
            raise ModelError("--step must be positive")
        count = int(math.floor(abs(hi - lo) / step + 1e-9)) + 1
        signed = math.copysign(step, hi - lo)
        return count, (lambda i, j: (lo + signed * np.arange(i, j))[:, None]), None
    if len(steps) != 1:
        raise ModelError("--steps of one input is one number")
    n = int(steps[0])
    width = (hi - lo) / n

    def values(i, j):  # as np.linspace(lo, hi, n + 1): the last value is hi itself
        k = np.arange(i, j)
        return np.where(k == n, hi, lo + k * width)[:, None]
    return n + 1, values, None


SWEEP_CHUNK = 20_000  # positions solved and written at a time: memory stays bounded whatever --steps


def _steps_list(text) -> list[int]:
    """--steps: one positive count, or one per input of a grid (argparse type)."""
    counts = [_positive_int(part) for part in str(text).split(",")]
    return counts


def _values_list(text) -> list[float]:
    """--from / --to: one finite value per input, comma-separated (argparse type)."""
    return [_finite_float(part) for part in str(text).split(",")]


class _Output:
    """A text output opened at its first write (so a command refused before it leaves no file), and
    removed when the command fails with an error part way (a truncated table would pass for a whole
    one); standard output when `path` is None."""

    def __init__(self, path):
        self.path, self.file = path, None

    def write_rows(self, rows):
        if self.file is None:
            self.file = open(self.path, "w", newline="", encoding="utf-8") if self.path else sys.stdout
            import csv
            self.writer = csv.writer(self.file)
        self.writer.writerows(rows)

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        if self.path and self.file is not None:
            self.file.close()
            if kind is not None and not issubclass(kind, (BrokenPipeError, KeyboardInterrupt, Interrupted)):
                os.remove(self.path)  # (Ctrl-C keeps the rows written: the message says how many)
        elif self.file is not None:
            self.file.flush()
        return False


def _forces_columns(engine, motion, inertia):
    """Header, columns (B, k) and a failure message (or None) of a sweep's reactions and balancing loads."""
    from .forces._kinetostatics import kinetostatics
    result = kinetostatics(engine, motion, inertia or 0.0)
    header, cols = forces_columns(engine, result)
    return header, cols, (None if result.success else result.message)


def _cells(rows):
    """CSV cells of a table (k, n): 12 significant digits, non-finite cells left empty."""
    return [["" if not math.isfinite(x) else f"{x:.12g}" for x in row] for row in rows.tolist()]


def _sweep_block(engine, values, args, cache, with_forces, angle_unit, display, first):
    """The table of one block of a sweep's rows `values` (k, n_in) (model units): header, rows, the motion
    and the force analysis's failure message (or None)."""
    from .forces._loads import warn_idle_resistances
    n_in = len(engine.inputs)
    phi = np.column_stack([inp.to_si(values[:, k]) for k, inp in enumerate(engine.inputs)])
    omega, epsilon, inertia = _speeds(engine, phi[:, 0], args, cache=cache)
    if args.input_inertia is not None:
        inertia = args.input_inertia
    motion = _motion(engine, phi if n_in > 1 else phi[:, 0], omega, epsilon)
    header, rows = sweep_table(engine, motion, angle_unit)
    failed = None
    if with_forces:
        if first:
            warn_idle_resistances(engine, motion)
        f_header, f_rows, failed = _forces_columns(engine, motion, inertia)
        header, rows = header + f_header, np.column_stack([rows, f_rows]) if len(rows) else rows
    header, rows = convert_table(header, rows, display, skip=n_in)
    return header, rows, motion, failed


SWEEP_PROBE = 200_000  # a sweep of more positions first times one block of them (its time estimate)


def _sweep_estimate(engine, count, values_of, block, args, source):
    """Refuse (or ask about) a sweep estimated above 10 minutes, from a timed probe: one block computed
    and formatted as CSV, not written (`_progress.confirm_long_run`)."""
    import time
    from ._progress import confirm_long_run
    if count <= SWEEP_PROBE:
        return
    n = min(count, SWEEP_CHUNK)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")       # (the run itself gives them)
        block(values_of(0, 100), {}, False)   # the one-off costs (a backend's load) out of the timing
        start = time.perf_counter()
        _cells(block(values_of(0, n), {}, False)[1])
        seconds = time.perf_counter() - start
    confirm_long_run(seconds * count / n, f"a sweep of {count} positions",
                     f"the first {n} took {seconds:.3g} s", args.yes, source)


def cmd_sweep(args):
    from ._progress import Progress
    from .forces._loads import has_force_data
    engine = _load(args)
    n_in = len(engine.inputs)
    start = None if args.start is None else args.start
    stop = None if args.stop is None else args.stop
    for name, given in (("--from", start), ("--to", stop)):
        if given is not None and len(given) != n_in:
            raise ModelError(f"{name} needs {n_in} value(s) separated by commas")
    if args.grid and n_in == 1:
        raise ModelError("--grid applies to several inputs")
    count, values_of, shape = sweep_plan(engine, args.steps, args.step, start, stop, args.grid)
    _plan(count)
    if args.true_motion or n_in == 1:
        _speeds(engine, None, args, check_only=True)
    with_forces = args.forces == "yes" or (args.forces == "auto" and has_force_data(engine.mech))
    angle_unit = args.angles or ("rad" if engine.inputs[0].unit == "rad" else "deg")
    display = display_units(engine.mech, args.units)
    cache, notes, written, missing, forces_failed, stopped = {}, [], 0, 0, None, None

    def block(values, cache, first):
        return _sweep_block(engine, values, args, cache, with_forces, angle_unit, display, first)

    _sweep_estimate(engine, count, values_of, block, args, engine.mech.source)
    size = SWEEP_CHUNK if shape is None else shape[-1] * max(1, SWEEP_CHUNK // shape[-1])
    with _Output(args.output) as out, Progress(count, "positions", show=args.progress, guard=False) as bar:
        try:
            for i in range(0, count, size):
                j = min(count, i + size)
                for a, b in ([(i, j)] if shape is None else [(k, k + shape[-1]) for k in range(i, j, shape[-1])]):
                    values = values_of(a, b)
                    header, rows, motion, failed = block(values, cache, written == 0)
                    forces_failed = forces_failed or failed
                    if written == 0:
                        out.write_rows([header])
                    notes += [c for c in motion.crossings if all(c.phi[0] != n.phi[0] for n in notes)]
                    reached = len(motion.phi)
                    if shape is not None and reached < len(values):  # a grid line: the rest left empty
                        full = np.full((len(values), len(header)), np.nan)
                        full[:reached] = rows.reshape(reached, len(header))
                        full[reached:, :n_in] = values[reached:]
                        rows, missing = full, missing + len(values) - reached
                        stopped = stopped or motion.message
                    out.write_rows(_cells(rows))
                    written += len(rows)
                    if shape is None and not motion.success:
                        stopped = motion
                        break
                bar.update(written)
                if shape is None and stopped is not None:
                    break
        except KeyboardInterrupt:
            where = f" to {args.output}" if args.output else ""
            raise Interrupted(f"interrupted (Ctrl-C): wrote the first {written} of {count} positions{where}",
                              source=engine.mech.source) from None
    from .kinematics._motion import describe_crossing
    for c in notes:
        print(f"mbplanar: {engine.mech.source}: note: {describe_crossing(engine, c)}", file=sys.stderr)
    if forces_failed:
        print(f"mbplanar: {engine.mech.source}: {forces_failed} (their force cells are empty)", file=sys.stderr)
        return 1
    if shape is not None and missing:
        print(f"mbplanar: {engine.mech.source}: {missing} of the {count} grid points cannot be reached from the "
              f"drawn pose (their cells are empty), e.g.: {stopped}", file=sys.stderr)
        return 1
    if stopped is not None:
        print(f"mbplanar: {engine.mech.source}: {stopped.message}; wrote the {written} of {count} positions "
              "before it", file=sys.stderr)
        return 1
    return 0


# -- forces -----------------------------------------------------------------------------------------
NO_FORCE_DATA = ("the model has no loads, gravity or masses, so every reaction and the balancing moment would "
                 "be zero; add [[loads]], [gravity] or link masses")


def cmd_forces(args):
    from .forces._dynamics import true_motion
    from .forces._kinetostatics import kinetostatics
    from .forces._loads import has_force_data
    engine = _load(args)
    _plan(1)
    values = _inputs_at(engine, args.at)
    if not has_force_data(engine.mech):
        raise ModelError(NO_FORCE_DATA, source=engine.mech.source)
    phi = _at_si(engine, values)
    phi = phi[:, 0] if len(engine.inputs) == 1 else phi
    omega, epsilon, inertia, how = args.omega, args.epsilon, args.input_inertia, "given"
    if omega is None and epsilon is None and engine.mech.dynamics is not None \
            and len(engine.inputs) == 1:
        omega, epsilon, dyn_inertia = true_motion(engine, phi)
        inertia, how = (dyn_inertia if inertia is None else inertia), "true motion from the machine dynamics"
    motion = _motion(engine, phi, omega, epsilon)
    if not motion.success:
        raise _unreachable(engine, args.at, motion)
    inertia = inertia or 0.0
    from .forces._friction import friction_kinetostatics, read_friction
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
            from .forces._friction import implausible_friction, not_converged
            at = "at " + ", ".join(f"{i.name} = {v:g} {i.unit}" for i, v in zip(engine.inputs, values))
            error = ModelError if implausible_friction(engine.mech, spec) else MotionError
            raise error(not_converged(engine, spec, fr, at), source=engine.mech.source)
    display = display_units(engine.mech, args.units)
    doc = convert_forces(engine, doc, display)
    if args.json:
        print(_dumps(doc, indent=2))
        return 0
    rate, accel, inertia_kind = (_text_unit(display.name(k)) for k in input_kinds(engine))
    moment_unit = _text_unit(display.name("moment"))
    print(f"{doc['model']}: " + "); ".join(f"{i['name']} = {i['value']:g} {i['unit']}  (ω = {i['omega']:g} {rate}, "
                                            f"ε = {i['epsilon']:g} {accel}" for i in doc["inputs"])
          + f", J_I = {doc['input']['input_inertia']:g} {inertia_kind}; {how})")
    tiny = 1e-12 * max([0.0] + [r["magnitude"] for r in doc["reactions"].values()])  # (relative: any scale)
    rows = []
    for name, r in doc["reactions"].items():
        fx, fy, moment = (_clean(r[k], tiny) for k in ("fx", "fy", "moment"))
        rows.append([name, r["type"], r["on"], r["from"], _num(fx), _num(fy), _num(_clean(r["magnitude"], tiny)),
                     f"{r['direction_deg']:.3f}", _num(moment) if r["type"] == "P" else ""])
    _print_columns(["joint", "type", "on", "from", "Fx [N]", "Fy [N]", "|F| [N]", "dir [°]", f"M [{moment_unit}]"],
                   rows)
    for name, q in doc["balancing"].items():
        revolute = engine.mech.joints[name].kind == "R"
        unit = moment_unit if revolute else "N"
        q = _clean(q, tiny * (engine.size / display.scale("moment") if revolute else 1.0))
        print(f"balancing {'moment' if revolute else 'force'} at {name}: {q:.6g} {unit}")
    print(f"virtual-power residual: {doc['virtual_power_residual']:.3g}")
    if "friction" in doc:
        f = doc["friction"]
        print(f"friction: {f['iterations']} iterations, residual {f['residual']:.3g}; power lost "
              f"{-f['losses']:.6g} W; instantaneous efficiency {f['efficiency']}")
    return 0


# -- dynamics ---------------------------------------------------------------------------------------
def cmd_dynamics(args):
    from .forces._dynamics import machine_dynamics, read_dynamics
    engine = _load(args)
    if args.steps < 36:
        raise ModelError("--steps must be at least 36")
    if args.delta is not None and not (math.isfinite(args.delta) and 0 < args.delta < 1):
        raise ModelError("--delta must be a number between 0 and 1")
    from .model._table import crank_input
    crank_input(engine.mech)  # (a machine of several inputs, or driven by a slider, says so first)
    spec = read_dynamics(engine.mech, args.delta)
    if spec is None:
        raise ModelError("the model has no [dynamics] section; give --delta", source=engine.mech.source)
    dyn = machine_dynamics(engine, spec, steps=args.steps)
    at = None if args.at is None else np.array([_input_si(engine, v) for v in _at_values(args.at)])
    display = display_units(engine.mech, args.units)
    doc = convert_dynamics(engine, dynamics_document(engine, dyn, at), display)
    if args.output:
        write_csv(args.output, *convert_table(*dynamics_table(dyn), display))
    if args.json:
        print(_dumps(doc, indent=2, ensure_ascii=False))
        return 0
    _print_dynamics(engine, dyn, doc, display)
    return 0


def _print_dynamics(engine, dyn, doc, display):
    from .forces._dynamics import summary
    inp = doc["input"]
    inertia, moment = _text_unit(display.name("inertia")), _text_unit(display.name("moment"))
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
    return plain(doc)


def simulate_table(doc, engine=None) -> tuple[list, np.ndarray]:
    """Header (each column's unit in brackets, SI) and columns (N, k) of the simulated motion for CSV."""
    prismatic = {} if engine is None else {n: j.kind == "P" for n, j in engine.mech.joints.items()}
    header, cols = ["t[s]"], [doc["t"]]
    for name, d in doc["inputs"].items():
        p = prismatic.get(d["joint"], False)
        units = ("m", "m/s", "m/s^2", "N") if p else ("rad", "rad/s", "rad/s2", "N*m")
        header += [f"{name}[{units[0]}]", f"{name}.omega[{units[1]}]", f"{name}.epsilon[{units[2]}]",
                   f"{name}.drive[{units[3]}]"]
        cols += [d["phi"], d["omega"], d["epsilon"], d["drive"]]
    for name, d in doc["links"].items():
        header += [f"angle.{name}[rad]", f"omega.{name}[rad/s]", f"epsilon.{name}[rad/s2]"]
        cols += [d["angle"], d["omega"], d["epsilon"]]
    for name, d in doc["joints"].items():
        header += [f"{name}.value[{'m' if prismatic.get(name) else 'rad'}]", f"F{name}.x[N]", f"F{name}.y[N]"]
        cols += [d["value"], d["fx"], d["fy"]]
    header += ["kinetic[J]", "potential[J]", "drive_work[J]"]
    cols += [doc["energy"]["kinetic"], doc["energy"]["potential"], doc["energy"]["drive_work"]]
    return header, np.column_stack([np.asarray(c, float) for c in cols])


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


def cmd_simulate(args):
    from ._progress import Progress
    from .forces._simulation import read_simulate, simulate_motion
    from .io._units import convert_simulation
    engine = _load(args)
    over = {"t": args.t, "rtol": args.rtol, "atol": args.atol, "method": args.method, "steps": args.steps}
    for key, text in (("torque", args.torque), ("motor_slope", args.motor_slope), ("omega", args.omega),
                      ("input_inertia", args.input_inertia)):
        over[key] = None if text is None else _numbers_of(text, "--" + key.replace("_", "-"))
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
        print(_dumps(doc, indent=2, ensure_ascii=False))
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
        unit = [_text_unit(display.name(kind)) for kind in kinds]
        print(f"  {name}: {d['phi'][last]:.12g} {unit[0]}, speed {d['omega'][last]:.12g} {unit[1]}, acceleration "
              f"{d['epsilon'][last]:.12g} {unit[2]}; drive {d['drive'][last]:.6g} {unit[3]}, balancing "
              f"{d['balancing'][last]:.6g} {unit[3]}")
    e = doc["energy"]
    print(f"  energy: kinetic {e['kinetic'][last]:.9g} J, potential {e['potential'][last]:.9g} J, "
          f"work of the drive {e['drive_work'][last]:.9g} J")
    return 0 if tr.success else 1


def balance_document(engine, bal, count: int = 360) -> dict:
    """Counterweights, and before/after at the model's speed over a turn: the RMS and largest shaking
    force and the largest shaking moment (the resultant of the links' inertia forces, `inertia_shaking`:
    the counterweights' static weight is no shaking), the largest reaction in every pair, the largest
    balancing moment (or force)."""
    from .forces._shaking import inertia_shaking
    from .engine._solver import Engine
    from .forces._kinetostatics import kinetostatics
    from .kinematics._motion import analyse
    doc = {"model": engine.mech.name, "counterweights": [vars(cw) for cw in bal.counterweights],
           "rms_unit_speed": {"before": bal.rms_before, "after": bal.rms_after}}
    phi = engine.phi_drawn[0] + np.linspace(0.0, 2 * math.pi, count, endpoint=False)
    balanced = Engine(bal.mechanism, backend=engine.backend, threads=engine.threads)
    for when, eng in (("before", engine), ("after", balanced)):
        motion = analyse(eng, phi)
        ks = kinetostatics(eng, motion)
        sh = inertia_shaking(eng, motion)
        doc[when] = {"shaking_force_max": float(np.max(sh.magnitude)),
                     "shaking_force_rms": float(np.sqrt(np.mean(sh.magnitude ** 2))),
                     "shaking_moment_max": float(np.max(np.abs(sh.moment))),
                     "reaction_max": {n: float(np.max(r.magnitude)) for n, r in ks.reactions.items()},
                     "balancing_max": {n: float(np.max(np.abs(q))) for n, q in ks.balancing.items()}}
    return plain(doc)


def cmd_balance(args):
    from .forces._shaking import balance
    from .io._units import convert_balance
    from .model._scale import drawing_size, warn_scale
    engine = _load(args)
    display = display_units(engine.mech, args.units)
    length = display.scale("length")
    links = [n.strip() for n in args.links.split(",") if n.strip()]
    radius = None if args.radius is None else [r * length for r in _numbers_of(args.radius, "--radius")]
    if radius is not None and not all(r > 0 for r in radius):
        raise ModelError("--radius must be positive")
    for r in radius or ():
        warn_scale("--radius", r, drawing_size(engine.mech), display.name("length"), length,
                   source=engine.mech.source)
    bal = balance(engine, links, radius)
    doc = convert_balance(engine, balance_document(engine, bal), display)
    if args.json:
        print(_dumps(doc, indent=2, ensure_ascii=False))
        return 0
    u = doc["units"]
    lu, mu, fu = u["length"], _text_unit(u["moment"]), _text_unit(u["first_moment"])
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


# -- pictures ---------------------------------------------------------------------------------------
def _suffix(path, allowed):
    suffix = str(path).rsplit(".", 1)[-1].lower() if "." in str(path) else ""
    if suffix not in allowed:
        raise ModelError(f"{path}: the output must end in {' or '.join('.' + a for a in allowed)}")
    return suffix


def cmd_plot(args):
    from .accuracy.plots import register as register_accuracy
    from .viz import _plotting as plotting
    register_accuracy()  # (the pictures of other packages: registered here, as the report's sections are)
    _suffix(args.output, ("png", "svg", "pdf"))
    if args.what not in plotting.FIGURES:
        raise ModelError(plotting.unknown_picture(args.what))
    if args.show is not None and args.what != "diagram":
        raise ModelError(f"--show applies to the diagram, not to '{args.what}'")
    if args.points is not None and args.what != "trajectories":
        raise ModelError(f"--points applies to the trajectories, not to '{args.what}'")
    options = plotting.show_options(args.show) if args.what == "diagram" else {}
    if args.points is not None:
        options["points"] = [n.strip() for n in args.points.split(",") if n.strip()]
        if not options["points"]:
            raise ModelError("--points needs names of pairs or points separated by commas")
    plotting.require_matplotlib()
    engine = _load(args)
    from .forces._loads import has_force_data
    if args.what in ("forces", "shaking") and not has_force_data(engine.mech):
        raise ModelError(f"nothing to draw for '{args.what}': {NO_FORCE_DATA}", source=engine.mech.source)
    at = None
    if args.at is not None:
        at = _at_reduced(engine, _inputs_at(engine, args.at))
        at = at[0] if len(at) == 1 else at
    plotting.save_figure(plotting.make_figure(engine, args.what, at, **options), args.output, dpi=args.dpi)
    return 0


def cmd_animate(args):
    from .viz import _plotting as plotting
    kind = _suffix(args.output, ("gif", "html"))
    if args.frames < 2:
        raise ModelError("--frames must be at least 2")
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
        print(f"mbplanar: {engine.mech.source}: the animation turns back at the motion limits: "
              + "; ".join(describe_limit(engine, lim) for lim in motion.limits), file=sys.stderr)
    return 0


def cmd_report(args):
    from .accuracy.plots import register as register_accuracy
    from .cam.present import register as register_cam_section
    from .gears.report import register as register_gears_section
    from .synthesis.report import register as register_synthesis_section
    from .viz import _plotting as plotting
    from .viz._report import write_report
    register_cam_section()  # (the report's sections of other packages: registered here, so that the other
    register_gears_section()  # commands do not import those packages)
    register_synthesis_section()
    register_accuracy()
    _suffix(args.output, ("html",))
    plotting.require_matplotlib()
    engine = _load(args)
    write_report(engine, args.output, frames=args.frames)
    return 0


# -- compile ----------------------------------------------------------------------------------------
def cmd_compile(args):
    """Compile the numba backend's kernels into numba's cache (`backends._aot`), the design batch's too:
    later processes load them."""
    from .backends._aot import build
    from .study.batch import compile_sample
    build(sys.stderr, samples=(compile_sample,))
    return 0


# -- check ------------------------------------------------------------------------------------------
def cmd_check(args):
    from .analysis._check import check, check_region, format_region, format_report
    engine = _load(args)
    if len(engine.inputs) == 2:
        region = check_region(engine)
        if args.json:
            print(_dumps(plain(region.as_dict()), indent=2, ensure_ascii=False))
        else:
            print(format_region(region))
        return 0
    report = check(engine)
    display = display_units(engine.mech, args.units)
    if args.json:
        print(_dumps(convert_check(engine, plain(report.as_dict()), display), indent=2, ensure_ascii=False))
    else:
        print(format_report(report, length=(display.name("length"), display.scale("length"))))
    return 0


# -- cam --------------------------------------------------------------------------------------------
def cmd_cam(args):
    from .cam.present import run_command
    return run_command(args)


# -- gear -------------------------------------------------------------------------------------------
def cmd_gear(args):
    from .gears.command import run
    return run(args)


# -- main -------------------------------------------------------------------------------------------
def _located(exc, args) -> str:
    """One line; an error raised without a `source` (an argument's) is located at the model file."""
    model = getattr(args, "model", None) or getattr(args, "file", None)  # (cam names its file 'file')
    if isinstance(exc, MbplanarError) and exc.source is None and model is not None and str(model) not in str(exc):
        exc = type(exc)(exc.message, source=str(model), where=exc.where)
    return " ".join(str(exc).split())


def _speed_options(s):
    """--omega, --epsilon or --true-motion of solve and sweep (see `_speeds`)."""
    s.add_argument("--omega", type=float, help="input speed dφ/dt in rad/s or m/s (default 1: the analogues)")
    s.add_argument("--epsilon", type=float, help="input acceleration (default 0)")
    s.add_argument("--true-motion", action="store_true",
                   help="ω(φ), ε(φ) from the machine dynamics (models with [dynamics]); in a sweep also J_I "
                        "on the input link in the force columns")


def cmd_synth(args) -> int:
    from .synthesis.command import run
    return run(args)


def _units_option(s):
    from .model._units import add_units_option
    add_units_option(s)


def _info_options(s):
    s.add_argument("model")
    s.add_argument("--json", action="store_true")
    _units_option(s)


def _solve_options(s):
    s.add_argument("model")
    s.add_argument("--at", required=True, help="generalized coordinate in the model's unit")
    _speed_options(s)
    s.add_argument("--json", action="store_true")
    _units_option(s)


def _sweep_options(s):
    s.add_argument("model")
    g = s.add_mutually_exclusive_group()
    g.add_argument("--steps", type=_steps_list, help="number of equal intervals (both ends included); with "
                   "--grid one per input (e.g. 20,30) or one for all")
    g.add_argument("--step", type=_finite_float, help="spacing in the model's unit")
    s.add_argument("--from", dest="start", type=_values_list,
                   help="first value (default: the model's sweep); one per input, comma-separated")
    s.add_argument("--to", dest="stop", type=_values_list, help="last value (one per input)")
    s.add_argument("--grid", action="store_true",
                   help="several inputs: every combination over the box from --from to --to, not a path")
    _speed_options(s)
    s.add_argument("--angles", choices=("deg", "rad"), help="unit of angles in the table")
    s.add_argument("-o", "--output", help="CSV file (default: standard output)")
    s.add_argument("--forces", choices=("auto", "yes", "no"), default="auto",
                   help="reaction and balancing columns: auto = when the model has loads or masses")
    s.add_argument("--input-inertia", type=float, help="J_I on the input link for the force columns")
    add_long_run_options(s)
    _units_option(s)


def _forces_options(s):
    s.add_argument("model")
    s.add_argument("--at", required=True, help="generalized coordinate in the model's unit")
    s.add_argument("--omega", type=float, help="input speed dφ/dt (default: the model's omega)")
    s.add_argument("--epsilon", type=float, help="input acceleration (default: the model's, else 0)")
    s.add_argument("--input-inertia", type=float, help="reduced inertia J_I on the input link (kg·m²)")
    s.add_argument("--mu", type=float, help="friction coefficient of every pair (overrides [friction] mu)")
    s.add_argument("--json", action="store_true")
    _units_option(s)


def _dynamics_options(s):
    s.add_argument("model")
    s.add_argument("--at", help="also the values at these input values (model's unit, comma-separated)")
    s.add_argument("--steps", type=_bounded_int(36, 10 ** 6), default=3600,
                   help="intervals over the cycle (36 to 10⁶, default 3600)")
    s.add_argument("--delta", type=float, help="coefficient of speed fluctuation (default: the model's)")
    s.add_argument("-o", "--output", help="CSV file of the cycle table")
    s.add_argument("--json", action="store_true")
    _units_option(s)


def _simulate_options(s):
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
    add_long_run_options(s)
    _units_option(s)


def _balance_options(s):
    s.add_argument("model")
    s.add_argument("--links", required=True, help="comma list of the links that get a counterweight")
    s.add_argument("--radius", help="counterweight radius on links turning about a frame pivot (one or per link), "
                                    "in the unit of --units: m, or the model's length_unit")
    s.add_argument("--json", action="store_true")
    _units_option(s)


def _plot_options(s):
    s.add_argument("model")
    s.add_argument("what", help="diagram, vectors, trajectories, kinematics, analogues, transmission, forces, ...")
    s.add_argument("--at", help="generalized coordinate(s) in the model's unit, one per input, comma-separated "
                               "(default: the drawn pose)")
    s.add_argument("--show", help="on the diagram: a comma list of velocities, accelerations, reactions, "
                                  "centres (or all)")
    s.add_argument("--points", help="trajectories of these pairs or points only (comma list, e.g. B,S3)")
    s.add_argument("--dpi", type=_bounded_int(*DPI_RANGE), default=120, help="resolution (10 to 1200)")
    s.add_argument("-o", "--output", required=True, help="FILE.png, .svg or .pdf")


def _animate_options(s):
    s.add_argument("model")
    s.add_argument("--frames", type=_bounded_int(2, FRAMES_MAX), default=36)
    s.add_argument("--dpi", type=_bounded_int(*DPI_RANGE), default=80, help="resolution (10 to 1200)")
    s.add_argument("-o", "--output", required=True, help="FILE.gif or FILE.html")


def _report_options(s):
    s.add_argument("model")
    s.add_argument("--frames", type=_bounded_int(2, FRAMES_MAX), default=36,
                   help="frames of the animation in the report")
    s.add_argument("-o", "--output", required=True, help="FILE.html")


def _synth_options(s):
    from .synthesis.command import add_arguments
    add_arguments(s)


def _check_options(s):
    s.add_argument("model")
    s.add_argument("--json", action="store_true")
    _units_option(s)


def _no_options(s):
    pass


def _cam_options(s):
    from .cam.present import add_arguments
    add_arguments(s)


def _accuracy_options(s):
    from .accuracy.command import add_arguments
    add_arguments(s)


def cmd_accuracy(args) -> int:
    from .accuracy.command import run
    return run(args)


def _gear_options(s):
    from .gears.command import add_arguments
    add_arguments(s)


def _formats(name):
    """The options and the run of a command of `mbplanar.formats.command`, imported when it runs."""
    def add_options(s):
        from .formats.command import add_arguments
        add_arguments(name, s)

    def run_command(args):
        from .formats.command import run
        return run(name, args)
    return add_options, run_command


def _serve_options(s):
    from .web.command import add_arguments
    add_arguments(s)


def cmd_serve(args) -> int:
    """The workbench; its panels' forms are made from this command line's parsers."""
    from .web import command
    from .web._runs import EXPORTS, PANELS, form
    return command.run(args, forms={name: form(build_parser(name), name) for name in PANELS + EXPORTS})


#: every command in the order of `mbplanar --help`: its line there, the function that adds its options
#: to its parser, and the function that runs it. The options are added for the running command only
#: (`build_parser`): the cam, gear, synthesis and study code is imported only when its command runs or shows
#: its help. `study` builds its own parser (`study.command.add_parser`).
COMMANDS = {
    "info": ("links, joints, DOF, loops, Assur groups", _info_options, cmd_info),
    "solve": ("one position: positions, velocities, accelerations", _solve_options, cmd_solve),
    "sweep": ("the whole cycle as a CSV table", _sweep_options, cmd_sweep),
    "forces": ("one position: every joint reaction and the balancing moment", _forces_options, cmd_forces),
    "dynamics": ("reduced inertia and moments, flywheel, true ω(φ) and ε(φ)", _dynamics_options, cmd_dynamics),
    "simulate": ("motion under given forces: integrate the equations of motion in time", _simulate_options,
                 cmd_simulate),
    "balance": ("counterweights that cancel the shaking force (or minimise its RMS)", _balance_options, cmd_balance),
    "plot": ("a picture: diagram, vectors, trajectories, kinematics, analogues, transmission, forces, ...",
             _plot_options, cmd_plot),
    "animate": ("animation of a cycle: GIF or a browser page (SVG)", _animate_options, cmd_animate),
    "report": ("one self-contained HTML report of the model", _report_options, cmd_report),
    "synth": ("synthesis: seed 001's guiding mechanism, function, motion and path generation", _synth_options,
              cmd_synth),
    "check": ("full turn?, dead points, extreme positions, transmission angles", _check_options, cmd_check),
    "compile": ("compile the numba backend's kernels into numba's cache, once after installing mbplanar[fast]: "
                "later runs load them instead of compiling", _no_options, cmd_compile),
    "cam": ("design a cam: motion law, size for a pressure-angle limit, exact profile", _cam_options, cmd_cam),
    "gear": ("design gears: a spur pair with profile shift (checks, block contour, exact profiles), planetary "
             "trains by tooth numbers", _gear_options, cmd_gear),
    "study": ("a table of design variants: full turn, motion limits, strokes, transmission angles per variant",
              None, None),
    "accuracy": ("tolerances and clearances: sensitivities, worst-case and statistical stacks, Monte Carlo",
                 _accuracy_options, cmd_accuracy),
    "schema": ("the JSON Schema of the model table (for editors: completion and checks)", *_formats("schema")),
    "import": ("a Pyslvs, PMKS+ or pylinkage file as an mbplanar model (TOML)", *_formats("import")),
    "export": ("the mechanism at a position as a drawing: DXF (CAD layers) or SVG", *_formats("export")),
    "examples": ("list the bundled example models, or copy them out", *_formats("examples")),
    "serve": ("the workbench in the browser: edit the table, see it move, run every analysis "
              "(pip install 'mbplanar[web]')", _serve_options, cmd_serve),
}
#: commands whose options live in a package of their own
OWN_MODULE = {name: COMMANDS[name][0] for name in ("synth", "cam", "gear", "study", "accuracy", "schema", "import",
                                                    "export", "examples", "serve")}
CORE_COMMANDS = tuple(name for name in COMMANDS if name not in OWN_MODULE)  # the commands of this module
GLOBAL_VALUED = ("--backend", "--threads")  # the global options that take a value
HELP = ("-h", "--help")


def command_in(argv) -> str | None:
    """The command `argv` runs (the first word that is neither a global option nor its value), or None
    when it cannot tell (an unknown word, an abbreviated global option) or the global help comes first:
    then every command's parser is built."""
    words = iter(argv)
    for word in words:
        if word in GLOBAL_VALUED:
            next(words, None)
        elif word in HELP:
            return None
        elif not word.startswith("-"):
            return word if word in COMMANDS else None
    return None


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The argument parser: of every command with None; with a `command` (see `command_in`) only that
    command's parser (its options, and the others' imports, cost the other commands' start-up for
    nothing), with the same usage line, so that an error of a global option reads the same; ""
    lists every command without their options."""
    p = argparse.ArgumentParser(prog="mbplanar", description="Planar linkage analysis from a table of pairs.")
    p.add_argument("--debug", action="store_true", help="show tracebacks")
    p.add_argument("--backend", choices=("numpy", "numba"), default="numpy",
                   help="numba: compiled kinematics and forces for long sweeps (pip install 'mbplanar[fast]' "
                        "&& mbplanar compile; without that compile, importing numba costs ~1 s per process and the "
                        "very first run compiles for ~10 s)")
    p.add_argument("--threads", type=_positive_int, default=None, metavar="N",
                   help="cores the numba backend splits a long sweep over (default: all available, or "
                        "MBPLANAR_THREADS)")
    p.add_argument("--no-cache", action="store_true",
                   help="build the engine from the model file instead of reading the engine cache "
                        "(also MBPLANAR_NO_CACHE=1; the cache lives in MBPLANAR_CACHE_DIR, else ~/.cache/mbplanar)")
    # (with one command's parser, the usage line names every command as the whole parser's does)
    sub = p.add_subparsers(dest="command", required=True, metavar=("{" + ",".join(COMMANDS) + "}") if command else None)
    for name, (line, add_options, run) in COMMANDS.items():
        if command and name != command:
            continue
        if name == "study":
            if command is None or command == "study":
                from .study.command import add_parser as add_study_parser  # (argparse only; the work on use)
                add_study_parser(sub)
            else:
                sub.add_parser(name, help=line)
            continue
        s = sub.add_parser(name, help=line)
        if command is None or command == name:
            add_options(s)
        s.set_defaults(func=run)
    return p


def run() -> int:
    """The command line as a process of its own (the `mbplanar` script, ``python -m mbplanar``): `main` on
    the process's arguments, its exit status returned for `sys.exit`. The process ends next, so the cyclic
    garbage collector is kept off the objects that exist by then (`gc.freeze`): at exit the interpreter
    would otherwise walk the whole heap, numpy's objects included, to free what the OS frees anyway
    (~15 ms of CPU, as much as a command's own work). Files are closed by the commands themselves."""
    code = main()
    gc.freeze()
    return code


def negative_values_joined(argv) -> list[str]:
    """`argv` with a negative number (or comma list) written after an option joined to it, as argparse
    needs: ``--at -10,105`` → ``--at=-10,105`` (argparse takes a word starting with '-' for an option
    unless it is a plain number). No positional argument of mbplanar is a number, so a negative number
    after a flag is an error either way."""
    out = []
    for word in argv:
        if out and NEGATIVE.match(word) and out[-1].startswith("--") and "=" not in out[-1]:
            out[-1] = f"{out[-1]}={word}"
        else:
            out.append(word)
    return out


NEGATIVE = re.compile(r"^-(\d|\.\d)")  # -10, -.5, -1e-3, -10,105


def main(argv=None) -> int:
    argv = negative_values_joined(sys.argv[1:] if argv is None else argv)
    parser = build_parser(command_in(argv))
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help (0) or a refused argument (2, one line on standard error)
        return exc.code if isinstance(exc.code, int) else 2
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ModelWarning)
        warnings.simplefilter("always", PrecisionWarning)
        code, message = _run(args)
    notes = list(dict.fromkeys(str(w.message) for w in caught if issubclass(w.category, ModelWarning)))
    for w in caught:
        if issubclass(w.category, PrecisionWarning):
            print(f"mbplanar: note: {w.message}", file=sys.stderr)
        elif not issubclass(w.category, ModelWarning):
            warnings.showwarning(w.message, w.category, w.filename, w.lineno)
    if message is None:                 # success: each warning on its own line
        for note in notes:
            print(f"mbplanar: warning: {note}", file=sys.stderr)
    else:                               # failure: one line, the warnings (often the cause) after the error
        notes = [note for note in notes if not _said(note, message)]
        print("mbplanar: " + "; warning: ".join([message] + notes), file=sys.stderr)
    return code


def _said(note: str, message: str) -> bool:
    """Whether the error's `message` already says the warning `note` (its text after a 'source: where: '
    prefix)."""
    return any(note[k + 2:] in message for k in range(len(note)) if note.startswith(": ", k))


def _run(args) -> tuple[int, str | None]:
    """Run the command: its exit status, and the error's one-line message (None on success). mbplanar's
    errors map to their exit status (2 bad input, 1 cannot move); a closed standard output (a pipe into
    `head`) ends quietly with status 0."""
    from .engine._backend import planned
    try:
        with planned(None):
            return args.func(args), None
    except BrokenPipeError:
        return _quiet_broken_pipe(), None
    except KeyboardInterrupt:  # (the long commands say what they wrote: `Interrupted`)
        if args.debug:
            raise
        return 130, _located(MbplanarError("interrupted (Ctrl-C)"), args)
    except MbplanarError as exc:
        if args.debug:
            raise
        return exc.exit_code, _located(exc, args)
    except (OSError, ValueError) as exc:
        if args.debug:
            raise
        return 2, " ".join(str(exc).split())


def _quiet_broken_pipe() -> int:
    """The reader of our standard output went away (`mbplanar sweep ... | head`): stop quietly, as a
    filter does, with no message and no error at the interpreter's final flush."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass
    return 0


if __name__ == "__main__":
    sys.exit(run())
