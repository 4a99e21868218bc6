"""`mbplanar sweep`: a sweep of the model planned from the arguments (`plan`), solved and written as a CSV
table block by block (`sweep`), with an estimate before a long one and Ctrl-C that keeps the rows written."""

from __future__ import annotations

import math
import os
import sys
import warnings

import numpy as np

from .._progress import Interrupted
from ..errors import ModelError
from ._tables import forces_columns, sweep_table
from ._units import convert_table, display_units
from .inputs import motion_of, speeds

__all__ = ["plan", "sweep", "SWEEP_CHUNK", "SWEEP_PROBE"]


SWEEP_CHUNK = 20_000  # positions solved and written at a time: memory stays bounded whatever --steps


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
    from ..forces import kinetostatics
    result = kinetostatics(engine, motion, inertia or 0.0)
    header, cols = forces_columns(engine, result)
    return header, cols, (None if result.success else result.message)


def _cells(rows):
    """CSV cells of a table (k, n): 12 significant digits, non-finite cells left empty."""
    return [["" if not math.isfinite(x) else f"{x:.12g}" for x in row] for row in rows.tolist()]


def _sweep_block(engine, values, args, cache, with_forces, angle_unit, display, first):
    """The table of one block of a sweep's rows `values` (k, n_in) (model units): header, rows, the motion
    and the force analysis's failure message (or None)."""
    from ..forces import warn_idle_resistances
    n_in = len(engine.inputs)
    phi = np.column_stack([inp.to_si(values[:, k]) for k, inp in enumerate(engine.inputs)])
    omega, epsilon, inertia = speeds(engine, phi[:, 0], args, cache=cache)
    if args.input_inertia is not None:
        inertia = args.input_inertia
    motion = motion_of(engine, phi if n_in > 1 else phi[:, 0], omega, epsilon)
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
    from .._progress import confirm_long_run
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


def plan(engine, args):
    """The sweep `args` ask for: `mbplanar.kinematics.plan.sweep_plan` of ``--steps``, ``--step``,
    ``--from``, ``--to`` and ``--grid``.

    Parameters
    ----------
    engine : Engine
        The model's engine.
    args : argparse.Namespace
        The parsed arguments of `mbplanar sweep` (``steps``, ``step``, ``start``, ``stop``, ``grid``).

    Returns
    -------
    tuple
        ``(count, values, shape)`` as `sweep_plan` gives them.

    Raises
    ------
    ModelError
        ``--from`` or ``--to`` without one value per input, ``--grid`` of one input, or what `sweep_plan`
        refuses.

    Examples
    --------
    >>> import argparse, mbplanar
    >>> from mbplanar.io.sweep import plan
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> args = argparse.Namespace(steps=[4], step=None, start=None, stop=None, grid=False)
    >>> count, values, shape = plan(engine, args)
    >>> count, values(0, count)[:, 0].tolist()
    (5, [0.0, 90.0, 180.0, 270.0, 360.0])
    """
    from ..kinematics.plan import sweep_plan
    n_in = len(engine.inputs)
    for name, given in (("--from", args.start), ("--to", args.stop)):
        if given is not None and len(given) != n_in:
            raise ModelError(f"{name} needs {n_in} value(s) separated by commas")
    if args.grid and n_in == 1:
        raise ModelError("--grid applies to several inputs")
    return sweep_plan(engine, args.steps, args.step, args.start, args.stop, args.grid)


def sweep(engine, planned, args) -> int:
    """`mbplanar sweep`: the rows of a `plan` solved and written block by block (``SWEEP_CHUNK`` positions
    at a time, so that memory stays bounded), to ``-o`` or standard output, with the force columns where
    asked; the notes of change points passed, and the exit status: 1 where the sweep stops at a motion
    limit or the force analysis fails.

    Parameters
    ----------
    engine : Engine
        The model's engine.
    planned : tuple
        The sweep's ``(count, values, shape)`` (`plan`).
    args : argparse.Namespace
        The parsed arguments of `mbplanar sweep`.

    Returns
    -------
    int
        The exit status: 0, or 1 where the sweep stopped or a force analysis failed.

    Raises
    ------
    ModelError
        Contradicting options (``--true-motion`` with ``--omega``), or a sweep refused as too long.
    Interrupted
        Ctrl-C: the message says how many rows were written.

    Examples
    --------
    >>> import contextlib, io, mbplanar
    >>> from mbplanar.cli import build_parser
    >>> from mbplanar.io.sweep import plan, sweep
    >>> args = build_parser("sweep").parse_args(["sweep", "models/fourbar.toml", "--steps", "2"])
    >>> engine = mbplanar.Engine(mbplanar.read_model(args.model))
    >>> with contextlib.redirect_stdout(io.StringIO()) as out:
    ...     code = sweep(engine, plan(engine, args), args)
    >>> code, out.getvalue().splitlines()[2][:5]
    (0, '180,1')
    """
    from .._progress import Progress
    from ..forces import has_force_data
    n_in = len(engine.inputs)
    count, values_of, shape = planned
    if args.true_motion or n_in == 1:
        speeds(engine, None, args, check_only=True)
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
    from ..kinematics import describe_crossing
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
