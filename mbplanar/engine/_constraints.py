"""Joint laws: how a revolute or prismatic joint places a link (as a tree joint) or closes a loop (as a
cut joint), with the time derivatives of both, vectorised over a batch of positions.

Coordinates. The engine solves in its own frame: the world frame moved to the engine's centre c (the
mean of the drawn joints on a coarse grid, `model._scale.frame_origin`; 0 for a mechanism drawn near
the world's origin), so that every position it compares is a vector within the mechanism, a few of its
sizes long, however far from the world's origin it is drawn (a closure residual formed from world
coordinates 1000 sizes away carries rounding of 1000 times the closure tolerance). Every link k carries
a frame that coincides with that frame in the drawn pose; its state is the rotation θ_k from the drawn
pose and the position r_k of its frame origin, so a point drawn at p (world) on link k is at
X = c + r_k + R(θ_k) s with s = p − c (the joint law's `s0`).  Ground has θ = 0, r = 0.
`world_frames` gives the link frames in the world convention (the frame that coincides with the world
frame in the drawn pose), as results report them.

Tree joints place a child link from its parent with one variable: a revolute joint sets the child's
rotation (absolute; relative to the parent for a driving joint between moving links), a prismatic joint
sets the slider's displacement along the guide (rotation shared with the parent). Cut joints give two
closure equations each: revolute, the two links' copies of the joint point coincide; prismatic, the
relative rotation stays as drawn and the slider point stays on the guide line.

Rate passes are linear in the rates of the parents and of the tree variables, with C columns (the
Jacobian uses one column per unknown). The same pass gives accelerations when `vel` (the actual
velocities) is given: it then adds the centripetal and Coriolis terms.

Shapes (batch last, so that every elementwise operation runs over a contiguous batch): B = batch of
positions, C = columns; angles (B,), points (2, B), rates (C, B) and (2, C, B).
"""

from __future__ import annotations

import numpy as np

from ..model import Joint

__all__ = ["Pose", "Rates", "Revolute", "Prismatic", "make_law", "perp", "rotate", "dot", "world_frames"]


def perp(v: np.ndarray) -> np.ndarray:
    """v rotated by +90°, components first: (x, y) → (−y, x)."""
    out = np.empty_like(v)
    out[0] = -v[1]
    out[1] = v[0]
    return out


def dot(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Scalar product over the leading component axis."""
    return p[0] * q[0] + p[1] * q[1]


def rotate(c: np.ndarray, s: np.ndarray, vec: np.ndarray) -> np.ndarray:
    """R(θ)·vec for a batch of angles given by cos, sin (B,); vec (2,) → (2, B) (complex for a complex vec:
    the complex step of `mbplanar.accuracy`)."""
    out = np.empty((2,) + c.shape, np.result_type(c, vec))
    out[0] = c * vec[0] - s * vec[1]
    out[1] = s * vec[0] + c * vec[1]
    return out


class Pose:
    """Placed links of one batch: rotation θ, its cos and sin (B,), frame origin r (2, B); and the
    contact parameters u (B,) of the higher pairs that have one (by the pair's name)."""

    def __init__(self, batch: int):
        zero = np.zeros(batch)
        self.batch = batch
        self.th, self.c, self.s, self.r, self.u = {}, {}, {}, {}, {}
        self._ground = (zero, np.ones(batch), zero, np.zeros((2, batch)))

    def set_ground(self, name: str):
        self.th[name], self.c[name], self.s[name], self.r[name] = self._ground

    def place(self, link: str, th: np.ndarray, r: np.ndarray | None = None):
        self.th[link], self.c[link], self.s[link] = th, np.cos(th), np.sin(th)
        if r is not None:
            self.r[link] = r

    def rot(self, link: str, vec: np.ndarray) -> np.ndarray:
        return rotate(self.c[link], self.s[link], vec)


class Rates:
    """Angular rate w (C, B) and frame-origin rate v (2, C, B) per link; absent links are at rest. The
    rates p (C, B) of the higher pairs' contact parameters, by the pair's name (absent: 0)."""

    def __init__(self, batch: int, columns: int):
        self.w, self.v, self.p = {}, {}, {}
        self._rest = (np.zeros((columns, batch)), np.zeros((2, columns, batch)))

    def get(self, link):
        if link in self.w:
            return self.w[link], self.v[link]
        return self._rest

    def set(self, link, w, v):
        self.w[link], self.v[link] = w, v

    def param(self, name):
        return self.p.get(name, self._rest[0])

    def set_param(self, name, rate):
        self.p[name] = rate


class JointLaw:
    """The hooks each joint type fills in (tree placement, loop closure, and their rates); `kind` is the
    joint's type, "R" or "P" (as `Joint.kind`)."""

    kind = ""

    def __init__(self, joint: Joint, centre=(0.0, 0.0)):
        self.name = joint.name
        self.links = joint.links
        self.s0 = np.array(joint.at, dtype=float) - np.asarray(centre, float)  # in the engine's frame

    def point(self, link: str) -> np.ndarray:
        """The joint's point in `link`'s frame: the drawn point on both links (a made mechanism's links
        hold their own, `mbplanar.accuracy.made`)."""
        return self.s0

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

    kind = "R"

    def place(self, pose, parent, child, q, relative):
        rho_p = pose.rot(parent, self.point(parent))
        th = pose.th[parent] + q if relative else q
        pose.place(child, th)
        rho_c = pose.rot(child, self.point(child))
        pose.r[child] = pose.r[parent] + rho_p - rho_c
        return rho_p, rho_c, perp(rho_p)[:, None], perp(rho_c)[:, None]

    def place_rates(self, cache, rates, parent, child, qd, relative, vel=None, qd_vel=None):
        rho_p, rho_c, perp_p, perp_c = cache
        wp, vp = rates.get(parent)
        wc = qd + wp if relative else qd
        vc = vp + wp * perp_p - wc * perp_c
        if vel is not None:
            Wp, Wc = vel.get(parent)[0], vel.w[child]
            vc = vc - (Wp * Wp) * rho_p[:, None] + (Wc * Wc) * rho_c[:, None]
        rates.set(child, wc, vc)

    def closure(self, pose):
        a, b = self.links
        rho_a, rho_b = pose.rot(a, self.point(a)), pose.rot(b, self.point(b))
        return pose.r[a] + rho_a - pose.r[b] - rho_b, (rho_a, rho_b, perp(rho_a)[:, None], perp(rho_b)[:, None])

    def closure_rates(self, cache, rates, vel=None):
        (a, b), (rho_a, rho_b, perp_a, perp_b) = self.links, cache
        wa, va = rates.get(a)
        wb, vb = rates.get(b)
        out = va + wa * perp_a - vb - wb * perp_b
        if vel is not None:
            Wa, Wb = vel.get(a)[0], vel.get(b)[0]
            out = out - (Wa * Wa) * rho_a[:, None] + (Wb * Wb) * rho_b[:, None]
        return out


class Prismatic(JointLaw):
    """Prismatic pair: the slider keeps its drawn angle to the carrier, its point stays on the guide."""

    kind = "P"

    def __init__(self, joint: Joint, centre=(0.0, 0.0)):
        super().__init__(joint, centre)
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
        pose.r[child] = pose.r[parent] + (sign * q) * u
        return sign, u[:, None], q, perp(u)[:, None]

    def place_rates(self, cache, rates, parent, child, qd, relative, vel=None, qd_vel=None):
        sign, u, q, pu = cache
        wp, vp = rates.get(parent)
        vc = vp + sign * (qd * u + (q * wp) * pu)
        if vel is not None:
            Wp = vel.get(parent)[0]
            vc = vc + sign * ((2 * qd_vel * Wp) * pu - (q * Wp * Wp) * u)
        rates.set(child, wp, vc)

    def closure(self, pose):
        c, s = self.carrier, self.slider
        n = pose.rot(c, self.n0)
        rho_s, rho_c = pose.rot(s, self.point(s)), pose.rot(c, self.point(c))
        delta = pose.r[s] + rho_s - pose.r[c] - rho_c
        out = np.empty((2, pose.batch), dtype=delta.dtype)
        out[0] = pose.th[s] - pose.th[c]
        out[1] = dot(n, delta)
        perps = perp(rho_s)[:, None], perp(rho_c)[:, None]
        return out, (n, delta, rho_s, rho_c, perps, dot(perp(n), delta))

    def _delta_rate(self, cache, rates):
        """Rate of (slider point − carrier point), (2, C, B)."""
        perp_s, perp_c = cache[4]
        ws, vs = rates.get(self.slider)
        wc, vc = rates.get(self.carrier)
        return vs + ws * perp_s - vc - wc * perp_c

    def closure_rates(self, cache, rates, vel=None):
        n, delta, rho_s, rho_c, _, pn_delta = cache
        ws, wc = rates.get(self.slider)[0], rates.get(self.carrier)[0]
        d_rate = self._delta_rate(cache, rates)
        out = np.empty(d_rate.shape)
        out[0] = ws - wc
        out[1] = d_rate[0] * n[0] + d_rate[1] * n[1] + wc * pn_delta
        if vel is not None:  # centripetal and Coriolis terms of (n·Δ)''
            Ws, Wc = vel.get(self.slider)[0][0], vel.get(self.carrier)[0][0]
            d_vel = self._delta_rate(cache, vel)[:, 0]
            accel_bias = -(Ws * Ws) * rho_s + (Wc * Wc) * rho_c
            out[1] += -(Wc * Wc) * dot(n, delta) + 2 * Wc * dot(perp(n), d_vel) + dot(n, accel_bias)
        return out


def make_law(joint: Joint, centre=(0.0, 0.0)) -> JointLaw:
    """The joint's law in the frame centred on `centre` (world coordinates, (2,))."""
    return Revolute(joint, centre) if joint.kind == "R" else Prismatic(joint, centre)


def world_frames(centre: np.ndarray, c: np.ndarray, s: np.ndarray, r: np.ndarray, w=None, v=None, e=None, a=None):
    """The link frames of the engine's frame (centred on `centre` (2,)) in the world convention: the
    motion of each link's point drawn at the world's origin. From cos θ, sin θ (L, B) and r (2, L, B),
    with w, e (L, B) and v, a (2, L, B) when given; returns (r, v, a) (None where not given), the
    arrays given themselves when `centre` is 0 (the engine's frame is then the world's). Far from the
    origin the answer carries the rounding of world coordinates (~1e-16 of them)."""
    cx, cy = float(centre[0]), float(centre[1])
    if cx == 0.0 and cy == 0.0:
        return r, v, a
    # ρ = −R(θ)·c, from the frame's origin to the world origin's point (operation for operation as the
    # compiled kernel, `backends._numba_kinematics`)
    rho_x = s * cy
    rho_x -= c * cx
    rho_y = s * cx
    rho_y += c * cy
    np.negative(rho_y, out=rho_y)
    out_r = np.empty(r.shape)
    np.add(r[0], rho_x, out=out_r[0])
    np.add(r[1], rho_y, out=out_r[1])
    out_r[0] += cx
    out_r[1] += cy
    out_v = out_a = None
    if v is not None:  # v + ω·perp(ρ)
        out_v = np.empty(v.shape)
        np.subtract(v[0], w * rho_y, out=out_v[0])
        np.add(v[1], w * rho_x, out=out_v[1])
    if a is not None:  # a + ε·perp(ρ) − ω²ρ
        out_a = np.empty(a.shape)
        w2 = w * w
        t = e * rho_y
        t += w2 * rho_x
        np.subtract(a[0], t, out=out_a[0])
        np.multiply(e, rho_x, out=t)
        t -= w2 * rho_y
        np.add(a[1], t, out=out_a[1])
    return out_r, out_v, out_a
