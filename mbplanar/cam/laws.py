"""Motion laws of a cam follower in closed form, and motion programs built from them.

A *law* is a normalised shape y(u) on u ∈ [0, 1] with y(0) = 0, y(1) = 1; it returns y and its first
three derivatives with respect to u. A *segment* scales a law to a stroke over a cam angle β:
s = s₀ + Δs·y(u), u = (φ − φ₀)/β, so v = ds/dφ = Δs·y′/β, a = Δs·y″/β², j = Δs·y‴/β³ (the analogues:
derivatives with respect to the cam angle). A return is the rise mirrored in time, s = s_end + Δ·y(1 − u)
(the seed's convention for the asymmetric constant-acceleration law: the return starts with the small
deceleration and ends with the large one).

A *program* is a sequence of segments covering 360° (rise, dwell, return, dwell, ...). Its continuity
report lists every angle where s, v or a jumps: a jump of v is infinite acceleration, a jump of a is
infinite jerk (warnings); a jump of s is an error.

Peak coefficients C_v = max|y′|, C_a = max|y″|, C_j = max|y‴| are measured on each law (dense grid
through its breakpoints, then a bounded golden-section refinement), not copied from tables.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError, did_you_mean

__all__ = ["Law", "PiecewiseSineLaw", "PolynomialLaw", "CycloidalLaw", "HarmonicLaw", "Segment",
           "Program", "Jump", "program", "LAWS", "make_law", "dwell", "constant_velocity", "constant_acceleration",
           "simple_harmonic", "cycloidal", "polynomial_345", "polynomial_4567", "modified_trapezoid",
           "modified_sine", "polynomial_through", "peak_coefficients"]


class Law:
    """A normalised motion law y(u), u ∈ [0, 1]; subclasses implement `derivatives`."""

    #: inner breakpoints (u values where the law changes piece); subclasses with pieces set it
    breakpoints = ()

    def derivatives(self, u: np.ndarray) -> np.ndarray:
        """y, y′, y″, y‴ at u (array of shape (4,) + u.shape)."""
        raise NotImplementedError

    @property
    def jumps(self) -> tuple[int, ...]:
        """Orders of derivative (1 = y′, 2 = y″) that jump inside (0, 1)."""
        out = []
        for b in self.breakpoints:
            left, right = self.derivatives(np.array([b - 1e-12, b + 1e-12])).T
            for order in (1, 2):
                if abs(left[order] - right[order]) > 1e-6 * (1 + abs(left[order])):
                    out.append(order)
        return tuple(sorted(set(out)))

    def peaks(self) -> tuple[float, float, float]:
        """(C_v, C_a, C_j); a derivative is infinite when the one below it jumps inside the law.
        Measured once per law (laws are frozen and hashable)."""
        return _peaks(self)


@functools.lru_cache(maxsize=64)
def _peaks(law: Law) -> tuple[float, float, float]:
    cv, ca, cj = peak_coefficients(law)
    jumps = law.jumps
    return (cv, math.inf if 1 in jumps else ca, math.inf if 1 in jumps or 2 in jumps else cj)


def peak_coefficients(law: Law, samples: int = 4001) -> tuple[float, float, float]:
    """max|y′|, max|y″|, max|y‴| over [0, 1]: the largest grid value refined by golden section."""
    from scipy.optimize import minimize_scalar
    grid = np.unique(np.concatenate([np.linspace(0.0, 1.0, samples), law.breakpoints]))
    values = np.abs(law.derivatives(grid))
    out = []
    for order in (1, 2, 3):
        i = int(np.argmax(values[order]))
        best = values[order, i]
        lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
        # stay inside one piece: a breakpoint is a grid point, so the bracket never straddles one
        # unless the maximum sits on it (then the grid value is exact)
        if hi > lo:
            res = minimize_scalar(lambda x: -abs(float(law.derivatives(np.array([x]))[order, 0])),
                                  bounds=(lo, hi), method="bounded", options={"xatol": 1e-13})
            best = max(best, -float(res.fun))
        out.append(float(best))
    return tuple(out)


@dataclass(frozen=True)
class PiecewiseSineLaw(Law):
    """A law whose acceleration is c + A·sin(ω t + p) on each piece (t from the piece's start).

    `pieces` rows are (u_start, c, A, ω, p); the last piece ends at u = 1. The shape is integrated in
    closed form from y(0) = 0, y′(0) = `v0`, then scaled so that y(1) = 1. Constant acceleration,
    modified trapezoid, modified sine and constant velocity are of this form.
    """

    name: str
    pieces: tuple[tuple[float, float, float, float, float], ...]
    v0: float = 0.0
    _start: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        rows = np.array(self.pieces, float)
        ends = np.append(rows[1:, 0], 1.0)
        s0, v0, states = 0.0, self.v0, []
        for (u0, c, amp, w, p), u1 in zip(rows, ends):
            states.append((s0, v0))
            s, v, _, _ = _sine_piece(np.array(u1 - u0), c, amp, w, p, s0, v0)
            s0, v0 = float(s), float(v)
        scale = 1.0 / s0
        table = np.column_stack([rows[:, 0], rows[:, 1] * scale, rows[:, 2] * scale, rows[:, 3], rows[:, 4],
                                 np.array(states)[:, 0] * scale, np.array(states)[:, 1] * scale])
        object.__setattr__(self, "_start", table)
        object.__setattr__(self, "breakpoints", tuple(float(x) for x in rows[1:, 0]))

    def derivatives(self, u):
        u = np.asarray(u, float)
        k = np.clip(np.searchsorted(self._start[:, 0], u, side="right") - 1, 0, len(self._start) - 1)
        u0, c, amp, w, p, s0, v0 = (self._start[k, i] for i in range(7))
        return np.stack(_sine_piece(u - u0, c, amp, w, p, s0, v0))


def _sine_piece(t, c, amp, w, p, s0, v0):
    """s, v, a, j of a piece with acceleration c + amp·sin(w t + p), from s0, v0 at t = 0."""
    w_safe = np.where(w == 0, 1.0, w)
    a = c + amp * np.sin(w * t + p)
    j = amp * w * np.cos(w * t + p)
    v = v0 + c * t - amp / w_safe * (np.cos(w * t + p) - np.cos(p))
    s = (s0 + v0 * t + c * t * t / 2
         - amp / w_safe * ((np.sin(w * t + p) - np.sin(p)) / w_safe - t * np.cos(p)))
    return s, v, a, j


@dataclass(frozen=True)
class PolynomialLaw(Law):
    """y(u) = Σ c_i u^i (coefficients from the constant term up)."""

    name: str
    coefficients: tuple[float, ...]

    def derivatives(self, u):
        u = np.asarray(u, float)
        p = np.polynomial.Polynomial(self.coefficients)
        return np.stack([p(u), p.deriv(1)(u), p.deriv(2)(u), p.deriv(3)(u)])


@dataclass(frozen=True)
class CycloidalLaw(Law):
    """y = u − sin(2πu)/(2π): zero acceleration at both ends."""

    name: str = "cycloidal"

    def derivatives(self, u):
        u = np.asarray(u, float)
        x = 2 * np.pi * u
        return np.stack([u - np.sin(x) / (2 * np.pi), 1 - np.cos(x), 2 * np.pi * np.sin(x),
                         4 * np.pi ** 2 * np.cos(x)])


@dataclass(frozen=True)
class HarmonicLaw(Law):
    """y = (1 − cos πu)/2: finite acceleration at both ends (jumps to a dwell)."""

    name: str = "simple_harmonic"

    def derivatives(self, u):
        u = np.asarray(u, float)
        x = np.pi * u
        return np.stack([(1 - np.cos(x)) / 2, np.pi / 2 * np.sin(x), np.pi ** 2 / 2 * np.cos(x),
                         -np.pi ** 3 / 2 * np.sin(x)])


def polynomial_through(start, end) -> PolynomialLaw:
    """The lowest-degree polynomial y(u) with y^(i)(0) = start[i] and y^(i)(1) = end[i] (normalised)."""
    start, end = list(map(float, start)), list(map(float, end))
    n = len(start) + len(end)
    rows, rhs = [], []
    for x, values in ((0.0, start), (1.0, end)):
        for order, value in enumerate(values):
            row = [0.0] * n
            for i in range(order, n):
                row[i] = math.prod(range(i - order + 1, i + 1)) * x ** (i - order)
            rows.append(row)
            rhs.append(value)
    coeffs = np.linalg.solve(np.array(rows), np.array(rhs))
    return PolynomialLaw("polynomial", tuple(float(c) for c in coeffs))


def dwell() -> PolynomialLaw:
    """No motion (a segment with zero stroke)."""
    return PolynomialLaw("dwell", (0.0,))


def constant_velocity() -> PiecewiseSineLaw:
    """y = u: infinite acceleration where it meets a dwell."""
    return PiecewiseSineLaw("constant_velocity", ((0.0, 0.0, 0.0, 0.0, 0.0),), v0=1.0)


def constant_acceleration(k: float = 1.0) -> PiecewiseSineLaw:
    """Acceleration a₁ on the first 1/(k+1) of the segment, −a₁/k on the rest (k = a₁/a₂).

    Normalised a₁ = 2(k + 1) (the seed's a_q1 = 2(k+1)h/φ²).
    """
    if not k > 0:
        raise ModelError(f"constant acceleration: the asymmetry k = a1/a2 must be positive, got {k}")
    a1 = 2.0 * (k + 1.0)
    return PiecewiseSineLaw("constant_acceleration", ((0.0, a1, 0.0, 0.0, 0.0),
                                                      (1.0 / (k + 1.0), -a1 / k, 0.0, 0.0, 0.0)))


def simple_harmonic() -> HarmonicLaw:
    """y = (1 − cos πu)/2."""
    return HarmonicLaw()


def cycloidal() -> CycloidalLaw:
    """y = u − sin(2πu)/(2π)."""
    return CycloidalLaw()


def polynomial_345() -> PolynomialLaw:
    """y = 10u³ − 15u⁴ + 6u⁵ (zero v and a at both ends)."""
    return PolynomialLaw("polynomial_345", (0.0, 0.0, 0.0, 10.0, -15.0, 6.0))


def polynomial_4567() -> PolynomialLaw:
    """y = 35u⁴ − 84u⁵ + 70u⁶ − 20u⁷ (zero v, a and j at both ends)."""
    return PolynomialLaw("polynomial_4567", (0.0, 0.0, 0.0, 0.0, 35.0, -84.0, 70.0, -20.0))


def modified_trapezoid() -> PiecewiseSineLaw:
    """Constant-acceleration plateaus joined by quarter and half sine waves (eighths of the segment)."""
    w, half = 4 * np.pi, np.pi / 2
    return PiecewiseSineLaw("modified_trapezoid", (
        (0.0, 0.0, 1.0, w, 0.0), (0.125, 1.0, 0.0, 0.0, 0.0), (0.375, 0.0, 1.0, w, half),
        (0.625, -1.0, 0.0, 0.0, 0.0), (0.875, 0.0, -1.0, w, half)))


def modified_sine() -> PiecewiseSineLaw:
    """Quarter sine waves of period 1/2 at the ends joined by a half wave of period 3/2."""
    w, half = 4 * np.pi, np.pi / 2
    return PiecewiseSineLaw("modified_sine", (
        (0.0, 0.0, 1.0, w, 0.0), (0.125, 0.0, 1.0, w / 3, half), (0.875, 0.0, -1.0, w, half)))


LAWS = {
    "dwell": dwell, "constant_velocity": constant_velocity, "constant_acceleration": constant_acceleration,
    "simple_harmonic": simple_harmonic, "cycloidal": cycloidal, "polynomial_345": polynomial_345,
    "polynomial_4567": polynomial_4567, "modified_trapezoid": modified_trapezoid,
    "modified_sine": modified_sine,
}


def make_law(name: str, **options) -> Law:
    """A motion law by name: a normalised shape y(u) on [0, 1] with y(0) = 0 and y(1) = 1.

    Parameters
    ----------
    name : str
        One of `LAWS`: "dwell", "constant_velocity", "constant_acceleration", "simple_harmonic",
        "cycloidal", "polynomial_345", "polynomial_4567", "modified_trapezoid", "modified_sine".
    **options
        ``k`` for "constant_acceleration": the ratio of its acceleration to its deceleration.

    Returns
    -------
    Law
        `derivatives(u)` gives y and its first three derivatives; `peaks()` the peak coefficients
        C_v, C_a, C_j (measured on the law).

    Raises
    ------
    ModelError
        An unknown name (the message gives the closest).
    TypeError
        An option the law does not take.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.cam import make_law
    >>> np.round(make_law("cycloidal").peaks(), 6).tolist()         # 2, 2π, 4π²
    [2.0, 6.283185, 39.478418]
    >>> np.round(make_law("polynomial_345").peaks(), 6).tolist()    # 15/8, 10/√3, 60
    [1.875, 5.773503, 60.0]
    """
    if name not in LAWS:
        raise ModelError(f"unknown motion law '{name}'; {did_you_mean(name, list(LAWS) + ['polynomial'], 'laws')}")
    return LAWS[name](**options)


@dataclass(frozen=True)
class Segment:
    """One phase of a motion program: a law scaled from displacement `s_start` to `s_end` over the cam
    angles `start` … `start + span`.

    s = s_start + (s_end − s_start)·y(u), u = (φ − start)/span. A `PolynomialLaw` built with
    `physical=True` boundary values is given in (s, v, a, ...) units and scaled by the segment (see
    `Segment.through`).

    Attributes
    ----------
    kind : str
        "rise", "dwell", "return" or "polynomial".
    law : Law
        The normalised shape.
    start, span : float
        Cam angles, rad.
    s_start, s_end : float
        Displacements at its ends, m.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.cam import Segment, make_law
    >>> rise = Segment("rise", make_law("cycloidal"), 0.0, np.pi / 2, 0.0, 0.02)
    >>> np.round(rise.peaks, 6).tolist()            # peak |v|, |a|, |j|: 2h/β, 2πh/β², 4π²h/β³
    [0.025465, 0.05093, 0.203718]
    >>> np.round(rise.evaluate(np.array([np.pi / 4]))[:, 0], 6).tolist()      # s, v, a, j at mid-rise
    [0.01, 0.025465, 0.0, -0.203718]
    """

    kind: str                 # "rise", "return", "dwell" or "polynomial"
    law: Law
    start: float
    span: float
    s_start: float
    s_end: float

    @classmethod
    def through(cls, start, span, s_from, s_to) -> "Segment":
        """A polynomial segment through physical boundary values: s_from = (s, v, a, ...) at the start,
        s_to at the end, v in m/rad, a in m/rad², ... ."""
        scale = [span ** i for i in range(max(len(s_from), len(s_to)))]
        y0 = [s_from[0]] + [s_from[i] * scale[i] for i in range(1, len(s_from))]
        y1 = [s_to[0]] + [s_to[i] * scale[i] for i in range(1, len(s_to))]
        law = polynomial_through(y0, y1)
        return cls("polynomial", law, start, span, 0.0, 1.0)

    def evaluate(self, phi: np.ndarray) -> np.ndarray:
        """s, v, a, j (shape (4,) + phi.shape) at cam angles phi inside the segment."""
        u = (np.asarray(phi, float) - self.start) / self.span
        delta = self.s_end - self.s_start
        if self.kind == "return":
            y = self.law.derivatives(1.0 - u) * np.array([1, -1, 1, -1]).reshape((4,) + (1,) * u.ndim)
            base, delta = self.s_end, -delta
        else:
            y = self.law.derivatives(u)
            base = self.s_start
        scale = np.array([1, 1 / self.span, 1 / self.span ** 2, 1 / self.span ** 3])
        out = delta * y * scale.reshape((4,) + (1,) * u.ndim)
        out[0] += base
        return out

    @property
    def peaks(self) -> tuple[float, float, float]:
        """Peak |v|, |a|, |j| of the segment in m/rad, m/rad², m/rad³ (inf where unbounded)."""
        cv, ca, cj = self.law.peaks()
        d = abs(self.s_end - self.s_start)           # a polynomial segment: 1 (its law is in metres)
        return (d * cv / self.span, d * ca / self.span ** 2, d * cj / self.span ** 3)


@dataclass(frozen=True)
class Jump:
    """A discontinuity of the program: `order` 0 = s, 1 = v (infinite a), 2 = a (infinite j)."""

    angle: float
    order: int
    size: float

    @property
    def message(self) -> str:
        what = ("displacement", "velocity", "acceleration")[self.order]
        effect = ("the follower would jump", "infinite acceleration (a hard impact)",
                  "infinite jerk (a soft impact)")[self.order]
        return (f"{what} jumps by {self.size:.6g} at cam angle {math.degrees(self.angle):.6g}°: "
                f"{effect}")


@dataclass(frozen=True)
class Program:
    """Segments covering one turn of the cam, in order from cam angle 0.

    `evaluate(phi)` gives s, v, a, j (m, m/rad, m/rad², m/rad³) at any cam angles; `stroke` the
    largest minus the smallest displacement; `continuity()` every jump of s, v or a; `grid(samples)`
    equal steps with every breakpoint.

    Attributes
    ----------
    segments : tuple of Segment
        The phases, their spans adding up to 2π.

    Raises
    ------
    ModelError
        On construction, when the spans do not add up to 360°.

    Examples
    --------
    A constant-velocity rise and return: the velocity jumps at both ends, hard impacts:

    >>> import numpy as np
    >>> from mbplanar.cam import make_law, program
    >>> line = make_law("constant_velocity")
    >>> p = program([("rise", line, np.pi, 0.02), ("return", line, np.pi, 0.02)])
    >>> [j.message.split(":")[0] for j in p.continuity()]
    ['velocity jumps by 0.0127324 at cam angle 0°', 'velocity jumps by -0.0127324 at cam angle 180°']
    """

    segments: tuple[Segment, ...]

    def __post_init__(self):
        total = sum(seg.span for seg in self.segments)
        if abs(total - 2 * np.pi) > 1e-9:
            raise ModelError(f"the phases add up to {math.degrees(total):.6g}°, not 360°")

    @property
    def stroke(self) -> float:
        """Largest minus smallest displacement over the cycle (m)."""
        ends = [v for seg in self.segments for v in (seg.s_start, seg.s_end)]
        return max(ends) - min(ends)

    @property
    def starts(self) -> np.ndarray:
        return np.array([seg.start for seg in self.segments])

    def evaluate(self, phi) -> np.ndarray:
        """s, v, a, j at cam angles `phi` (rad, any; taken modulo 2π): shape (4,) + phi.shape."""
        phi = np.mod(np.asarray(phi, float), 2 * np.pi)
        k = np.clip(np.searchsorted(self.starts, phi, side="right") - 1, 0, len(self.segments) - 1)
        out = np.zeros((4,) + phi.shape)
        for i, seg in enumerate(self.segments):
            mask = k == i
            if np.any(mask):
                out[:, mask] = seg.evaluate(phi[mask])
        return out

    def breakpoints(self) -> np.ndarray:
        """Cam angles (rad) where a segment starts or a law changes piece."""
        pts = [seg.start + seg.span * (1 - b if seg.kind == "return" else b)
               for seg in self.segments for b in seg.law.breakpoints]
        return np.unique(np.mod(np.concatenate([self.starts, pts]), 2 * np.pi))

    def grid(self, samples: int = 1440) -> np.ndarray:
        """`samples` equal steps over [0, 2π) plus every breakpoint (a grid point closer than 1e-6 of a
        step to a breakpoint is dropped, so no interval is tiny)."""
        even = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)
        cuts = self.breakpoints()
        gap = np.min(np.abs(even[:, None] - np.concatenate([cuts, cuts + 2 * np.pi])[None, :]), axis=1)
        return np.unique(np.concatenate([even[gap > 1e-6 * 2 * np.pi / samples], cuts]))

    def continuity(self) -> tuple[Jump, ...]:
        """Every jump of s, v or a at a segment boundary or a law's breakpoint."""
        out = []
        for b in self.breakpoints():
            left = self._one_sided(b, -1)
            right = self._one_sided(b, +1)
            for order in (0, 1, 2):
                size = float(right[order] - left[order])
                if abs(size) > 1e-7 * max(self.stroke, 1e-300):
                    out.append(Jump(float(b), order, size))
        return tuple(out)

    def _one_sided(self, phi, side) -> np.ndarray:
        """s, v, a at φ approached from one side (`side` ±1): the value just beside it, carried to φ
        by its own derivative (first-order Taylor step of 1e-10 rad)."""
        eps = 1e-10
        near = self.evaluate(np.array([phi + side * eps]))[:, 0]
        return near[:3] - side * eps * near[1:4]


def program(segments) -> Program:
    """A `Program` from rows (kind, law, span, stroke): starts and displacements accumulate from cam
    angle 0 and lift 0.

    Parameters
    ----------
    segments : iterable of tuple
        (kind, law, span (rad), stroke (m)) rows: a rise adds its stroke, a return takes it off,
        a dwell keeps the lift (its stroke None).

    Returns
    -------
    Program
        The program.

    Raises
    ------
    ModelError
        Spans that do not add up to 360°.
    TypeError
        A rise or return without a stroke.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.cam import make_law, program
    >>> cyc, dwell = make_law("cycloidal"), make_law("dwell")
    >>> p = program([("rise", cyc, np.pi / 2, 0.02), ("dwell", dwell, np.pi / 2, None),
    ...              ("return", cyc, np.pi / 2, 0.02), ("dwell", dwell, np.pi / 2, None)])
    >>> p.stroke, [(s.kind, s.s_start, s.s_end) for s in p.segments][:3], p.continuity()
    (0.02, [('rise', 0.0, 0.02), ('dwell', 0.02, 0.02), ('return', 0.02, 0.0)], ())
    """
    out, start, s = [], 0.0, 0.0
    for kind, law, span, stroke in segments:
        end = s + stroke if kind == "rise" else s - stroke if kind == "return" else s
        out.append(Segment(kind, law, start, span, s, end))
        start, s = start + span, end
    return Program(tuple(out))
