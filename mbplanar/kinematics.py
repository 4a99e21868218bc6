"""Kinematic results for every link, joint and point: positions, analogues (d/dφ, d²/dφ²) and real
velocities and accelerations, instantaneous centres of velocity.

`analyse(engine, phi, omega, epsilon)` solves a batch and returns a `Motion`: arrays with the batch
first, in SI units (m, rad, s). Real values follow the analogues: v = v_q·ω, a = a_q·ω² + v_q·ε.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .constraints import perp
from .solver import Engine, Limit

__all__ = ["Motion", "analyse"]


@dataclass
class Motion:
    """Kinematics of a batch of positions (only those reached on the drawn branch).

    phi (B, n_in): input values (SI); omega, epsilon (B, n_in): input speed and acceleration.
    Links: angle, w, e (B, L) real; wq, eq analogues. Points: xy, v, a (B, P, 2); vq, aq analogues.
    Joints: value, rate, accel (B, J); rate_q, accel_q analogues. Analogues are None with several inputs.
    """

    engine: Engine
    phi: np.ndarray
    omega: np.ndarray
    epsilon: np.ndarray
    link_names: list
    angle: np.ndarray
    w: np.ndarray
    e: np.ndarray
    point_names: list
    xy: np.ndarray
    v: np.ndarray
    a: np.ndarray
    joint_names: list
    value: np.ndarray
    rate: np.ndarray
    accel: np.ndarray
    ic: np.ndarray
    wq: np.ndarray | None = None
    eq: np.ndarray | None = None
    vq: np.ndarray | None = None
    aq: np.ndarray | None = None
    rate_q: np.ndarray | None = None
    accel_q: np.ndarray | None = None
    requested: int = 0
    limits: list[Limit] = field(default_factory=list)
    frames: dict = field(default_factory=dict)

    @property
    def success(self) -> bool:
        return len(self.phi) == self.requested

    @property
    def message(self) -> str:
        if self.success:
            return "solved"
        return "; ".join(describe_limit(self.engine, lim) for lim in self.limits) or \
            f"{self.requested - len(self.phi)} position(s) could not be solved on the drawn branch"

    def point(self, name: str) -> int:
        return self.point_names.index(name)

    def link(self, name: str) -> int:
        return self.link_names.index(name)

    def joint(self, name: str) -> int:
        return self.joint_names.index(name)


def describe_limit(engine: Engine, lim: Limit) -> str:
    inp = engine.inputs[0]
    where = ", ".join(f"{i.name} = {i.from_si(p):.10g} {i.unit}" for i, p in zip(engine.inputs, lim.phi))
    way = {1: "going up", -1: "going down"}.get(lim.direction, "")
    return (f"motion limit at {where} ({way}): links {', '.join(lim.links)} — {lim.kind}"
            if inp else "motion limit")


def _point_table(engine: Engine):
    """(names, link index, drawn coordinates) of every joint (its slider point for P) and point."""
    mech = engine.mech
    names, links, at = [], [], []
    for j in mech.joints.values():
        names.append(j.name)
        links.append(engine.link_index[j.slider if j.kind == "P" else j.links[0]])
        at.append(j.at)
    for p in mech.points.values():
        names.append(p.name)
        links.append(engine.link_index[p.link])
        at.append(p.at)
    return names, np.array(links, int), np.array(at, float).reshape(-1, 2)


def material_points(th, r, w, v, e, a, links, at):
    """Position, velocity and acceleration of points drawn at `at` (P, 2) on links `links` (P,)."""
    c, s = np.cos(th[:, links]), np.sin(th[:, links])
    rho = np.stack((c * at[:, 0] - s * at[:, 1], s * at[:, 0] + c * at[:, 1]), axis=-1)
    xy = r[:, links] + rho
    wl, el = w[:, links, None], e[:, links, None]
    vel = v[:, links] + wl * perp(rho)
    acc = a[:, links] + el * perp(rho) - wl * wl * rho
    return xy, vel, acc


def _joint_values(engine: Engine, th, r, w, v, e, a):
    """value, rate, accel (B, J) of every joint from the link states."""
    mech = engine.mech
    out = [[], [], []]
    for j in mech.joints.values():
        ia, ib = engine.link_index[j.links[0]], engine.link_index[j.links[1]]
        if j.kind == "R":
            out[0].append(th[:, ib] - th[:, ia] + engine.joint_value_drawn[j.name])
            out[1].append(w[:, ib] - w[:, ia])
            out[2].append(e[:, ib] - e[:, ia])
            continue
        law = engine.laws[j.name]
        at = np.array([j.at])
        xs, vs, as_ = material_points(th, r, w, v, e, a, np.array([ib]), at)
        xc, vc, ac = material_points(th, r, w, v, e, a, np.array([ia]), at)
        d, dd, ddd = (xs - xc)[:, 0], (vs - vc)[:, 0], (as_ - ac)[:, 0]
        c, s = np.cos(th[:, ia]), np.sin(th[:, ia])
        u = np.stack((c * law.u0[0] - s * law.u0[1], s * law.u0[0] + c * law.u0[1]), axis=-1)
        pu = perp(u)
        wc, ec = w[:, ia], e[:, ia]
        dot = lambda p, q: np.einsum("bi,bi->b", p, q)  # noqa: E731
        out[0].append(engine.joint_value_drawn[j.name] + dot(u, d))
        out[1].append(wc * dot(pu, d) + dot(u, dd))
        out[2].append(ec * dot(pu, d) - wc * wc * dot(u, d) + 2 * wc * dot(pu, dd) + dot(u, ddd))
    return tuple(np.stack(x, axis=1) for x in out)


def _link_states(engine: Engine, sol):
    names = engine.links
    th = np.stack([sol.pose.th[n] for n in names], axis=1)
    r = np.stack([sol.pose.r[n] for n in names], axis=1)
    return th, r


def _instant_centres(r, v, w):
    """Instantaneous centre of every link: r + perp(v)/ω; NaN where ω = 0 (translation)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        ic = r + perp(v) / w[..., None]
    ic[~np.isfinite(ic)] = np.nan
    return ic


def _per_position(value, default, batch, n_in):
    """A scalar, one value per input, or one per position → (B, n_in)."""
    arr = np.asarray(default if value is None else value, float)
    if arr.ndim == 0:
        arr = np.full(n_in, float(arr))
    if arr.ndim == 1 and n_in == 1:
        arr = arr[:, None]
    return np.broadcast_to(arr, (batch, n_in))


def analyse(engine: Engine, phi, omega=None, epsilon=None) -> Motion:
    """Solve `phi` and return the kinematics of the positions reached (rows past a motion limit, which
    hold no solution, are dropped before anything is returned)."""
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        return _analyse(engine, phi, omega, epsilon)


def _analyse(engine: Engine, phi, omega=None, epsilon=None) -> Motion:
    """Solve `phi` (SI; (B,) or (B, n_in)) and return the kinematics of the positions reached.

    omega, epsilon: input speed and acceleration, scalars or per position (default: the model's).
    """
    n_in = len(engine.inputs)
    phi = np.asarray(phi, float)
    phi = phi.reshape(-1, n_in) if phi.ndim <= 1 and n_in == 1 else np.atleast_2d(phi)
    sol = engine.solve(phi)
    keep = np.flatnonzero(sol.valid)
    batch = len(phi)
    omega = _per_position(omega, [i.omega for i in engine.inputs], batch, n_in)
    epsilon = _per_position(epsilon, [i.epsilon for i in engine.inputs], batch, n_in)
    th, r = _link_states(engine, sol)
    names, links, at = _point_table(engine)
    analog = n_in == 1
    if analog:
        engine.rates(sol, np.ones((batch, 1)), np.zeros((batch, 1)))
        wq, vq_f, eq, aq_f = sol.w, sol.v, sol.e, sol.a
        om, ep = omega[:, :1], epsilon[:, :1]
        w, e = wq * om, eq * om ** 2 + wq * ep
        v = vq_f * om[..., None]
        a = aq_f * om[..., None] ** 2 + vq_f * ep[..., None]
    else:
        engine.rates(sol, omega, epsilon)
        w, v, e, a = sol.w, sol.v, sol.e, sol.a
    xy, pv, pa = material_points(th, r, w, v, e, a, links, at)
    value, rate, accel = _joint_values(engine, th, r, w, v, e, a)
    alpha = np.array([engine.reference_angle[n] for n in engine.links])
    m = Motion(engine=engine, phi=phi[keep], omega=omega[keep], epsilon=epsilon[keep],
               link_names=list(engine.links), angle=(th + alpha)[keep], w=w[keep], e=e[keep],
               point_names=names, xy=xy[keep], v=pv[keep], a=pa[keep],
               joint_names=list(engine.mech.joints), value=value[keep], rate=rate[keep],
               accel=accel[keep], ic=_instant_centres(r, v, w)[keep], requested=batch,
               limits=sol.limits, frames={"th": th[keep], "r": r[keep]})
    if analog:
        _, pvq, paq = material_points(th, r, wq, vq_f, eq, aq_f, links, at)
        _, rq, accq = _joint_values(engine, th, r, wq, vq_f, eq, aq_f)
        m.wq, m.eq, m.vq, m.aq = wq[keep], eq[keep], pvq[keep], paq[keep]
        m.rate_q, m.accel_q = rq[keep], accq[keep]
        m.frames.update(w=wq[keep], v=vq_f[keep], e=eq[keep], a=aq_f[keep])
    return m
