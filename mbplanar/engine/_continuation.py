"""The continuation's rules, each written once: whether a step along the branch is accepted, how far its
rates jumped, and the quintic Hermite interpolant between two nodes (its coefficients, its value, its
first and second derivatives).

They are used by the numpy atlas (`engine._atlas`: the walk, the fill-in, the batch predictor and the
rates at a change point), by the numpy design batch (`mbplanar.study.batch`), and compiled by the
kernels (`mbplanar.backends._numba_blocks` compiles these same functions for the sweep and design
kernels). Each is plain arithmetic on its arguments, so it reads numpy arrays elementwise and floats
alike, with the same floating-point operations in the same order; `tol` is a `Tolerances` or a
`KernelTol` (the same names).
"""

from __future__ import annotations

import numpy as np

__all__ = ["HERMITE5", "REJECT", "ACCEPT", "CROSS", "step_verdict", "rate_jump", "hermite_coefficients",
           "hermite_value", "hermite_slope", "hermite_curvature"]

#: coefficients of t⁰ … t⁵ (rows) of the quintic Hermite interpolant on t ∈ [0, 1] from the end values
#: (q0, q1, h·q0', h·q1', h²·q0'', h²·q1'') (columns)
HERMITE5 = np.array([
    [1, 0, 0, 0, 0, 0],
    [0, 0, 1, 0, 0, 0],
    [0, 0, 0, 0, 0.5, 0],
    [-10, 10, -6, -4, -1.5, 0.5],
    [15, -15, 8, 7, 1.5, -1],
    [-6, 6, -3, -3, -0.5, 0.5]], float)

#: `step_verdict`'s answers: halve the step; accept it; it went through a change point
REJECT, ACCEPT, CROSS = 0, 1, 2


def step_verdict(converged, ratio, dist, jump, same, h, tol):
    """The verdict on a continuation step: accept it, halve it, or go through a change point.

    Parameters
    ----------
    converged : bool or array of bool
        Newton converged.
    ratio : float or array
        The position's smallest pivot ratio (not singular when at least ``tol.pivot_cross``).
    dist : float or array
        How far the corrector moved from the predictor (scaled unknowns); within ``tol.max_correction``.
    jump : float or array
        How far the unknowns' derivatives jumped (`rate_jump`); within ``tol.rate_jump``.
    same : bool or array of bool
        No block's determinant changed sign.
    h : float or array
        The step's length, in the march parameter's units.
    tol : Tolerances or KernelTol
        The thresholds.

    Returns
    -------
    int or array of int
        `ACCEPT` (1) when every check passes; `CROSS` (2) when only a sign changed, over a short step
        (``h <= tol.h_cross``) that the corrector barely moved (``dist <= tol.cross_dist``): a change
        point, another branch crossing this one; else `REJECT` (0). Elementwise for arrays.

    Raises
    ------
    Nothing: plain arithmetic (NaN distances give `REJECT`).

    Examples
    --------
    >>> from mbplanar.engine import ACCEPT, CROSS, Tolerances, step_verdict
    >>> tol = Tolerances()
    >>> step_verdict(True, 0.5, 1e-9, 0.01, True, 0.1, tol) == ACCEPT
    True
    >>> int(step_verdict(True, 0.5, 1e-9, 0.01, False, 0.01, tol)) == CROSS     # a sign changed, short step
    True
    >>> int(step_verdict(True, 0.5, 1e-9, 0.01, False, 0.1, tol))               # ... over a long one: halve
    0
    """
    good = converged * (ratio >= tol.pivot_cross) * (dist <= tol.max_correction) * (jump <= tol.rate_jump)
    through = (h <= tol.h_cross) * (dist <= tol.cross_dist)
    return good * (same + (1 - same) * 2 * through)


def rate_jump(qd_new, qd, qdd, h, scale):
    """How far an unknown's derivative after a step lies from its Taylor prediction.

    A large jump means the corrector found another branch.

    Parameters
    ----------
    qd_new : float or array
        The derivative after the step.
    qd, qdd : float or array
        The first and second derivatives before it.
    h : float or array
        The step.
    scale : float or array
        The unknown's scale (1 for an angle, 1/size for a length).

    Returns
    -------
    float or array
        ``abs(qd_new - qd - qdd * h) * scale / (1 + abs(qd) * scale)``.

    Raises
    ------
    Nothing: plain arithmetic, elementwise for arrays.

    Examples
    --------
    >>> from mbplanar.engine import rate_jump
    >>> rate_jump(1.25, 1.0, 2.0, 0.125, 1.0)           # predicted 1.0 + 2.0·0.125: no jump
    0.0
    >>> rate_jump(-1.0, 1.0, 0.0, 0.1, 1.0)             # the rate reversed: 2 / (1 + 1)
    1.0
    """
    return abs(qd_new - qd - qdd * h) * scale / (1.0 + abs(qd) * scale)


def hermite_coefficients(e0, e1, e2, e3, e4, e5, weights):
    """The coefficients of the quintic Hermite interpolant between two nodes of a walk.

    Parameters
    ----------
    e0, e1, e2, e3, e4, e5 : float or array
        The end values (q0, q1, h·q0', h·q1', h²·q0'', h²·q1''), h the interval's width.
    weights : numpy.ndarray
        `HERMITE5` (6, 6).

    Returns
    -------
    tuple of 6 floats or arrays
        c0 … c5, of t⁰ … t⁵ on t ∈ [0, 1]: c_k = Σ_e weights[k, e]·e_e, summed in that order.

    Raises
    ------
    IndexError
        `weights` smaller than (6, 6).

    Examples
    --------
    >>> from mbplanar.engine import HERMITE5, hermite_coefficients
    >>> [float(c) for c in hermite_coefficients(0.0, 1.0, 0.0, 3.0, 0.0, 6.0, HERMITE5)]   # q = φ³ on [0, 1]
    [0.0, 0.0, 0.0, 1.0, 0.0, 0.0]
    """
    w = weights
    return (w[0, 0] * e0 + w[0, 1] * e1 + w[0, 2] * e2 + w[0, 3] * e3 + w[0, 4] * e4 + w[0, 5] * e5,
            w[1, 0] * e0 + w[1, 1] * e1 + w[1, 2] * e2 + w[1, 3] * e3 + w[1, 4] * e4 + w[1, 5] * e5,
            w[2, 0] * e0 + w[2, 1] * e1 + w[2, 2] * e2 + w[2, 3] * e3 + w[2, 4] * e4 + w[2, 5] * e5,
            w[3, 0] * e0 + w[3, 1] * e1 + w[3, 2] * e2 + w[3, 3] * e3 + w[3, 4] * e4 + w[3, 5] * e5,
            w[4, 0] * e0 + w[4, 1] * e1 + w[4, 2] * e2 + w[4, 3] * e3 + w[4, 4] * e4 + w[4, 5] * e5,
            w[5, 0] * e0 + w[5, 1] * e1 + w[5, 2] * e2 + w[5, 3] * e3 + w[5, 4] * e4 + w[5, 5] * e5)


def hermite_value(c0, c1, c2, c3, c4, c5, t):
    """The interpolant's value at t, by Horner's rule.

    Parameters
    ----------
    c0, c1, c2, c3, c4, c5 : float or array
        Its coefficients (`hermite_coefficients`).
    t : float or array
        Where, on [0, 1] across the interval.

    Returns
    -------
    float or array
        q(t).

    Raises
    ------
    Nothing: plain arithmetic, elementwise for arrays.

    Examples
    --------
    >>> from mbplanar.engine import HERMITE5, hermite_coefficients, hermite_value
    >>> c = hermite_coefficients(0.0, 1.0, 0.0, 3.0, 0.0, 6.0, HERMITE5)   # q = φ³: reproduced exactly
    >>> float(hermite_value(*c, 0.5))
    0.125
    """
    return ((((c5 * t + c4) * t + c3) * t + c2) * t + c1) * t + c0


def hermite_slope(c1, c2, c3, c4, c5, t):
    """The interpolant's derivative d/dt at t, by Horner's rule (d/dφ: divided by the interval's width).

    Parameters
    ----------
    c1, c2, c3, c4, c5 : float or array
        Its coefficients (`hermite_coefficients`; c0 drops out).
    t : float or array
        Where, on [0, 1].

    Returns
    -------
    float or array
        dq/dt at t.

    Raises
    ------
    Nothing: plain arithmetic, elementwise for arrays.

    Examples
    --------
    >>> from mbplanar.engine import HERMITE5, hermite_coefficients, hermite_slope
    >>> c = hermite_coefficients(0.0, 1.0, 0.0, 3.0, 0.0, 6.0, HERMITE5)   # q = φ³, q' = 3φ²
    >>> float(hermite_slope(*c[1:], 0.5))
    0.75
    """
    return (((5.0 * c5 * t + 4.0 * c4) * t + 3.0 * c3) * t + 2.0 * c2) * t + c1


def hermite_curvature(c2, c3, c4, c5, t):
    """Its second derivative d²/dt² at t, by Horner's rule (d²/dφ²: divided by the width squared)."""
    return ((20.0 * c5 * t + 12.0 * c4) * t + 6.0 * c3) * t + 2.0 * c2
