"""Joint laws of the higher pairs: gears, a pinion on a rack, a cam's contact, a pin in a curved slot. Like
the lower pairs' (`_constraints`), each gives the closure residuals of a block and their rates; a higher
pair is always a cut (it does not place a link), and a contact along a curve adds its parameter u (the
contact's place on the curve) to the block's unknowns.

Laws, with θ the links' rotations from the drawn pose (so every law holds with zero in the drawn pose):

- gear (1 equation): r_a(θ_a − θ_c) ± r_b(θ_b − θ_c) = 0, + for external teeth, − for internal, θ_c the
  carrier's rotation: the pitch circles roll on each other;
- rack (1 equation): (X_C − X_A)·U + σ·r·(θ_p − θ_k) = 0, X_C the pinion's centre, X_A the rack's material
  point drawn at the pitch point, U the rack's line direction turning with the rack, σ = ±1 the side: the
  pitch circle rolls on the pitch line (the rack moves r·Δθ relative to the pinion's axis);
- a point on a curve (cam with a knife, a roller or a circular face; pin in a slot; 2 equations, 1
  parameter): X_F(P) − X_C(c(u)) = 0, P the follower's point, c the curve on the other link (a roller's
  centre runs on the profile's offset by its radius);
- a flat face on a curve (2 equations, 1 parameter): N·(X_C(c(u)) − X_F(A)) = 0 and N·T(u) = 0, N the
  face's normal turning with the follower, A a point of the face, T = R_C·c'(u) the profile's tangent.

The rates are the laws' time derivatives, linear in the links' rates and the parameters' rates (one column
per unknown for the Jacobian), with the centripetal, Coriolis and curvature terms when the velocities
`vel` are given (accelerations), as in `_constraints`. Shapes as there: B the batch, C the columns.
"""

from __future__ import annotations

import math

import numpy as np

from ..model import PairGeometry
from ._constraints import dot, perp

__all__ = ["HigherLaw", "Gear", "Rack", "PointOnCurve", "FaceOnCurve", "make_higher_law"]


def _on_link(rates, vel, link, rho, name=None, d1=None, d2=None):
    """Rate (2, C, B) of the point X = r + R·c(u) of `link` (ρ = R·c(u), d1 = R·c'(u), d2 = R·c''(u),
    (2, B); without `name` a material point, ρ = R·s): v + ω·perp(ρ) + d1·u̇, and with `vel` the terms
    −Ω²ρ + 2Ω·U·perp(d1) + U²·d2 of the acceleration (Ω, U the velocities)."""
    return rates.get(link)[1] + _turning(rates, vel, link, rho, name, d1, d2)


def _turning(rates, vel, link, vec, name=None, d1=None, d2=None):
    """Rate (2, C, B) of a vector V = R·f(u) of `link` (vec = V, d1 = R·f', d2 = R·f'' (2, B); without
    `name` a fixed vector): ω·perp(V) + d1·u̇, and with `vel` the acceleration's terms as `_on_link`."""
    w, _ = rates.get(link)
    out = w * perp(vec)[:, None]
    if name is not None:
        out = out + d1[:, None] * rates.param(name)
    if vel is not None:
        big_w = vel.get(link)[0]
        out = out - (big_w * big_w) * vec[:, None]
        if name is not None:
            big_u = vel.param(name)
            out = out + (2 * big_w * big_u) * perp(d1)[:, None] + (big_u * big_u) * d2[:, None]
    return out


def _dot_rate(a, a_rate, b, b_rate, a_vel=None, b_vel=None):
    """Rate (C, B) of a·b for vectors a, b (2, B) with rates (2, C, B); with the velocities a_vel, b_vel
    (2, 1, B) (an acceleration pass, the rates then holding their own terms) also 2·ȧ·ḃ."""
    out = dot(a_rate, b[:, None]) + dot(a[:, None], b_rate)
    if a_vel is not None:
        out = out + 2 * dot(a_vel, b_vel)
    return out


class HigherLaw:
    """A higher pair's law as a cut: `equations` rows, `parameters` (0 or 1) unknowns of its own.

    `row_scale(size)` (equations,) and `param_scale(size)` make the rows and the parameter
    dimensionless; `param0` is the parameter in the drawn pose; `param_period` the period of a closed
    curve's parameter (0: none), `param_range` the ends of an open one."""

    kind = ""
    equations = 1
    parameters = 0
    param0 = 0.0
    param_period = 0.0
    param_range = (-math.inf, math.inf)

    def __init__(self, geometry: PairGeometry, local: PairGeometry | None = None):
        self.geometry = geometry          # as drawn, in world coordinates
        self.local = local or geometry    # the same in the engine's frame (`Engine.centre`): what it solves with
        self.pair = geometry.pair
        self.name = self.pair.name
        self.links = self.pair.links

    def row_scale(self, size: float) -> list:
        return [1.0 / size] * self.equations

    def param_scale(self, size: float) -> float:
        return 1.0

    def inside(self, u) -> np.ndarray:
        """Whether the parameter values u (B,) lie on the curve (an open curve ends)."""
        lo, hi = self.param_range
        return (u >= lo) & (u <= hi)


class Gear(HigherLaw):
    """Two gears on a carrier: r_a(θ_a − θ_c) ± r_b(θ_b − θ_c) = 0."""

    kind = "gear"

    def __init__(self, geometry: PairGeometry, local: PairGeometry | None = None):
        super().__init__(geometry, local)
        ra, rb = self.pair.radii
        sb = -1.0 if self.pair.internal else 1.0
        self.carrier = geometry.carrier
        self.coef = ((self.links[0], ra), (self.links[1], sb * rb), (self.carrier, -(ra + sb * rb)))

    def closure(self, pose):
        out = sum(c * pose.th[link] for link, c in self.coef)
        return out[None, :], None

    def closure_rates(self, cache, rates, vel=None):
        return sum(c * rates.get(link)[0] for link, c in self.coef)[None]


class Rack(HigherLaw):
    """A pinion's pitch circle rolling on a rack's pitch line: (X_C − X_A)·U + σ·r·(θ_p − θ_k) = 0."""

    kind = "rack"

    def __init__(self, geometry: PairGeometry, local: PairGeometry | None = None):
        super().__init__(geometry, local)
        self.centre = np.array(self.local.centres[0], float)
        self.at = np.array(self.local.pitch, float)
        self.line = np.array(geometry.tangent, float)
        out = np.array(geometry.normal, float)                 # from the centre to the pitch point
        # σ = perp(out)·U: d/dt (X_C − X_A)·U = −σ·r·(ω_p − ω_k) when the pitch circle rolls on the line
        self.sigma_r = float(out[0] * self.line[1] - out[1] * self.line[0]) * self.pair.radius

    def closure(self, pose):
        p, k = self.links
        rho_c, rho_a = pose.rot(p, self.centre), pose.rot(k, self.at)
        d = pose.r[p] + rho_c - pose.r[k] - rho_a
        u = pose.rot(k, self.line)
        res = dot(d, u) + self.sigma_r * (pose.th[p] - pose.th[k])
        return res[None, :], (rho_c, rho_a, d, u)

    def _d_rate(self, cache, rates, vel):
        rho_c, rho_a, _, _ = cache
        p, k = self.links
        return _on_link(rates, vel, p, rho_c) - _on_link(rates, vel, k, rho_a)

    def closure_rates(self, cache, rates, vel=None):
        _, _, d, u = cache
        p, k = self.links
        d_rate, u_rate = self._d_rate(cache, rates, vel), _turning(rates, vel, k, u)
        vels = (self._d_rate(cache, vel, None), _turning(vel, None, k, u)) if vel is not None else (None, None)
        out = _dot_rate(d, d_rate, u, u_rate, *vels)
        return (out + self.sigma_r * (rates.get(p)[0] - rates.get(k)[0]))[None]


class _OnCurve(HigherLaw):
    """A contact along the curve `path` of the pair's first link, at the parameter u (a closed curve's
    repeats, an open curve's ends); the second link's point `at`."""

    equations = 2
    parameters = 1

    def __init__(self, geometry: PairGeometry, local: PairGeometry | None, path):
        super().__init__(geometry, local)
        self.path = path
        self.at = np.array(self.local.pair.at, float)
        self.param0 = geometry.u0
        self.param_period = path.period if path.closed else 0.0
        self.param_range = (-math.inf, math.inf) if path.closed else (path.lo, path.hi)

    def param_scale(self, size):
        return self.path.scale / size


class PointOnCurve(_OnCurve):
    """A point P of link F on a curve c(u) of link C: X_F(P) − X_C(c(u)) = 0 (a knife, a roller's or a
    circle's centre on the profile or its offset, a pin in a slot)."""

    kind = "point"

    def __init__(self, geometry: PairGeometry, local: PairGeometry | None = None):
        super().__init__(geometry, local, (local or geometry).path)
        self.curve_link, self.point_link = self.links

    def closure(self, pose):
        c, f = self.curve_link, self.point_link
        u = pose.u[self.name]
        rho_f = pose.rot(f, self.at)
        on = [pose.rot(c, self.path.point(u, n)) for n in range(3)]
        res = pose.r[f] + rho_f - pose.r[c] - on[0]
        return res, (rho_f, on)

    def closure_rates(self, cache, rates, vel=None):
        rho_f, (o0, o1, o2) = cache
        return (_on_link(rates, vel, self.point_link, rho_f)
                - _on_link(rates, vel, self.curve_link, o0, self.name, o1, o2))


class FaceOnCurve(_OnCurve):
    """A flat face of link F (through its point A, normal n) touching a curve c(u) of link C:
    N·(X_C(c(u)) − X_F(A)) = 0 and N·R_C·c'(u) = 0."""

    kind = "face"

    def __init__(self, geometry: PairGeometry, local: PairGeometry | None = None):
        super().__init__(geometry, local, (local or geometry).profile)
        self.curve_link, self.face_link = self.links
        self.n0 = np.array(geometry.normal, float)

    def row_scale(self, size):
        return [1.0 / size, 1.0 / self.path.scale]

    def closure(self, pose):
        c, f = self.curve_link, self.face_link
        u = pose.u[self.name]
        on = [pose.rot(c, self.path.point(u, n)) for n in range(4)]
        rho_f = pose.rot(f, self.at)
        normal = pose.rot(f, self.n0)
        d = pose.r[c] + on[0] - pose.r[f] - rho_f
        res = np.empty((2, pose.batch), np.result_type(normal, d))
        res[0] = dot(normal, d)
        res[1] = dot(normal, on[1])
        return res, (on, rho_f, normal, d)

    def _rates(self, cache, rates, vel):
        """Rates of d = X_C(c(u)) − X_F(A), the normal N and the tangent T = R_C·c'(u)."""
        (o0, o1, o2, o3), rho_f, normal, _ = cache
        c, f = self.curve_link, self.face_link
        d = _on_link(rates, vel, c, o0, self.name, o1, o2) - _on_link(rates, vel, f, rho_f)
        return d, _turning(rates, vel, f, normal), _turning(rates, vel, c, o1, self.name, o2, o3)

    def closure_rates(self, cache, rates, vel=None):
        on, _, normal, d = cache
        d_rate, n_rate, t_rate = self._rates(cache, rates, vel)
        if vel is None:
            d_vel = n_vel = t_vel = None
        else:
            d_vel, n_vel, t_vel = self._rates(cache, vel, None)
        out = np.empty((2,) + d_rate.shape[1:])
        out[0] = _dot_rate(normal, n_rate, d, d_rate, n_vel, d_vel)
        out[1] = _dot_rate(normal, n_rate, on[1], t_rate, n_vel, t_vel)
        return out


def make_higher_law(geometry: PairGeometry, local: PairGeometry | None = None) -> HigherLaw:
    """The law of a higher pair from its drawn geometry (`mbplanar.model._drawn.drawn_pair`), solving
    with `local`, the same geometry in the engine's frame (`Engine.centre`; None: the world's)."""
    h = geometry.pair
    if h.kind == "gear":
        return Gear(geometry, local)
    if h.kind == "rack":
        return Rack(geometry, local)
    if h.kind == "cam" and h.follower == "flat":
        return FaceOnCurve(geometry, local)
    return PointOnCurve(geometry, local)
