"""The involute function inv α = tan α − α and its inverse, accurate to a few units of the last place.

`inv` sums the Taylor series of tan α − α below 0.3 rad (where tan α − α loses digits to cancellation)
and uses tan α − α above; `arcinv` solves inv α = v by Newton's method from an upper bound of the root
(inv is convex and increasing on [0, π/2), so Newton from above approaches the root monotonically and
cannot overshoot), to a relative error below 1e-15. Both take numpy arrays (any shape) or floats.

    >>> from mbplanar.gears.involute import inv, arcinv
    >>> import math
    >>> round(float(inv(math.radians(20))), 12)
    0.014904383867
    >>> round(math.degrees(float(arcinv(0.034316))), 4)
    26.0886
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

__all__ = ["inv", "arcinv", "SERIES_LIMIT"]

SERIES_LIMIT = 0.3          # rad: below, the series; above, tan α − α (relative error ≲ 3·eps/α²)


def _tan_series_coefficients(terms: int) -> tuple[float, ...]:
    """Coefficients c_k of tan x − x = Σ c_k x^(2k+1), k = 1 … terms, from the tangent numbers
    (exact integers: T₁ = 1, T₃ = 2, T₅ = 16, …; the coefficient of x^(2n−1) in tan x is T/(2n−1)!)."""
    # Tangent numbers by the boustrophedon-like recurrence on the derivative polynomials of tan.
    poly = [0, 1]                       # d^0 tan / dx^0 as a polynomial in t = tan x: t
    out = []
    for n in range(1, 2 * terms + 2):
        # derivative of P(t) is P'(t)(1 + t²)
        deriv = [0] * (len(poly) + 1)
        for k, c in enumerate(poly):
            if k and c:
                deriv[k - 1] += k * c
                deriv[k + 1] += k * c
        poly = deriv
        if n % 2 == 1 and n >= 3:       # odd derivative at 0: the tangent number of order n
            out.append(float(Fraction(poly[0], math.factorial(n))))
        if len(out) == terms:
            break
    return tuple(out)


_COEFFICIENTS = _tan_series_coefficients(16)   # x³ … x³³: at 0.3 rad the last term is ~1e-19 of the sum


def inv(alpha):
    """The involute function tan α − α (α in radians, 0 ≤ α < π/2), elementwise.

    Parameters
    ----------
    alpha : float or array_like
        angles in radians.

    Returns
    -------
    float or numpy.ndarray
        tan α − α, with a relative error of a few 1e-16 (the series below `SERIES_LIMIT`).

    Examples
    --------
    >>> from mbplanar.gears.involute import inv
    >>> float(inv(0.0)), round(float(inv(0.5)), 12)
    (0.0, 0.046302489844)
    """
    a = np.asarray(alpha, dtype=float)
    small = np.abs(a) < SERIES_LIMIT
    a2 = a * a
    series = np.zeros_like(a)
    for c in reversed(_COEFFICIENTS):
        series = (series + c) * a2
    series = series * a                 # Σ c_k a^(2k+1)
    with np.errstate(invalid="ignore"):
        out = np.where(small, series, np.tan(a) - a)
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
