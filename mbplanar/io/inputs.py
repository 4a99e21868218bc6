"""The commands' input values: ``--at`` in the model's units (one value per input, reduced by whole periods
where far), the input's speed and acceleration (given, or the true motion), and the motion at them with
the errors a command reports (an unreachable value, rates out of the floating-point range)."""

from __future__ import annotations

import math
import sys

import numpy as np

from ..errors import ModelError, MotionError

__all__ = ["inputs_at", "at_reduced"]


def _at_values(text) -> list[float]:
    """The finite numbers of a comma-separated --at."""
    return numbers_of(text, "--at")


def numbers_of(text, option) -> list[float]:
    """The finite numbers of a comma-separated option's value."""
    try:
        values = [float(v) for v in str(text).split(",")]
    except ValueError:
        values = [math.nan]
    if not all(math.isfinite(v) for v in values):
        raise ModelError(f"{option} needs finite value(s) separated by commas")
    return values


def inputs_at(engine, text) -> list[float]:
    """The ``--at`` values, one per input of the model.

    Parameters
    ----------
    engine : Engine
        The model's engine (its inputs).
    text : str
        Finite numbers separated by commas, in the model's units.

    Returns
    -------
    list of float
        One value per input.

    Raises
    ------
    ModelError
        A value that is not a finite number, or not one value per input.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.io.inputs import inputs_at
    >>> five = mbplanar.Engine(mbplanar.read_model("models/five_bar.toml"))
    >>> inputs_at(five, "40,90")
    [40.0, 90.0]
    >>> inputs_at(five, "40")
    Traceback (most recent call last):
    ...
    mbplanar.errors.ModelError: --at needs 2 finite value(s) separated by commas (phi1, phi2)
    """
    values = _at_values(text)
    if len(values) != len(engine.inputs):
        raise ModelError(f"--at needs {len(engine.inputs)} finite value(s) separated by commas "
                        f"({', '.join(i.name for i in engine.inputs)})")
    return values


def at_si(engine, values) -> np.ndarray:
    """--at values (model units) as SI (1, n_in), reduced by whole periods where far (`at_reduced`)."""
    return np.array([[i.to_si(v) for i, v in zip(engine.inputs, at_reduced(engine, values))]])


def at_reduced(engine, values) -> list[float]:
    """Input values reduced by whole periods where far from the drawn pose.

    Unchanged unless a single revolute input lies more than `mbplanar.engine.FAR_TURNS` turns from the
    drawn pose on a periodic branch: then reduced by whole periods in the model's unit, exactly for
    degrees (fmod is exact), with a note on standard error (the engine reduces SI values itself, to the
    float spacing of φ).

    Parameters
    ----------
    engine : Engine
        The model's engine.
    values : list of float
        One value per input, in the model's units.

    Returns
    -------
    list of float
        The values, reduced where far.

    Raises
    ------
    ModelError
        A value so large that its reduction is uncertain by more than `mbplanar.engine.LOST_PRECISION`
        rad (possible in radians only).

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.io.inputs import at_reduced
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> at_reduced(engine, [30])
    [30.0]
    >>> import contextlib, io
    >>> with contextlib.redirect_stderr(io.StringIO()) as note:
    ...     at_reduced(engine, [36030])
    [30.0]
    >>> "solved at the equivalent 30 deg" in note.getvalue()
    True
    """
    from ..engine import FAR_TURNS, LOST_PRECISION
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


def unreachable(engine, at, motion) -> MotionError:
    """The error of an --at the drawn branch cannot reach, with the range a single input can move
    through when a motion limit stopped it."""
    where = ""
    if len(engine.inputs) == 1 and motion.limits:
        from ..kinematics import reach_text
        inp = engine.inputs[0]
        lo, hi = engine.reach()
        where = f" (the input moves within {reach_text(inp, lo, hi)})"
    return MotionError(f"{engine.mech.source}: cannot reach {at} on the drawn branch: {motion.message}{where}")


def motion_of(engine, values_si, omega=None, epsilon=None):
    """`analyse` of SI input values, refusing rates out of the floating-point range (`check_overflow`)."""
    from ..kinematics import analyse
    motion = analyse(engine, values_si, omega, epsilon)
    check_overflow(motion)
    return motion


def one_position(engine, phi, omega, epsilon, at):
    """The position phi (1, n_in) by the lean path (`mbplanar.position`); where the drawn branch does not
    reach it, the batch path says why, with the range the input moves through."""
    from ..kinematics import position
    try:
        result = position(engine, phi[0], omega, epsilon)
    except MotionError:
        motion = motion_of(engine, phi, omega, epsilon)
        if motion.success:
            raise
        raise unreachable(engine, at, motion) from None
    check_overflow(result)
    return result


def check_overflow(motion):
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


def speeds(engine, phi, args, cache=None, check_only=False):
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
    from ..forces import true_motion
    return None if check_only else true_motion(engine, phi, cache)
