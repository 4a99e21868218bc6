"""The smallest cam that keeps the pressure angle within its limits (separate limits on rise and return).

Translating roller or knife follower: with s₀ = √(r₀² − e²), tan(σθ) = (σv − e)/(s₀ + s), so each cam
angle adds two half-planes in (e, s₀); the smallest r₀ = |(e, s₀)| is the point of their intersection
nearest the origin (or, for a given offset e, the smallest s₀).

Oscillating roller or knife follower (the seed's construction): in the pivot's frame (P at the origin,
the arm at the start along −x, ψ counter-clockwise) the contact normal passes through the roller centre
and is parallel to O − E, E = (l − σv)·e(ψ) being the point laid off on the arm (the seed's curve
x = −(l − v)cos ψ, y = (l − v)sin ψ is its mirror image). |θ| ≤ θ_max is again two half-planes for the
cam centre O at each cam angle; the admissible region is their intersection, and the smallest
r₀ = |O − B₀| is its point nearest the roller's start B₀ = (−l, 0). Then a_w = |O| and φ₂₀ is the angle
from P→O to the arm.

Flat face (translating): the profile's radius of curvature r_b + s + a must stay above `min_radius`, so
r_b = max(min_radius − s − a); the face must reach the contact points, σv from the axis.

Constraints are sampled at the program's angles and then resampled densely around the active ones, so
the answer does not depend on the grid to ~1e-12 m.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from .followers import Follower

__all__ = ["Sizing", "Construction", "size_follower", "pressure_limits"]


@dataclass(frozen=True)
class Construction:
    """The seed's graphical construction as data (pivot frame of the seed: arm at the start along −x).

    Attributes
    ----------
    curve : (N, 2) E(φ) = (−(l − σv)cos ψ, (l − σv) sin ψ), m
    arm : (N, 2) roller centre (−l cos ψ, l sin ψ), m
    region : (M, 2) vertices of the admissible region for the cam centre (clipped to a box), m
    centre : (2,) the chosen cam centre, m
    limits : (N,) the limit (rad) that applies at each sample, 0 where none
    """

    curve: np.ndarray
    arm: np.ndarray
    region: np.ndarray
    centre: np.ndarray
    limits: np.ndarray


@dataclass(frozen=True)
class Sizing:
    """The smallest follower layout found, and what it was asked to meet."""

    follower: Follower
    prime_radius: float
    rise_limit: float
    return_limit: float
    construction: Construction | None = None


def pressure_limits(v, rise_limit, return_limit) -> np.ndarray:
    """The limit at each sample: the rise limit where v > 0, the return limit where v < 0, else 0."""
    v = np.asarray(v, float)
    return np.where(v > 0, rise_limit, np.where(v < 0, return_limit, 0.0))


def size_follower(follower: Follower, program, rise_limit: float, return_limit: float, *,
                  free_offset: bool = True, min_radius: float | None = None,
                  samples: int = 3600) -> Sizing:
    """The smallest follower of a given kind that keeps the pressure angle within its limits.

    The same kind, arm, roller and rotation; a translating follower's `offset` is kept unless
    `free_offset`; the base radius (or the centre distance and arm angle) is the least that meets
    the limits.

    Parameters
    ----------
    follower : Follower
        The follower to size.
    program : Program
        The motion program.
    rise_limit, return_limit : float
        Allowed |pressure angle| on the rise and on the return, rad, in (0, π/2).
    free_offset : bool
        Translating roller or knife: choose the offset too.
    min_radius : float, optional
        Flat face: the smallest radius of curvature of the profile (default: 0.1 of the stroke).
    samples : int
        Cam angles of the first pass.

    Returns
    -------
    Sizing
        The sized follower, its prime radius and the limits met.

    Raises
    ------
    ModelError
        When no size meets the limits.

    Examples
    --------
    A cycloidal rise of 20 mm over 90°, roller on the cam's axis, 30° allowed: the least r0 with
    max (ds/dφ)/(r0 + s) = tan 30°, 35.018891 mm (by a dense search and a root finder):

    >>> import numpy as np
    >>> from mbplanar.cam import Follower, make_law, program, size_follower
    >>> cyc, dwell = make_law("cycloidal"), make_law("dwell")
    >>> p = program([("rise", cyc, np.pi / 2, 0.02), ("dwell", dwell, np.pi / 2, None),
    ...              ("return", cyc, np.pi / 2, 0.02), ("dwell", dwell, np.pi / 2, None)])
    >>> start = Follower("translating", "roller", base_radius=0.01, roller=0.005)
    >>> sized = size_follower(start, p, np.radians(30), np.radians(30), free_offset=False)
    >>> round(sized.follower.base_radius * 1e3, 6), sized.follower.offset
    (35.018891, 0.0)
    """
    for name, lim in (("rise", rise_limit), ("return", return_limit)):
        if not 0 < lim < math.pi / 2:
            raise ModelError(f"the {name} pressure-angle limit must lie between 0° and 90°, got "
                             f"{math.degrees(lim):.6g}°")
    phi = np.unique(np.concatenate([np.linspace(0, 2 * np.pi, samples, endpoint=False),
                                    program.breakpoints()]))
    if follower.contact == "flat":
        return _size_flat(follower, program, phi, rise_limit, return_limit, min_radius)
    if follower.motion == "translating":
        return _size_translating(follower, program, phi, rise_limit, return_limit, free_offset)
    return _size_oscillating(follower, program, phi, rise_limit, return_limit)


def _size_flat(f, program, phi, rise_limit, return_limit, min_radius):
    if f.motion != "translating":
        raise ModelError("sizing an oscillating flat-faced follower is not supported: give a_w, φ20 "
                         "and the face offset")
    if min_radius is None:
        min_radius = 0.1 * program.stroke
    s, _, a, _ = _refined(program, phi, lambda s, v, a, lim: -(s + a))
    base = float(np.max(min_radius - s - a))
    base = max(base, min_radius)
    g = f.with_size(base_radius=base)
    return Sizing(g, base, rise_limit, return_limit)


def _refined(program, phi, score, rounds=3):
    """s, v, a, j on `phi` plus dense samples around the largest `score` (a vectorised function)."""
    for _ in range(rounds):
        s, v, a, j = program.evaluate(phi)
        k = int(np.argmax(score(s, v, a, None)))
        step = np.max(np.diff(phi)) if phi.size > 1 else 1e-3
        phi = np.unique(np.concatenate([phi, phi[k] + np.linspace(-2 * step, 2 * step, 401)]))
    return program.evaluate(phi)


def _size_translating(f, program, phi, rise_limit, return_limit, free_offset):
    sigma = f.rotation

    def rows(phi):
        s, v, _, _ = program.evaluate(phi)
        lim = pressure_limits(v, rise_limit, return_limit)
        on = lim > 0
        t, s, v = np.tan(lim[on]), s[on], v[on]
        one = np.ones_like(t)
        a = np.concatenate([np.stack([-one, -t], -1), np.stack([one, -t], -1)])
        b = np.concatenate([t * s - sigma * v, t * s + sigma * v])
        return a, b, np.concatenate([phi[on], phi[on]])

    if free_offset:
        x = _nearest_admissible(rows, phi, np.zeros(2), program.stroke)
        e, s0 = x
    else:
        e = f.offset
        s0 = _smallest_along(rows, phi, e)
    s0 = max(s0, 0.0)                         # the limits alone may allow the follower's line through O
    r0 = math.hypot(e, s0)
    if r0 <= 0:
        raise ModelError("sizing found a zero base radius: the limits do not bound the cam")
    g = f.with_size(base_radius=r0, offset=float(e))
    return Sizing(g, r0, rise_limit, return_limit)


def _smallest_along(rows, phi, e):
    """Smallest s₀ meeting every half-plane for a fixed offset e."""
    for _ in range(3):
        a, b, where = rows(phi)
        need = (b - a[:, 0] * e) / a[:, 1]          # a[:, 1] = −tan θ < 0: s₀ ≥ need
        k = int(np.argmax(need))
        step = np.max(np.diff(phi))
        phi = np.unique(np.concatenate([phi, where[k] + np.linspace(-2 * step, 2 * step, 401)]))
    return float(np.max(need))


def _size_oscillating(f, program, phi, rise_limit, return_limit):
    sigma, l = f.rotation, f.arm

    def frame(phi):
        s, v, _, _ = program.evaluate(phi)
        psi = s / l
        e = np.stack([np.cos(np.pi + psi), np.sin(np.pi + psi)], -1)
        w = np.stack([-e[:, 1], e[:, 0]], -1)
        return s, v, psi, e, w

    def rows(phi):
        s, v, psi, e, w = frame(phi)
        lim = pressure_limits(v, rise_limit, return_limit)
        on = lim > 0
        t, e, w, v = np.tan(lim[on]), e[on], w[on], v[on]
        pt = (l - sigma * v)[:, None] * e
        we = np.sum(w * pt, -1)
        cross = w[:, 0] * pt[:, 1] - w[:, 1] * pt[:, 0]
        a1 = np.stack([w[:, 1], -w[:, 0]], -1) + t[:, None] * w
        a2 = np.stack([-w[:, 1], w[:, 0]], -1) + t[:, None] * w
        return (np.concatenate([a1, a2]), np.concatenate([t * we - cross, t * we + cross]),
                np.concatenate([phi[on], phi[on]]))

    start = np.array([-l, 0.0])
    centre = _nearest_admissible(rows, phi, start, program.stroke + l)
    a_w = float(np.hypot(*centre))
    phi20 = float(np.mod(np.pi - math.atan2(centre[1], centre[0]), 2 * np.pi))
    if not 0 < phi20 < np.pi:
        raise ModelError(f"sizing put the cam centre on the wrong side of the arm (φ20 = "
                         f"{math.degrees(phi20):.6g}°): the limits cannot be met with this arm")
    g = f.with_size(centre_distance=a_w, arm_angle=phi20)
    s, v, psi, e, w = frame(phi)
    mirror = np.array([1.0, -1.0])
    curve = ((l - sigma * v)[:, None] * e) * mirror
    region = _polygon(*rows(phi)[:2], program.stroke + l) * mirror
    cons = Construction(curve, l * e * mirror, region, centre * mirror,
                        pressure_limits(v, rise_limit, return_limit))
    return Sizing(g, g.prime_radius, rise_limit, return_limit, cons)


def _box(scale):
    """Half-planes of a square of side 200·scale about the origin (bounds the region)."""
    big = 100.0 * scale
    return np.array([[1.0, 0], [-1, 0], [0, 1], [0, -1]]), np.full(4, big)


def _polygon(a, b, scale):
    """Vertices (counter-clockwise) of {x: a x ≤ b} clipped to the box; ModelError when empty."""
    from scipy.optimize import linprog
    from scipy.spatial import HalfspaceIntersection
    ba, bb = _box(scale)
    a, b = np.concatenate([a, ba]), np.concatenate([b, bb])
    norm = np.linalg.norm(a, axis=1)
    res = linprog([0, 0, -1], A_ub=np.column_stack([a, norm]), b_ub=b,
                  bounds=[(None, None), (None, None), (None, scale)], method="highs")
    if res.status != 0 or res.x[2] <= 1e-12 * scale:
        raise ModelError("no size of the cam meets the pressure-angle limits (the admissible region for "
                         "the cam centre is empty): allow larger angles or a smaller stroke")
    hs = HalfspaceIntersection(np.column_stack([a, -b]), res.x[:2])
    pts = hs.intersections
    centre = pts.mean(axis=0)
    order = np.argsort(np.arctan2(pts[:, 1] - centre[1], pts[:, 0] - centre[0]))
    return pts[order]


def _nearest_on_polygon(poly, x0):
    """The point of the convex polygon (vertices in order) nearest to x0."""
    edge, rel = np.roll(poly, -1, 0) - poly, x0 - poly
    inside = np.all(edge[:, 0] * rel[:, 1] - edge[:, 1] * rel[:, 0] >= 0)
    if inside:
        return x0.copy()
    p, q = poly, np.roll(poly, -1, 0)
    d = q - p
    t = np.clip(np.sum((x0 - p) * d, -1) / np.maximum(np.sum(d * d, -1), 1e-300), 0, 1)
    cand = p + t[:, None] * d
    return cand[int(np.argmin(np.linalg.norm(cand - x0, axis=1)))]


def _nearest_admissible(rows, phi, x0, scale, rounds=3):
    """The admissible point nearest x0; the angles are resampled around the active half-planes."""
    for _ in range(rounds + 1):
        a, b, where = rows(phi)
        x = _nearest_on_polygon(_polygon(a, b, scale), x0)
        slack = (b - a @ x) / np.linalg.norm(a, axis=1)
        active = np.unique(where[slack < 1e-9 * scale + np.sort(slack)[min(1, slack.size - 1)]])
        step = np.max(np.diff(phi))
        extra = (active[:, None] + np.linspace(-2 * step, 2 * step, 201)).ravel()
        phi = np.unique(np.concatenate([phi, extra]))
    return x


