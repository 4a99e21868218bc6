"""Motion generation with four-bars (two RR dyads) through 2 to 5 poses of the coupler: Burmester theory.

A pose j is the coupler's reference point r_j and angle θ_j. A coupler point with coordinates p in the
coupler's frame is at P_j = r_j + R(θ_j)·p. It is a circle point with centre (fixed pivot) m when all
its positions are equally far from m; subtracting pose 1's equation from pose j's cancels |p|²:

    2·[(r_j − m)ᵀR_j − (r_1 − m)ᵀR_1]·p = |r_1 − m|² − |r_j − m|²,   j = 2..n,

linear in p for a given m. Two poses: any point of the perpendicular bisector of P_1P_2 is a centre.
Three poses: the centre of any circle point is the circumcentre of its three positions. Four poses: the
three equations in the two unknowns p are consistent only on the centre-point curve, a cubic in m
(det of the 3×3 augmented matrix = 0) through the six poles; the matching circle points form the
circle-point curve. Five poses: the Burmester points are the common points of the centre-point curves
of poses 1234 and 1235 other than the poles P12, P13, P23 (up to four real ones).
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass

import numpy as np

from ..engine import Engine
from ..errors import ModelError
from ..kinematics import analyse
from ._models import fourbar_toml, read_design, slider_crank_toml
from .defects import Defects, check_defects

__all__ = ["Dyad", "SliderDyad", "slider_points", "slider_dyad", "MotionResult", "positions", "centre_point_curve", "burmester_points",
           "dyad_from_circle_point", "dyad_from_centre_point", "synthesise_motion", "evaluate_fourbar",
           "validate_poses"]


def _rot(theta):
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def validate_poses(poses) -> np.ndarray:
    """Poses (n, 3): x, y, θ (rad); 2 to 5 of them, finite and distinct."""
    poses = np.asarray(poses, float)
    if poses.ndim != 2 or poses.shape[1] != 3:
        raise ModelError("poses must be rows of x, y, angle")
    n = len(poses)
    if not 2 <= n <= 5:
        raise ModelError(f"motion generation takes 2 to 5 poses, got {n}")
    if not np.all(np.isfinite(poses)):
        raise ModelError("poses must be finite numbers")
    for i, j in itertools.combinations(range(n), 2):
        dtheta = abs(math.remainder(poses[i, 2] - poses[j, 2], 2 * math.pi))
        if np.hypot(*(poses[i, :2] - poses[j, :2])) < 1e-9 and dtheta < 1e-9:
            raise ModelError(f"poses {i + 1} and {j + 1} are the same: inconsistent poses")
    return poses


def positions(poses, p_body) -> np.ndarray:
    """Positions (..., n, 2) of coupler points `p_body` (..., 2) (coupler frame) in the n poses."""
    poses = np.asarray(poses, float)
    p = np.asarray(p_body, float)[..., None, :]
    return poses[:, :2] + np.einsum("nij,...nj->...ni", _rot(poses[:, 2]), np.broadcast_to(p, p.shape[:-2] + (len(poses), 2)))


def to_body(poses, z) -> np.ndarray:
    """Coupler-frame coordinates of points `z` (..., 2) given in the plane at pose 1."""
    poses = np.asarray(poses, float)
    return np.einsum("ji,...j->...i", _rot(poses[0, 2]), np.asarray(z, float) - poses[0, :2])


def _system(poses, m):
    """Rows (..., n−1, 2) and right sides (..., n−1) of the circle-point equations for centres m (..., 2)."""
    poses = np.asarray(poses, float)
    m = np.asarray(m, float)[..., None, :]
    r, rot = poses[:, :2], _rot(poses[:, 2])
    d = r - m                                                       # (..., n, 2)
    rows = np.einsum("...ni,nij->...nj", d, rot)                    # (r_j − m)ᵀ R_j
    a = 2 * (rows[..., 1:, :] - rows[..., :1, :])
    rhs = (d[..., :1, :] ** 2).sum(-1) - (d[..., 1:, :] ** 2).sum(-1)
    return a, rhs


def _det4(poses, m):
    a, rhs = _system(poses[:4], m)
    return np.linalg.det(np.concatenate([a, rhs[..., None]], -1))


def pole(poses, i: int, j: int) -> np.ndarray | None:
    """The displacement pole P_ij (fixed point of pose i → pose j), None for a pure translation."""
    q = _rot(poses[j, 2] - poses[i, 2])
    lhs = np.eye(2) - q
    if abs(np.linalg.det(lhs)) < 1e-14:
        return None
    return np.linalg.solve(lhs, poses[j, :2] - q @ poses[i, :2])


def _size(poses) -> float:
    span = np.ptp(poses[:, :2], axis=0).max()
    return float(span) if span > 0 else 1.0


def centre_point_curve(poses, samples: int = 721) -> dict:
    """Centre-point and circle-point curves of 4 poses, sampled along lines through a pole.

    The fixed pivots of every RR dyad through 4 poses lie on a cubic, the centre-point curve; each
    line through the pole P12 at direction α meets it in two further points.

    Parameters
    ----------
    poses : (4, 3) array_like
        x, y (m) and angle (rad) of the coupler in each pose.
    samples : int
        Directions α sampled over [0, π).

    Returns
    -------
    dict
        "centre" (2, samples, 2): the two intersections for each α (NaN where they are not real);
        "circle" (2, samples, 2): the matching circle points at pose 1; "alpha" (samples,): the
        directions, rad; "pole" (2,): the pole the lines pass through.

    Raises
    ------
    ModelError
        Not exactly 4 poses, poses that are not rows of finite x, y, angle, two equal poses, or pure
        translations (no finite pole).

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.synthesis import centre_point_curve
    >>> poses = [[0.1546, 0.1652, 0.886], [0.1579, 0.204, 0.6156], [0.1063, 0.2171, 0.5122],
    ...          [0.0404, 0.1951, 0.5252]]
    >>> curve = centre_point_curve(poses, samples=181)
    >>> curve["centre"].shape, int(np.isfinite(curve["centre"][..., 0]).sum())
    ((2, 181, 2), 362)
    """
    poses = validate_poses(poses)
    if len(poses) != 4:
        raise ModelError("the centre-point curve needs exactly 4 poses")
    base = _base_pole(poses)
    scale = _size(poses)
    alpha = np.linspace(0.0, math.pi, samples, endpoint=False)
    u = np.stack([np.cos(alpha), np.sin(alpha)], -1)
    ss = scale * np.array([-1.0, 1.0, 2.0, 3.0])
    vals = np.stack([_det4(poses, base + s * u) for s in ss], -1)                 # (samples, 4)
    van = np.vander(ss, 4, increasing=True)
    coef = np.linalg.solve(van, vals.T).T                                           # c0..c3
    c1, c2, c3 = coef[:, 1], coef[:, 2], coef[:, 3]
    disc = c2 * c2 - 4 * c3 * c1
    with np.errstate(invalid="ignore", divide="ignore"):
        roots = np.stack([(-c2 + np.sqrt(disc)) / (2 * c3), (-c2 - np.sqrt(disc)) / (2 * c3)])
    centre = base + roots[..., None] * u[None]
    circle = np.full_like(centre, np.nan)
    good = np.isfinite(centre).all(-1)
    if good.any():
        circle[good] = _circle_points(poses, centre[good])
    return {"centre": centre, "circle": circle, "alpha": alpha, "pole": base}


def _base_pole(poses):
    best = max(itertools.combinations(range(len(poses)), 2),
               key=lambda ij: abs(math.sin(0.5 * (poses[ij[1], 2] - poses[ij[0], 2]))))
    base = pole(poses, *best)
    if base is None:
        raise ModelError("the poses are pure translations of each other: no finite pole, no four-bar by "
                         "Burmester's method (every centre point is at infinity)")
    return base


def _circle_points(poses, m):
    """Circle points at pose 1 (..., 2) of centres m (..., 2), least squares in the circle-point equations."""
    a, rhs = _system(poses, m)
    p = np.einsum("...ij,...j->...i", np.linalg.pinv(a), rhs)
    return positions(poses, p)[..., 0, :]


def burmester_points(poses, samples: int = 3600) -> list:
    """The real Burmester points of 5 poses: the dyads whose circle point meets all five.

    They are the common points of the centre-point curves of poses 1234 and 1235, found along lines
    through a pole and polished by Newton's method.

    Parameters
    ----------
    poses : (5, 3) array_like
        x, y (m) and angle (rad) of the coupler in each pose.
    samples : int
        Directions sampled when looking for the common points.

    Returns
    -------
    list of tuple
        [(centre (2,), circle point at pose 1 (2,)), ...], m; 0, 2 or 4 of them.

    Raises
    ------
    ModelError
        Not exactly 5 poses, invalid or equal poses, or pure translations.

    Examples
    --------
    Poses of models/fourbar.toml's coupler (rounded to 0.1 mm): its pivots (0, 0) and (0.3, 0) are
    among the Burmester points, to the rounding:

    >>> from mbplanar.synthesis import burmester_points
    >>> poses = [[0.1546, 0.1652, 0.886], [0.1579, 0.204, 0.6156], [0.1063, 0.2171, 0.5122],
    ...          [0.0404, 0.1951, 0.5252], [-0.0071, 0.1464, 0.6331]]
    >>> [(centre.round(2) + 0.0).tolist() for centre, circle in burmester_points(poses)]
    [[0.71, 0.32], [0.0, 0.0], [0.3, 0.0], [0.75, -1.14]]
    """
    poses = validate_poses(poses)
    if len(poses) != 5:
        raise ModelError("Burmester points need exactly 5 poses")
    from scipy.optimize import brentq
    base = pole(poses, 0, 1)
    if base is None:
        base = _base_pole(poses[:4])
    scale = _size(poses)
    other = [poses[[0, 1, 2, 3]], poses[[0, 1, 2, 4]]]
    ss = scale * np.array([-1.0, 1.0, 2.0, 3.0])
    van_inv = np.linalg.inv(np.vander(ss, 4, increasing=True))

    def quads(alpha):
        u = np.stack([np.cos(alpha), np.sin(alpha)], -1)
        out = []
        for sub in other:
            vals = np.stack([_det4(sub, base + s * u) for s in ss], -1)
            coef = vals @ van_inv.T
            out.append(coef[..., 1:])            # c1 + c2 s + c3 s² (the pole's root s = 0 removed)
        return out

    def resultant(alpha):
        (a1, b1, c1), (a2, b2, c2) = (np.moveaxis(q, -1, 0) for q in quads(alpha))
        # resultant of c1 s² + b1 s + a1 and c2 s² + b2 s + a2
        return (c1 * a2 - c2 * a1) ** 2 - (c1 * b2 - c2 * b1) * (b1 * a2 - b2 * a1)

    alpha = np.linspace(0.0, math.pi, samples + 1)
    res = resultant(alpha)
    found = []
    for k in np.flatnonzero(np.sign(res[:-1]) * np.sign(res[1:]) < 0):
        a0 = brentq(lambda x: float(resultant(np.array(x))), alpha[k], alpha[k + 1], xtol=1e-15)
        u = np.array([math.cos(a0), math.sin(a0)])
        (q1, q2) = (q for q in quads(np.array(a0)))
        r1 = np.roots(q1[::-1])
        r2 = np.roots(q2[::-1])
        best = min(((abs(x - y), x) for x in r1 for y in r2), key=lambda t: t[0])[1]
        if abs(best.imag) > 1e-6 * scale:
            continue
        m = base + best.real * u
        found.append(_polish(poses, m))
    out = []
    poles = [pole(poses, i, j) for i, j in itertools.combinations(range(5), 2)]
    for m, z in found:
        if m is None or any(p is not None and np.hypot(*(m - p)) < 1e-6 * scale for p in poles):
            continue
        if not any(np.hypot(*(m - q[0])) < 1e-7 * scale for q in out):
            out.append((m, z))
    return out


def _polish(poses, m0, iterations: int = 30):
    """Newton on the 4 circle-point equations of 5 poses in (m, p): a Burmester point to rounding."""
    p0 = to_body(poses, _circle_points(poses, m0))
    x = np.r_[m0, p0]
    for _ in range(iterations):
        f, jac = _residual(poses, x)
        try:
            dx = np.linalg.solve(jac, -f)
        except np.linalg.LinAlgError:
            return None, None
        x = x + dx
        if np.max(np.abs(dx)) < 1e-15 * (1 + np.max(np.abs(x))):
            break
    f, _ = _residual(poses, x)
    if np.max(np.abs(f)) > 1e-9 * _size(poses) ** 2:
        return None, None
    return x[:2], positions(poses, x[2:])[0]


def _residual(poses, x):
    """|P_j − m|² − |P_1 − m|², j = 2..n, and its Jacobian in (m, p)."""
    m, p = x[:2], x[2:]
    pts = positions(poses, p)
    d = pts - m
    sq = (d ** 2).sum(-1)
    f = sq[1:] - sq[0]
    rot = _rot(poses[:, 2])
    dm = -2 * (d[1:] - d[0])
    dp = 2 * (np.einsum("ni,nij->nj", d[1:], rot[1:]) - d[0] @ rot[0])
    return f, np.hstack([dm, dp])


@dataclass(frozen=True)
class Dyad:
    """An RR dyad of a motion generator: a fixed pivot and a moving pivot on the coupler.

    Attributes
    ----------
    centre : (2,) ndarray
        The fixed pivot (a centre point), m.
    circle : (2,) ndarray
        The moving pivot at pose 1 (a circle point), m.

    Examples
    --------
    >>> from mbplanar.synthesis import synthesise_motion
    >>> poses = [[0.1546, 0.1652, 0.886], [0.1579, 0.204, 0.6156], [0.1063, 0.2171, 0.5122]]
    >>> crank, rocker = synthesise_motion(poses, centre_points=[[0.0, 0.0], [0.3, 0.0]]).dyads
    >>> crank.centre.tolist(), crank.circle.round(4).tolist()
    ([0.0, 0.0], [0.0985, 0.0174])
    """

    centre: np.ndarray
    circle: np.ndarray


def dyad_from_circle_point(poses, z, centre_hint=None) -> Dyad:
    """The dyad of circle point z (pose 1): 3 poses, the circumcentre of its positions; 2 poses, the
    point of the perpendicular bisector of its two positions nearest `centre_hint`."""
    poses = validate_poses(poses)
    pts = positions(poses, to_body(poses, z))
    if len(poses) == 2:
        if centre_hint is None:
            raise ModelError("with 2 poses every dyad needs a centre-point hint besides its circle point")
        mid, chord = 0.5 * (pts[0] + pts[1]), pts[1] - pts[0]
        if np.hypot(*chord) < 1e-12:
            raise ModelError("this circle point does not move between the 2 poses (it is their pole)")
        t = chord / np.hypot(*chord)
        h = np.asarray(centre_hint, float)
        return Dyad(h - ((h - mid) @ t) * t, np.asarray(z, float))
    if len(poses) != 3:
        raise ModelError("a circle point alone fixes a dyad for 2 or 3 poses; for 4 give a centre-point hint")
    # |P_j − m|² equal for j = 1..3: linear in m
    lhs = 2 * (pts[1:] - pts[0])
    rhs = (pts[1:] ** 2).sum(-1) - (pts[0] ** 2).sum(-1)
    if abs(np.linalg.det(lhs)) < 1e-12 * _size(poses) ** 2:
        raise ModelError("the circle point's three positions are in line: its centre is at infinity (a slider)")
    return Dyad(np.linalg.solve(lhs, rhs), np.asarray(z, float))


def dyad_from_centre_point(poses, m) -> Dyad:
    """The dyad of centre point m: 3 poses, its circle point (2 linear equations); 4 poses, the point
    of the centre-point curve nearest to m."""
    poses = validate_poses(poses)
    m = np.asarray(m, float)
    if len(poses) == 3:
        a, rhs = _system(poses, m)
        if abs(np.linalg.det(a)) < 1e-14 * _size(poses) ** 2:
            raise ModelError("this centre point has no circle point (a pole or a degenerate point)")
        return Dyad(m, positions(poses, np.linalg.solve(a, rhs))[0])
    if len(poses) == 4:
        centre = _nearest_on_curve(poses, m)
        return Dyad(centre, _circle_points(poses, centre))
    raise ModelError("a centre point fixes a dyad for 3 or 4 poses")


def _curve_point(poses, base, alpha, near):
    """The centre-point curve's point on the line through `base` at direction α nearest to `near`."""
    u = np.array([math.cos(alpha), math.sin(alpha)])
    ss = _size(poses) * np.array([-1.0, 1.0, 2.0, 3.0])
    vals = np.array([_det4(poses, base + s * u) for s in ss])
    coef = np.linalg.solve(np.vander(ss, 4, increasing=True), vals)
    pts = [base + r.real * u for r in np.roots(coef[1:][::-1]) if abs(r.imag) < 1e-9 * (1 + abs(r))]
    return min(pts, key=lambda q: np.hypot(*(q - near))) if pts else None


def _nearest_on_curve(poses, hint):
    """The point of the centre-point curve of 4 poses nearest to `hint`: the nearest of a dense sample,
    refined over the direction α of its line through the pole."""
    from scipy.optimize import minimize_scalar
    curve = centre_point_curve(poses, 3600)
    c = curve["centre"]
    dist = np.where(np.isfinite(c).all(-1), np.hypot(c[..., 0] - hint[0], c[..., 1] - hint[1]), np.inf)
    b, k = np.unravel_index(np.argmin(dist), dist.shape)
    if not np.isfinite(dist[b, k]):
        raise ModelError("the centre-point curve has no real point")
    step = curve["alpha"][1] - curve["alpha"][0]
    near = c[b, k]

    def gap(alpha):
        q = _curve_point(poses, curve["pole"], alpha, near)
        return np.inf if q is None else float(np.hypot(*(q - hint)))
    res = minimize_scalar(gap, bounds=(curve["alpha"][k] - step, curve["alpha"][k] + step), method="bounded",
                          options={"xatol": 1e-14})
    best = _curve_point(poses, curve["pole"], res.x, near)
    return near if best is None or gap(res.x) > dist[b, k] else best


@dataclass(frozen=True)
class SliderDyad:
    """An RP dyad of a motion generator: a coupler point sliding on a fixed line.

    Attributes
    ----------
    point : (2,) ndarray
        The coupler point at pose 1, m.
    direction : (2,) ndarray
        Unit vector of the fixed line through `point`.

    Examples
    --------
    >>> from mbplanar.synthesis import slider_points, synthesise_motion
    >>> poses = [[0.1546, 0.1652, 0.886], [0.1579, 0.204, 0.6156], [0.1063, 0.2171, 0.5122]]
    >>> point = slider_points(poses, hint=[0.3, 0.0])[0]
    >>> crank, slider = synthesise_motion(poses, centre_points=[[0.0, 0.0]], slider_points=[point]).dyads
    >>> slider.point.round(4).tolist(), slider.direction.round(4).tolist()
    ([0.3159, 0.0006], [-0.9993, 0.0366])
    """

    point: np.ndarray
    direction: np.ndarray


def _collinearity_circle(poses3):
    """Centre, squared radius (or None, None) of the points whose positions in the 3 poses are in line:
    cross(P2 − P1, P3 − P1) = k·|z|² + l·z + c (a circle: the quadratic part of the cross product of
    two rotation-scaled copies of z is a multiple of |z|²)."""
    s = _size(poses3)

    def f(z):
        pts = positions(poses3, to_body(poses3, z))
        u, v = pts[1] - pts[0], pts[2] - pts[0]
        return u[0] * v[1] - u[1] * v[0]
    c = f(np.zeros(2))
    fx, fmx, fy, fmy = (f(np.array(z)) for z in ([s, 0.0], [-s, 0.0], [0.0, s], [0.0, -s]))
    k = (fx + fmx - 2 * c) / (2 * s * s)
    lin = np.array([fx - fmx, fy - fmy]) / (2 * s)
    if abs(k) * s * s < 1e-12 * (abs(c) + np.hypot(*lin) * s + 1e-300):
        return None, None
    centre = -lin / (2 * k)
    return centre, float(centre @ centre - c / k)


def slider_points(poses, hint=None) -> list:
    """Coupler points whose positions in all the poses lie on one line: the sliders' points.

    Parameters
    ----------
    poses : (n, 3) array_like
        x, y (m) and angle (rad) of the coupler, 2 ≤ n ≤ 5.
    hint : (2,) array_like, optional
        A point near the one wanted (m, at pose 1). 2 poses: the point itself; 3 poses: the point of
        the circle of such points nearest it; 4 or 5 poses: orders the few points there are.

    Returns
    -------
    list of ndarray
        The points (2,) at pose 1, m, nearest `hint` first.

    Raises
    ------
    ModelError
        Invalid poses, a missing hint for 2 or 3 poses, or poses with no such point.

    Examples
    --------
    >>> from mbplanar.synthesis import slider_points
    >>> poses = [[0.1546, 0.1652, 0.886], [0.1579, 0.204, 0.6156], [0.1063, 0.2171, 0.5122]]
    >>> [p.round(4).tolist() for p in slider_points(poses, hint=[0.3, 0.0])]
    [[0.3159, 0.0006]]
    """
    poses = validate_poses(poses)
    n = len(poses)
    if n == 2:
        if hint is None:
            raise ModelError("with 2 poses a slider dyad needs its coupler point (slider_points)")
        return [np.asarray(hint, float)]
    centre, r2 = _collinearity_circle(poses[:3])
    if centre is None or r2 < 0:
        raise ModelError("the poses have no coupler point whose positions are in line (no slider dyad)")
    if n == 3:
        if hint is None:
            raise ModelError("with 3 poses a slider dyad needs a hint for its coupler point (slider_points)")
        h = np.asarray(hint, float)
        d = h - centre
        dist = np.hypot(*d)
        return [centre + math.sqrt(r2) * (d / dist if dist > 0 else np.array([1.0, 0.0]))]
    c2, q2 = _collinearity_circle(poses[[0, 1, 3]])
    if c2 is None or q2 < 0:
        raise ModelError("the poses have no coupler point whose positions are in line (no slider dyad)")
    pts = _circle_intersections(centre, r2, c2, q2)
    scale = _size(poses)
    pts = [z for z in pts if _line_residual(poses, z) < 1e-9 * scale]
    if hint is not None:
        pts.sort(key=lambda z: np.hypot(*(z - np.asarray(hint, float))))
    if not pts:
        raise ModelError(f"no feasible design: the {n} poses have no coupler point whose positions are in line")
    return pts


def _circle_intersections(c1, r1sq, c2, r2sq) -> list:
    d = c2 - c1
    dist = np.hypot(*d)
    if dist < 1e-15:
        return []
    a = (r1sq - r2sq + dist * dist) / (2 * dist)
    h2 = r1sq - a * a
    if h2 < -1e-12 * r1sq:
        return []
    h = math.sqrt(max(h2, 0.0))
    u = d / dist
    base = c1 + a * u
    nrm = np.array([-u[1], u[0]])
    return [base + h * nrm, base - h * nrm] if h > 0 else [base]


def _line_fit(pts):
    """Unit direction of the best line through points (n, 2) and the largest distance from it."""
    mean = pts.mean(axis=0)
    _, _, vt = np.linalg.svd(pts - mean)
    direction = vt[0]
    normal = np.array([-direction[1], direction[0]])
    return direction, float(np.max(np.abs((pts - mean) @ normal)))


def _line_residual(poses, z) -> float:
    return _line_fit(positions(poses, to_body(poses, z)))[1]


def slider_dyad(poses, z) -> SliderDyad:
    """The slider dyad of coupler point z (pose 1): the guide through its positions, which must be in line."""
    pts = positions(poses, to_body(poses, z))
    direction, off = _line_fit(pts)
    if off > 1e-9 * _size(poses):
        raise ModelError(f"the positions of coupler point {np.asarray(z).tolist()} are not in line "
                         f"(off by {off:.3g}): not a slider point")
    if np.ptp(pts @ direction) < 1e-12 * _size(poses):
        raise ModelError("this slider point does not move between the poses")
    return SliderDyad(np.asarray(z, float), direction)


@dataclass(frozen=True)
class MotionResult:
    """A defect-free motion generator through the poses, checked by mbplanar's analysis of its model.

    Attributes
    ----------
    dyads : (Dyad, Dyad or SliderDyad)
        The crank (first) and the second dyad.
    toml : str
        The model's TOML text: crank joint "A0", coupler reference point "P" and "Q" a point on the
        coupler's x axis.
    mechanism : Mechanism
        The model read back from `toml`.
    poses : (n, 3) ndarray
        The poses asked for: x, y (m), angle (rad).
    crank_phi : (n,) ndarray
        The model's input at each pose, rad.
    pose_errors : (n,) ndarray
        The analysed reference point's distance from each pose, m.
    angle_errors_deg : (n,) ndarray
        The analysed coupler angle's error at each pose, degrees.
    defects : Defects
        mbplanar's check of the design.
    alternatives : list of dict
        The dyad pairs tried before this one, with their defects.
    seconds : float
        Wall time.
    burmester : tuple
        For 5 poses, every real Burmester point [(centre (2,), circle point at pose 1 (2,)), ...].

    Examples
    --------
    >>> from mbplanar.synthesis import synthesise_motion
    >>> poses = [[0.1546, 0.1652, 0.886], [0.1579, 0.204, 0.6156], [0.1063, 0.2171, 0.5122]]
    >>> r = synthesise_motion(poses, centre_points=[[0.0, 0.0], [0.3, 0.0]])
    >>> r.defects.ok, bool(r.pose_errors.max() < 1e-12), r.crank_phi.round(4).tolist()
    (True, True, [0.1748, 0.872, 1.5701])
    """

    dyads: tuple
    toml: str
    mechanism: object
    poses: np.ndarray
    crank_phi: np.ndarray
    pose_errors: np.ndarray
    angle_errors_deg: np.ndarray
    defects: Defects
    alternatives: list
    seconds: float
    burmester: tuple = ()


def evaluate_fourbar(poses, d1: Dyad, d2, full_turn: bool = False):
    """Model text, Engine and defects of the four-bar of two dyads (crank = d1, d2 an RR `Dyad` or a
    `SliderDyad`), drawn at pose 1."""
    poses = np.asarray(poses, float)
    second = d2.point if isinstance(d2, SliderDyad) else d2.circle
    size = _size(poses) + np.hypot(*(d1.centre - poses[0, :2])) + np.hypot(*(second - poses[0, :2]))
    a_pts = positions(poses, to_body(poses, d1.circle))
    b_pts = positions(poses, to_body(poses, second))
    ref = max(size, 1e-9)
    q_body = np.array([ref, 0.0])
    p_pts = poses[:, :2]
    q_pts = positions(poses, q_body)
    phi = np.arctan2(a_pts[:, 1] - d1.centre[1], a_pts[:, 0] - d1.centre[0])
    order = None
    for s in (1, -1):
        u = np.mod(s * (phi - phi[0]), 2 * math.pi)
        if np.all(np.diff(u) > 0):
            order = s
            break
    sense = order or 1
    comment = "Synthesised by mbplanar synth motion. P: the coupler's reference point; Q: a point on its x axis."
    if isinstance(d2, SliderDyad):
        text = slider_crank_toml(d1.centre, a_pts[0], b_pts[0], math.degrees(math.atan2(*d2.direction[::-1])),
                                 {"P": p_pts[0], "Q": q_pts[0]}, name="motion_generator",
                                 title="Motion generator (Burmester, crank and slider)", sense=sense, comment=comment)
    else:
        text = fourbar_toml(d1.centre, a_pts[0], b_pts[0], d2.centre, {"P": p_pts[0], "Q": q_pts[0]},
                            name="motion_generator", title="Motion generator (Burmester)", sense=sense,
                            comment=comment)
    mech = read_design(text)
    engine = Engine(mech)
    defects = check_defects(engine, sense * phi, {"A": a_pts, "B": b_pts, "P": p_pts, "Q": q_pts},
                            full_turn=full_turn, tol=1e-7 * ref)
    return text, mech, engine, defects, sense * phi


def _pose_errors(engine, poses, phi):
    m = analyse(engine, phi)
    if len(m.phi) != len(phi):
        raise ModelError("the design does not reach every pose")
    p = m.xy[:, m.point("P")]
    q = m.xy[:, m.point("Q")]
    ang = np.arctan2(q[:, 1] - p[:, 1], q[:, 0] - p[:, 0])
    return np.hypot(*(p - poses[:, :2]).T), np.degrees(np.abs(np.remainder(ang - poses[:, 2] + math.pi, 2 * math.pi) - math.pi))


def synthesise_motion(poses, circle_points=None, centre_points=None, slider_points=None,
                      full_turn: bool = False, curve_samples: int = 181) -> MotionResult:
    """A defect-free four-bar (or crank and slider) through 2–5 coupler poses (Burmester).

    Parameters
    ----------
    poses : (n, 3) array_like
        x, y (m) and angle (rad) of the coupler in each pose, 2 ≤ n ≤ 5, in the order to be met.
    circle_points, centre_points : (k, 2) array_like, optional
        The RR dyads' moving pivots at pose 1 (circle points) or fixed pivots (centre points); k = 2
        for a four-bar, 1 with a slider dyad. 2 poses: circle points plus centre-point hints (projected
        on the bisectors); 3 poses: either; 4 poses: centre-point hints (the nearest points of the
        centre-point curve). Without them, 4 poses try pairs of sampled curve points (best
        transmission first) and 5 poses every pair of real Burmester points.
    slider_points : (1, 2) array_like, optional
        Ask for a crank and a slider: a coupler point whose positions are in line (a hint for 3 poses,
        the point itself for 2; 4–5 poses find them).
    full_turn : bool
        Require a crank that turns fully.
    curve_samples : int
        Directions sampled on the centre-point curve when 4 poses come without hints.

    Returns
    -------
    MotionResult
        The first defect-free design; the crank is the first RR dyad.

    Raises
    ------
    ModelError
        Fewer than 2 or more than 5 poses, invalid or equal poses, missing or inconsistent pivots for
        the number of poses, or no design without a circuit, branch or order defect (the message gives
        an example of the defects met).

    Examples
    --------
    Three poses of a coupler and the two fixed pivots wanted:

    >>> from mbplanar.synthesis import synthesise_motion
    >>> poses = [[0.1546, 0.1652, 0.886], [0.1579, 0.204, 0.6156], [0.1063, 0.2171, 0.5122]]
    >>> r = synthesise_motion(poses, centre_points=[[0.0, 0.0], [0.3, 0.0]])
    >>> [d.circle.round(4).tolist() for d in r.dyads]            # the moving pivots at pose 1
    [[0.0985, 0.0174], [0.2876, 0.2517]]
    >>> r.defects.ok, bool(r.pose_errors.max() < 1e-12)
    (True, True)
    """
    t0 = time.perf_counter()
    poses = validate_poses(poses)
    chosen = circle_points is not None or centre_points is not None
    burmester = tuple(burmester_points(poses)) if len(poses) == 5 and not chosen else ()
    pairs = _pairs(poses, circle_points, centre_points, slider_points, curve_samples, burmester)
    alternatives = []
    for d1, d2 in pairs:
        second = d2.point if isinstance(d2, SliderDyad) else d2.centre
        if (not isinstance(d2, SliderDyad) and np.hypot(*(d1.centre - second)) < 1e-9) or \
                np.hypot(*(d1.circle - (d2.point if isinstance(d2, SliderDyad) else d2.circle))) < 1e-9:
            continue
        text, mech, engine, defects, phi = evaluate_fourbar(poses, d1, d2, full_turn)
        if not defects.ok:
            alternatives.append({"crank": _dyad_dict(d1), "second": _dyad_dict(d2), "defects": defects.describe()})
            if len(alternatives) >= 200:
                break
            continue
        err, aerr = _pose_errors(engine, poses, np.asarray(defects.node_phi))
        return MotionResult((d1, d2), text, mech, poses, np.asarray(defects.node_phi), err, aerr, defects,
                            alternatives, time.perf_counter() - t0, burmester)
    why = alternatives[0]["defects"] if alternatives else "no dyad pair"
    raise ModelError(f"no feasible design: every four-bar tried ({len(alternatives)}) has a defect, e.g. {why}")


def _rr_dyads(poses, circle_points, centre_points, count):
    """The RR dyads the user chose, `count` of them."""
    if circle_points is not None:
        cps = np.asarray(circle_points, float).reshape(-1, 2)
        hints = [None] * len(cps) if centre_points is None else np.asarray(centre_points, float).reshape(-1, 2)
        if len(cps) != count or len(hints) != count:
            raise ModelError(f"give {count} circle point(s) (and, for 2 poses, as many centre-point hints)")
        return [dyad_from_circle_point(poses, z, h) for z, h in zip(cps, hints)]
    cs = np.asarray(centre_points, float).reshape(-1, 2)
    if len(cs) != count:
        raise ModelError(f"give {count} centre point(s)")
    return [dyad_from_centre_point(poses, m) for m in cs]


def _pairs(poses, circle_points, centre_points, slider_hints, curve_samples, burmester=()):
    """(crank dyad, second dyad) pairs to try, in order."""
    n = len(poses)
    chosen = circle_points is not None or centre_points is not None
    if slider_hints is not None:
        hints = np.asarray(slider_hints, float).reshape(-1, 2)
        if len(hints) != 1:
            raise ModelError("give one slider point")
        sliders = [slider_dyad(poses, z) for z in slider_points(poses, hints[0])]
        if chosen:
            cranks = _rr_dyads(poses, circle_points, centre_points, 1)
        elif n == 4:
            curve = centre_point_curve(poses, curve_samples)
            c, z = curve["centre"].reshape(-1, 2), curve["circle"].reshape(-1, 2)
            good = np.isfinite(c).all(1) & np.isfinite(z).all(1)
            cranks = [Dyad(m, q) for m, q in zip(c[good], z[good])]
        elif n == 5:
            cranks = [Dyad(m, z) for m, z in burmester]
        else:
            raise ModelError(f"with {n} poses give the crank's circle point or centre point")
        return [(c, s) for s in sliders for c in cranks]
    if n == 5 and not chosen:
        pts = burmester
        if len(pts) < 2:
            raise ModelError(f"no feasible design: the 5 poses have {len(pts)} real Burmester point(s), a four-bar "
                             "needs 2")
        return list(itertools.permutations([Dyad(m, z) for m, z in pts], 2))
    if chosen:
        return [tuple(_rr_dyads(poses, circle_points, centre_points, 2))]
    if n == 4:
        return _curve_pairs(poses, curve_samples)
    raise ModelError(f"with {n} poses give two circle points (circle_points) or two centre points")


def _dyad_dict(d) -> dict:
    if isinstance(d, SliderDyad):
        return {"slider_point": [float(v) for v in d.point], "guide": [float(v) for v in d.direction]}
    return {"centre": [float(v) for v in d.centre], "circle": [float(v) for v in d.circle]}


def _curve_pairs(poses, samples, reach: float = 3.0):
    """Dyad pairs from the sampled centre-point curve of 4 poses, pre-screened in closed form (the
    coupler triangle's orientation the same at every pose: one circuit, no fold between), best smallest
    transmission-angle deviation first. Pivots farther than `reach` times the poses' span from their
    middle are left out (a designer's frame, not pivots at infinity)."""
    curve = centre_point_curve(poses, samples)
    c = curve["centre"].reshape(-1, 2)
    z = curve["circle"].reshape(-1, 2)
    good = np.isfinite(c).all(1) & np.isfinite(z).all(1)
    scale = _size(poses)
    middle = poses[:, :2].mean(axis=0)
    good &= np.hypot(*(c - z).T) > 1e-3 * scale                          # not a pole
    good &= (np.hypot(*(c - middle).T) < reach * scale) & (np.hypot(*(z - middle).T) < reach * scale)
    c, z = c[good], z[good]
    if len(c) < 2:
        raise ModelError("no feasible design: the centre-point curve has too few real points")
    a = positions(poses, to_body(poses, z))               # (K, n, 2) moving pivots at every pose
    i, j = np.triu_indices(len(c), 1)
    i, j = np.r_[i, j], np.r_[j, i]
    ab = a[j] - a[i]
    bb0 = c[j][:, None, :] - a[j]
    cross = ab[..., 0] * bb0[..., 1] - ab[..., 1] * bb0[..., 0]
    cosmu = np.abs((ab * bb0).sum(-1)) / (np.hypot(*np.moveaxis(ab, -1, 0)) * np.hypot(*np.moveaxis(bb0, -1, 0)) + 1e-300)
    same = np.all(np.sign(cross) == np.sign(cross[:, :1]), axis=1)
    score = np.where(same, cosmu.max(axis=1), np.inf)
    best = np.argsort(score, kind="stable")
    best = best[np.isfinite(score[best])][:400]
    return [(Dyad(c[i[k]], z[i[k]]), Dyad(c[j[k]], z[j[k]])) for k in best]
