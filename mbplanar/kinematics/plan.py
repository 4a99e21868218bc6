"""Sweep planning: the input values of a sweep, generated lazily in blocks so that a long sweep never sits
in memory (`sweep_plan`), or all at once (`sweep_values`). Values are in the model's units (degrees, or
the model's length unit for a slider); `mbplanar sweep` streams them block by block."""

from __future__ import annotations

import math

import numpy as np

from ..errors import ModelError

__all__ = ["sweep_plan", "sweep_values"]


def sweep_values(engine, steps=None, step=None, start=None, stop=None) -> np.ndarray:
    """Input values of a one-input sweep, both ends included.

    Parameters
    ----------
    engine : Engine
        The engine of a model with one input.
    steps : int, optional
        Number of equal intervals (default: the input's ``steps``, else 72).
    step : float, optional
        Spacing in the model's unit, instead of `steps`.
    start, stop : float, optional
        The ends (default: the model's sweep of the input).

    Returns
    -------
    numpy.ndarray
        The values (n,), in the model's unit of the input.

    Raises
    ------
    ModelError
        A `step` that is not positive.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.kinematics.plan import sweep_values
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> sweep_values(engine, steps=4).tolist()
    [0.0, 90.0, 180.0, 270.0, 360.0]
    >>> sweep_values(engine, step=50, start=10, stop=120).tolist()
    [10.0, 60.0, 110.0]
    """
    count, values, _ = sweep_plan(engine, None if steps is None else [steps], step,
                                  None if start is None else [start], None if stop is None else [stop])
    return values(0, count)[:, 0]


def sweep_plan(engine, steps=None, step=None, start=None, stop=None, grid=False):
    """A sweep's positions, generated lazily so that a long one never sits in memory.

    One input: `steps` intervals or a `step` from `start` to `stop` (default: the model's sweep), both
    ends included; equal ends give one row. Several inputs: `start` and `stop` (one value per input)
    are the ends of a straight path in input space with `steps` intervals; with `grid` the box they
    span, with `steps` intervals per input (one count for all, or one per input), the first input
    varying slowest.

    Parameters
    ----------
    engine : Engine
        The model's engine (its inputs and their default sweeps).
    steps : list of int, optional
        Intervals: one count, or with `grid` one per input (default: the input's ``steps``, else 72).
    step : float, optional
        Spacing in the model's unit (one input only).
    start, stop : list of float, optional
        One value per input, in the model's units (required with several inputs).
    grid : bool
        Several inputs: every combination over the box from `start` to `stop`, not a path.

    Returns
    -------
    count : int
        The number of rows.
    values : callable
        ``values(i, j)`` → the input values (j − i, n_in) of rows i … j − 1, in the model's units.
    shape : tuple of int or None
        The grid's shape, or None for a path.

    Raises
    ------
    ModelError
        Several inputs without both ends, a `step` with several inputs or not positive, or a count of
        `steps` that does not fit the inputs.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.kinematics.plan import sweep_plan
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> count, values, shape = sweep_plan(engine, [10 ** 8])
    >>> count, shape, values(count - 2, count)[:, 0].tolist()
    (100000001, None, [359.9999964, 360.0])
    >>> five = mbplanar.Engine(mbplanar.read_model("models/five_bar.toml"))
    >>> count, values, shape = sweep_plan(five, [2, 1], start=[40, 90], stop=[100, 150], grid=True)
    >>> count, shape, values(0, 3).tolist()
    (6, (3, 2), [[40.0, 90.0], [40.0, 150.0], [70.0, 90.0]])
    """
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
