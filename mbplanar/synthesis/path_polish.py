"""The local stage of four-bar path generation: least squares from a screened design, and the design
constraints in closed form.

Untimed targets are fitted by orthogonal distances (variable projection): for the current design each
target's crank angle is the foot of its perpendicular on the coupler curve (`feet`: the nearest of a
sampled turn, refined by Newton's method on (P − t)·P' = 0), the residual is the signed distance along
the curve's normal there, and its derivative with respect to the design is the normal component of
∂P/∂design at that angle (the angle's own derivative drops out at the foot). The least squares then has
nine unknowns whatever the number of targets. Timed targets fit the coupler point at the crank angle
the timing gives (nine unknowns and the crank's angle at the first target).

The constraints enter as weighted residuals (a length each, zero when met), the weight growing ×100 twice
while the polished design misses one. For a crank that turns fully they are exact and smooth: the
crank-rocker condition |b − c| ≤ g − a, b + c ≥ g + a (g the ground), the smallest transmission angle
(at the two positions where the crank lies along the ground line) and the link ratio; a limited travel
measures them over sampled positions (`constraints.fourbar_violations`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .batch import fourbar_coupler_paths
from .constraints import PathConstraints, fourbar_violations
from .path_screen import shape_bounds

__all__ = ["Polished", "closed_form_violations", "violations", "feet", "polish_untimed", "polish_timed",
           "meets", "positive_lengths", "least_squares_fit", "constraint_bounds"]

TWO_PI = 2.0 * math.pi
WEIGHTS = (10.0, 1e3, 1e5)
MARGIN = 0.01
"""Polished designs are kept this far inside the constraints (a share of the crank-rocker slack, of the
ratio, and 0.05° of transmission angle), so that they meet them exactly."""
GRID = 64
"""Crank positions of the sampled turn that brackets each target's foot."""


@dataclass(frozen=True)
class Polished:
    """A polished design: `design` (10,), `phi` (T,) the crank angle at each target, `errors` (T,) the
    targets' distances from the coupler point there, `evaluations` (designs traced)."""

    design: np.ndarray
    phi: np.ndarray
    errors: np.ndarray
    evaluations: int

    @property
    def rms(self) -> float:
        return float(np.sqrt(np.mean(self.errors ** 2)))


def positive_lengths(design, phi_t):
    """The same four-bar with positive lengths: a negative crank is the crank turned by π, a negative
    coupler the coupler frame turned by π (u, v → −u, −v); the rocker enters squared."""
    d, phi_t = np.array(design, float), np.array(phi_t, float)
    if d[4] < 0:
        d[4], phi_t = -d[4], phi_t + math.pi
    if d[5] < 0:
        d[5], d[7], d[8] = -d[5], -d[7], -d[8]
    d[6] = abs(d[6])
    return d, phi_t


def closed_form_violations(c: PathConstraints, d, size: float, margin: float = MARGIN) -> np.ndarray:
    """How far crank-rocker designs d (K, 10) are from meeting `c` with a crank that turns fully, in
    lengths (K, 4): turn, link ratio, transmission angle (rad × size), pivot boxes; zero when met."""
    d = np.atleast_2d(np.asarray(d, float))
    a, b, cr = np.abs(d[:, 4]), np.abs(d[:, 5]), np.abs(d[:, 6])
    g = np.hypot(d[:, 2] - d[:, 0], d[:, 3] - d[:, 1])
    slack = g - a
    out = np.zeros((len(d), 4))
    out[:, 0] = (np.maximum(np.abs(b - cr) - (1.0 - margin) * slack, 0.0)
                 + np.maximum(g + a + margin * np.abs(slack) - (b + cr), 0.0) + np.maximum(-slack, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        mu, ratio = shape_bounds(d)
    if c.max_ratio is not None:
        excess = ratio / (c.max_ratio * (1.0 - margin)) - 1.0
        out[:, 1] = size * np.nan_to_num(np.maximum(excess, 0.0), nan=1e3, posinf=1e3)
    if c.min_transmission_deg is not None:
        need = math.radians(c.min_transmission_deg + margin * 5.0)
        out[:, 2] = size * np.maximum(need - np.radians(np.nan_to_num(mu, nan=0.0)), 0.0)
    out[:, 3] = _box_violations(c, d)
    return out


def _box_violations(c: PathConstraints, d) -> np.ndarray:
    out = np.zeros(len(d))
    for name, col in (("A0", 0), ("B0", 2)):
        box = c.box(name)
        if box is not None:
            xy = d[:, col:col + 2]
            out += np.hypot(*np.maximum(np.maximum(box[0] - xy, xy - box[1]), 0.0).T)
    return out


def violations(c: PathConstraints, d, size: float, travel=None, margin: float = MARGIN) -> np.ndarray:
    """Constraint violations (K, 4) of designs d (K, 10): closed form for a full turn, else measured on
    the crank angles `travel` ((P,) or (K, P)) where the loop must close."""
    if c.full_turn:
        return closed_form_violations(c, d, size, margin)
    a, b, _, ok = fourbar_coupler_paths(d, travel)
    return fourbar_violations(c, np.atleast_2d(d), a, b, ok, size, margin=margin)


def meets(c: PathConstraints, design, size: float, travel=None) -> bool:
    """Whether one design (10,) meets the constraints exactly (no margin)."""
    v = violations(c, np.asarray(design, float)[None], size, travel, margin=0.0)
    return bool(np.all(v <= 1e-12 * size))


def feet(design, targets, phi=None, grid: int = GRID, iterations: int = 3):
    """Feet of the perpendiculars from targets (T, 2) on the closed coupler curve of `design` (10,):
    crank angles (T,), the points (T, 2) and the curve's unit tangents there (T, 2). Each starts from the
    nearest of `grid` positions of a turn (or from `phi`, where nearer) and takes Newton steps on
    (P − t)·P' = 0 within one grid step."""
    t = np.asarray(targets, float)
    d = np.asarray(design, float)[None]
    ring = np.linspace(0.0, TWO_PI, grid, endpoint=False)
    _, _, p, ok = fourbar_coupler_paths(d, ring)
    gap = np.where(ok[0][:, None], np.hypot(p[0, :, None, 0] - t[:, 0], p[0, :, None, 1] - t[:, 1]), np.inf)
    x = ring[np.argmin(gap, axis=0)]
    if phi is not None:
        _, _, q, okq = fourbar_coupler_paths(d, phi)
        there = np.where(okq[0], np.hypot(*(q[0] - t).T), np.inf)
        x = np.where(there < gap.min(axis=0), phi, x)
    step_max = TWO_PI / grid
    h = 1e-5
    for k in range(iterations + 1):
        _, _, q, okq = fourbar_coupler_paths(d, np.concatenate([x, x - h, x + h]))
        q = q[0].reshape(3, len(t), 2)
        if k == iterations:
            break
        good = okq[0].reshape(3, len(t)).all(axis=0)
        v = (q[2] - q[1]) / (2 * h)
        acc = (q[2] - 2 * q[0] + q[1]) / (h * h)
        miss = q[0] - t
        slope = np.sum(v * v, axis=1) + np.sum(miss * acc, axis=1)
        grad = np.sum(miss * v, axis=1)
        step = np.where(good & (slope > 0), -grad / np.where(slope > 0, slope, 1.0), 0.0)
        x = x + np.clip(step, -step_max, step_max)
    tangent = q[2] - q[1]
    norm = np.hypot(*tangent.T)
    tangent = np.where(norm[:, None] > 0, tangent / np.where(norm > 0, norm, 1.0)[:, None], 0.0)
    return x, q[0], tangent


def _signed(points, tangent, targets) -> np.ndarray:
    """Signed distances (T,) of targets from the points along the curve's normal (the distance itself
    where the tangent is unknown)."""
    miss = points - targets
    normal = np.column_stack([-tangent[:, 1], tangent[:, 0]])
    along = np.sum(miss * normal, axis=1)
    known = np.hypot(*tangent.T) > 0
    return np.where(known, along, np.hypot(*miss.T))


def _design(z, mode):
    return np.r_[z[:9], mode]


def least_squares_fit(fun, jac, z, lo, hi, max_nfev):
    """scipy's least squares: MINPACK's Levenberg-Marquardt, or the trust-region reflective method where
    bounds apply; zero rows pad the residuals up to the unknowns (fewer targets than unknowns)."""
    from scipy.optimize import least_squares
    bounded = np.isfinite(np.r_[lo, hi]).any()
    if bounded:
        pad = 1e-12 * (np.abs(np.where(np.isfinite(lo), lo, 0.0)) + np.abs(np.where(np.isfinite(hi), hi, 0.0)) + 1.0)
        z = np.clip(z, np.where(np.isfinite(lo), lo + pad, -np.inf), np.where(np.isfinite(hi), hi - pad, np.inf))
    short = max(len(z) - len(fun(z)), 0)

    def f(u):
        return np.r_[fun(u), np.zeros(short)]

    def j(u):
        return np.vstack([jac(u), np.zeros((short, len(u)))])
    return least_squares(f, z, jac=j, method="trf" if bounded else "lm", x_scale="jac",
                         bounds=(lo, hi) if bounded else (-np.inf, np.inf),
                         xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=max_nfev)


def constraint_bounds(c: PathConstraints, n: int):
    """Bounds (n,) each of unknowns whose first four are the fixed pivots: their boxes, else none."""
    lo, hi = np.full(n, -np.inf), np.full(n, np.inf)
    for name, col in (("A0", 0), ("B0", 2)):
        box = c.box(name)
        if box is not None:
            lo[col:col + 2], hi[col:col + 2] = box
    return lo, hi


def _steps(z, size):
    """Finite-difference steps of the unknowns: 1e-7 of the targets' size for the design's nine numbers
    (coordinates and lengths, whatever the distance from the origin), 1e-7 rad for an angle."""
    h = np.full(len(z), 1e-7 * size)
    h[9:] = 1e-7
    return h


def polish_untimed(design, targets, c: PathConstraints, size: float, max_nfev: int = 60) -> Polished:
    """Least squares of the targets' orthogonal distances from the closed coupler curve of a crank that
    turns fully, from `design` (10,), with the constraints `c` as weighted residuals."""
    t = np.asarray(targets, float)
    mode = float(design[9])
    state = {"z": None, "phi": None}
    count = [0]

    def at(z):
        if state["z"] is None or not np.array_equal(state["z"], z):
            phi, p, tangent = feet(_design(z, mode), t, state["phi"])
            state.update(z=z.copy(), phi=phi, p=p, tangent=tangent)
            count[0] += 1
        return state

    z = np.asarray(design, float)[:9].copy()
    lo, hi = constraint_bounds(c, 9)
    for weight in WEIGHTS:
        def fun(u, weight=weight):
            s = at(u)
            v = closed_form_violations(c, _design(u, mode)[None], size)[0]
            return np.r_[_signed(s["p"], s["tangent"], t), weight * v]

        def jac(u, weight=weight):
            s = at(u)
            h = _steps(u, size)
            rows = np.vstack([u, u + np.diag(h)])
            designs = np.column_stack([rows, np.full(len(rows), mode)])
            _, _, p, _ = fourbar_coupler_paths(designs, s["phi"])
            normal = np.column_stack([-s["tangent"][:, 1], s["tangent"][:, 0]])
            dp = (p[1:] - p[0]) / h[:, None, None]                                   # (9, T, 2)
            known = np.hypot(*s["tangent"].T) > 0
            miss = s["p"] - t
            radial = miss / np.maximum(np.hypot(*miss.T), 1e-300)[:, None]
            direction = np.where(known[:, None], normal, radial)
            dist = np.einsum("jtk,tk->tj", dp, direction)
            v = closed_form_violations(c, designs, size)
            dv = ((v[1:] - v[0]) / h[:, None]).T * weight
            count[0] += len(rows)
            return np.vstack([dist, dv])
        res = least_squares_fit(fun, jac, z, lo, hi, max_nfev)
        z = res.x
        if meets(c, _design(z, mode), size):
            break
    s = at(z)
    final, phi = positive_lengths(_design(z, mode), s["phi"])
    _, _, p, _ = fourbar_coupler_paths(final[None], phi)
    return Polished(final, phi, np.hypot(*(p[0] - t).T), count[0])


def polish_timed(design, phase: float, targets, timing, c: PathConstraints, size: float,
                 travel=None, max_nfev: int = 60) -> Polished:
    """Least squares of the coupler point's misses at the timed crank angles phase + timing (T,), in the
    design's nine numbers and the phase, with the constraints `c` (a limited travel: sampled over
    `travel`, a function of the phase) as weighted residuals."""
    t = np.asarray(targets, float)
    timing = np.asarray(timing, float)
    mode = float(design[9])
    count = [0]

    def residuals(rows, weight):
        designs = np.column_stack([rows[:, :9], np.full(len(rows), mode)])
        _, _, p, ok = fourbar_coupler_paths(designs, rows[:, 9:10] + timing[None, :])
        miss = np.where(ok[..., None], p - t, size).reshape(len(rows), -1)
        span = None if travel is None else travel(rows[:, 9])
        v = violations(c, designs, size, span)
        count[0] += len(rows)
        return np.column_stack([miss, weight * v])

    z = np.r_[np.asarray(design, float)[:9], phase]
    lo, hi = constraint_bounds(c, 10)
    for weight in WEIGHTS:
        def fun(u, weight=weight):
            return residuals(u[None], weight)[0]

        def jac(u, weight=weight):
            h = _steps(u, size)
            r = residuals(np.vstack([u, u + np.diag(h)]), weight)
            return ((r[1:] - r[0]) / h[:, None]).T
        res = least_squares_fit(fun, jac, z, lo, hi, max_nfev)
        z = res.x
        span = None if travel is None else travel(z[9:10])
        if meets(c, _design(z, mode), size, span):
            break
    final, phi = positive_lengths(_design(z, mode), z[9] + timing)
    _, _, p, _ = fourbar_coupler_paths(final[None], phi)
    return Polished(final, phi, np.hypot(*(p[0] - t).T), count[0])
