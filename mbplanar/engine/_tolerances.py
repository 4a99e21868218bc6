"""The engine's tuning constants as data: tolerances, step sizes and thresholds of the block Newton, the
continuation, the singular-position solvers and the kinetostatic solve (`Tolerances`; lengths relative
to the mechanism's size, angles in rad).

An engine carries one `Tolerances` (``Engine(mech, tol=Tolerances(closure=1e-12))``) and hands the values
to the numpy code and, as arguments, to the compiled kernels: numba freezes module globals into its
on-disk cache, so a constant read by a kernel would leave the two backends on different values after
an edit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import NamedTuple

import numpy as np

__all__ = ["Tolerances", "KernelTol"]


@dataclass(frozen=True)
class Tolerances:
    """Tolerances and thresholds of an `Engine` (the defaults are the validated ones).

    Attributes
    ----------
    closure : float
        Closure residual that ends Newton (lengths relative to the mechanism's size).
    polish : float
        While some position of a batch still needs a step, the others below `closure` are polished to this.
    max_newton : int
        Newton iterations per solve.
    h_start, h_max, h_min : float
        First, largest and smallest continuation step (relative to the input's scale: rad, or the size).
        A step that cannot be made smaller than `h_min` marks a motion limit.
    h_dense : float
        Widest atlas interval the predictor interpolates over.
    max_correction : float
        Largest accepted corrector distance (rad, or lengths / size).
    rate_jump : float
        Largest accepted change of the unknowns' derivatives against their prediction, relative to
        1 + ``|q'|``: a larger one means the corrector found another branch.
    h_cross : float
        Widest step across a change point; the nodes that bracket it are half of it away, where the
        Jacobian is still well enough conditioned for rates to ~1e-12.
    cross_dist : float
        Largest corrector distance of a step across a change point.
    pivot_polish : float
        Below this pivot ratio a converged position gets one more Newton step.
    pivot_cross : float
        Nodes on either side of a change point must be at least this far from singular.
    fold_iterations : int
        Newton iterations of the fold location (0: limits stay the middle of the walk's bracket).
    fold_delta : float
        Central-difference step of the fold system's Jacobian (scaled unknowns, s).
    fold_step : float
        The fold location has converged when a step moves nothing by more than this.
    fold_sqrt_law : float
        Largest relative departure from the square-root law between a node and its fold.
    singular : float
        Kinetostatics: a block whose ``|det| / Π‖row‖`` is not above this is singular (NaN reactions).
    turn : float
        Design kernel: the largest turn (rad) of a link placed from its anchor angle by the series of
        cos and sin of the turn rather than by cos and sin of the new angle.
    nudge : float
        Design kernel: the largest move (rad) of a link within one solve placed to first order.
    lazy_step : float
        Design kernel: the largest last Newton step (scaled) after which a converged block keeps its
        Jacobian for its rates.

    Raises
    ------
    ValueError
        A value that is not a positive finite number (a non-negative integer for the counts), `polish`
        above `closure`, or steps out of the order ``h_min <= h_start <= h_max``.

    Examples
    --------
    >>> from mbplanar.engine import Tolerances
    >>> Tolerances().closure, Tolerances(closure=1e-12).closure
    (1e-13, 1e-12)
    >>> Tolerances().kernel().max_newton                  # as the compiled kernels read them
    14
    >>> Tolerances(h_min=1.0)
    Traceback (most recent call last):
    ValueError: Tolerances: need h_min <= h_start <= h_max, not 1.0, 0.104719755..., 0.261799387...
    """

    closure: float = 1e-13
    polish: float = 1e-14
    max_newton: int = 14
    h_start: float = math.radians(6.0)
    h_max: float = math.radians(15.0)
    h_min: float = 1e-10
    h_dense: float = math.radians(1.0)
    max_correction: float = 0.05
    rate_jump: float = 0.25
    h_cross: float = 2e-2
    cross_dist: float = 1e-6
    pivot_polish: float = 0.05
    pivot_cross: float = 1e-9
    fold_iterations: int = 8
    fold_delta: float = 1e-6
    fold_step: float = 1e-14
    fold_sqrt_law: float = 0.1
    singular: float = 1e-12
    turn: float = 0.05
    nudge: float = 1e-8
    lazy_step: float = 1e-6

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            if f.type == "int":
                if not isinstance(value, (int, np.integer)) or isinstance(value, bool) or value < 0:
                    raise ValueError(f"Tolerances.{f.name} must be a non-negative integer, not {value!r}")
            elif (isinstance(value, bool) or not isinstance(value, (int, float, np.floating))
                  or not math.isfinite(value) or value <= 0):
                raise ValueError(f"Tolerances.{f.name} must be a positive finite number, not {value!r}")
        if self.polish > self.closure:
            raise ValueError(f"Tolerances.polish ({self.polish}) must not exceed closure ({self.closure})")
        if not self.h_min <= self.h_start <= self.h_max:
            raise ValueError(f"Tolerances: need h_min <= h_start <= h_max, not {self.h_min}, {self.h_start}, "
                             f"{self.h_max}")

    def kernel(self) -> "KernelTol":
        """The same values as the compiled kernels read them: a `KernelTol` (integers as int, the rest as
        float), one argument of every kernel, so that no threshold is a constant frozen into numba's
        cache."""
        return KernelTol(*(int(getattr(self, f.name)) if f.type == "int" else float(getattr(self, f.name))
                           for f in fields(self)))


class KernelTol(NamedTuple):
    """`Tolerances` as the kernels read them (`Tolerances.kernel`): one named field per tolerance, in
    the order of `Tolerances`' fields (see there for each one's meaning)."""

    closure: float
    polish: float
    max_newton: int
    h_start: float
    h_max: float
    h_min: float
    h_dense: float
    max_correction: float
    rate_jump: float
    h_cross: float
    cross_dist: float
    pivot_polish: float
    pivot_cross: float
    fold_iterations: int
    fold_delta: float
    fold_step: float
    fold_sqrt_law: float
    singular: float
    turn: float
    nudge: float
    lazy_step: float

