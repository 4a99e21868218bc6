"""`mbplanar check`: full-turn verdicts, dead points, extreme positions and transmission angles, compared
with closed forms (four-bar, slider-crank) and REFERENCE.md (shaper stroke H and swing β; the lock of
seed 002 at t = 1.799912)."""

import math
from pathlib import Path

import numpy as np
import pytest

import mbplanar
from mbplanar.analysis import check, transmission_angles
from mbplanar.cli import main

ROOT = Path(__file__).resolve().parent.parent
OA, AB, BC, OC = 0.10, 0.30, 0.25, 0.30  # models/fourbar.toml


def _engine(name):
    return mbplanar.Engine(mbplanar.read_model(ROOT / "models" / name))


def _rocker_extremes():
    """B and the crank angle (deg) where crank and coupler line up (|OB| = AB ± OA), upper branch."""
    out = []
    for ob, folded in ((AB + OA, False), (AB - OA, True)):
        x = (ob ** 2 - BC ** 2 + OC ** 2) / (2 * OC)
        b = np.array([x, math.sqrt(ob ** 2 - x * x)])
        crank = math.degrees(math.atan2(b[1], b[0])) + (180.0 if folded else 0.0)
        out.append((b, crank % 360.0))
    return out


def test_fourbar_crank_rocker():
    report = check(_engine("fourbar.toml"))
    assert report.grashof.grashof and report.grashof.kind == "crank-rocker"
    assert report.grashof.input_turns and report.full_turn and not report.limits
    rocker = next(e for e in report.extremes if e.name == "3")
    at = sorted(x % 360.0 for x in (rocker.at_min, rocker.at_max))
    expected = sorted(c for _, c in _rocker_extremes())
    assert np.allclose(at, expected, atol=1e-6)
    (b1, _), (b2, _) = _rocker_extremes()
    c = np.array([OC, 0.0])
    swing = abs(math.remainder(math.atan2(*(b1 - c)[::-1]) - math.atan2(*(b2 - c)[::-1]), 2 * math.pi))
    assert abs((rocker.maximum - rocker.minimum) - swing) < 1e-9
    assert next(e for e in report.extremes if e.name == "1").turns
    mu = report.transmission[0]
    assert mu.points == ("A", "B", "C")
    # cos μ = (AB² + BC² − AC²) / (2 AB BC): smallest at crank angle 0 (AC = OC − OA), 90° reached
    mu_min = math.degrees(math.acos((AB ** 2 + BC ** 2 - (OC - OA) ** 2) / (2 * AB * BC)))
    assert abs(math.degrees(mu.minimum) - mu_min) < 1e-6 and math.degrees(mu.maximum) > 89.9


def test_transmission_angle_matches_cosine_law():
    engine = _engine("fourbar.toml")
    phi = np.radians(np.arange(0.0, 360.0, 7.0))
    motion = mbplanar.analyse(engine, phi)
    _, mu = transmission_angles(engine, motion)
    ac2 = OA ** 2 + OC ** 2 - 2 * OA * OC * np.cos(phi)
    cos_mu = (AB ** 2 + BC ** 2 - ac2) / (2 * AB * BC)
    assert np.allclose(mu[:, 0], np.arccos(np.abs(cos_mu)), atol=1e-10)


def test_fourbar_driven_at_the_rocker_has_two_dead_points():
    (b1, _), (b2, _) = _rocker_extremes()
    theta = math.radians(60.0)
    a = (OA * math.cos(theta), OA * math.sin(theta))
    m = mbplanar.Mechanism("rocker-driven")
    for name in "123":
        m.add_link(name)
    # exact pose: crank at 60°, B from the two circles (upper branch)
    d = np.array([OC, 0.0]) - np.array(a)
    dist = np.linalg.norm(d)
    x = (AB ** 2 - BC ** 2 + dist ** 2) / (2 * dist)
    u = d / dist
    b = np.array(a) + x * u + math.sqrt(AB ** 2 - x * x) * np.array([-u[1], u[0]])
    m.add_joint("O", "R", "0", "1", at=(0, 0))
    m.add_joint("A", "R", "1", "2", at=a)
    m.add_joint("B", "R", "2", "3", at=tuple(b))
    m.add_joint("C", "R", "3", "0", at=(OC, 0))
    m.add_input("C", unit="deg")
    report = check(mbplanar.Engine(m))
    assert report.grashof.kind.startswith("crank-rocker") is False and not report.grashof.input_turns
    assert not report.full_turn and len(report.limits) == 2
    assert all(" A " in lim.kind or "at A" in lim.kind for lim in report.limits)
    c = np.array([OC, 0.0])
    swing = abs(math.remainder(math.atan2(*(b1 - c)[::-1]) - math.atan2(*(b2 - c)[::-1]), 2 * math.pi))
    assert abs(math.radians(report.range[1] - report.range[0]) - swing) < 1e-12
    crank = next(e for e in report.extremes if e.name == "1")
    assert not crank.turns  # driven at the rocker, the crank cannot turn fully either
    # at the dead points the crank lies along OB (|OB| = AB + OA) or against it (|OB| = AB − OA), exactly:
    # both come from the configurations solved at the limits
    got = sorted(math.degrees(x) % 360.0 for x in (crank.minimum, crank.maximum))
    assert np.allclose(got, sorted(c for _, c in _rocker_extremes()), rtol=0, atol=1e-10)


def test_shaper_stroke_and_lever_swing():
    report = check(_engine("shaper.toml"))
    assert report.full_turn and report.grashof is None
    k_v = 1.6
    beta = math.pi * (k_v - 1) / (k_v + 1)
    lever = next(e for e in report.extremes if e.name == "3")
    assert abs((lever.maximum - lever.minimum) - beta) < 1e-9
    ram = next(e for e in report.extremes if e.name == "F")
    assert abs((ram.maximum - ram.minimum) - 0.5) < 1e-9  # H = 0.5 m


def test_locking_model_limits():
    report = check(_engine("crank_slider_rocker_locking.toml"))
    assert not report.full_turn
    up = next(lim for lim in report.limits if lim.direction == 1)
    assert abs(up.phi - 1.799912) < 5e-7 and "stretched at B" in up.kind
    assert report.range[1] == up.phi
    mu = next(a for a in report.transmission if a.points == ("C", "B", "D"))
    assert math.degrees(mu.minimum) < 0.1  # the dyad is stretched at the lock


def test_cli_check(capsys):
    assert main(["check", str(ROOT / "models/crank_slider_rocker_locking.toml")]) == 0
    out = capsys.readouterr().out
    assert "does NOT turn fully" in out and "1.79991" in out
    assert main(["check", "--json", str(ROOT / "models/fourbar.toml")]) == 0
    import json
    doc = json.loads(capsys.readouterr().out)
    assert doc["full_turn"] and doc["grashof"]["kind"] == "crank-rocker"


def test_sweep_has_transmission_and_pressure_angle_columns(tmp_path):
    out = tmp_path / "fourbar.csv"
    assert main(["sweep", str(ROOT / "models" / "fourbar.toml"), "--step", "15", "-o", str(out)]) == 0
    lines = out.read_text().splitlines()
    header = lines[0].split(",")
    rows = np.array([[float(x) for x in line.split(",")] for line in lines[1:]])
    phi = np.radians(rows[:, 0])
    ac2 = OA ** 2 + OC ** 2 - 2 * OA * OC * np.cos(phi)
    mu = np.degrees(np.arccos(np.abs((AB ** 2 + BC ** 2 - ac2) / (2 * AB * BC))))
    assert np.allclose(rows[:, header.index("transmission.A-B-C[deg]")], mu, atol=1e-8)
    out = tmp_path / "slider.csv"
    assert main(["sweep", str(ROOT / "models" / "slider_crank.toml"), "--steps", "8", "-o", str(out)]) == 0
    header = out.read_text().splitlines()[0].split(",")
    assert any(h.startswith("pressure.") and h.endswith("[deg]") for h in header)


def test_limits_are_only_those_the_request_ran_into():
    """The engine's atlas remembers a lock found by an earlier sweep; a later request that stays clear of
    it reports no limit."""
    engine = _engine("crank_slider_rocker_locking.toml")
    assert len(mbplanar.analyse(engine, np.linspace(0.0, 3.0, 31)).limits) == 1
    inside = mbplanar.analyse(engine, np.linspace(0.0, 1.0, 11))
    assert inside.success and inside.limits == []
    across = mbplanar.analyse(engine, np.linspace(1.7, 1.9, 5))
    assert not across.success and len(across.limits) == 1


DATA = ROOT / "tests" / "data"


def test_extreme_on_a_sample_is_found():
    """An inclined slider-crank (guide at 45° through the crank pivot) drawn at 90°: the rod's extremes
    fall exactly on samples (135°, 315°), where the sampled rate is exactly 0. Closed form: the rod
    swings 45° ± asin(r / l)."""
    report = check(mbplanar.Engine(mbplanar.read_model(DATA / "incl_slider.toml")))
    rod = next(e for e in report.extremes if e.name == "2")
    swing = math.degrees(math.asin(0.04 / 0.14))
    assert abs(math.degrees(rod.minimum) - (45 - swing)) < 1e-9
    assert abs(math.degrees(rod.maximum) - (45 + swing)) < 1e-9
    assert sorted(x % 360 for x in (rod.at_min, rod.at_max)) == pytest.approx([135.0, 315.0], abs=1e-7)
    assert [loc.kind for loc in rod.local] in (["min", "max"], ["max", "min"])


def test_every_local_extreme_is_a_zero_of_the_rate():
    """Every interior local extreme listed (shaper: the block on the lever has two minima and two
    maxima per turn) has a rate of zero, and its neighbours lie on the right side of it."""
    engine = _engine("shaper.toml")
    report = check(engine)
    dp = next(e for e in report.extremes if e.name == "Dp")
    assert len(dp.local) == 4 and [loc.kind for loc in dp.local].count("max") == 2
    inp = engine.inputs[0]
    for loc in dp.local:
        phi = inp.to_si(loc.at) + np.array([-1e-3, 0.0, 1e-3])
        m = mbplanar.analyse(engine, phi)
        k = m.joint("Dp")
        assert abs(m.rate_q[1, k]) < 1e-10
        assert abs(m.value[1, k] - loc.value) < 1e-12
        side = m.value[[0, 2], k] - m.value[1, k]
        assert np.all(side < 0) if loc.kind == "max" else np.all(side > 0)


def test_double_rocker_interior_and_end_extremes():
    report = check(mbplanar.Engine(mbplanar.read_model(DATA / "double_rocker.toml")))
    out = next(e for e in report.extremes if e.name == "3")
    assert [loc.kind for loc in out.local] == ["max", "min", "max"]
    assert [loc.end for loc in out.local] == [True, False, True]
    # the interior minimum: the output stands still where v_B = 0, i.e. where O, A and B are in line
    engine = mbplanar.Engine(mbplanar.read_model(DATA / "double_rocker.toml"))
    m = mbplanar.analyse(engine, [math.radians(out.local[1].at)])
    a, b = m.xy[0, m.point("A")], m.xy[0, m.point("B")]
    assert abs(a[0] * b[1] - a[1] * b[0]) < 1e-12 * 0.4 * 0.6
    # the ends are the configurations at the input's dead points: AB and O4B stretched in line
    assert out.local[0].value == pytest.approx(-out.local[2].value, abs=1e-9)


@pytest.mark.parametrize("lengths, drawn_crossed, kind", [
    ((0.1, 0.3, 0.1, 0.3), False, "parallelogram (change point)"),
    ((0.1, 0.3, 0.1, 0.3), True, "anti-parallelogram (change point)"),
    ((0.2, 0.2, 0.3, 0.3), False, "deltoid (kite; change point)"),
    ((0.2, 0.2, 0.2, 0.2), False, "rhombus (change point)"),
    ((0.1, 0.35, 0.25, 0.2), False, "change-point crank-rocker"),
    ((0.1, 0.3, 0.2, 0.35), False, "crank-rocker"),
    ((0.35, 0.3, 0.25, 0.1), False, "double crank"),
    ((0.3, 0.1, 0.35, 0.25), False, "double rocker"),
])
def test_grashof_names(lengths, drawn_crossed, kind):
    """Input OA, coupler AB, output BC, ground OC; the equality cases get their own names."""
    r1, r2, r3, r0 = lengths
    m = mbplanar.Mechanism("g")
    for name in "123":
        m.add_link(name)
    a = np.array([r1 * math.cos(1.0), r1 * math.sin(1.0)])
    c = np.array([r0, 0.0])
    d = np.linalg.norm(c - a)
    x = (r2 ** 2 - r3 ** 2 + d * d) / (2 * d)
    u = (c - a) / d
    h = math.sqrt(r2 ** 2 - x * x) * (-1 if drawn_crossed else 1)
    b = a + x * u + h * np.array([-u[1], u[0]])
    if kind.startswith("parallelogram"):
        b = a + c  # the uncrossed assembly of equal opposite links
    m.add_joint("O", "R", "0", "1", at=(0, 0))
    m.add_joint("A", "R", "1", "2", at=tuple(a))
    m.add_joint("B", "R", "2", "3", at=tuple(b))
    m.add_joint("C", "R", "3", "0", at=tuple(c))
    m.add_input("O", unit="deg")
    g = mbplanar.Engine(m)
    from mbplanar.analysis import grashof
    assert grashof(g).kind == kind


def test_parallelogram_is_not_a_crank_rocker():
    report = check(mbplanar.Engine(mbplanar.read_model(DATA / "parallelogram.toml")))
    g = report.grashof
    assert g.kind == "parallelogram (change point)" and g.change_point
    assert g.input_turns and g.output_turns and report.full_turn
    assert next(e for e in report.extremes if e.name == "3").turns
