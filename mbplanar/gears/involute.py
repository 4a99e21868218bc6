"""The involute function inv α = tan α − α and its inverse, accurate to a few units of the last place.

`inv` evaluates (sin α − α cos α)/cos α with the numerator summed as its Taylor series,
Σ_{k≥1} (−1)^(k+1) 2k α^(2k+1)/(2k+1)!, whose terms decrease fast for every α < π/2 and which does not
lose the digits that tan α − α loses to cancellation for small α. `arcinv` solves inv α = v by Newton's
method from an upper bound of the root (inv is convex and increasing on [0, π/2), so Newton from above
approaches the root monotonically and cannot overshoot), to a relative error below 1e-15. Both take
numpy arrays (any shape) or floats.

    >>> from mbplanar.gears.involute import inv, arcinv
    >>> import math
    >>> round(float(inv(math.radians(20))), 12)
    0.014904383867
    >>> round(math.degrees(float(arcinv(0.0343161))), 4)      # KHK's pair z = 12, 24, x = 0.6, 0.36
    26.0886
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["inv", "arcinv"]

# coefficients of sin α − α cos α = α³ Σ_k c_k α^(2(k−1)), c_k = (−1)^(k+1) 2k/(2k+1)!, k = 1 … 20:
# at α = π/2 the last term is below 1e-30 of the sum
_COEFFICIENTS = tuple((-1) ** (k + 1) * 2 * k / math.factorial(2 * k + 1) for k in range(1, 21))


def inv(alpha):
    """The involute function tan α − α (α in radians, 0 ≤ α < π/2), elementwise.

    Parameters
    ----------
    alpha : float or array_like
        angles in radians.

    Returns
    -------
    float or numpy.ndarray
        tan α − α, with a relative error of a few 1e-16.

    Raises
    ------
    TypeError
        A value that is not a number; angles outside [0, π/2) are not refused: tan α − α is returned
        (negative below 0, unbounded towards π/2).

    Examples
    --------
    >>> from mbplanar.gears.involute import inv
    >>> float(inv(0.0)), round(float(inv(0.5)), 12)
    (0.0, 0.046302489844)
    """
    a = np.asarray(alpha, dtype=float)
    a2 = a * a
    series = np.zeros_like(a)
    for c in reversed(_COEFFICIENTS):
        series = series * a2 + c
    with np.errstate(invalid="ignore", divide="ignore"):
        out = series * a2 * a / np.cos(a)
    return float(out) if np.ndim(alpha) == 0 else out


def arcinv(value, max_iter: int = 60):
    """The angle α in [0, π/2) whose involute function is `value` (≥ 0), elementwise.

    Newton's method on inv α − v from the upper bound min((3v)^⅓, atan(v + π/2)) of the root: inv is
    increasing and convex, so the iterates decrease monotonically to the root; the iteration stops when a
    step no longer changes α by more than 2 units of its last place.

    Parameters
    ----------
    value : float or array_like
        inv α, ≥ 0 (finite).
    max_iter : int
        Newton steps at most (about 6 are needed from the bound).

    Returns
    -------
    float or numpy.ndarray
        α in radians; NaN where `value` is negative or not finite.

    Raises
    ------
    TypeError
        A value that is not a number; a negative or non-finite value gives NaN, not an error.

    Examples
    --------
    >>> from mbplanar.gears.involute import arcinv, inv
    >>> import math
    >>> alpha = float(arcinv(inv(math.radians(26.0886))))
    >>> abs(math.degrees(alpha) - 26.0886) < 1e-12
    True
    """
    v = np.array(value, dtype=float, ndmin=1)
    bad = ~np.isfinite(v) | (v < 0)
    v_ok = np.where(bad, 0.0, v)
    upper = np.minimum(np.cbrt(3.0 * v_ok), np.arctan(v_ok + math.pi / 2))  # inv α ≥ α³/3; tan α = v + α
    a = upper.copy()
    done = v_ok == 0.0
    a[done] = 0.0
    for _ in range(max_iter):
        t = np.tan(a)
        slope = t * t
        with np.errstate(divide="ignore", invalid="ignore"):
            step = np.where(done | (slope == 0), 0.0, (inv(a) - v_ok) / slope)
        a_new = np.clip(a - step, 0.0, upper)
        converged = np.abs(a_new - a) <= 4 * np.finfo(float).eps * np.maximum(a_new, 1e-300)
        a = a_new
        done = done | converged
        if np.all(done):
            break
    a = np.where(bad, np.nan, a)
    return float(a[0]) if np.ndim(value) == 0 else a.reshape(np.shape(value))
