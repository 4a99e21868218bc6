"""Kinetostatics: seed 000's reactions (REFERENCE.md), a closed-form static four-bar, per-link equilibrium
from the reported reactions (action = −reaction), virtual power on random mechanisms, the CLI."""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import mbplanar
from mbplanar.cli import main
from mbplanar.forces import kinetostatics
from mbplanar.forces import evaluate_loads

SHAPER = "models/shaper.toml"


@pytest.fixture(scope="module")
def shaper():
    engine = mbplanar.Engine(mbplanar.read_model(SHAPER))
    motion = mbplanar.analyse(engine, np.radians([140.769]), 7.646, -0.577)
    return engine, motion, kinetostatics(engine, motion, input_inertia=147.173)


def _on(result, joint, link):
    """Force and moment on `link` in `joint` (the reported one or its opposite)."""
    r = result.reaction(joint)
    sign = 1.0 if r.on == link else -1.0
    assert link in (r.on, r.source)
    return sign * np.stack([r.fx, r.fy], axis=-1), sign * r.moment


# REFERENCE.md, seed 000, reactions at f = 140.769 (F_ij on i from j).
SEED000 = {
    ("O", "1"): (1568.43, -212.751), ("A", "1"): (-1568.43, 212.751), ("C", "3"): (-488.504, 386.649),
    ("D", "3"): (-1105.27, 0.0), ("Ap", "2"): (-1568.43, 212.751), ("Dp", "4"): (-1105.27, 0.0),
    ("F", "5"): (0.0, 637.65),
}


@pytest.mark.parametrize("joint,link", list(SEED000))
def test_seed000_reactions(shaper, joint, link):
    _, _, result = shaper
    force, _ = _on(result, joint, link)
    expected = SEED000[(joint, link)]
    for got, want in zip(force[0], expected):
        assert got == pytest.approx(want, rel=1e-3, abs=1e-6 * 1568)


def test_seed000_moments_and_balancing(shaper):
    _, _, result = shaper
    assert _on(result, "Ap", "2")[1][0] == pytest.approx(0.0, abs=1e-9)
    assert _on(result, "Dp", "4")[1][0] == pytest.approx(0.0, abs=1e-9)
    assert _on(result, "F", "5")[1][0] == pytest.approx(227.322, rel=1e-3)
    assert result.balancing["O"][0] == pytest.approx(-102.059, rel=1e-3)
    assert result.virtual_power_residual[0] < 1e-9
    r = result.reaction("A")
    assert (r.on, r.source) == ("1", "2")
    assert r.magnitude[0] == pytest.approx(1582.8, rel=1e-4)
    assert r.direction_deg[0] == pytest.approx(172.275, abs=1e-3)
    r = result.reaction("C")
    assert r.magnitude[0] == pytest.approx(623.0, rel=1e-4)
    assert r.direction_deg[0] == pytest.approx(141.639, abs=1e-3)


def test_seed000_exact_balancing_is_the_driving_moment():
    """With the exact ω1(f), ε1(f) and J_I of REFERENCE.md, M1 = −M_dr = −102.058."""
    engine = mbplanar.Engine(mbplanar.read_model(SHAPER))
    motion = mbplanar.analyse(engine, np.radians([140.769]), 7.64558, -0.577148)
    result = kinetostatics(engine, motion, input_inertia=147.141)
    assert result.balancing["O"][0] == pytest.approx(-102.058, rel=2e-4)
    f10, _ = _on(result, "O", "1")
    assert f10[0, 0] == pytest.approx(1568.46, rel=1e-4)


def _equilibrium_residual(engine, motion, result):
    """Max |ΣF|, |ΣM| over the moving links from the reported reactions and the loads (no matrix)."""
    mech = engine.mech
    worst = 0.0
    for link in mech.moving_links:
        k = engine.link_index[link]
        f = np.zeros((len(motion.phi), 2))
        m = np.zeros(len(motion.phi))
        for j in mech.joints_of(link):
            force, moment = _on(result, j.name, link)
            at_link = j.slider if j.kind == "P" else link
            p = motion.frames.r[:, engine.link_index[at_link]] + _rot(
                motion.frames.th[:, engine.link_index[at_link]], j.at)
            f += force
            m += p[:, 0] * force[:, 1] - p[:, 1] * force[:, 0] + moment
        for ld in result.loads:
            if ld.link == k:
                f += ld.force
                m += ld.point[:, 0] * ld.force[:, 1] - ld.point[:, 1] * ld.force[:, 0] + ld.moment
        for inp in engine.inputs:
            if link in mech.joints[inp.joint].links and mech.joints[inp.joint].kind == "R":
                sign = 1.0 if link != mech.ground else 0.0
                m += sign * result.balancing[inp.joint]
        scale = 1.0 + max(np.abs(ld.force).max() for ld in result.loads)
        worst = max(worst, np.abs(f).max() / scale, np.abs(m).max() / (scale * engine.size))
    return worst


def _rot(th, at):
    c, s = np.cos(th), np.sin(th)
    return np.stack((c * at[0] - s * at[1], s * at[0] + c * at[1]), axis=-1)


def test_every_link_in_equilibrium_from_reported_reactions(shaper):
    """Summing each link's loads with the reported reactions (their opposites on the other side) gives
    zero: action = −reaction and the on/from labels are right."""
    engine, _, _ = shaper
    motion = mbplanar.analyse(engine, np.radians(np.linspace(0, 355, 36)), 7.6, 0.4)
    result = kinetostatics(engine, motion, input_inertia=10.0)
    assert result.success
    assert _equilibrium_residual(engine, motion, result) < 1e-10
    assert np.all(result.virtual_power_residual < 1e-9)


def _fourbar(pose, masses=None):
    """A four-bar drawn at O, A, B, C (its own exact pose)."""
    (ax, ay), (bx, by), (cx, cy) = pose
    mech = mbplanar.Mechanism("random fourbar")
    kw = masses or {}
    for name in ("1", "2", "3"):
        mech.add_link(name, **kw.get(name, {}))
    mech.add_joint("O", "R", "0", "1", at=(0.0, 0.0))
    mech.add_joint("A", "R", "1", "2", at=(ax, ay))
    mech.add_joint("B", "R", "2", "3", at=(bx, by))
    mech.add_joint("C", "R", "0", "3", at=(cx, cy))
    mech.add_input("O", unit="rad")
    return mech


def test_static_fourbar_closed_form():
    """A moment M3 on the rocker; the coupler is a two-force member along AB with tension S where
    (B−C)×(S·u) = −M3; then F10 = S·u, F12 = −S·u, F23 = −S·u, F30 = −S·u, M1 = S·(A−O)×u."""
    pose = ((0.3, 0.4), (1.4, 0.9), (1.2, 0.0))
    mech = _fourbar(pose)
    mech.add_load("moment", link="3", moment=25.0)
    engine = mbplanar.Engine(mech)
    motion = mbplanar.analyse(engine, engine.phi_drawn, 0.0, 0.0)
    result = kinetostatics(engine, motion)
    A, B, C = (np.array(p) for p in pose)
    u = (B - A) / np.linalg.norm(B - A)
    cross = lambda p, q: p[0] * q[1] - p[1] * q[0]  # noqa: E731
    S = -25.0 / cross(B - C, u)
    expect = {("O", "1"): S * u, ("A", "1"): -S * u, ("B", "2"): -S * u, ("C", "3"): -S * u}
    for (joint, link), force in expect.items():
        np.testing.assert_allclose(_on(result, joint, link)[0][0], force, rtol=1e-10, atol=1e-10)
    assert result.balancing["O"][0] == pytest.approx(S * cross(A, u), rel=1e-10)
    # and by virtual work: M1·ω1 + M3·ω3 = 0
    assert result.balancing["O"][0] == pytest.approx(-25.0 * motion.wq[0, 3] / motion.wq[0, 1], rel=1e-10)


def _slider_crank(pose):
    (ax, ay), (bx, by) = pose
    mech = mbplanar.Mechanism("random slider-crank")
    for name in ("1", "2", "3"):
        mech.add_link(name)
    mech.add_joint("O", "R", "0", "1", at=(0.0, 0.0))
    mech.add_joint("A", "R", "1", "2", at=(ax, ay))
    mech.add_joint("B", "R", "2", "3", at=(bx, by))
    mech.add_joint("Bp", "P", "0", "3", at=(bx, by), guide=0.0)
    mech.add_input("O", unit="rad")
    return mech


coord = st.floats(-1.0, 1.0, allow_nan=False)
positive = st.floats(0.1, 10.0, allow_nan=False)


def _random_mass_and_loads(mech, draw, links):
    """Random masses and centres on every moving link, plus a force and a moment on each."""
    loads = []
    for name in links:
        centre = (draw(coord), draw(coord))
        mech.add_point(f"S{name}", name, at=centre)
        old = mech.links[name]
        mech.links[name] = type(old)(old.name, old.lengths, old.angle, draw(positive), draw(positive), f"S{name}")
        loads.append({"type": "force", "link": name, "at": [draw(coord), draw(coord)],
                      "force": [draw(coord) * 100, draw(coord) * 100]})
        loads.append({"type": "moment", "link": name, "moment": draw(coord) * 50})
    for row in loads:
        mech.add_load(**row)
    mech.set_gravity(9.81)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_virtual_power_on_random_mechanisms(data):
    draw = data.draw
    if draw(st.booleans()):
        pose = ((draw(coord), draw(coord)), (1 + draw(coord), 1 + draw(coord)), (1.5 + draw(coord), draw(coord)))
        mech = _fourbar(pose)
    else:
        pose = ((draw(coord), draw(coord)), (1.5 + draw(coord), draw(coord)))
        mech = _slider_crank(pose)
    assume(min(np.hypot(*np.subtract(p, q)) for p in [(0, 0), *pose] for q in [(0, 0), *pose]
               if p is not q) > 0.1)
    _random_mass_and_loads(mech, draw, ("1", "2", "3"))
    try:
        engine = mbplanar.Engine(mech)
    except mbplanar.MbplanarError:
        assume(False)
    phi = engine.phi_drawn[0] + np.linspace(-0.02, 0.02, 3)
    motion = mbplanar.analyse(engine, phi, draw(positive), draw(coord) * 5)
    assume(motion.success)
    # keep away from dead points where the crank cannot balance anything
    assume(np.all(np.abs(motion.wq[:, 1:]) < 50) and np.all(np.abs(motion.eq[:, 1:]) < 1e4))
    result = kinetostatics(engine, motion, input_inertia=draw(positive))
    assume(result.success)
    assert np.all(result.virtual_power_residual < 1e-9)
    assert _equilibrium_residual(engine, motion, result) < 1e-8


def test_cli_forces_json(capsys):
    code = main(["forces", SHAPER, "--at", "140.769", "--omega", "7.646", "--epsilon", "-0.577",
                 "--input-inertia", "147.173", "--json"])
    assert code == 0
    doc = json.loads(capsys.readouterr().out)
    a = doc["reactions"]["A"]
    assert (a["on"], a["from"]) == ("1", "2")
    assert math.hypot(a["fx"], a["fy"]) == pytest.approx(1582.8, rel=1e-4)
    assert math.degrees(math.atan2(a["fy"], a["fx"])) % 360 == pytest.approx(172.275, abs=1e-3)
    c = doc["reactions"]["C"]
    assert math.degrees(math.atan2(c["fy"], c["fx"])) % 360 == pytest.approx(141.639, abs=1e-3)
    assert doc["reactions"]["F"]["moment"] == pytest.approx(227.322, rel=1e-4)
    assert doc["balancing"]["O"] == pytest.approx(-102.059, rel=1e-4)
    assert doc["virtual_power_residual"] < 1e-9


def test_cli_forces_default_omega_and_table(capsys, tmp_path):
    """Without a [dynamics] section, forces runs at the model's constant omega."""
    text = Path(SHAPER).read_text(encoding="utf-8")
    model = tmp_path / "shaper_no_dynamics.toml"
    model.write_text(text[:text.index("[dynamics]")], encoding="utf-8")
    assert main(["forces", str(model), "--at", "140.769"]) == 0
    out = capsys.readouterr().out
    assert "ω = 7.64454 rad/s" in out and "ε = 0 rad/s²," in out and "balancing moment at O" in out


def test_cli_forces_bad_input(capsys):
    assert main(["forces", SHAPER, "--at", "140", "--input-inertia", "-1"]) == 2
    assert "input_inertia must be a finite number >= 0" in capsys.readouterr().err


def test_cli_sweep_force_columns(tmp_path, capsys):
    out = tmp_path / "s.csv"
    assert main(["sweep", "models/six_bar_press.toml", "--steps", "6", "--omega", "6.8", "-o", str(out)]) == 0
    header = out.read_text().splitlines()[0].split(",")
    assert "O.balancing[N*m]" in header and "Hp.moment[N*m]" in header and "A.fx[N]" in header
    rows = np.array([[float(x) for x in line.split(",")] for line in out.read_text().splitlines()[1:]])
    assert np.all(rows[:, header.index("virtual_power_residual")] < 1e-9)
    assert main(["sweep", "models/fourbar.toml", "--steps", "2", "-o", str(out)]) == 0
    assert "O.balancing[N*m]" not in out.read_text()


def test_no_loads_no_forces():
    engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    motion = mbplanar.analyse(engine, np.radians([10.0, 50.0]), 3.0, 0.0)
    result = kinetostatics(engine, motion)
    assert evaluate_loads(engine, motion) == [] or all(
        np.all(ld.force == 0) for ld in evaluate_loads(engine, motion))
    for r in result.reactions.values():
        assert np.all(r.fx == 0) and np.all(r.fy == 0)


@pytest.mark.parametrize("path,m_dr", [(SHAPER, 102.058), ("models/six_bar_press.toml", 2263.03)])
def test_cycle_mean_of_balancing_moment_is_the_driving_moment(path, m_dr):
    """At constant ω the inertia and weights do no net work per cycle: the mean balancing moment is
    the driving moment M_dr = −A_c/2π of REFERENCE.md (a clockwise crank: M1 = −M_dr)."""
    engine = mbplanar.Engine(mbplanar.read_model(path))
    phi = np.linspace(0.0, 2 * np.pi, 1441)
    motion = mbplanar.analyse(engine, phi)
    result = kinetostatics(engine, motion)
    assert result.success and np.all(result.virtual_power_residual < 1e-9)
    mean = np.trapezoid(result.balancing["O"], phi) / (2 * np.pi)
    assert mean == pytest.approx(-m_dr, rel=2e-5)
