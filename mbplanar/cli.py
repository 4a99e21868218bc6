"""Command-line interface: `mbplanar COMMAND MODEL ...`.

Exit status: 0 success, 1 a mechanism that cannot move as asked (lock, dead point, cannot assemble),
2 bad input (model file, arguments). Messages go to stderr; no traceback unless --debug.
"""

from __future__ import annotations

import argparse
import gc
import importlib
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

from ._progress import add_long_run_options  # noqa: E402  (after the BLAS threads are set)
from .errors import MbplanarError, ModelWarning, PrecisionWarning  # noqa: E402

__all__ = ["main", "run"]


def _load(args):
    """The engine of the command's model file, from the engine cache unless --no-cache (`engine._cache`)."""
    from .engine import load_engine
    engine = load_engine(args.model, backend=args.backend, threads=args.threads,
                         use_cache=not getattr(args, "no_cache", False))
    return engine


def _plan(positions: int) -> None:
    """Tell the backends that this command (one per process) solves `positions` positions: a backend
    whose loading costs more than it saves then declines (`Backend.should_run`; numba's own start is
    ~0.8 s, a position saves ~1 µs); the answers are the same to rounding. `_run` forgets the plan
    when the command ends."""
    from .engine import planned
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


def _list_of(parse):
    """Comma-separated values, each read by `parse` (argparse type): --steps of a grid, --from, --to."""
    return lambda text: [parse(part) for part in str(text).split(",")]


# -- the commands: each one's work is in the library (`io.commands`, `io.sweep`, `viz.command`, the packages
# of OWN_MODULE), imported when it runs; here the engine of the command's model is loaded and handed over
def _imported(target: str):
    """The function "module:name" of mbplanar, imported now."""
    module, name = target.split(":")
    return getattr(importlib.import_module(f"mbplanar.{module}"), name)


def _on_engine(target: str, positions: int | None = None, checks_first: bool = False, registers=()):
    """The run of a command whose work `target` ("module:name") takes the engine of the command's model
    and the arguments (with `checks_first`: the arguments and a loader, called once it has checked them);
    a command of one position leaves out a backend that would not pay (`positions`). `registers`: modules
    of the packages above viz whose pictures or report sections the command registers first (so that the
    other commands do not import those packages)."""
    def run_command(args):
        for module in registers:
            _imported(f"{module}:register")()
        if checks_first:
            return _imported(target)(args, lambda: _load(args))
        engine = _load(args)
        if positions is not None:
            _plan(positions)
        return _imported(target)(engine, args)
    return run_command


def _own(module: str, run: str = "run", *name):
    """The options and the run of a command whose options and work live in `module` of its own (a command
    of `formats.command` passes its `name` first)."""
    return (lambda s: _imported(f"{module}:add_arguments")(*name, s),
            lambda args: _imported(f"{module}:{run}")(*name, args))


def cmd_sweep(args):
    from .io.sweep import plan, sweep
    engine = _load(args)
    planned = plan(engine, args)
    _plan(planned[0])
    return sweep(engine, planned, args)


def cmd_compile(args):
    """The numba backend's kernels and the design batch's compiled into numba's cache (`backends.build`)."""
    from .backends import build
    from .study.batch import compile_sample
    build(sys.stderr, samples=(compile_sample,))
    return 0


def _located(exc, args) -> str:
    """One line; an error raised without a `source` (an argument's) is located at the model file."""
    model = getattr(args, "model", None) or getattr(args, "file", None)  # (cam names its file 'file')
    if isinstance(exc, MbplanarError) and exc.source is None and model is not None and str(model) not in str(exc):
        exc = type(exc)(exc.message, source=str(model), where=exc.where)
    return " ".join(str(exc).split())


def _speed_options(s):
    """--omega, --epsilon or --true-motion of solve and sweep (see `io.inputs.speeds`)."""
    s.add_argument("--omega", type=float, help="input speed dφ/dt in rad/s or m/s (default 1: the analogues)")
    s.add_argument("--epsilon", type=float, help="input acceleration (default 0)")
    s.add_argument("--true-motion", action="store_true",
                   help="ω(φ), ε(φ) from the machine dynamics (models with [dynamics]); in a sweep also J_I "
                        "on the input link in the force columns")


def _units_option(s):
    from .model import add_units_option
    add_units_option(s)


def _json_options(s):
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
    g.add_argument("--steps", type=_list_of(_positive_int), help="number of equal intervals (both ends included); with "
                   "--grid one per input (e.g. 20,30) or one for all")
    g.add_argument("--step", type=_finite_float, help="spacing in the model's unit")
    s.add_argument("--from", dest="start", type=_list_of(_finite_float),
                   help="first value (default: the model's sweep); one per input, comma-separated")
    s.add_argument("--to", dest="stop", type=_list_of(_finite_float), help="last value (one per input)")
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


def cmd_serve(args) -> int:
    """The workbench; its panels' forms are made from this command line's parsers."""
    from .web import command
    return command.run(args, forms=command.panel_forms(build_parser))


#: every command in the order of `mbplanar --help`: its line there, the function that adds its options
#: to its parser, and the function that runs it. The options are added for the running command only
#: (`build_parser`): the cam, gear, synthesis and study code is imported only when its command runs or shows
#: its help. `study` builds its own parser (`study.command.add_parser`).
COMMANDS = {
    "info": ("links, joints, DOF, loops, Assur groups", _json_options, _on_engine("io.commands:info")),
    "solve": ("one position: positions, velocities, accelerations", _solve_options,
              _on_engine("io.commands:solve", 1)),
    "sweep": ("the whole cycle as a CSV table", _sweep_options, cmd_sweep),
    "forces": ("one position: every joint reaction and the balancing moment", _forces_options,
               _on_engine("io.commands:forces", 1)),
    "dynamics": ("reduced inertia and moments, flywheel, true ω(φ) and ε(φ)", _dynamics_options,
                 _on_engine("io.commands:dynamics")),
    "simulate": ("motion under given forces: integrate the equations of motion in time", _simulate_options,
                 _on_engine("io.commands:simulate")),
    "balance": ("counterweights that cancel the shaking force (or minimise its RMS)", _balance_options,
                _on_engine("io.commands:balance")),
    "plot": ("a picture: diagram, vectors, trajectories, kinematics, analogues, transmission, forces, ...",
             _plot_options, _on_engine("viz.command:plot", checks_first=True, registers=("accuracy.plots",))),
    "animate": ("animation of a cycle: GIF or a browser page (SVG)", _animate_options,
                _on_engine("viz.command:animate", checks_first=True)),
    "report": ("one self-contained HTML report of the model", _report_options,
               _on_engine("viz.command:report", checks_first=True,
                          registers=("accuracy.plots", "cam.present", "gears.report", "synthesis.report"))),
    "synth": ("synthesis: seed 001's guiding mechanism, function, motion and path generation",
              *_own("synthesis.command")),
    "check": ("full turn?, dead points, extreme positions, transmission angles", _json_options,
              _on_engine("io.commands:check")),
    "compile": ("compile the numba backend's kernels into numba's cache, once after installing mbplanar[fast]: "
                "later runs load them instead of compiling", lambda s: None, cmd_compile),
    "cam": ("design a cam: motion law, size for a pressure-angle limit, exact profile",
            *_own("cam.present", "run_command")),
    "gear": ("design gears: a spur pair with profile shift (checks, block contour, exact profiles), planetary "
             "trains by tooth numbers", *_own("gears.command")),
    "study": ("a table of design variants: full turn, motion limits, strokes, transmission angles per variant",
              None, None),
    "accuracy": ("tolerances and clearances: sensitivities, worst-case and statistical stacks, Monte Carlo",
                 *_own("accuracy.command")),
    "schema": ("the JSON Schema of the model table (for editors: completion and checks)",
              *_own("formats.command", "run", "schema")),
    "import": ("a Pyslvs, PMKS+ or pylinkage file as an mbplanar model (TOML)",
              *_own("formats.command", "run", "import")),
    "export": ("the mechanism at a position as a drawing: DXF (CAD layers) or SVG",
              *_own("formats.command", "run", "export")),
    "examples": ("list the bundled example models, or copy them out", *_own("formats.command", "run", "examples")),
    "serve": ("the workbench in the browser: edit the table, see it move, run every analysis "
              "(pip install 'mbplanar[web]')", _own("web.command")[0], cmd_serve),
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
    from .engine import planned
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
