"""Kinematics against numbers nobody here wrote: the seeds' tables (REFERENCE.md), closed forms."""

import csv
import math
import sys
from pathlib import Path

import numpy as np
import pytest

import mbplanar
from mbplanar.kinematics import material_points
from mbplanar.model import read_model_text

from conftest import trammel

DATA = Path(__file__).resolve().parent / "data"
sys.path.insert(0, str(DATA.parent.parent / "benchmarks"))
from closed_forms import circle_meet  # noqa: E402  (the dyad's closed form)


def rel(a, b):
    return abs(a - b) / max(abs(b), 1e-12)


# -- seed 002: the printed table, 50 rows x 8 columns -----------------------------------------------
def _seed002_rows():
    with open(DATA / "seed002_table.csv") as fh:
        rows = list(csv.reader(fh))
    return rows[0], rows[1:]


def test_seed002_table_reproduced_to_its_last_digit(engine_of):
    engine = engine_of("crank_slider_rocker")
    header, rows = _seed002_rows()
    assert len(rows) == 50 and len(header) == 8
    t = np.array([float(r[0]) for r in rows])
    m = mbplanar.analyse(engine, t)
    assert m.success
    ours = {
        "phi2": m.angle[:, m.link("2")], "phi3": m.angle[:, m.link("3")], "phi4": m.angle[:, m.link("4")],
        "omega2": m.w[:, m.link("2")], "omega3": m.w[:, m.link("3")], "omega4": m.w[:, m.link("4")],
        "vC": m.v[:, m.point("C"), 0],
    }
    checked = 0
    for col, name in enumerate(header[1:], start=1):
        for k, row in enumerate(rows):
            text = row[col]
            decimals = len(text.split(".")[1]) if "." in text else 0
            value = ours[name][k]
            if name.startswith("phi"):  # the seed's angles are continuous, not wrapped
                value = float(text) + math.remainder(value - float(text), 2 * math.pi)
            assert abs(value - float(text)) <= 0.5 * 10 ** -decimals + 1e-9, (name, row[0], value, text)
            checked += 1
    assert checked == 50 * 7


def test_seed002_pi_over_2(engine_of):
    m = mbplanar.analyse(engine_of("crank_slider_rocker"), [math.pi / 2])
    # REFERENCE.md (with D from the initial angles): phi3 = 1.6018744, omega3 = -0.410775, vC = -0.5
    assert m.angle[0, m.link("2")] == pytest.approx(-0.0205759, abs=2e-7)
    assert m.angle[0, m.link("3")] == pytest.approx(1.6018744, abs=2e-7)
    assert m.angle[0, m.link("4")] % (2 * math.pi) == pytest.approx(3.586760, abs=2e-6)
    assert m.w[0, m.link("2")] == pytest.approx(0.0, abs=1e-12)
    assert m.w[0, m.link("3")] == pytest.approx(-0.410775, abs=2e-6)
    assert m.w[0, m.link("4")] == pytest.approx(0.0212135, abs=2e-7)
    assert m.v[0, m.point("C"), 0] == pytest.approx(-0.5, abs=1e-12)


def test_seed002_locking_data_locks_at_1_799912(engine_of):
    engine = engine_of("crank_slider_rocker_locking")
    t = np.linspace(0, 49 * math.pi / 50, 50)
    m = mbplanar.analyse(engine, t)
    assert not m.success
    assert len(m.phi) == np.sum(t < 1.799912)
    (limit,) = m.limits
    assert limit.phi[0] == pytest.approx(1.799912, abs=1e-6)
    assert set(limit.links) == {"3", "4"} and "stretched at B" in limit.kind


# -- seeds 000 and 003 at their reference positions (REFERENCE.md, exact values, 0.1 %) -------------
SHAPER_F = 140.76923076923077


def test_shaper_reference_position(engine_of):
    e = engine_of("shaper")
    m = mbplanar.analyse(e, [math.radians(SHAPER_F)])
    p = lambda n: m.xy[0, m.point(n)]  # noqa: E731
    for got, want in [(p("A")[0], 0.0638289), (p("A")[1], 0.110555), (p("D")[0], 0.0947639),
                      (p("D")[1], 0.338612), (p("S3")[0], 0.047382), (p("S3")[1], -0.0106939),
                      (math.degrees(m.angle[0, m.link("3")]), 82.2752),
                      (m.vq[0, m.point("D"), 0], 0.173793), (m.vq[0, m.point("S3"), 0], 0.0868963),
                      (m.vq[0, m.point("S3"), 1], -0.0117871), (m.wq[0, m.link("3")], -0.248768),
                      (m.eq[0, m.link("3")], 0.0512018), (m.aq[0, m.point("D"), 0], -0.0416347),
                      (m.aq[0, m.point("S3"), 0], -0.0208174), (m.aq[0, m.point("S3"), 1], -0.019191)]:
        assert rel(got, want) < 1e-3, (got, want)


def test_shaper_real_values_at_seed_speed(engine_of):
    """REFERENCE: with omega1 = 7.64558, epsilon1 = -0.577148: a_S3 = (-1.26703, -1.115), eps3 = 3.13657."""
    e = engine_of("shaper")
    m = mbplanar.analyse(e, [math.radians(SHAPER_F)], omega=7.64558, epsilon=-0.577148)
    assert rel(m.a[0, m.point("S3"), 0], -1.26703) < 1e-3
    assert rel(m.a[0, m.point("S3"), 1], -1.115) < 1e-3
    assert rel(m.a[0, m.point("D"), 0], -2.53406) < 1e-3
    assert rel(m.e[0, m.link("3")], 3.13657) < 1e-3


def test_six_bar_press_reference_position(engine_of):
    e = engine_of("six_bar_press")
    m = mbplanar.analyse(e, [math.radians(99.1)])
    expect_xy = {"A": (-0.1735, 0.300511), "B": (1.16470, 0.845709), "D": (1.07940, 1.69142),
                 "H": (2.58395, 0.9), "S2": (0.495601, 0.57311)}
    expect_vq = {"A": (0.300511, 0.1735), "B": (0.356546, 0.035961), "D": (0.713091, 0.071922),
                 "H": (0.675259, 0), "S2": (0.328528, 0.104731), "S4": (0.694175, 0.035961)}
    expect_aq = {"A": (0.1735, -0.300511), "B": (0.0926432, -0.142503), "D": (0.185286, -0.285005),
                 "H": (0.330815, 0), "S2": (0.133072, -0.221507), "S4": (0.258051, -0.142503)}
    for table, arr in ((expect_xy, m.xy), (expect_vq, m.vq), (expect_aq, m.aq)):
        for name, want in table.items():
            got = arr[0, m.point(name)]
            for g, w in zip(got, want):
                assert abs(g - w) <= 1e-3 * abs(w) + 1e-9, (name, got, want)
    assert m.xy[0, m.point("S4"), 0] == pytest.approx(1.83168, rel=1e-4)
    for link, angle, wq, eq in (("2", 22.1665, -0.102779, 0.122379), ("3", 95.7594, -0.421594, -0.091618),
                                ("4", 152.255, -0.047803, 0.188227)):
        k = m.link(link)
        assert rel(math.degrees(m.angle[0, k]), angle) < 1e-4
        assert rel(m.wq[0, k], wq) < 1e-3 and rel(m.eq[0, k], eq) < 1e-3


def test_six_bar_press_stroke(engine_of):
    e = engine_of("six_bar_press")
    m = mbplanar.analyse(e, np.radians(np.linspace(0, 360, 7201)))
    x = m.xy[:, m.point("H"), 0]
    assert np.ptp(x) == pytest.approx(1.579893, abs=2e-6)


# -- closed forms over a whole cycle -------------------------------------------------------------
def _circle_intersection(a, c, ra, rc, sign):
    d = c - a
    dist = np.linalg.norm(d, axis=-1)
    along = (ra ** 2 - rc ** 2 + dist ** 2) / (2 * dist)
    h = np.sqrt(ra ** 2 - along ** 2)
    u = d / dist[..., None]
    return a + along[..., None] * u + sign * h[..., None] * np.stack([-u[..., 1], u[..., 0]], -1)


def test_fourbar_closed_form_whole_cycle(engine_of):
    e = engine_of("fourbar")
    phi = np.linspace(0, 2 * np.pi, 721)
    m = mbplanar.analyse(e, phi)
    a = 0.1 * np.stack([np.cos(phi), np.sin(phi)], -1)
    c = np.array([0.3, 0.0])
    b = _circle_intersection(a, c, 0.3, 0.25, +1.0)
    assert np.abs(m.xy[:, m.point("B")] - b).max() < 1e-9
    # rocker angular velocity from the velocity of B: v_B = ω3 × (B − C)
    rel_b, vb = b - c, m.vq[:, m.point("B")]
    w3 = (rel_b[:, 0] * vb[:, 1] - rel_b[:, 1] * vb[:, 0]) / np.sum(rel_b ** 2, -1)
    assert np.abs(m.wq[:, m.link("3")] - w3).max() < 1e-9


def test_slider_crank_closed_form_whole_cycle(engine_of):
    e = engine_of("slider_crank")
    phi = np.linspace(0, 2 * np.pi, 721)
    m = mbplanar.analyse(e, phi)
    r, l = 0.1, 0.3
    s, c = np.sin(phi), np.cos(phi)
    root = np.sqrt(l * l - r * r * s * s)
    x = r * c + root
    v = -r * s - r * r * s * c / root
    acc = -r * c - r * r * (c * c - s * s) / root - r ** 4 * s * s * c * c / root ** 3
    k = m.point("B")
    assert np.abs(m.xy[:, k, 0] - x).max() < 1e-9
    assert np.abs(m.vq[:, k, 0] - v).max() < 1e-9
    assert np.abs(m.aq[:, k, 0] - acc).max() < 1e-9
    assert np.abs(m.xy[:, k, 1]).max() < 1e-12


def test_instant_centre_of_coupler_is_where_crank_and_rocker_lines_meet(engine_of):
    e = engine_of("fourbar")
    m = mbplanar.analyse(e, np.radians([30.0, 100.0, 200.0]))
    o, c = np.zeros(2), np.array([0.3, 0.0])
    for k in range(3):
        a, b = m.xy[k, m.point("A")], m.xy[k, m.point("B")]
        # intersection of lines O-A and C-B
        mat = np.array([a - o, -(b - c)]).T
        t = np.linalg.solve(mat, c - o)
        assert np.allclose(m.ic[k, m.link("2")], o + t[0] * (a - o), atol=1e-9)
    assert np.allclose(m.ic[:, m.link("1")], 0.0, atol=1e-12)


def test_real_values_scale_with_omega_and_epsilon(engine_of):
    e = engine_of("six_bar_press")
    phi = np.radians([10.0, 99.1, 250.0])
    base = mbplanar.analyse(e, phi)
    m = mbplanar.analyse(e, phi, omega=3.0, epsilon=-2.0)
    assert np.allclose(m.v, base.vq * 3.0, atol=1e-12)
    assert np.allclose(m.a, base.aq * 9.0 + base.vq * -2.0, atol=1e-12)
    assert np.allclose(m.e, base.eq * 9.0 + base.wq * -2.0, atol=1e-12)


# -- seed 004: the class IV group (models/class4_group.toml) over a full turn -----------------------
FD_STEP = 1e-5


@pytest.fixture(scope="module")
def class4_turn(engine_of):
    """360 positions over a full turn, each with its neighbours at ±FD_STEP (rad) for central differences."""
    engine = engine_of("class4_group")
    phi = engine.phi_drawn[0] + np.radians(np.arange(360.0))
    m = mbplanar.analyse(engine, np.concatenate([phi - FD_STEP, phi, phi + FD_STEP]))
    assert m.success, m.message
    return engine, m, len(phi)


def _e(angle):
    return np.stack([np.cos(angle), np.sin(angle)], -1)


def test_class4_group_closes_every_joint_over_a_full_turn(class4_turn):
    """Both links of every joint carry the same material point: position, velocity, acceleration."""
    engine, m, _ = class4_turn
    f = m.frames
    for j in engine.mech.joints.values():
        assert j.kind == "R"
        sides = [material_points(f.th, f.r, f.w, f.v, f.e, f.a,
                                 np.array([engine.link_index[link]]), np.array([j.at])) for link in j.links]
        (xa, va, aa), (xb, vb, ab) = sides
        assert np.abs(xa - xb).max() < 1e-10, j.name
        assert np.abs(va - vb).max() < 1e-10 * (1 + np.abs(va).max()), j.name
        assert np.abs(aa - ab).max() < 1e-10 * (1 + np.abs(aa).max()), j.name


def test_class4_group_satisfies_the_seed_loop_equations(class4_turn):
    """Seed 004's equations (1)-(3) in its notation, with l21, alpha, ..., gamma, beta read off the drawn
    pose, hold for the solved angles phi2..phi7, and so do their first and second derivatives."""
    engine, m, _ = class4_turn
    at = {name: np.array(j.at) for name, j in engine.mech.joints.items()}
    dist = lambda p, q: float(np.linalg.norm(at[q] - at[p]))  # noqa: E731
    ang = lambda p, q: math.atan2(*(at[q] - at[p])[::-1])  # noqa: E731
    phi2, phi5 = ang("G", "D"), ang("K", "E")
    alpha, gamma, beta = phi2 - ang("A", "D"), ang("E", "F") - phi5 - math.pi, phi5 - ang("K", "L")
    l21, l2, l3, l4, l5 = dist("A", "D"), dist("G", "D"), dist("D", "E"), dist("G", "K"), dist("K", "E")
    l51, l52, l6, l7 = dist("E", "F"), dist("K", "L"), dist("B", "F"), dist("C", "L")
    # each equation: (point terms, [(coefficient, link, angle offset)]) with left minus right side = 0
    equations = [
        ((+1, "A", -1, "B"), [(l21, "2", -alpha), (l3, "3", 0.0), (l51, "5", gamma + math.pi), (-l6, "6", 0.0)]),
        ((+1, "A", -1, "C"), [(l21, "2", -alpha), (-l2, "2", 0.0), (l4, "4", 0.0), (l52, "5", -beta),
                              (-l7, "7", 0.0)]),
        ((0, "A", 0, "A"), [(l2, "2", 0.0), (l3, "3", 0.0), (-l4, "4", 0.0), (-l5, "5", 0.0)]),
    ]
    for (sp, p, sq, q), terms in equations:
        ip, iq = m.point(p), m.point(q)
        x = sp * m.xy[:, ip] + sq * m.xy[:, iq]
        v = sp * m.vq[:, ip] + sq * m.vq[:, iq]
        a = sp * m.aq[:, ip] + sq * m.aq[:, iq]
        for c, link, offset in terms:
            k = m.link(link)
            along, across = _e(m.angle[:, k] + offset), _e(m.angle[:, k] + offset + math.pi / 2)
            w, e = m.wq[:, k, None], m.eq[:, k, None]
            x = x + c * along
            v = v + c * w * across
            a = a + c * (e * across - w * w * along)
        assert np.abs(x).max() < 1e-10
        assert np.abs(v).max() < 1e-10
        assert np.abs(a).max() < 1e-9


def test_class4_group_rates_are_central_differences(class4_turn):
    engine, m, n = class4_turn
    lo, mid, hi = slice(0, n), slice(n, 2 * n), slice(2 * n, 3 * n)
    h2 = 2 * FD_STEP
    # points: velocity = d(position)/dphi, acceleration = d(velocity)/dphi
    v_scale = np.abs(m.vq[mid]).max()
    a_scale = np.abs(m.aq[mid]).max()
    assert np.abs((m.xy[hi] - m.xy[lo]) / h2 - m.vq[mid]).max() < 1e-7 * (1 + v_scale)
    assert np.abs((m.vq[hi] - m.vq[lo]) / h2 - m.aq[mid]).max() < 1e-7 * (1 + a_scale)
    # links: omega = d(angle)/dphi, epsilon = d(omega)/dphi
    turn = np.remainder(m.angle[hi] - m.angle[lo] + np.pi, 2 * np.pi) - np.pi
    assert np.abs(turn / h2 - m.wq[mid]).max() < 1e-7 * (1 + np.abs(m.wq[mid]).max())
    assert np.abs((m.wq[hi] - m.wq[lo]) / h2 - m.eq[mid]).max() < 1e-7 * (1 + np.abs(m.eq[mid]).max())
    # the group really moves: every link turns or rocks by more than 5 degrees
    swing = np.ptp(np.unwrap(m.angle[mid], axis=0), axis=0)
    assert np.all(swing[[m.link(k) for k in "234567"]] > math.radians(5))


def test_class4_group_assembles_from_a_sketch(engine_of):
    """The same mechanism given as dimensions (every link rigid by its distances) and a sketch 1 cm off:
    the assembly finds the model's exact pose, so the motion is the same."""
    exact = engine_of("class4_group")
    at = {name: np.array(j.at) for name, j in exact.mech.joints.items()}
    rigid = {"1": "OA", "2": "AD AG DG", "3": "DE", "4": "GK", "5": "KE EF KF KL EL", "6": "BF", "7": "CL"}
    rng = np.random.default_rng(4)
    m = mbplanar.Mechanism("sketch")
    for link, pairs in rigid.items():
        m.add_link(link, lengths=tuple((p, q, float(np.linalg.norm(at[p] - at[q]))) for p, q in pairs.split()))
    for name, j in exact.mech.joints.items():
        off = np.zeros(2) if name in "OBC" else rng.uniform(-0.01, 0.01, 2)  # the frame is where it is drawn
        m.add_joint(name, "R", *j.links, at=at[name] + off)
    m.add_input("O", drawn_at=30.0)
    sketch = mbplanar.Engine(m)
    assert max(np.abs(np.array(sketch.mech.joints[n].at) - at[n]).max() for n in at) < 1e-12
    phi = np.radians([30.0, 100.0, 250.0])
    a, b = mbplanar.analyse(sketch, phi), mbplanar.analyse(exact, phi)
    joints = [a.point(n) for n in at]
    assert np.abs(a.xy[:, joints] - b.xy[:, joints]).max() < 1e-12


def test_class4_group_with_a_long_crank_stops_at_located_dead_points():
    """A 0.3 m crank (twice the model's) cannot turn the group: the walk stops both ways at a singular
    position of the group's block, located so well that the analogues grow as (distance)^(-1/2) down to
    1e-8 rad from it, as at a fold of the loop equations (a limit off by 1e-10 rad would put the last
    ratio ~0.5 % off)."""
    text = (Path(__file__).resolve().parent.parent / "models" / "class4_group.toml").read_text()
    crank_pin = "at = [0.12990381056766578, 0.075]"
    assert crank_pin in text
    engine = mbplanar.Engine(read_model_text(text.replace(crank_pin, "at = [0.2598076211353316, 0.15]")))
    m = mbplanar.analyse(engine, engine.phi_drawn[0] + np.radians(np.arange(-180.0, 180.0, 1.0)))
    assert not m.success and len(m.limits) == 2
    for limit in m.limits:
        assert limit.links == ("2", "3", "4", "5", "6", "7") and "dead point" in limit.kind
        near = mbplanar.analyse(engine, limit.phi[0] - limit.direction * np.array([1e-4, 1e-6, 1e-8]))
        assert near.success and limit.q is not None
        grow = np.abs(near.wq).max(axis=1)
        assert 9.5 < grow[1] / grow[0] < 10.5
        assert abs(grow[2] / grow[1] - 10.0) < 0.01


def test_jansen_linkage_follows_its_circle_construction_over_a_full_turn():
    """Jansen's leg (models/jansen.toml, his holy numbers in cm) against the construction by circle
    intersections, dyad after dyad, on the drawn assembly."""
    engine = mbplanar.Engine(mbplanar.read_model(Path(__file__).resolve().parent.parent / "models" / "jansen.toml"))
    phi = np.linspace(0.0, 2 * np.pi, 361)
    motion = mbplanar.analyse(engine, phi)
    assert motion.success
    cm = 0.01
    A = 15 * cm * np.stack([np.cos(phi), np.sin(phi)], axis=-1)
    P = np.broadcast_to(np.array([-38.0, -7.8]) * cm, A.shape)
    B = circle_meet(A, P, 50 * cm, 41.5 * cm, -1)
    C = circle_meet(A, P, 61.9 * cm, 39.3 * cm, +1)
    D = circle_meet(B, P, 55.8 * cm, 40.1 * cm, -1)
    E = circle_meet(D, C, 39.4 * cm, 36.7 * cm, -1)
    F = circle_meet(E, C, 65.7 * cm, 49 * cm, -1)
    for name, ref in (("B", B), ("C1", C), ("D", D), ("E", E), ("F", F)):
        assert np.abs(motion.xy[:, motion.point(name)] - ref).max() < 1e-11, name


def test_scotch_yoke_is_harmonic():
    """Crank r, its pin in a vertical slot of a yoke sliding horizontally: x = r·cos φ (RPP dyad)."""
    r, phi0 = 0.1, 0.3
    pin = (r * math.cos(phi0), r * math.sin(phi0))
    m = mbplanar.Mechanism("scotch_yoke")
    for name in "123":
        m.add_link(name)
    m.add_joint("O", "R", "0", "1", at=(0.0, 0.0))
    m.add_joint("A", "R", "1", "2", at=pin)
    m.add_joint("Ap", "P", "3", "2", at=pin, guide=90.0)
    m.add_joint("Y", "P", "0", "3", at=(pin[0] + 0.2, 0.0), guide=0.0)
    m.add_input("O", unit="rad")
    phi = np.linspace(0.0, 2 * np.pi, 73)
    motion = mbplanar.analyse(mbplanar.Engine(m), phi, omega=2.0, epsilon=0.5)
    k = motion.joint("Y")
    assert np.allclose(motion.value[:, k], r * np.cos(phi) - pin[0], atol=1e-14)
    assert np.allclose(motion.rate[:, k], -2.0 * r * np.sin(phi), atol=1e-14)
    assert np.allclose(motion.accel[:, k], -4.0 * r * np.cos(phi) - 0.5 * r * np.sin(phi), atol=1e-14)


def test_elliptic_trammel_driven_by_a_slider_stops_at_its_dead_point():
    """Rod AB (L = 1) with A on the x axis (the input slider) and B on the y axis: y_B = √(L² − x_A²),
    the midpoint on an ellipse (a circle here); the slider cannot pass x_A = L."""
    engine, L, th0 = trammel()
    A = (L * math.cos(th0), 0.0)
    s = np.linspace(-0.3, 0.3, 25)
    motion = mbplanar.analyse(engine, s)
    xa = A[0] + motion.phi[:, 0]
    yb = np.sqrt(L * L - xa * xa)
    assert np.abs(motion.xy[:, motion.point("B"), 1] - yb).max() < 1e-12
    assert np.abs(motion.xy[:, motion.point("M")] - np.stack([xa / 2, yb / 2], axis=1)).max() < 1e-12
    assert not motion.success and len(motion.limits) == 1
    assert A[0] + motion.limits[0].phi[0] == pytest.approx(L, abs=1e-15)


# Andrews' squeezing mechanism (Schiehlen's multibody benchmark; Hairer & Wanner, Solving ODEs II, VII.7):
# its geometry and the consistent initial angles of the test set, to 30 digits.
ANDREWS = dict(xa=-0.06934, ya=-0.00227, xb=-0.03635, yb=0.03273, d=28e-3, e=2e-2, rr=7e-3, ss=35e-3,
               zf=2e-2, zt=4e-2, u=4e-2)
ANDREWS_START = dict(beta=-0.0617138900142764496358948458001, theta=0.0, gamma=0.455279819163070380255912382449,
                     phi=0.222668390165885884674473185609, delta=0.487364979543842550225598953530,
                     omega=-0.222668390165885884674473185609, eps=1.23054744454982119249735015568)


def _andrews_points(beta, theta, gamma, phi, delta, omega, eps):
    """E (from the crank and rod 2), G, H of Andrews' mechanism from its seven angles (the test set's
    loop equations g1…g6 say that E is also at ss from B, at e from G and at zf from H)."""
    g = ANDREWS
    F = g["rr"] * np.array([math.cos(beta), math.sin(beta)])
    E = F - g["d"] * np.array([math.cos(beta + theta), math.sin(beta + theta)])
    G = np.array([g["xa"], g["ya"]]) + g["zt"] * np.array([math.cos(delta), math.sin(delta)])
    H = np.array([g["xa"], g["ya"]]) + g["u"] * np.array([math.sin(eps), -math.cos(eps)])
    return F, E, G, H


def test_andrews_squeezer_assembles_from_a_sketch_to_the_published_consistent_position():
    """Drawn 1 mm off with the benchmark's lengths, Andrews' mechanism assembles to the test set's
    consistent initial position, and a full turn of the crank brings it back there."""
    g, start = ANDREWS, ANDREWS_START
    F, E, G, H = _andrews_points(**start)
    A, B = (g["xa"], g["ya"]), (g["xb"], g["yb"])
    off = np.array([1e-3, -1e-3])
    m = mbplanar.Mechanism("andrews")
    m.add_link("1", lengths=(("O", "F", g["rr"]),))
    m.add_link("2", lengths=(("F", "E3", g["d"]),))
    m.add_link("3", lengths=(("E3", "B", g["ss"]),))
    m.add_link("4", lengths=(("E4", "G", g["e"]),))
    m.add_link("5", lengths=(("G", "A5", g["zt"]),))
    m.add_link("6", lengths=(("E6", "H", g["zf"]),))
    m.add_link("7", lengths=(("H", "A7", g["u"]),))
    m.add_joint("O", "R", "0", "1", at=(0.0, 0.0))
    m.add_joint("F", "R", "1", "2", at=tuple(F))
    for name, link in (("E3", "3"), ("E4", "4"), ("E6", "6")):
        m.add_joint(name, "R", "2", link, at=tuple(E + off))
    m.add_joint("B", "R", "3", "0", at=B)
    m.add_joint("G", "R", "4", "5", at=tuple(G - off))
    m.add_joint("A5", "R", "5", "0", at=A)
    m.add_joint("H", "R", "6", "7", at=tuple(H + off))
    m.add_joint("A7", "R", "7", "0", at=A)
    m.add_input("O", unit="rad", drawn_at=start["beta"])
    engine = mbplanar.Engine(m)
    assert engine.topology.structure.formula == "I(0,1) → II(2,3) → II(4,5) → II(6,7)"
    phi = start["beta"] + np.linspace(0.0, 2 * np.pi, 361)
    motion = mbplanar.analyse(engine, phi)
    assert motion.success
    for name, ref in (("E3", E), ("G", G), ("H", H)):
        for row in (0, -1):
            assert np.abs(motion.xy[row, motion.point(name)] - ref).max() < 1e-13, (name, row)


# -- what a caller asks for: analyse(..., points=, rates=) ------------------------------------------
def test_asked_points_are_the_same_columns_in_the_asked_order(engine_of):
    engine = engine_of("shaper")
    phi = engine.phi_drawn[0] + np.linspace(0.0, 2 * math.pi, 37)
    full = mbplanar.analyse(engine, phi, 3.0, -0.4)
    asked = [full.point_names[-1], full.point_names[1]]
    some = mbplanar.analyse(engine, phi, 3.0, -0.4, points=asked)
    assert some.point_names == asked and some.xy.shape == (37, 2, 2)
    idx = [full.point(n) for n in asked]
    for name in ("xy", "v", "a", "vq", "aq"):
        np.testing.assert_array_equal(getattr(some, name), getattr(full, name)[:, idx], err_msg=name)
    for name in ("angle", "w", "e", "value", "rate", "accel"):  # links and joints do not depend on it
        np.testing.assert_array_equal(getattr(some, name), getattr(full, name), err_msg=name)
    with pytest.raises(KeyError, match=r"holds the points .* not 'O'"):
        some.point("O")


def test_positions_only_are_the_positions_and_leave_the_rates_out(engine_of):
    engine = engine_of("six_bar_press")
    phi = engine.phi_drawn[0] + np.linspace(0.0, 2 * math.pi, 25)
    full, bare = mbplanar.analyse(engine, phi), mbplanar.analyse(engine, phi, rates=False)
    for name in ("angle", "xy", "value"):
        np.testing.assert_array_equal(getattr(bare, name), getattr(full, name), err_msg=name)
    for name in ("v", "w", "aq", "rate_q", "ic"):
        assert getattr(bare, name) is None and getattr(full, name) is not None, name
    assert bare.frames.w is None and bare.frames.th is not None
    from mbplanar.forces import kinetostatics
    with pytest.raises(mbplanar.ModelError, match="rates=True"):
        kinetostatics(engine, bare)


def test_unknown_or_repeated_points_are_refused(engine_of):
    engine = engine_of("fourbar")
    with pytest.raises(mbplanar.ModelError, match=r"no joint or point named 'Q'; the joints and points are O, A, B, C, M"):
        mbplanar.analyse(engine, [1.0], points=["A", "Q"])
    with pytest.raises(mbplanar.ModelError, match="'A' is asked twice"):
        mbplanar.analyse(engine, [1.0], points=["A", "B", "A"])
    assert mbplanar.analyse(engine, [1.0], points=[]).xy.shape == (1, 0, 2)
