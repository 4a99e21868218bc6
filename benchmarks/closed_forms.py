"""Hand-written vectorised closed forms of the four-bar, the slider-crank and the six-bar press (the
practical speed limit for the benchmark, and an independent check of the engine in
tests/test_speed_invariance.py).

All functions take the input value phi (N,) in rad, its speed omega and acceleration epsilon (scalars or
(N,)), and return a dict of (N,) / (N, 2) arrays: link angles th1, th2, ... (rad, absolute, of the lines
named in each docstring), angular velocities w*, accelerations e*, joint points A, B, ... with velocities
vA, vB, ... and accelerations aA, aB, ...

Each also returns what `mbplanar.analyse` returns for the same model file, the benchmark's equal work:
``xy`` (point name → (N, 2)) for every point of the model, ground pivots included, ``angle`` (link name →
(N,)) for every link with the model's reference lines, and, unless `positions_only`, ``v`` and ``a``
(point name → (N, 2)). `read` touches all of them, as the benchmark reads a Motion.
"""

from __future__ import annotations

import numpy as np

__all__ = ["FOURBAR", "SLIDER_CRANK", "SIX_BAR_PRESS", "circle_meet", "fourbar", "slider_crank",
           "six_bar_press", "read"]

# models/fourbar.toml: O = (0, 0), C = (0.3, 0), OA = 0.1, AB = 0.3, CB = 0.25, B above the line AC;
# coupler point M at the middle of AB, 0.05 m to its left.
FOURBAR = dict(a=0.10, b=0.30, c=0.25, xc=0.30, branch=+1.0)
# models/slider_crank.toml: OA = 0.1, AB = 0.3, B on the x axis to the right of A.
SLIDER_CRANK = dict(a=0.10, b=0.30)
# models/six_bar_press.toml (seed 003): O = (0, 0), C = (1.25, 0), OA = 0.347, AB = 1.445, CB = 0.85 with
# B the middle of CD, DH = 1.7, slider H on the line y = 0.9 to the right of D; S2 on AB 0.7225 m from A,
# S4 the middle of DH. The input f turns the crank clockwise: crank angle = 219.1° − f.
SIX_BAR_PRESS = dict(a=0.347, b=1.445, c=0.85, xc=1.25, d=1.7, y_guide=0.9, s2=0.7225,
                     zero=np.radians(219.1), sense=-1.0)


def _cross(p, q):
    return p[..., 0] * q[..., 1] - p[..., 1] * q[..., 0]


def _dot(p, q):
    return p[..., 0] * q[..., 0] + p[..., 1] * q[..., 1]


def _unit(th):
    return np.stack((np.cos(th), np.sin(th)), axis=-1)


def _perp(v):
    return np.stack((-v[..., 1], v[..., 0]), axis=-1)


def _fixed(p, n):
    """A ground point (2,) as an (n, 2) array (a read-only view: it costs nothing to make)."""
    return np.broadcast_to(np.asarray(p, float), (n, 2))


def _spin(x, w, e):
    """Velocity and acceleration (N, 2) of the tip of x (N, 2) turning at w, e (N,) about a fixed end."""
    return w[:, None] * _perp(x), e[:, None] * _perp(x) - (w * w)[:, None] * x


def read(out) -> float:
    """Touch every array of the equal work of a closed form's result (the sum of all of them), as the
    benchmark reads a Motion."""
    return sum(float(x.sum()) for key in ("xy", "v", "a", "angle") if out.get(key) for x in out[key].values())


def circle_meet(P, Q, rp, rq, side):
    """The point at distance rp from P and rq from Q, on `side` (±1: left/right of P→Q); P, Q (N, 2).
    The dyad's closed form, used to build test mechanisms dyad after dyad."""
    d = Q - P
    dist = np.linalg.norm(d, axis=-1)
    x = (rp * rp - rq * rq + dist * dist) / (2 * dist)
    h = np.sqrt(np.maximum(rp * rp - x * x, 0.0))
    u = d / dist[:, None]
    return P + x[:, None] * u + side * h[:, None] * _perp(u)


def _dyad_rates(vA, aA, r2, r3, vC=0.0, aC=0.0):
    """Angular velocities and accelerations (N,) of the two links of an RRR dyad from the loop
    A + r2 = C + r3 (r2 from A, r3 from C to the common pin), given the motion of its ends A and C."""
    dv, da = vA - vC, aA - aC
    w2 = -_dot(dv, r3) / _cross(r2, r3)
    w3 = _dot(dv, r2) / _cross(r3, r2)
    K = da - (w2 * w2)[:, None] * r2 + (w3 * w3)[:, None] * r3
    e2 = -_dot(K, r3) / _cross(r2, r3)
    e3 = _dot(K, r2) / _cross(r3, r2)
    return w2, w3, e2, e3


def fourbar(phi, omega=1.0, epsilon=0.0, positions_only=False, a=0.10, b=0.30, c=0.25, xc=0.30,
            branch=+1.0):
    """Crank-rocker four-bar O-A-B-C: B from the triangle A, B, C (law of cosines), rates from the
    loop r1 + r2 = C + r3 crossed with r3 and r2. th1, th2, th3: lines OA, AB, CB."""
    phi = np.asarray(phi, float)
    n = len(phi)
    r1 = a * _unit(phi)
    d = np.array([xc, 0.0]) - r1
    dist = np.hypot(d[:, 0], d[:, 1])
    cos_ang = (b * b + dist * dist - c * c) / (2 * b * dist)
    th2 = np.arctan2(d[:, 1], d[:, 0]) + branch * np.arccos(cos_ang)
    u2 = _unit(th2)
    r2 = b * u2
    B = r1 + r2
    r3 = B - np.array([xc, 0.0])
    th3 = np.arctan2(r3[:, 1], r3[:, 0])
    m = 0.5 * r2 + 0.05 * _perp(u2)  # coupler point M from A
    M = r1 + m
    O, C = _fixed((0.0, 0.0), n), _fixed((xc, 0.0), n)
    out = dict(th1=phi, th2=th2, th3=th3, A=r1, B=B, M=M,
               xy=dict(O=O, A=r1, B=B, C=C, M=M),
               angle={"0": np.zeros(n), "1": phi, "2": th2, "3": th3 + np.pi})  # link 3's line is BC
    if positions_only:
        return out
    w1 = np.broadcast_to(np.asarray(omega, float), phi.shape)
    e1 = np.broadcast_to(np.asarray(epsilon, float), phi.shape)
    w2 = -w1 * _cross(r1, r3) / _cross(r2, r3)
    w3 = w1 * _cross(r1, r2) / _cross(r3, r2)
    vA, aA = _spin(r1, w1, e1)
    vB = w3[:, None] * _perp(r3)
    # e1 J r1 - w1² r1 + e2 J r2 - w2² r2 = e3 J r3 - w3² r3; K collects the known terms
    K = e1[:, None] * _perp(r1) - (w1 * w1)[:, None] * r1 - (w2 * w2)[:, None] * r2 + (w3 * w3)[:, None] * r3
    JK = _perp(K)
    e2 = _cross(JK, r3) / _cross(r2, r3)
    e3 = -_cross(JK, r2) / _cross(r3, r2)
    aB = e3[:, None] * _perp(r3) - (w3 * w3)[:, None] * r3
    vm, am = _spin(m, w2, e2)
    vM, aM = vA + vm, aA + am
    zero = _fixed((0.0, 0.0), n)
    out.update(w1=w1, w2=w2, w3=w3, e1=e1, e2=e2, e3=e3, vA=vA, vB=vB, aA=aA, aB=aB, vM=vM, aM=aM,
               v=dict(O=zero, A=vA, B=vB, C=zero, M=vM), a=dict(O=zero, A=aA, B=aB, C=zero, M=aM))
    return out


def slider_crank(phi, omega=1.0, epsilon=0.0, positions_only=False, a=0.10, b=0.30):
    """Central slider-crank: sin θ2 = −a sin φ / b with cos θ2 > 0; x_B = a cos φ + b cos θ2.
    th1, th2: lines OA, AB; the slider's point Bp is B."""
    phi = np.asarray(phi, float)
    n = len(phi)
    s1, c1 = np.sin(phi), np.cos(phi)
    s2 = -a * s1 / b
    c2 = np.sqrt(1 - s2 * s2)
    th2 = np.arctan2(s2, c2)
    A = a * np.stack((c1, s1), axis=-1)
    xB = a * c1 + b * c2
    B = np.stack((xB, np.zeros_like(xB)), axis=-1)
    zeros = np.zeros(n)
    out = dict(th1=phi, th2=th2, A=A, B=B, xy=dict(O=_fixed((0.0, 0.0), n), A=A, B=B, Bp=B),
               angle={"0": zeros, "1": phi, "2": th2, "3": zeros})
    if positions_only:
        return out
    w1 = np.broadcast_to(np.asarray(omega, float), phi.shape)
    e1 = np.broadcast_to(np.asarray(epsilon, float), phi.shape)
    w2 = -a * w1 * c1 / (b * c2)
    vB = -a * w1 * s1 - b * w2 * s2
    e2 = (a * w1 * w1 * s1 - a * e1 * c1 + b * w2 * w2 * s2) / (b * c2)
    aB = -a * (e1 * s1 + w1 * w1 * c1) - b * (e2 * s2 + w2 * w2 * c2)
    vA, aA = _spin(A, w1, e1)
    vB, aB = np.stack((vB, zeros), axis=-1), np.stack((aB, zeros), axis=-1)
    zero = _fixed((0.0, 0.0), n)
    out.update(w1=w1, w2=w2, e1=e1, e2=e2, vA=vA, aA=aA, vB=vB, aB=aB,
               v=dict(O=zero, A=vA, B=vB, Bp=vB), a=dict(O=zero, A=aA, B=aB, Bp=aB))
    return out


def six_bar_press(phi, omega=1.0, epsilon=0.0, positions_only=False, a=0.347, b=1.445, c=0.85, xc=1.25,
                  d=1.7, y_guide=0.9, s2=0.7225, zero=np.radians(219.1), sense=-1.0, rocker=(2.0, 0.0)):
    """Six-bar press of seed 003: crank OA (angle zero + sense·phi), dyad A-B-C (B left of A→C), rocker
    C-B-D with D = C + k (B − C) + h J (B − C), (k, h) = `rocker` ((2, 0): B the middle of CD), rod DH
    with the slider H on the line y = y_guide right of D.
    th1, th2, th3, th4: lines OA, AB, CD, HD (the model's reference lines)."""
    phi = np.asarray(phi, float)
    n = len(phi)
    th1 = zero + sense * phi
    A = a * _unit(th1)
    C = np.array([xc, 0.0])
    B = circle_meet(A, _fixed(C, n), b, c, +1.0)
    r2, r3 = B - A, B - C
    k, h = rocker
    D = C + k * r3 + h * _perp(r3)
    dy = y_guide - D[:, 1]
    dx = np.sqrt(d * d - dy * dy)
    H = np.stack((D[:, 0] + dx, np.full(n, y_guide)), axis=-1)
    r4 = H - D
    u2 = r2 / b
    S2 = A + s2 * u2
    S4 = 0.5 * (D + H)
    th2 = np.arctan2(r2[:, 1], r2[:, 0])
    th3 = np.arctan2(D[:, 1] - C[1], D[:, 0] - C[0])
    th4 = np.arctan2(-r4[:, 1], -r4[:, 0])
    zeros = np.zeros(n)
    out = dict(th1=th1, th2=th2, th3=th3, th4=th4, A=A, B=B, D=D, H=H, S2=S2, S4=S4,
               xy=dict(O=_fixed((0.0, 0.0), n), A=A, B=B, C=_fixed(C, n), D=D, H=H, Hp=H, S2=S2, S3=B, S4=S4),
               angle={"0": zeros, "1": th1, "2": th2, "3": th3, "4": th4, "5": zeros})
    if positions_only:
        return out
    w1 = sense * np.broadcast_to(np.asarray(omega, float), phi.shape)
    e1 = sense * np.broadcast_to(np.asarray(epsilon, float), phi.shape)
    vA, aA = _spin(A, w1, e1)
    w2, w3, e2, e3 = _dyad_rates(vA, aA, r2, r3)
    vB, aB = _spin(r3, w3, e3)
    vD, aD = k * vB + h * _perp(vB), k * aB + h * _perp(aB)
    # slider on a horizontal line: H = D + r4 with vH_y = aH_y = 0
    w4 = -vD[:, 1] / r4[:, 0]
    e4 = (w4 * w4 * r4[:, 1] - aD[:, 1]) / r4[:, 0]
    v4, a4 = _spin(r4, w4, e4)
    vH, aH = vD + v4, aD + a4
    vs2, as2 = _spin(s2 * u2, w2, e2)
    vS2, aS2 = vA + vs2, aA + as2
    vS4, aS4 = 0.5 * (vD + vH), 0.5 * (aD + aH)
    fixed = _fixed((0.0, 0.0), n)
    out.update(w1=w1, w2=w2, w3=w3, w4=w4, e1=e1, e2=e2, e3=e3, e4=e4,
               v=dict(O=fixed, A=vA, B=vB, C=fixed, D=vD, H=vH, Hp=vH, S2=vS2, S3=vB, S4=vS4),
               a=dict(O=fixed, A=aA, B=aB, C=fixed, D=aD, H=aH, Hp=aH, S2=aS2, S3=aB, S4=aS4))
    return out
