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
    """Vectors rotated by +90°: (x, y) → (−y, x), components first.

    Parameters
    ----------
    v : numpy.ndarray
        Vectors (2, ...): the components on the first axis, any batch axes after.

    Returns
    -------
    numpy.ndarray
        The same shape and type.

    Raises
    ------
    IndexError
        An array whose first axis is shorter than 2.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.engine import perp
    >>> perp(np.array([[1.0, 3.0], [2.0, 4.0]]))     # (1, 2) and (3, 4) turned left
    array([[-2., -4.],
           [ 1.,  3.]])
    """
    out = np.empty_like(v)
    out[0] = -v[1]
    out[1] = v[0]
    return out


def dot(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Scalar products of vectors stored components first.

    Parameters
    ----------
    p, q : numpy.ndarray
        Vectors (2, ...), broadcast against each other after the component axis.

    Returns
    -------
    numpy.ndarray
        p·q (...).

    Raises
    ------
    IndexError
        An array whose first axis is shorter than 2.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.engine import dot, perp
    >>> p = np.array([[1.0, 3.0], [2.0, 4.0]])
    >>> dot(p, p), dot(p, perp(p))                  # |p|², and 0: perp(p) is normal to p
    (array([ 5., 25.]), array([0., 0.]))
    """
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
    rates p (C, B) of the higher pairs' contact parameters, by the pair's name (absent: 0).

    The rate passes fill it (`set`, `set_param`) joint by joint; C columns are the unknowns a Jacobian
    differentiates by (one for a velocity pass), B the batch.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.engine import Rates
    >>> rates = Rates(batch=3, columns=1)
    >>> rates.set("1", np.full((1, 3), 10.0), np.zeros((2, 1, 3)))
    >>> rates.get("1")[0].tolist(), rates.get("2")[0].tolist()   # link 2 was not set: at rest
    ([[10.0, 10.0, 10.0]], [[0.0, 0.0, 0.0]])
    """

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
    """Revolute pair: one point shared by both links.

    Made from a `Joint` and the engine's centre (`Engine.centre`); `s0` is the joint's drawn point in
    the engine's frame, `links` the two links. As a tree joint it places the child link by its angle
    (`place`); as a cut joint it gives two closure equations, the difference of the two links' copies of
    the point (`closure`), zero when the loop is closed; `place_rates` and `closure_rates` are their
    time derivatives.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.engine import Engine, Revolute, solve_positions
    >>> from mbplanar.model import read_model
    >>> engine = Engine(read_model("models/fourbar.toml"))
    >>> law = engine.laws["B"]
    >>> isinstance(law, Revolute), law.kind, law.links
    (True, 'R', ('2', '3'))
    >>> residual, _ = law.closure(solve_positions(engine, np.radians([30.0, 90.0])).pose)
    >>> bool(np.abs(residual).max() < 1e-12)                           # (2, B): B is where both say
    True
    """

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
    """Prismatic pair: the slider keeps its drawn angle to the carrier, its point stays on the guide.

    `carrier` is the joint's first link (the guide's), `slider` its second; `u0` the guide's direction
    and `n0` its normal in the drawn pose. As a tree joint it places the slider by its displacement along
    the guide; as a cut joint its two closure equations are the relative rotation and the slider point's
    distance from the guide line.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.engine import Engine, Prismatic, solve_positions
    >>> from mbplanar.model import read_model
    >>> engine = Engine(read_model("models/slider_crank.toml"))
    >>> name, law = next((n, l) for n, l in engine.laws.items() if isinstance(l, Prismatic))
    >>> law.kind, law.carrier, law.slider, law.u0.round(6).tolist()
    ('P', '0', '3', [1.0, 0.0])
    >>> residual, _ = law.closure(solve_positions(engine, np.radians([45.0])).pose)
    >>> bool(np.abs(residual).max() < 1e-12)
    True
    """

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
    """The link frames of the engine's frame in the world convention, as results report them.

    The motion of each link's point drawn at the world's origin. Far from the origin the answer carries
    the rounding of world coordinates (~1e-16 of them).

    Parameters
    ----------
    centre : array_like
        The engine's centre (2,), m (`Engine.centre`).
    c, s : numpy.ndarray
        cos θ, sin θ of each link's rotation from the drawn pose (L, B).
    r : numpy.ndarray
        The frame origins in the engine's frame (2, L, B), m.
    w, e : numpy.ndarray, optional
        Angular velocities and accelerations (L, B), rad/s and rad/s².
    v, a : numpy.ndarray, optional
        The frame origins' velocities and accelerations (2, L, B), m/s and m/s².

    Returns
    -------
    r, v, a : numpy.ndarray or None
        The world frames' origins, velocities, accelerations (2, L, B); None where `v` or `a` was not
        given; the arrays given themselves when `centre` is 0 (the engine's frame is then the world's).

    Raises
    ------
    TypeError
        `v` given without `w`, or `a` without `w` and `e`.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.engine import world_frames
    >>> c, s = np.array([[0.0]]), np.array([[1.0]])                   # one link turned by 90°
    >>> r = np.zeros((2, 1, 1))                                      # its frame at the engine's origin
    >>> world, _, _ = world_frames(np.array([8.0, 0.0]), c, s, r)     # the engine's origin at x = 8
    >>> world[:, 0, 0].tolist()                                      # the point drawn at the world's 0
    [8.0, -8.0]
    """
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
