"""The curves of the higher pairs, evaluated: a cam's profile, a slot's path, as functions c(u) of a
parameter u with their derivatives, vectorised over a batch of parameter values.

A `Curve` (`mbplanar.model._model`) is data: a circle (or an arc of one), or points with an optional
parameter. `shape(curve)` gives its `Shape`: `point(u, n)` is dⁿc/duⁿ (2, B) for n = 0 … 3, `closest(p)`
the parameter of the point nearest to p. A circle is c(u) = centre + R·(cos u, sin u), u the angle (rad)
from +x; a spline is scipy's interpolating B-spline (`make_interp_spline`, degree 3 or 5, periodic when
closed) through the points at their parameter values (by default the cumulative chord length, in
metres). A closed curve repeats with its period; an open one ends at `lo` and `hi`.

The offset of a curve by a distance d along its left normal (`Offset`, the path of a roller's centre
over a cam's profile) is a curve too: o = c + d·n, o' = c'·(1 − d·κ), o'' = c''·(1 − d·κ) − d·κ'·c',
o''' likewise, κ the signed curvature.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ModelError
from ._model import Curve

__all__ = ["Shape", "Circle", "Spline", "Offset", "shape", "curvature"]


class Shape:
    """A curve c(u) with its derivatives: `point(u, n)` (2, B) for u (B,); `lo`, `hi` the parameter's
    range (one period of a closed curve); `closed`; `scale` how far (m) the point moves per unit of u,
    typically (for the solver's scaling).

    The base of `Circle`, `Spline` and `Offset`; `wrap` takes a parameter into one period, `inside`
    says whether it lies on an open curve, `closest` finds the point nearest to another.

    Examples
    --------
    >>> from mbplanar.model import Circle
    >>> circle = Circle((0.0, 0.0), 0.5)
    >>> u, distance = circle.closest((2.0, 2.0))                 # the nearest point: at 45°, 2.33 m away
    >>> round(u, 6), round(distance, 6)
    (0.785398, 2.328427)
    """

    closed: bool = False
    lo: float = 0.0
    hi: float = 1.0
    scale: float = 1.0

    @property
    def period(self) -> float:
        return self.hi - self.lo

    def point(self, u, n: int = 0) -> np.ndarray:
        raise NotImplementedError

    def wrap(self, u):
        """u taken into [lo, hi) for a closed curve, unchanged for an open one."""
        if not self.closed:
            return np.asarray(u, float)
        return self.lo + np.mod(np.asarray(u, float) - self.lo, self.period)

    def inside(self, u, slack: float = 0.0) -> np.ndarray:
        """Whether u lies on the curve (always, closed), within `slack` of its ends."""
        u = np.asarray(u, float)
        if self.closed:
            return np.isfinite(u)
        return (u >= self.lo - slack) & (u <= self.hi + slack)

    def closest(self, p, samples: int = 2048) -> tuple[float, float]:
        """(u, distance) of the point of the curve nearest to p (2,): the best of `samples` points,
        polished by Newton on (c(u) − p)·c'(u) = 0 within its range."""
        p = np.asarray(p, float)
        u = np.linspace(self.lo, self.hi, samples + 1)
        if self.closed:
            u = u[:-1]
        d = self.point(u) - p[:, None]
        k = int(np.argmin(d[0] ** 2 + d[1] ** 2))
        x = float(u[k])
        for _ in range(50):
            c, c1, c2 = (self.point(np.array([x]), n)[:, 0] for n in range(3))
            g = float(np.dot(c - p, c1))
            h = float(np.dot(c1, c1) + np.dot(c - p, c2))
            if h <= 0:
                break
            step = -g / h
            x_new = x + step if self.closed else min(max(x + step, self.lo), self.hi)
            if abs(x_new - x) <= 1e-15 * (1 + abs(x)) * self.period:
                x = x_new
                break
            x = x_new
        c = self.point(np.array([x]))[:, 0]
        return x, float(np.hypot(*(c - p)))


class Circle(Shape):
    """A circle of `radius` (m) about `centre` (2,), or the arc `arc` (rad, (start, end)) of it: u is the
    angle from +x; closed unless it is an arc.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.model import Circle
    >>> circle = Circle((1.0, 0.0), 0.5)
    >>> circle.point(np.radians([0.0, 90.0])).round(3)         # c(u): (2, B)
    array([[1.5, 1. ],
           [0. , 0.5]])
    >>> circle.point(np.radians([90.0]), 1).round(3).ravel().tolist()   # c'(u) at 90°, m/rad
    [-0.5, 0.0]
    """

    def __init__(self, centre, radius: float, arc=None):
        self.centre = np.asarray(centre, float)
        self.radius = float(radius)
        self.closed = arc is None
        self.lo, self.hi = (0.0, 2 * math.pi) if arc is None else (float(arc[0]), float(arc[1]))
        self.scale = self.radius

    def point(self, u, n: int = 0) -> np.ndarray:
        u = np.asarray(u, float)
        c, s = np.cos(u), np.sin(u)
        # the n-th derivative of (cos u, sin u) is the vector turned by n·90°
        turned = [(c, s), (-s, c), (-c, -s), (s, -c)][n % 4]
        out = self.radius * np.stack(turned)
        if n == 0:
            out[0] += self.centre[0]
            out[1] += self.centre[1]
        return out


class Spline(Shape):
    """scipy's interpolating B-spline through `points` (N, 2) at `parameter` (N,), periodic when closed.

    The parameter is the cumulative chord length (m) unless given; `degree` 3 or 5. A `ModelError` when
    the parameter does not increase strictly or there are too few points for the degree.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.model import Spline
    >>> line = Spline([(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (3.0, 0.0), (4.0, 0.0), (5.0, 0.0)])
    >>> line.lo, line.hi, line.point(np.array([2.5])).round(6).ravel().tolist()
    (0.0, 5.0, [2.5, 0.0])
    >>> Spline([(0.0, 0.0), (1.0, 0.0)])
    Traceback (most recent call last):
    mbplanar.errors.ModelError: a spline of degree 5 needs at least 6 points, got 2
    """

    def __init__(self, points, parameter=None, closed: bool = False, degree: int = 5):
        from scipy.interpolate import make_interp_spline
        pts = np.asarray(points, float)
        if closed and not (len(pts) > 1 and np.allclose(pts[0], pts[-1], rtol=0, atol=1e-12 * np.ptp(pts))):
            pts = np.vstack([pts, pts[:1]])       # closed: back at the first point after the last
        if parameter is None:
            t = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])
        else:
            t = np.asarray(parameter, float)
        if len(t) != len(pts):
            extra = " (a closed curve: one more, where it is back at its first point)" if closed else ""
            raise ModelError(f"'parameter' has {len(t)} values for {len(pts)} points{extra}")
        if np.any(np.diff(t) <= 0):
            raise ModelError("the curve's parameter must increase strictly along its points (two points "
                             "coincide?)")
        given = len(pts) - (1 if closed else 0)
        if given < degree + 1:
            raise ModelError(f"a spline of degree {degree} needs at least {degree + 1} points, got {given}")
        self.closed = closed
        self.lo, self.hi = float(t[0]), float(t[-1])
        self.spline = make_interp_spline(t, pts, k=degree, bc_type="periodic" if closed else None)
        self.derivatives = [self.spline] + [self.spline.derivative(n) for n in (1, 2, 3)]
        speed = np.hypot(*self.derivatives[1](np.linspace(self.lo, self.hi, 64)).T)
        self.scale = float(np.median(speed)) or 1.0

    def point(self, u, n: int = 0) -> np.ndarray:
        return self.derivatives[n](self.wrap(u)).T


def curvature(d1: np.ndarray, d2: np.ndarray, d3: np.ndarray | None = None):
    """Signed curvature κ (B,) of a curve from c', c'' (2, B) (positive turning left), and with c'''
    its derivative dκ/du."""
    speed2 = d1[0] ** 2 + d1[1] ** 2
    speed3 = speed2 * np.sqrt(speed2)      # (no fifth power: it would underflow on a tiny drawing)
    cross = d1[0] * d2[1] - d1[1] * d2[0]
    kappa = cross / speed3
    if d3 is None:
        return kappa
    dot12 = d1[0] * d2[0] + d1[1] * d2[1]
    dkappa = ((d1[0] * d3[1] - d1[1] * d3[0]) - 3.0 * cross * (dot12 / speed2)) / speed3
    return kappa, dkappa


class Offset(Shape):
    """The curve `base` moved by `distance` along its left normal n = perp(c')/|c'| (a negative distance
    moves it right): the path of a roller's centre over a cam's profile.

    It gives its point and first two derivatives (`point(u, n)` for n ≤ 2); `stretch` is 1 − d·κ,
    not positive where the offset folds back (undercut).

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.model import Circle, Offset
    >>> roller_path = Offset(Circle((0.0, 0.0), 0.04), -0.01)  # a 10 mm roller outside a 40 mm circle
    >>> roller_path.point(np.array([0.0])).round(6).ravel().tolist()
    [0.05, 0.0]
    >>> float(roller_path.stretch(np.array([0.0]))[0])         # 1 + 0.01/0.04
    1.25
    """

    def __init__(self, base: Shape, distance: float):
        self.base, self.distance = base, float(distance)
        self.closed, self.lo, self.hi, self.scale = base.closed, base.lo, base.hi, base.scale

    def point(self, u, n: int = 0) -> np.ndarray:
        b = self.base
        d1 = b.point(u, 1)
        speed = np.sqrt(d1[0] * d1[0] + d1[1] * d1[1])    # (not hypot: complex numbers too)
        if n == 0:
            return b.point(u) + self.distance * np.stack([-d1[1], d1[0]]) / speed
        d2, d3 = b.point(u, 2), b.point(u, 3)
        kappa, dkappa = curvature(d1, d2, d3)
        f = 1.0 - self.distance * kappa
        if n == 1:
            return d1 * f
        if n == 2:
            return d2 * f - self.distance * dkappa * d1
        raise ValueError("an offset curve gives its point and first two derivatives")

    def stretch(self, u) -> np.ndarray:
        """1 − d·κ (B,): where it is not positive the offset curve folds back (a roller too big for
        profile's bend: undercut)."""
        b = self.base
        return 1.0 - self.distance * curvature(b.point(u, 1), b.point(u, 2))


def shape(curve: Curve) -> Shape:
    """The `Shape` of a table's `Curve`."""
    if curve.kind == "circle":
        return Circle(curve.centre, curve.radius, curve.arc)
    return Spline(curve.points, curve.parameter, curve.closed, curve.degree)
