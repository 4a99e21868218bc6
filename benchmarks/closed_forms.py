"""Hand-written vectorised closed forms of the four-bar and the slider-crank (the practical speed limit
for the benchmark, and an independent check of the engine in tests/test_speed_invariance.py), and the
same loop equations for scipy.optimize.fsolve per position.

All functions take the crank angle phi (N,) in rad, its speed omega and acceleration epsilon (scalars or
(N,)), and return a dict of (N,) / (N, 2) arrays: link angles th1, th2, th3 (rad, absolute, of the
lines OA, AB, CB / AB), angular velocities w*, accelerations e*, and joint points A, B with velocities
vA, vB and accelerations aA, aB.
"""

from __future__ import annotations

import numpy as np

__all__ = ["FOURBAR", "SLIDER_CRANK", "circle_meet", "fourbar", "slider_crank", "fourbar_fsolve",
           "slider_crank_fsolve"]

# models/fourbar.toml: O = (0, 0), C = (0.3, 0), OA = 0.1, AB = 0.3, CB = 0.25, B above the line AC.
FOURBAR = dict(a=0.10, b=0.30, c=0.25, xc=0.30, branch=+1.0)
# models/slider_crank.toml: OA = 0.1, AB = 0.3, B on the x axis to the right of A.
SLIDER_CRANK = dict(a=0.10, b=0.30)


def _cross(p, q):
    return p[..., 0] * q[..., 1] - p[..., 1] * q[..., 0]


def _unit(th):
    return np.stack((np.cos(th), np.sin(th)), axis=-1)


def _perp(v):
    return np.stack((-v[..., 1], v[..., 0]), axis=-1)


def circle_meet(P, Q, rp, rq, side):
    """The point at distance rp from P and rq from Q, on `side` (±1: left/right of P→Q); P, Q (N, 2).
    The dyad's closed form, used to build test mechanisms dyad after dyad."""
    d = Q - P
    dist = np.linalg.norm(d, axis=-1)
    x = (rp * rp - rq * rq + dist * dist) / (2 * dist)
    h = np.sqrt(np.maximum(rp * rp - x * x, 0.0))
    u = d / dist[:, None]
    return P + x[:, None] * u + side * h[:, None] * _perp(u)


def fourbar(phi, omega=1.0, epsilon=0.0, positions_only=False, a=0.10, b=0.30, c=0.25, xc=0.30,
            branch=+1.0):
    """Crank-rocker four-bar O-A-B-C: B from the triangle A, B, C (law of cosines), rates from the
    loop r1 + r2 = C + r3 crossed with r3 and r2."""
    phi = np.asarray(phi, float)
    r1 = a * _unit(phi)
    d = np.array([xc, 0.0]) - r1
    dist = np.hypot(d[:, 0], d[:, 1])
    cos_ang = (b * b + dist * dist - c * c) / (2 * b * dist)
    th2 = np.arctan2(d[:, 1], d[:, 0]) + branch * np.arccos(cos_ang)
    r2 = b * _unit(th2)
    B = r1 + r2
    r3 = B - np.array([xc, 0.0])
    th3 = np.arctan2(r3[:, 1], r3[:, 0])
    out = dict(th1=phi, th2=th2, th3=th3, A=r1, B=B)
    if positions_only:
        return out
    w1 = np.broadcast_to(np.asarray(omega, float), phi.shape)
    e1 = np.broadcast_to(np.asarray(epsilon, float), phi.shape)
    w2 = -w1 * _cross(r1, r3) / _cross(r2, r3)
    w3 = w1 * _cross(r1, r2) / _cross(r3, r2)
    vA = w1[:, None] * _perp(r1)
    vB = w3[:, None] * _perp(r3)
    # e1 J r1 - w1² r1 + e2 J r2 - w2² r2 = e3 J r3 - w3² r3; K collects the known terms
    K = e1[:, None] * _perp(r1) - (w1 * w1)[:, None] * r1 - (w2 * w2)[:, None] * r2 + (w3 * w3)[:, None] * r3
    JK = _perp(K)
    e2 = _cross(JK, r3) / _cross(r2, r3)
    e3 = -_cross(JK, r2) / _cross(r3, r2)
    aA = e1[:, None] * _perp(r1) - (w1 * w1)[:, None] * r1
    aB = e3[:, None] * _perp(r3) - (w3 * w3)[:, None] * r3
    out.update(w1=w1, w2=w2, w3=w3, e1=e1, e2=e2, e3=e3, vA=vA, vB=vB, aA=aA, aB=aB)
    return out


def slider_crank(phi, omega=1.0, epsilon=0.0, positions_only=False, a=0.10, b=0.30):
    """Central slider-crank: sin θ2 = −a sin φ / b with cos θ2 > 0; x_B = a cos φ + b cos θ2."""
    phi = np.asarray(phi, float)
    s1, c1 = np.sin(phi), np.cos(phi)
    s2 = -a * s1 / b
    c2 = np.sqrt(1 - s2 * s2)
    th2 = np.arctan2(s2, c2)
    A = a * np.stack((c1, s1), axis=-1)
    xB = a * c1 + b * c2
    B = np.stack((xB, np.zeros_like(xB)), axis=-1)
    out = dict(th1=phi, th2=th2, A=A, B=B)
    if positions_only:
        return out
    w1 = np.broadcast_to(np.asarray(omega, float), phi.shape)
    e1 = np.broadcast_to(np.asarray(epsilon, float), phi.shape)
    w2 = -a * w1 * c1 / (b * c2)
    vB = -a * w1 * s1 - b * w2 * s2
    e2 = (a * w1 * w1 * s1 - a * e1 * c1 + b * w2 * w2 * s2) / (b * c2)
    aB = -a * (e1 * s1 + w1 * w1 * c1) - b * (e2 * s2 + w2 * w2 * c2)
    zero = np.zeros_like(vB)
    out.update(w1=w1, w2=w2, e1=e1, e2=e2, vA=w1[:, None] * _perp(A),
               aA=e1[:, None] * _perp(A) - (w1 * w1)[:, None] * A,
               vB=np.stack((vB, zero), axis=-1), aB=np.stack((aB, zero), axis=-1))
    return out


def _fsolve_loop(residual, jacobian, bias, phi, x0, omega, epsilon, rates):
    """Per position: fsolve on the loop equations from the previous solution, then (if `rates`) the
    velocity and acceleration of the unknowns from the same Jacobian (np.linalg.solve)."""
    from scipy.optimize import fsolve

    x = np.array(x0, float)
    out = np.empty((len(phi), 6 if rates else 2))
    for k, p in enumerate(phi):
        x = fsolve(residual, x, args=(p,), fprime=jacobian, xtol=1e-12)
        out[k, :2] = x
        if rates:
            J = jacobian(x, p)
            xd = np.linalg.solve(J, -omega * residual.dphi(x, p))
            xdd = np.linalg.solve(J, -bias(x, p, xd, omega, epsilon))
            out[k, 2:4], out[k, 4:6] = xd, xdd
    return out


def _fourbar_equations(a=0.10, b=0.30, c=0.25, xc=0.30):
    def res(x, p):
        t2, t3 = x
        return [a * np.cos(p) + b * np.cos(t2) - xc - c * np.cos(t3), a * np.sin(p) + b * np.sin(t2) - c * np.sin(t3)]

    def jac(x, p):
        t2, t3 = x
        return np.array([[-b * np.sin(t2), c * np.sin(t3)], [b * np.cos(t2), -c * np.cos(t3)]])

    res.dphi = lambda x, p: np.array([-a * np.sin(p), a * np.cos(p)])

    def bias(x, p, xd, w1, e1):  # the acceleration equation's terms without the unknowns' ε
        t2, t3 = x
        w2, w3 = xd
        return np.array([-a * (e1 * np.sin(p) + w1 * w1 * np.cos(p)) - b * w2 * w2 * np.cos(t2) + c * w3 * w3 * np.cos(t3),
                         a * (e1 * np.cos(p) - w1 * w1 * np.sin(p)) - b * w2 * w2 * np.sin(t2) + c * w3 * w3 * np.sin(t3)])
    return res, jac, bias


def _slider_crank_equations(a=0.10, b=0.30):
    def res(x, p):
        t2, xb = x
        return [a * np.cos(p) + b * np.cos(t2) - xb, a * np.sin(p) + b * np.sin(t2)]

    def jac(x, p):
        t2, _ = x
        return np.array([[-b * np.sin(t2), -1.0], [b * np.cos(t2), 0.0]])

    res.dphi = lambda x, p: np.array([-a * np.sin(p), a * np.cos(p)])

    def bias(x, p, xd, w1, e1):
        t2 = x[0]
        w2 = xd[0]
        return np.array([-a * (e1 * np.sin(p) + w1 * w1 * np.cos(p)) - b * w2 * w2 * np.cos(t2),
                         a * (e1 * np.cos(p) - w1 * w1 * np.sin(p)) - b * w2 * w2 * np.sin(t2)])
    return res, jac, bias


def fourbar_fsolve(phi, omega=1.0, epsilon=0.0, rates=True):
    """(θ2, θ3[, ω2, ω3, ε2, ε3]) per position with scipy.optimize.fsolve, (N, 2 or 6)."""
    x0 = fourbar(np.asarray(phi[:1], float), positions_only=True)
    return _fsolve_loop(*_fourbar_equations(), phi, (x0["th2"][0], x0["th3"][0]), omega, epsilon, rates)


def slider_crank_fsolve(phi, omega=1.0, epsilon=0.0, rates=True):
    """(θ2, x_B[, ω2, v_B, ε2, a_B]) per position with scipy.optimize.fsolve, (N, 2 or 6)."""
    x0 = slider_crank(np.asarray(phi[:1], float), positions_only=True)
    return _fsolve_loop(*_slider_crank_equations(), phi, (x0["th2"][0], x0["B"][0, 0]), omega, epsilon, rates)
