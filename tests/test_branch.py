"""Branch safety: random Grashof crank-rockers and slider-cranks swept at 1°, 10° and 45° steps stay
on the assembly branch they were drawn in, checked against the closed form with the drawn branch sign."""

import math
import os
import sys
from pathlib import Path

import numpy as np

import mbplanar

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))
from closed_forms import circle_meet  # noqa: E402

RNG_SEED = 20240508
N_EACH = int(os.environ.get("MBPLANAR_BRANCH_N", 500))  # per kind: 1000 mechanisms in all (~60 s)
STEPS_DEG = (1.0, 10.0, 45.0)


def _random_crank_rocker(rng):
    while True:
        a = rng.uniform(0.05, 0.4)
        b, c = rng.uniform(0.3, 1.6, 2)
        d = 1.0
        s_, p, q, l_ = sorted((a, b, c, d))
        if s_ == a and (p + q) - (s_ + l_) > 0.05:
            return a, b, c, d


def _crank_rocker(rng):
    a, b, c, d = _random_crank_rocker(rng)
    th0, sign = rng.uniform(0, 2 * math.pi), rng.choice([-1.0, 1.0])
    A = np.array([[a * math.cos(th0), a * math.sin(th0)]])
    C = np.array([[d, 0.0]])
    B = circle_meet(A, C, b, c, sign)[0]
    m = mbplanar.Mechanism("crank-rocker")
    for name in "123":
        m.add_link(name)
    m.add_joint("O", "R", "0", "1", at=(0.0, 0.0))
    m.add_joint("A", "R", "1", "2", at=tuple(A[0]))
    m.add_joint("B", "R", "2", "3", at=tuple(B))
    m.add_joint("C", "R", "3", "0", at=(d, 0.0))
    m.add_input("O", unit="rad")

    def closed_form(phi):
        A = a * np.stack([np.cos(phi), np.sin(phi)], axis=-1)
        return circle_meet(A, np.broadcast_to(C, A.shape), b, c, sign)
    return m, th0, "B", closed_form


def _slider_crank(rng):
    r = rng.uniform(0.05, 0.5)
    e = rng.uniform(-0.3, 0.3)
    rod = r + abs(e) + rng.uniform(0.1, 1.5)
    th0, sign = rng.uniform(0, 2 * math.pi), rng.choice([-1.0, 1.0])
    A = (r * math.cos(th0), r * math.sin(th0))
    xb = A[0] + sign * math.sqrt(rod * rod - (e - A[1]) ** 2)
    m = mbplanar.Mechanism("slider-crank")
    for name in "123":
        m.add_link(name)
    m.add_joint("O", "R", "0", "1", at=(0.0, 0.0))
    m.add_joint("A", "R", "1", "2", at=A)
    m.add_joint("B", "R", "2", "3", at=(xb, e))
    m.add_joint("Bp", "P", "0", "3", at=(xb, e), guide=0.0)
    m.add_input("O", unit="rad")

    def closed_form(phi):
        x = r * np.cos(phi) + sign * np.sqrt(rod * rod - (e - r * np.sin(phi)) ** 2)
        return np.stack([x, np.full_like(x, e)], axis=-1)
    return m, th0, "B", closed_form


def _sweep_matches(build, rng):
    worst = 0.0
    for _ in range(N_EACH):
        mech, th0, point, closed_form = build(rng)
        engine = mbplanar.Engine(mech)
        assert abs(engine.phi_drawn[0] - math.remainder(th0, 2 * math.pi)) < 1e-9 or \
            abs(math.remainder(engine.phi_drawn[0] - th0, 2 * math.pi)) < 1e-9
        for step in STEPS_DEG:
            phi = engine.phi_drawn[0] + np.radians(np.arange(0.0, 360.0 + step / 2, step))
            motion = mbplanar.analyse(engine, phi)
            assert motion.success, motion.message
            got = motion.xy[:, motion.point(point)]
            worst = max(worst, float(np.max(np.abs(got - closed_form(phi)))))
    return worst


def test_crank_rockers_stay_on_drawn_branch():
    assert _sweep_matches(_crank_rocker, np.random.default_rng(RNG_SEED)) < 1e-8


def test_slider_cranks_stay_on_drawn_branch():
    assert _sweep_matches(_slider_crank, np.random.default_rng(RNG_SEED + 1)) < 1e-8
