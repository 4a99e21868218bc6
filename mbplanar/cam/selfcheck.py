"""Self-check: run the follower on the generated profile and compare its motion with the law.

The working profile is taken as data only: its points W_k at the sample angles (what `export` writes),
joined by cubic splines between the program's breakpoints (where the profile's curvature may jump, so a
spline must not run across them; every breakpoint is a sample). At other cam angles (the midpoints between the samples,
where the interpolation is least exact) the follower's position q is solved from the contact with that
curve alone, by batched Newton in (q, t) (t: the curve's parameter), starting from the middle of the
stroke, not from the law:

- roller or knife: the roller centre lies on the curve's normal at distance r (outside);
- flat face: the face's line is tangent to the curve.

The error is max |q − s(φ)| over the check angles. A second, global test looks for interference: no
profile point may lie inside the roller (or beyond the face) at any check angle.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .followers import face_line, pitch_point
from .geometry import CamGeometry, rotate

__all__ = ["SelfCheck", "self_check"]


@dataclass(frozen=True)
class SelfCheck:
    """Result of `self_check`.

    Attributes
    ----------
    phi : (M,) check angles, rad
    solved : (M,) follower position solved on the profile, m
    law : (M,) the law's s at the same angles, m
    error : max |solved − law|, m
    relative : error / stroke
    interference : deepest penetration of a profile point into the follower over the check angles, m
                   (≤ 0: none)
    converged : Newton converged at every check angle
    """

    phi: np.ndarray
    solved: np.ndarray
    law: np.ndarray
    error: float
    relative: float
    interference: float
    converged: bool


def _perp(v):
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def self_check(geometry: CamGeometry, program, max_iter: int = 60) -> SelfCheck:
    """Run the follower on the cam's profile and compare its lift with the program's.

    The follower's position is solved by Newton's method at the midpoints of the samples (where the
    profile was not built), so the check is independent of the construction.

    Parameters
    ----------
    geometry : CamGeometry
        The cam; its angles must include the program's breakpoints (`Program.grid` does).
    program : Program
        Used for its breakpoints and, after solving, for the comparison only.
    max_iter : int
        Newton iterations at most.

    Returns
    -------
    SelfCheck
        The lifts solved and wanted, the largest `error` (m), `relative` to the stroke, the
        `interference` and whether Newton `converged`.

    Raises
    ------
    ValueError
        A geometry with fewer than two samples.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.cam import Follower, cam_geometry, make_law, program, self_check
    >>> cyc, dwell = make_law("cycloidal"), make_law("dwell")
    >>> p = program([("rise", cyc, np.pi / 2, 0.02), ("dwell", dwell, np.pi / 2, None),
    ...              ("return", cyc, np.pi / 2, 0.02), ("dwell", dwell, np.pi / 2, None)])
    >>> phi = p.grid(720)
    >>> g = cam_geometry(Follower("translating", "knife", base_radius=0.04), phi, *p.evaluate(phi)[:3])
    >>> check = self_check(g, p)
    >>> check.converged, bool(check.relative < 1e-8)
    (True, True)
    """
    f, g = geometry.follower, geometry
    sigma = f.rotation
    knots = np.append(g.phi, g.phi[0] + 2 * np.pi)
    curve = _PiecewiseSpline(knots, np.vstack([g.profile, g.profile[:1]]), program.breakpoints())
    phi = 0.5 * (knots[:-1] + knots[1:])
    stroke = max(program.stroke, 1e-12)
    q = np.full(phi.shape, 0.5 * stroke)
    t = phi.copy()

    def residual(q, t):
        tt = g.phi[0] + np.mod(t - g.phi[0], 2 * np.pi)
        w, w1 = curve(tt)
        tangent = w1 / np.linalg.norm(w1, axis=-1, keepdims=True)
        zero = np.zeros_like(q)
        if f.contact == "flat":
            line = face_line(f, q, zero, zero)
            alpha = line.alpha - sigma * phi
            nu = np.stack([np.cos(alpha), np.sin(alpha)], -1)
            return np.stack([np.sum(tangent * nu, -1), np.sum(w * nu, -1) - line.p], -1)
        b = rotate(pitch_point(f, q, zero, zero).b, -sigma * phi)
        normal = sigma * _perp(tangent)
        return np.stack([np.sum((b - w) * tangent, -1), np.sum((b - w) * normal, -1) - f.roller], -1)

    hq, ht = 1e-7 * stroke, 1e-7
    ok = np.zeros(phi.shape, bool)
    for _ in range(max_iter):
        r = residual(q, t)
        dq = (residual(q + hq, t) - r) / hq
        dt = (residual(q, t + ht) - r) / ht
        det = dq[:, 0] * dt[:, 1] - dq[:, 1] * dt[:, 0]
        det = np.where(det == 0, 1e-300, det)
        step_q = (r[:, 0] * dt[:, 1] - r[:, 1] * dt[:, 0]) / det
        step_t = (dq[:, 0] * r[:, 1] - dq[:, 1] * r[:, 0]) / det
        limit = 0.5 * stroke + 1e-9
        q -= np.clip(step_q, -limit, limit)
        t -= np.clip(step_t, -0.2, 0.2)
        ok = (np.abs(step_q) < 1e-13 * (1 + stroke)) & (np.abs(step_t) < 1e-12)
        if np.all(ok):
            break
    law = program.evaluate(phi)[0]
    error = float(np.max(np.abs(q - law)))
    return SelfCheck(phi, q, law, error, error / stroke, _interference(g, phi, law), bool(np.all(ok)))


class _PiecewiseSpline:
    """Cubic splines through the samples, one per stretch between breakpoints: (W, W′) at t."""

    def __init__(self, knots, points, breakpoints):
        from scipy.interpolate import CubicSpline
        cuts = np.flatnonzero(np.isin(knots, np.mod(breakpoints, 2 * np.pi)) | (knots == knots[-1]))
        cuts = np.unique(np.concatenate([[0], cuts, [knots.size - 1]]))
        self.starts = knots[cuts[:-1]]
        self.pieces = [CubicSpline(knots[i:j + 1], points[i:j + 1]) for i, j in zip(cuts[:-1], cuts[1:])]

    def __call__(self, t):
        k = np.clip(np.searchsorted(self.starts, t, side="right") - 1, 0, len(self.pieces) - 1)
        w, w1 = np.empty(t.shape + (2,)), np.empty(t.shape + (2,))
        for i, piece in enumerate(self.pieces):
            m = k == i
            if np.any(m):
                w[m], w1[m] = piece(t[m]), piece(t[m], 1)
        return w, w1


def _interference(g: CamGeometry, phi, s) -> float:
    """Deepest penetration of any profile sample into the follower placed by the law, m."""
    f = g.follower
    zero = np.zeros_like(s)
    pts = g.profile                                     # (N, 2) in the cam's frame
    depth = np.empty(phi.shape)
    for lo in range(0, phi.size, 256):                 # chunks of check angles bound the memory
        sl = slice(lo, lo + 256)
        if f.contact == "flat":
            line = face_line(f, s[sl], zero[sl], zero[sl])
            alpha = line.alpha - f.rotation * phi[sl]
            nu = np.stack([np.cos(alpha), np.sin(alpha)], -1)
            depth[sl] = np.max(pts @ nu.T, axis=0) - line.p
        else:
            b = rotate(pitch_point(f, s[sl], zero[sl], zero[sl]).b, -f.rotation * phi[sl])
            dist = np.linalg.norm(pts[None, :, :] - b[:, None, :], axis=-1)
            depth[sl] = f.roller - dist.min(axis=1)
    return float(depth.max())
