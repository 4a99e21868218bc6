"""Motion limits located exactly: at a fold (dead point) the engine solves for the input value and the
configuration together (`Limit.phi`, `Limit.q`), and `check` reports the extreme positions there from
that configuration. Compared with closed forms: the cosine rule for a crank-rocker driven by its rocker,
s = l ± r for a slider-crank driven by its slider, the elliptic trammel, and the lock of seed 002 from
its scalar closure equation."""

import math
from pathlib import Path

import numpy as np
import pytest

import mbplanar
from mbplanar.engine import Tolerances, _nodes, _singular, solve_positions
from mbplanar.analysis import check
from mbplanar.kinematics import positions_at_limits

from conftest import trammel

ROOT = Path(__file__).resolve().parent.parent

# crank-rocker O-A-B-C (models/fourbar.toml): crank OA = r, coupler AB = l, rocker CB = c, ground OC = d
R_, L_, C_, D_ = 0.10, 0.30, 0.25, 0.30
PSI0 = math.radians(110.0)


def circle_meet(p, rp, q, rq, side):
    """Intersection of circles (p, rp) and (q, rq) to the left (side +1) or right (−1) of p → q."""
    p, q = np.asarray(p, float), np.asarray(q, float)
    d = np.linalg.norm(q - p)
    x = (rp * rp - rq * rq + d * d) / (2 * d)
    u = (q - p) / d
    return p + x * u + side * math.sqrt(rp * rp - x * x) * np.array([-u[1], u[0]])


def rocker_driven(tol=None):
    """The crank-rocker driven at C by the rocker angle ψ (the direction C → B, degrees), drawn at ψ0."""
    b = np.array([D_ + C_ * math.cos(PSI0), C_ * math.sin(PSI0)])
    a = circle_meet((0.0, 0.0), R_, b, L_, +1)
    m = mbplanar.Mechanism("rocker_driven")
    m.add_link("1"), m.add_link("2"), m.add_link("3", angle=("C", "B"))
    m.add_joint("O", "R", "0", "1", at=(0.0, 0.0))
    m.add_joint("A", "R", "1", "2", at=tuple(a))
    m.add_joint("B", "R", "2", "3", at=tuple(b))
    m.add_joint("C", "R", "0", "3", at=(D_, 0.0))
    m.add_input("C", unit="deg")
    return mbplanar.Engine(m, tol=tol)


def rocker_dead_points():
    """(ψ, crank angle) at the dead points, where O, A, B are in line: |OB| = l + r (stretched, the
    crank along OB) and |OB| = l − r (folded, the crank against OB); the cosine rule in triangle OCB,
    |OB|² = d² + c² + 2dc·cos ψ, gives ψ."""
    out = []
    for ob, sign in ((L_ + R_, +1), (L_ - R_, -1)):
        psi = math.acos((ob * ob - D_ * D_ - C_ * C_) / (2 * D_ * C_))
        b = np.array([D_ + C_ * math.cos(psi), C_ * math.sin(psi)])
        out.append((psi, math.atan2(sign * b[1], sign * b[0])))
    return sorted(out)


def test_rocker_driven_crank_rocker_limits_and_crank_extremes_are_exact():
    engine = rocker_driven()
    (psi_lo, crank_lo), (psi_hi, crank_hi) = rocker_dead_points()
    motion = mbplanar.analyse(engine, np.linspace(psi_lo - 0.1, psi_hi + 0.1, 50))
    assert not motion.success and len(motion.limits) == 2
    limits = sorted(motion.limits, key=lambda lim: lim.phi[0])
    assert [lim.direction for lim in limits] == [-1, +1]
    assert all(lim.q is not None for lim in limits)
    got = [math.degrees(lim.phi[0]) for lim in limits]
    assert np.abs(np.subtract(got, np.degrees([psi_lo, psi_hi]))).max() < 1e-10   # deg (bisection: ~6e-9)
    # the configuration at the limits: the crank pin A on the line OB, at r from O
    at = positions_at_limits(engine, limits)
    assert len(at.phi) == 2 and np.all(np.isnan(at.wq))
    for row, crank in enumerate((crank_lo, crank_hi)):
        a = at.xy[row, at.point("A")]
        assert np.abs(a - R_ * np.array([math.cos(crank), math.sin(crank)])).max() < 1e-13
        assert abs(math.remainder(at.angle[row, at.link("1")] - crank, 2 * math.pi)) < 1e-12

    report = check(engine)
    want = np.degrees([psi_lo, psi_hi])
    assert np.abs(np.subtract(report.range, want)).max() < 1e-10
    assert np.abs(np.subtract(sorted(lim.phi for lim in report.limits), want)).max() < 1e-10
    crank = next(e for e in report.extremes if e.name == "1")
    assert not crank.turns
    extremes = sorted([(crank.at_min, crank.minimum), (crank.at_max, crank.maximum)])
    for (at_phi, value), (psi, angle) in zip(extremes, ((psi_lo, crank_lo), (psi_hi, crank_hi))):
        assert at_phi == pytest.approx(math.degrees(psi), abs=1e-10)
        # the crank moves like √(distance) there: sampling 1e-9 of the range inside was off by ~0.005°
        assert abs(math.degrees(math.remainder(value - angle, 2 * math.pi))) < 1e-9
    rocker = next(e for e in report.extremes if e.name == "3")
    assert np.abs(np.degrees([rocker.minimum, rocker.maximum]) - want).max() < 1e-10


def slider_driven_slider_crank(r, l, phi0):
    """Central slider-crank (crank OA = r, rod AB = l, B on the x axis) drawn exactly at crank angle
    phi0 and driven by the slide of B (m, from its drawn x_B0); returns the engine and x_B0."""
    a = (r * math.cos(phi0), r * math.sin(phi0))
    x0 = a[0] + math.sqrt(l * l - a[1] ** 2)
    m = mbplanar.Mechanism("slider_driven")
    for name in "123":
        m.add_link(name)
    m.add_joint("O", "R", "0", "1", at=(0.0, 0.0))
    m.add_joint("A", "R", "1", "2", at=a)
    m.add_joint("B", "R", "2", "3", at=(x0, 0.0))
    m.add_joint("Bp", "P", "0", "3", at=(x0, 0.0), guide=0.0)
    m.add_input("Bp", unit="m")
    return mbplanar.Engine(m), x0


def test_slider_driven_slider_crank_stops_at_l_plus_minus_r():
    """Driven by its slider, the slider-crank (r = 0.1, l = 0.3, as models/slider_crank.toml) stops at
    x_B = l ± r, crank and rod in line: the crank's extremes are 0° and 180° exactly there."""
    r, l = 0.1, 0.3
    engine, x0 = slider_driven_slider_crank(r, l, math.radians(45.0))
    report = check(engine)
    assert not report.full_turn and len(report.limits) == 2
    assert np.abs(np.subtract(report.range, (l - r - x0, l + r - x0))).max() < 1e-15
    crank = next(e for e in report.extremes if e.name == "1")
    assert abs(crank.minimum) < 1e-14 and crank.at_min == report.range[1]
    assert abs(crank.maximum - math.pi) < 1e-14 and crank.at_max == report.range[0]
    # the crank stays above the axis: the rod dips to −asin(r/l) at crank angle 90° (x_B = √(l² − r²))
    # and lies on the axis at both limits
    rod = next(e for e in report.extremes if e.name == "2")
    assert abs(rod.minimum + math.asin(r / l)) < 1e-12
    assert rod.at_min == pytest.approx(math.sqrt(l * l - r * r) - x0, abs=1e-12)
    assert abs(rod.maximum) < 1e-15 and rod.at_max in report.range


def test_elliptic_trammel_driven_by_a_slider_reaches_the_axis_exactly():
    """x_A = ±L are the limits; there B is at the origin and the rod lies on the x axis, so B's slide
    Bp is smallest, −L sin θ0, at both. (A sample 1e-9 of the range inside is off by √(2·2e-9)·L.)"""
    engine, length, th0 = trammel()
    report = check(engine)
    x0 = length * math.cos(th0)
    assert np.abs(np.subtract(report.range, (-length - x0, length - x0))).max() < 1e-15
    slide = next(e for e in report.extremes if e.name == "Bp")
    assert abs(slide.minimum + length * math.sin(th0)) < 1e-15
    assert abs(slide.maximum - length * (1 - math.sin(th0))) < 1e-12   # B at (0, L) at x_A = 0
    limits = sorted(mbplanar.analyse(engine, [-3.0, 3.0]).limits, key=lambda lim: lim.phi[0])
    at = positions_at_limits(engine, limits)
    assert np.abs(at.xy[:, at.point("B")]).max() < 1e-15
    assert np.abs(at.xy[:, at.point("M")] - [[-length / 2, 0.0], [length / 2, 0.0]]).max() < 1e-15


def lock_closed_form():
    """Seed 002's lock: the rocker dyad C-B-D stretched, |CD| = l3 + l4 = 2, with C on its line y = y_C
    left of D: x_C = x_D − √(4 − (y_C − y_D)²). The crank gives x_C(t) = l1 cos t + √(l2² − (y_C −
    l1 sin t)²): both roots of x_C(t) = x_C by Newton, from the seed's 1.8 and −0.8."""
    y_c, (x_d, y_d) = math.sin(0.5), (2.030486393606232, -1.161030804550828)
    target = x_d - math.sqrt(4.0 - (y_c - y_d) ** 2)
    roots = []
    for t in (-0.8, 1.8):
        for _ in range(40):
            w = y_c - 0.5 * math.sin(t)
            f = 0.5 * math.cos(t) + math.sqrt(1.0 - w * w) - target
            t -= f / (-0.5 * math.sin(t) + w * 0.5 * math.cos(t) / math.sqrt(1.0 - w * w))
        roots.append(t)
    return roots


def test_seed_002_lock_against_its_closure_equation():
    engine = mbplanar.Engine(mbplanar.read_model(ROOT / "models" / "crank_slider_rocker_locking.toml"))
    report = check(engine)
    down, up = lock_closed_form()
    assert up == pytest.approx(1.799912, abs=5e-7)   # the seed's printed lock
    assert np.abs(np.subtract(report.range, (down, up))).max() < 1e-13
    lock = next(lim for lim in report.limits if lim.direction == 1)
    assert "stretched at B" in lock.kind and lock.phi == report.range[1]
    mu = next(a for a in report.transmission if a.points == ("C", "B", "D"))
    assert mu.minimum < 1e-6 and mu.at_min in report.range   # C, B, D in line at the lock


def test_rows_just_short_of_a_located_limit_are_solved_or_left_out_with_it():
    """The walk's last node can be a few 1e-10 short of the fold: a row between them is left out, and
    then the limit is reported with it; a row at the limit itself is left out too."""
    engine = rocker_driven()
    (psi_lo, _), (psi_hi, _) = rocker_dead_points()
    check(engine)
    hi = next(lim for lim in engine.atlas().limits.values() if lim.direction > 0).phi[0]
    for offset in np.logspace(-15, -8, 15):
        motion = mbplanar.analyse(engine, [PSI0, hi - offset])
        assert motion.success or [lim.direction for lim in motion.limits] == [1], offset
    at = mbplanar.analyse(engine, [PSI0, hi])
    assert not at.success and len(at.phi) == 1 and [lim.direction for lim in at.limits] == [1]


def test_without_the_fold_refinement_the_bracket_remains():
    """If the augmented Newton does not converge, the limit is the middle of the walk's bracket (q None),
    good to a few 1e-10, and `check` falls back on its end samples."""
    engine = rocker_driven(Tolerances(fold_iterations=0))
    report = check(engine)
    assert all(lim.q is None for lim in engine.atlas().limits.values())
    want = np.degrees([psi for psi, _ in rocker_dead_points()])
    assert np.abs(np.subtract(report.range, want)).max() < 1e-7
    crank = next(e for e in report.extremes if e.name == "1")
    want = sorted(math.degrees(c) % 360.0 for _, c in rocker_dead_points())
    got = sorted(math.degrees(x) % 360.0 for x in (crank.minimum, crank.maximum))
    assert np.abs(np.subtract(got, want)).max() < 0.01


def test_a_change_point_is_not_taken_for_a_fold():
    """From a node next to the parallelogram's change point (its Jacobian singular there too, but the
    branch goes on) the fold refinement finds nothing it accepts: the unknowns do not follow the
    square-root law of a fold."""
    a, b, c = (math.cos(1.0), math.sin(1.0)), (2 + math.cos(1.0), math.sin(1.0)), (2.0, 0.0)
    m = mbplanar.Mechanism("parallelogram")
    for name in "123":
        m.add_link(name)
    m.add_joint("O", "R", "0", "1", at=(0.0, 0.0))
    m.add_joint("A", "R", "1", "2", at=a)
    m.add_joint("B", "R", "2", "3", at=b)
    m.add_joint("C", "R", "3", "0", at=c)
    m.add_input("O", unit="rad")
    engine = mbplanar.Engine(m)
    assert mbplanar.analyse(engine, np.linspace(0.0, 2 * math.pi, 9)).success
    for d in (1e-3, 1e-6, 2e-10):
        for way in (+1.0, -1.0):
            phi = np.array([math.pi - way * d])
            sol = solve_positions(engine, phi)
            node = _nodes.node_at(engine.solver, phi, np.array([way]), [st.q for st in sol.blocks])
            k = int(np.argmin(np.abs(node.dets)))
            assert _singular._locate_fold(engine.solver, k, node, np.array([way])) is None
