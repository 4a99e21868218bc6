"""Planetary trains: a textbook train's tooth numbers for its ratio (cited), the enumeration against a
brute force written here, the assembly condition against a search over the planet's own turns, Willis'
formula checked on the model the train is written as (its gear joints solved as linear relations), and the
velocity diagram's straight lines."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from mbplanar.errors import ModelError
from mbplanar.gears import SCHEMES, gear_pair, planetary_trains, willis
from mbplanar.gears.planetary import Train, train_speeds
from mbplanar.gears.trainmodel import Stage, train_model


def test_sdp_planetary_example():
    """SDP/SI, "Elements of Metric Gear Technology", §13.3, http://www.sdp-si.com/D785/HTML1/D785T113_4.html
    (conditions 13-5, 13-7, 13-9) and D785T113_5.html, D785T113_6.html (speed ratios): z_a = 16, z_b = 16,
    z_c = 48 meet coaxiality (z_c = z_a + 2z_b), assembly with N planets when (z_a + z_c)/N is whole, the
    neighbourhood z_b + 2 < (z_a + z_b) sin(180°/N); speed ratios: planetary type (ring fixed) 1/4, solar
    type (sun fixed) 1/1.3333333, star type (carrier fixed) −1/3."""
    s = planetary_trains(4.0, "A", planets=4, min_teeth=16, tolerance=0.0, max_teeth=48)
    assert (16, 16, 48) in [t.teeth for t in s.trains]
    assert (16, 16, 48) not in [t.teeth for t in planetary_trains(4.0, "A", planets=3, min_teeth=16,
                                                                  tolerance=0.0, max_teeth=48).trains]
    t = next(t for t in s.trains if t.teeth == (16, 16, 48))
    assert abs(1 / t.ratio - 1 / 4) < 1e-15                  # planetary type: output/input = 1/4
    u_star = willis("A", (16, 16, 48))                        # carrier held: sun/ring = −z_c/z_a
    assert abs(1 / u_star - (-1 / 3)) < 1e-15                 # star type: ring/sun = −1/3
    # solar type, sun fixed, ring in, carrier out: (ω_c − ω_H)/(ω_a − ω_H) = −z_a/z_c with ω_a = 0
    ring_over_carrier = 1 + 16 / 48
    assert abs(1 / ring_over_carrier - 1 / 1.3333333) < 1e-7
    assert 16 + 2 < (16 + 16) * math.sin(math.pi / 4)         # the neighbourhood the train was kept by


def _brute_force(scheme, target, k, tol, lo, hi):
    """Every tooth set by plain loops and the conditions as the course books write them."""
    sch = SCHEMES[scheme]
    out = set()
    zs = range(lo, hi + 1)
    for z1 in zs:
        for z2 in zs:
            for z3 in (zs if sch.two_rows else [z2]):
                z4 = {"A": z1 + 2 * z2, "B": z1 + z2 + z3, "C": z1 + z2 - z3, "D": z1 - z2 + z3}[scheme]
                if not lo <= z4 <= hi or (scheme == "D" and (z1 <= z2 or z4 <= z3)):
                    continue
                sign = -1 if (sch.first == "external") != (sch.second == "external") else 1
                u1h = 1 - sign * z2 * z4 / (z1 * z3)
                if u1h == 0:
                    continue
                ratio = 1 / u1h if sch.driven_by_carrier else u1h
                if abs(ratio - target) > tol * abs(target):
                    continue
                # assembly: with the carrier turned by 2π/k the sun has turned u_1H z₁/k teeth; a planet block
                # turned by j of its row-3 teeth fits if that is a whole number of teeth plus z₂j/z₃
                numerator = round(u1h * z1 * z3)                  # u_1H z₁ z₃ = z₁z₃ ∓ z₂z₄
                if not any((numerator - k * z2 * j) % (k * z3) == 0 for j in range(z3)):
                    continue
                aw = z1 + z2 if sch.first == "external" else z1 - z2
                if k > 1 and not aw * math.sin(math.pi / k) > max(z2, z3) + 2:
                    continue
                ok = True
                for outer, planet, kind in ((z1, z2, sch.first), (z4, z3, sch.second)):
                    p = gear_pair(1e-3, (planet, outer), internal=True, ring_tip="cut") if kind == "internal" \
                        else gear_pair(1e-3, (outer, planet))
                    ok &= all(c.ok for c in p.checks if c.name != "undercut")
                if ok:
                    out.add((z1, z2, z4) if not sch.two_rows else (z1, z2, z3, z4))
    return out


@pytest.mark.parametrize("scheme, target, k, hi", [("A", 5.0, 3, 80), ("B", 5.0, 3, 70), ("C", 15.01, 3, 40),
                                                   ("D", 12.0, 2, 40)])
def test_enumeration_equals_a_brute_force(scheme, target, k, hi):
    lo = 18
    got = {t.teeth for t in planetary_trains(target, scheme, planets=k, tolerance=0.02, max_teeth=hi).trains}
    assert got == _brute_force(scheme, target, k, 0.02, lo, hi)


def test_assembly_condition_by_the_planets_turns():
    """(z₁z₃ ∓ z₂z₄)/(k·gcd(z₂, z₃)) whole ⇔ some turn ψ = 2πj/z₃ of a planet block (the turns that keep
    its row 3 in mesh with the fixed gear) brings row 2 into mesh with gear 1 after the carrier has turned
    by 2π/k: the sun has turned by u_1H·2π/k, a whole number of its teeth plus z₂j/z₃ of one."""
    for teeth in ((18, 33, 19, 70), (20, 34, 18, 72), (21, 30, 25, 76), (19, 38, 24, 81)):
        z1, z2, z3, z4 = teeth
        for k in (2, 3, 4, 5):
            u1h = 1 + z2 * z4 / (z1 * z3)
            by_gcd = (z1 * z3 + z2 * z4) % (k * math.gcd(z2, z3)) == 0
            sun_teeth = u1h * z1 / k                           # the sun's turn in teeth
            by_turns = any(abs((sun_teeth - z2 * j / z3) - round(sun_teeth - z2 * j / z3)) < 1e-9
                           for j in range(z3))
            assert by_gcd == by_turns, (teeth, k)


def _solve_model(text):
    """Angular velocities of a model's links from its gear rows alone, r_a(ω_a − ω_c) = ∓r_b(ω_b − ω_c),
    with the input link turning at 1 and the frame at 0."""
    table = tomllib.loads(text)
    links = [row["name"] for row in table["links"]]
    index = {name: i for i, name in enumerate(links)}
    joint_link = {j["name"]: j["links"][1] for j in table["joints"] if j["type"] == "R"}
    rows, rhs = [], []
    for j in table["joints"]:
        if j["type"] != "gear":
            continue
        if "radii" in j:
            ra, rb = j["radii"]
        else:
            ra, rb = (j["module"] * z / 2 for z in j["teeth"])
        sign = 1.0 if j["mesh"] == "external" else -1.0
        row = np.zeros(len(links))
        # r_a ω_a + sign r_b ω_b − (r_a + sign r_b) ω_c = 0 (a link named "0" is the frame: ω = 0)
        for name, coef in ((j["links"][0], ra), (j["links"][1], sign * rb), (j["carrier"], -(ra + sign * rb))):
            if name != table["ground"]:
                row[index[name]] += coef
        rows.append(row)
        rhs.append(0.0)
    row = np.zeros(len(links))
    row[index[joint_link[table["input"]["joint"]]]] = 1.0
    rows.append(row)
    rhs.append(1.0)
    w = np.linalg.lstsq(np.array(rows), np.array(rhs), rcond=None)[0]
    assert np.allclose(np.array(rows) @ w, rhs, atol=1e-13)    # the gear relations are consistent
    return dict(zip(links, w)), table


@pytest.mark.parametrize("scheme, ratio, k", [("A", 7.0, 3), ("B", 7.7392, 3), ("C", 30.0, 3), ("D", 19.348, 3)])
def test_model_of_the_train_gives_willis_ratio(scheme, ratio, k):
    """The written model's gear joints, solved as the engine will (each row's relation with its carrier),
    give the train's ratio, which is Willis' u_1H = 1 − u^H_14, to 1e-12; the pivots are as far apart as
    the gears' pitch radii say."""
    t = planetary_trains(ratio, scheme, planets=k, module=2e-3).trains[0]
    w, table = _solve_model(train_model(t))
    sch = SCHEMES[scheme]
    out = w["1"] if sch.driven_by_carrier else w["H"]
    assert abs(1 / out - t.ratio) < 1e-12 * abs(t.ratio)
    assert abs(t.ratio - ((1 / (1 - t.willis)) if sch.driven_by_carrier else 1 - t.willis)) < 1e-12 * abs(t.ratio)
    assert table["gears"]["train"]["teeth"] == list(t.teeth) and table["gears"]["train"]["planets"] == k
    joints = {j["name"]: j for j in table["joints"]}
    for g in (j for j in table["joints"] if j["type"] == "gear"):
        za, zb = g["teeth"]
        ra, rb = g["module"] * za / 2, g["module"] * zb / 2
        pivot = {"1": (0.0, 0.0), "0": (0.0, 0.0), "2": joints["O2"]["at"]}
        d = math.dist(pivot[g["links"][0]], pivot[g["links"][1]])
        assert abs(d - (ra + rb if g["mesh"] == "external" else abs(rb - ra))) < 1e-15
        assert abs(math.dist(g["at"], pivot[g["links"][0]]) - ra) < 1e-15


def test_model_with_a_stage_after_the_train():
    stage_pair = gear_pair(10e-3, (12, 30), (0.5923, 0.5278))
    t = planetary_trains(19.348 / 2.5, "B", planets=3, module=2e-3).trains[0]
    w, table = _solve_model(train_model(t, stage=Stage.from_pair(stage_pair), omega=147.9))
    assert abs(1 / w["out"] - t.ratio * -2.5) < 1e-12 * t.ratio * 2.5
    assert table["input"]["omega"] == 147.9 and table["gears"]["train"]["output"] == "out"
    g = next(j for j in table["joints"] if j["name"] == "G56")
    assert abs(sum(g["radii"]) - stage_pair.centre_distance) < 1e-15
    assert g["pressure_angle"] == stage_pair.working_pressure_angle_deg      # the line of action's angle


def test_velocity_diagram_lines():
    """The planet's velocities at its two pitch points and at its axis lie on one straight line (v = 0
    where it meets the fixed gear), as the diagram draws it."""
    for scheme, ratio in (("A", 7.0), ("B", 7.7392), ("C", 30.0), ("D", 19.348)):
        t = planetary_trains(ratio, scheme, planets=3).trains[0]
        w = train_speeds(t)
        sch = SCHEMES[scheme]
        m = t.module
        z1, z2, z3, z4 = (t.teeth[0], t.teeth[1], t.teeth[1], t.teeth[2]) if not sch.two_rows else t.teeth
        aw = t.centre_distance
        p1 = m * z1 / 2
        p2 = aw + m * z3 / 2 if sch.second == "internal" else aw - m * z3 / 2
        v_axis = w["carrier"] * aw
        assert abs(v_axis + w["planet"] * (p1 - aw) - w["gear 1"] * p1) < 1e-15   # at the first pitch point
        assert abs(v_axis + w["planet"] * (p2 - aw)) < 1e-15                        # at the fixed gear: 0
        drive = w["carrier"] if sch.driven_by_carrier else w["gear 1"]
        out = w["gear 1"] if sch.driven_by_carrier else w["carrier"]
        assert abs(drive / out - t.ratio) < 1e-12 * abs(t.ratio)


def test_ranked_by_overall_size():
    s = planetary_trains(8.0, "B", planets=3, tolerance=0.02)
    d = [t.diameter for t in s.trains]
    assert all(a <= b + 1e-15 for a, b in zip(d, d[1:])) and len(d) > 10
    t = s.trains[0]
    z1, z2, z3, z4 = t.teeth
    assert abs(t.diameter - t.module * (z4 + 2.5)) < 1e-15 or t.diameter > t.module * (z4 + 2.5)


@pytest.mark.parametrize("kwargs, match", [
    (dict(ratio=0.5), r"--ratio 0.5: no scheme reaches it .* nearest is 1.0"),
    (dict(ratio=1.5, scheme="A"), r"--ratio 1.5: no scheme reaches it .*nearest is 2.31579 \(scheme A\)"),
    (dict(ratio=40.0, scheme="A"), r"--ratio 40: no scheme reaches it"),
    (dict(ratio=0.0), "--ratio must be a finite number other than 0"),
    (dict(ratio=5.0, scheme="E"), "unknown scheme 'E'"),
    (dict(ratio=5.0, planets=0), "--planets must be a whole number ≥ 1, got 0"),
    (dict(ratio=5.0, tolerance=-1.0), "--tolerance must be ≥ 0"),
    (dict(ratio=5.0, module=0.0), "module must be > 0"),
    (dict(ratio=5.0, min_teeth=20, max_teeth=10), "--max-teeth"),
])
def test_bad_requests_name_the_value(kwargs, match):
    ratio = kwargs.pop("ratio")
    with pytest.raises(ModelError, match=match):
        planetary_trains(ratio, **kwargs)


def test_no_admissible_set_says_why():
    s = planetary_trains(4.0, "A", planets=5, tolerance=0.0, max_teeth=57)   # (18, 18, 54), (19, 19, 57)
    assert not s.success and "assembly" in s.message and s.rejected["assembly"] > 0


def test_train_record_is_frozen():
    t = Train("A", (18, 18, 54), 3, 4.0, 0.0, -3.0, 1e-3, 18e-3, 56.5e-3, 1.0)
    with pytest.raises(AttributeError):
        t.ratio = 5.0
