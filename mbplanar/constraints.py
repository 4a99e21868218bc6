"""Joint laws: how a revolute or prismatic joint places a link (as a tree joint) or closes a loop (as a
cut joint), with the time derivatives of both, vectorised over a batch of positions.

Coordinates. Every link k carries a frame that coincides with the world frame in the drawn pose; its
state is the rotation θ_k from the drawn pose and the position r_k of its frame origin, so a point drawn
at s on link k is at  X = r_k + R(θ_k) s.  Ground has θ = 0, r = 0.

Tree joints place a child link from its parent with one variable: a revolute joint sets the child's
rotation (absolute; relative to the parent for a driving joint between moving links), a prismatic joint
sets the slider's displacement along the guide (rotation shared with the parent). Cut joints give two
closure equations each: revolute, the two links' copies of the joint point coincide; prismatic, the
relative rotation stays as drawn and the slider point stays on the guide line.

Rate passes are linear in the rates of the parents and of the tree variables, with C columns (the
Jacobian uses one column per unknown). The same pass gives accelerations when `vel` (the actual
velocities) is given: it then adds the centripetal and Coriolis terms.

Shapes: B = batch of positions, C = columns; angles (B,), points (B, 2), rates (B, C), (B, C, 2).
"""

from __future__ import annotations

import numpy as np

from .model import Joint

__all__ = ["Pose", "Rates", "Revolute", "Prismatic", "make_law", "perp", "rotate"]


def perp(v: np.ndarray) -> np.ndarray:
    """v rotated by +90°: (x, y) → (−y, x)."""
    out = np.empty_like(v)
    out[..., 0] = -v[..., 1]
    out[..., 1] = v[..., 0]
    return out


def rotate(c: np.ndarray, s: np.ndarray, vec: np.ndarray) -> np.ndarray:
    """R(θ)·vec for a batch of angles given by cos, sin (B,); vec (2,) → (B, 2)."""
    out = np.empty(c.shape + (2,))
    out[..., 0] = c * vec[0] - s * vec[1]
    out[..., 1] = s * vec[0] + c * vec[1]
    return out


def _col(x):
    """(B, C) → (B, C, 1), to scale a direction per column."""
    return x[..., None]


class Pose:
    """Placed links of one batch: rotation θ, its cos and sin (B,), frame origin r (B, 2)."""

    def __init__(self, batch: int):
        zero = np.zeros(batch)
        self.batch = batch
        self.th, self.c, self.s, self.r = {}, {}, {}, {}
        self._ground = (zero, np.ones(batch), zero, np.zeros((batch, 2)))

    def set_ground(self, name: str):
        self.th[name], self.c[name], self.s[name], self.r[name] = self._ground

    def place(self, link: str, th: np.ndarray, r: np.ndarray | None = None):
        self.th[link], self.c[link], self.s[link] = th, np.cos(th), np.sin(th)
        if r is not None:
            self.r[link] = r

    def rot(self, link: str, vec: np.ndarray) -> np.ndarray:
        return rotate(self.c[link], self.s[link], vec)


class Rates:
    """Angular rate w (B, C) and frame-origin rate v (B, C, 2) per link; absent links are at rest."""

    def __init__(self, batch: int, columns: int):
        self.w, self.v = {}, {}
        self._rest = (np.zeros((batch, columns)), np.zeros((batch, columns, 2)))

    def get(self, link):
        if link in self.w:
            return self.w[link], self.v[link]
        return self._rest

    def set(self, link, w, v):
        self.w[link], self.v[link] = w, v


class JointLaw:
    """The hooks each joint type fills in (tree placement, loop closure, and their rates)."""

    def __init__(self, joint: Joint):
        self.name = joint.name
        self.links = joint.links
        self.s0 = np.array(joint.at, dtype=float)

    def place(self, pose: Pose, parent: str, child: str, q, relative: bool):
        raise NotImplementedError

    def place_rates(self, cache, rates: Rates, parent, child, qd, relative, vel=None, qd_vel=None):
        raise NotImplementedError

    def closure(self, pose: Pose):
        raise NotImplementedError

    def closure_rates(self, cache, rates: Rates, vel: Rates | None = None):
        raise NotImplementedError


class Revolute(JointLaw):
    """Revolute pair: one point shared by both links."""

    def place(self, pose, parent, child, q, relative):
        rho_p = pose.rot(parent, self.s0)
        th = pose.th[parent] + q if relative else q
        pose.place(child, th)
        rho_c = pose.rot(child, self.s0)
        pose.r[child] = pose.r[parent] + rho_p - rho_c
        return rho_p, rho_c

    def place_rates(self, cache, rates, parent, child, qd, relative, vel=None, qd_vel=None):
        rho_p, rho_c = cache
        wp, vp = rates.get(parent)
        wc = qd + wp if relative else qd
        vc = vp + _col(wp) * perp(rho_p)[:, None] - _col(wc) * perp(rho_c)[:, None]
        if vel is not None:
            Wp, Wc = vel.get(parent)[0], vel.w[child]
            vc = vc - _col(Wp * Wp) * rho_p[:, None] + _col(Wc * Wc) * rho_c[:, None]
        rates.set(child, wc, vc)

    def closure(self, pose):
        a, b = self.links
        rho_a, rho_b = pose.rot(a, self.s0), pose.rot(b, self.s0)
        return pose.r[a] + rho_a - pose.r[b] - rho_b, (rho_a, rho_b)

    def closure_rates(self, cache, rates, vel=None):
        (a, b), (rho_a, rho_b) = self.links, cache
        wa, va = rates.get(a)
        wb, vb = rates.get(b)
        out = va + _col(wa) * perp(rho_a)[:, None] - vb - _col(wb) * perp(rho_b)[:, None]
        if vel is not None:
            Wa, Wb = vel.get(a)[0], vel.get(b)[0]
            out = out - _col(Wa * Wa) * rho_a[:, None] + _col(Wb * Wb) * rho_b[:, None]
        return out


class Prismatic(JointLaw):
    """Prismatic pair: the slider keeps its drawn angle to the carrier, its point stays on the guide."""

    def __init__(self, joint: Joint):
        super().__init__(joint)
        angle = np.radians(joint.guide_deg)
        self.u0 = np.array([np.cos(angle), np.sin(angle)])
        self.n0 = perp(self.u0)

    @property
    def carrier(self):
        return self.links[0]

    @property
    def slider(self):
        return self.links[1]

    def place(self, pose, parent, child, q, relative):
        sign = 1.0 if parent == self.carrier else -1.0
        u = pose.rot(parent, self.u0)
        pose.th[child], pose.c[child], pose.s[child] = pose.th[parent], pose.c[parent], pose.s[parent]
        pose.r[child] = pose.r[parent] + (sign * q)[:, None] * u
        return sign, u, q

    def place_rates(self, cache, rates, parent, child, qd, relative, vel=None, qd_vel=None):
        sign, u, q = cache
        wp, vp = rates.get(parent)
        vc = vp + sign * (_col(qd) * u[:, None] + _col(q[:, None] * wp) * perp(u)[:, None])
        if vel is not None:
            Wp = vel.get(parent)[0]
            vc = vc + sign * (_col(2 * qd_vel * Wp) * perp(u)[:, None] - _col(q[:, None] * Wp * Wp) * u[:, None])
        rates.set(child, wp + np.zeros_like(qd), vc)

    def closure(self, pose):
        c, s = self.carrier, self.slider
        n = pose.rot(c, self.n0)
        rho_s, rho_c = pose.rot(s, self.s0), pose.rot(c, self.s0)
        delta = pose.r[s] + rho_s - pose.r[c] - rho_c
        out = np.empty((pose.batch, 2))
        out[:, 0] = pose.th[s] - pose.th[c]
        out[:, 1] = np.einsum("bi,bi->b", n, delta)
        return out, (n, delta, rho_s, rho_c)

    def _delta_rate(self, cache, rates):
        """Rate of (slider point − carrier point), (B, C, 2)."""
        n, delta, rho_s, rho_c = cache
        ws, vs = rates.get(self.slider)
        wc, vc = rates.get(self.carrier)
        return vs + _col(ws) * perp(rho_s)[:, None] - vc - _col(wc) * perp(rho_c)[:, None]

    def closure_rates(self, cache, rates, vel=None):
        n, delta, rho_s, rho_c = cache
        ws, wc = rates.get(self.slider)[0], rates.get(self.carrier)[0]
        d_rate = self._delta_rate(cache, rates)
        out = np.empty(d_rate.shape)
        out[..., 0] = ws - wc
        out[..., 1] = (np.einsum("bci,bi->bc", d_rate, n)
                       + wc * np.einsum("bi,bi->b", perp(n), delta)[:, None])
        if vel is not None:  # centripetal and Coriolis terms of (n·Δ)''
            Ws, Wc = vel.get(self.slider)[0][:, 0], vel.get(self.carrier)[0][:, 0]
            d_vel = self._delta_rate(cache, vel)[:, 0]
            accel_bias = -(Ws * Ws)[:, None] * rho_s + (Wc * Wc)[:, None] * rho_c
            bias = (-(Wc * Wc) * np.einsum("bi,bi->b", n, delta)
                    + 2 * Wc * np.einsum("bi,bi->b", perp(n), d_vel)
                    + np.einsum("bi,bi->b", n, accel_bias))
            out[..., 1] += bias[:, None]
        return out


def make_law(joint: Joint) -> JointLaw:
    return Revolute(joint) if joint.kind == "R" else Prismatic(joint)
