"""Machine dynamics against seeds 000 and 003 (REFERENCE.md), and against laws that must hold: J_II is
twice the kinetic energy of the second group over ω², dJ_II its derivative, M_red the power of the loads
(virtual work: the static balancing moment), the simulated motion the energy integral of the equation
of motion."""

import dataclasses
import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import mbplanar
from mbplanar.cli import main
from mbplanar.forces import DynamicsSpec, machine_dynamics, reduce, simulate
from mbplanar.errors import ModelError
from mbplanar.forces import kinetostatics

MODELS = Path(__file__).resolve().parent.parent / "models"
F_SHAPER = math.radians(140.76923076923077)
F_PRESS = math.radians(99.1)


@pytest.fixture(scope="module")
def shaper(engine_of):
    return engine_of("shaper"), machine_dynamics(engine_of("shaper"))


@pytest.fixture(scope="module")
def press(engine_of):
    return engine_of("six_bar_press"), machine_dynamics(engine_of("six_bar_press"))


def _press_with_the_seeds_mass_slip():
    """Seed 003 as its own dynamics computed it: link 3's mass 9 kg (m2) at B, the slider massless."""
    text = (MODELS / "six_bar_press.toml").read_text(encoding="utf-8")
    slip = text.replace("mass = 16.0, inertia = 0.55", "mass = 9.0, inertia = 0.55")
    slip = slip.replace('{ name = "5", mass = 3.5, centre = "H" }', '{ name = "5" }')
    assert slip.count("mass = 9.0") == 2 and "mass = 3.5" not in slip
    return mbplanar.Engine(mbplanar.parse_model(tomllib.loads(slip), "six_bar_press_slip"))


# -- seed 000: the shaper ---------------------------------------------------------------------------
def test_shaper_energy_mass_method(shaper):
    _, d = shaper
    assert d.resistance_work == pytest.approx(-641.25, rel=1e-4)
    assert d.driving_moment == pytest.approx(102.058, rel=1e-4)
    assert d.dT_I_max == pytest.approx(27.7321, rel=1e-3)
    assert d.dT_I_min == pytest.approx(-402.208, rel=1e-4)
    assert d.phi_dT_max == pytest.approx(0.6168, abs=2e-3)
    assert d.phi_dT_min == pytest.approx(5.0588, abs=2e-3)
    assert d.inertia_first_group == pytest.approx(147.141, rel=1e-3)
    assert d.omega_min == pytest.approx(7.45343, rel=1e-5)
    assert d.omega_max == pytest.approx(7.83566, rel=1e-5)
    assert d.epsilon_min == pytest.approx(-2.84991, rel=1e-3)
    assert d.epsilon_max == pytest.approx(3.54765, rel=1e-3)


def test_shaper_values_at_the_reference_position(shaper):
    engine, d = shaper
    s = d.state_at(engine, [F_SHAPER, 0.0])
    assert s["J_II"][0] == pytest.approx(2.18512, rel=1e-4)
    assert s["dJ_II"][0] == pytest.approx(-1.03199, rel=1e-4)
    assert s["moments"]["cutting"][0] == pytest.approx(-191.172, rel=1e-5)
    assert s["moments"]["friction"][0] == pytest.approx(-29.5447, rel=1e-5)
    assert s["moments"]["gravity on 3"][0] == pytest.approx(2.31264, rel=1e-5)
    assert s["A_c"][0] == pytest.approx(-372.967, rel=1e-4)
    assert s["dT_I"][0] == pytest.approx(-186.07, rel=1e-4)
    assert s["omega"] == pytest.approx([7.64558, 7.811], rel=1e-5)
    assert s["epsilon"] == pytest.approx([-0.577148, 0.693606], rel=1e-4)


def test_shaper_flywheel_on_the_motor_shaft(shaper):
    _, d = shaper
    fw = d.flywheel
    assert fw.shaft == "motor" and fw.needed
    assert fw.inertia == pytest.approx(0.305132, rel=1e-4)
    assert fw.rim.outer_diameter == pytest.approx(0.34465, rel=1e-4)
    assert fw.rim.mass == pytest.approx(18.048, rel=1e-4)


def test_simulated_delta_is_near_the_target(shaper, press):
    for _, d in (shaper, press):
        sim = d.simulation
        assert sim.success, sim.message
        assert sim.delta == pytest.approx(d.spec.delta, rel=0.1)
        assert (sim.omega_max + sim.omega_min) / 2 == pytest.approx(d.omega_mean, rel=1e-6)


# -- seed 003: the six-bar press --------------------------------------------------------------------
def test_press_physically_correct_values(press):
    engine, d = press
    assert d.driving_moment == pytest.approx(2263.03, rel=1e-5)
    assert d.resistance_work == pytest.approx(-14219.03, rel=1e-5)
    assert d.dT_I_max == pytest.approx(591.41, rel=1e-4)
    assert d.dT_I_min == pytest.approx(-6859.8, rel=1e-4)
    assert d.inertia_first_group == pytest.approx(1462.0, rel=1e-4)
    s = d.state_at(engine, [F_PRESS])
    assert s["J_II"][0] == pytest.approx(15.457, rel=1e-4)
    assert s["dJ_II"][0] == pytest.approx(10.485, rel=1e-4)
    assert s["omega"][0] - d.omega_mean == pytest.approx(0.12838, rel=1e-3)
    assert s["epsilon"][0] == pytest.approx(-2.7679, rel=1e-3)
    # the seed's flywheel on the crank shaft, J_O = 2.5 kg·m² already there: rim and disc as printed
    fw = d.flywheel
    assert fw.inertia == pytest.approx(d.inertia_first_group - 2.5)
    assert (fw.rim.outer_diameter, fw.rim.inner_diameter, fw.rim.width) == \
        pytest.approx((1.876, 1.501, 0.375), abs=6e-4)
    assert fw.rim.mass == pytest.approx(2912, abs=0.5)     # printed 2.912·10² for 2.912·10³ kg
    assert (fw.disc.diameter, fw.disc.width) == pytest.approx((1.571, 0.314), abs=6e-4)
    assert fw.disc.mass == pytest.approx(4773, abs=1)


def test_press_with_the_seeds_mass_slip_gives_its_printed_values():
    engine = _press_with_the_seeds_mass_slip()
    d = machine_dynamics(engine, simulate_motion=False)
    assert d.inertia_first_group == pytest.approx(1462, abs=0.5)
    s = d.state_at(engine, [F_PRESS])
    omega, epsilon = s["omega"][0], s["epsilon"][0]
    assert omega - d.omega_mean == pytest.approx(0.133, abs=5e-4)
    assert epsilon == pytest.approx(-2.742, abs=5e-4)
    m = mbplanar.analyse(engine, [F_PRESS], omega=omega, epsilon=epsilon)
    assert m.w[0, m.link("2")] == pytest.approx(-0.713, abs=5e-4)
    assert m.e[0, m.link("4")] == pytest.approx(9.197, abs=5e-4)
    speeds = {p: np.linalg.norm(m.v[0, m.point(p)]) for p in "ADH"}
    assert speeds == pytest.approx({"A": 2.408, "D": 4.974, "H": 4.686}, abs=5e-4)


# -- laws -------------------------------------------------------------------------------------------
def _kinetic_energy_of_the_second_group(engine, phi, omega):
    """Σ ½(m·|v_S|² + I·ω²) over the links other than the crank, from real velocities."""
    mech = engine.mech
    m = mbplanar.analyse(engine, phi, omega=omega, epsilon=0.0)
    crank = {n for n in mech.joints[engine.inputs[0].joint].links if n != mech.ground}
    T = np.zeros(len(phi))
    for name, lk in mech.links.items():
        if name == mech.ground or name in crank or not (lk.mass or lk.inertia):
            continue
        v = m.v[:, m.point(lk.centre)] if lk.mass else np.zeros((len(phi), 2))
        T += 0.5 * (lk.mass * np.sum(v * v, axis=1) + lk.inertia * m.w[:, m.link(name)] ** 2)
    return T


@pytest.mark.parametrize("name", ["shaper", "six_bar_press"])
def test_reduced_inertia_is_the_kinetic_energy_and_its_derivative(engine_of, name):
    engine = engine_of(name)
    phi = np.linspace(0.1, 6.2, 25)
    red = reduce(engine, phi)
    omega = 3.7
    T = _kinetic_energy_of_the_second_group(engine, phi, omega)
    assert np.allclose(red.J_II, 2 * T / omega ** 2, rtol=1e-12, atol=1e-12)
    h = 1e-5
    fd = (reduce(engine, phi + h).J_II - reduce(engine, phi - h).J_II) / (2 * h)
    assert np.allclose(red.dJ_II, fd, rtol=1e-6, atol=1e-6 * np.abs(red.J_II).max())


@pytest.mark.parametrize("name", ["shaper", "six_bar_press"])
def test_reduced_moment_is_balanced_by_the_static_balancing_moment(engine_of, name):
    """Virtual work: the crank's static balancing moment (matrix solve) cancels the loads' power."""
    engine = engine_of(name)
    phi = np.linspace(0.05, 6.25, 40)
    red = reduce(engine, phi)
    ks = kinetostatics(engine, red.motion, inertia=False)
    crank = red.motion.link(engine.mech.joints[engine.inputs[0].joint].links[1])
    balancing = ks.balancing[engine.inputs[0].joint]
    scale = np.abs(red.M_red).max()
    assert np.allclose(balancing * red.motion.wq[:, crank] + red.M_red, 0.0, atol=1e-9 * scale)


def test_gravity_moment_is_minus_the_derivative_of_the_potential_energy(engine_of):
    engine = engine_of("shaper")
    phi, h = np.linspace(0.1, 6.1, 13), 1e-6
    red = reduce(engine, phi)

    def potential(p):
        m = mbplanar.analyse(engine, p)
        return 9.81 * 20.0 * m.xy[:, m.point("S3"), 1] + 9.81 * 65.0 * m.xy[:, m.point("S5"), 1]
    fd = -(potential(phi + h) - potential(phi - h)) / (2 * h)
    gravity = red.moments["gravity on 3"] + red.moments["gravity on 5"]
    assert np.allclose(gravity, fd, atol=1e-6)


def test_simulation_is_the_energy_integral(shaper):
    """With a constant driving moment the exact motion is (J_I + J_II)·ω²/2 = E0 + A_Σ(φ)."""
    _, d = shaper
    om = d.simulation.omega
    E0 = (d.inertia_first_group + d.J_II[0]) * om[0] ** 2 / 2
    exact = np.sqrt(2 * (E0 + d.A_total) / (d.inertia_first_group + d.J_II))
    assert np.allclose(om, exact, rtol=1e-6)
    # ε = ω·dω/dφ
    grad = np.gradient(om, d.phi)
    assert np.allclose(d.simulation.epsilon[5:-5], (om * grad)[5:-5], atol=2e-3 * np.abs(d.simulation.epsilon).max())


def test_motor_characteristic_gives_a_unique_periodic_motion(shaper):
    _, d = shaper
    spec = DynamicsSpec(d.spec.delta, d.omega_mean, motor_slope=200.0, flywheel=d.spec.flywheel)
    d2 = machine_dynamics(shaper[0], spec)
    sim = d2.simulation
    assert sim.success, sim.message
    assert sim.omega[-1] == pytest.approx(sim.omega[0], rel=1e-7)
    assert (sim.omega_max + sim.omega_min) / 2 == pytest.approx(d.omega_mean, rel=5e-3)
    assert sim.delta < d.simulation.delta   # the motor's slope damps the fluctuation


@settings(max_examples=8, deadline=None)
@given(st.floats(0.5, 50.0), st.floats(0.01, 5.0), st.floats(0.01, 0.3))
def test_first_group_inertia_scales_as_one_over_delta(mass, inertia, delta):
    """J_I·δ does not depend on δ; with heavier links the kinetic energy term changes but J_I stays
    the energy range over ω_m²δ."""
    m = mbplanar.read_model(MODELS / "six_bar_press.toml")
    m.links["4"] = dataclasses.replace(m.links["4"], mass=mass, inertia=inertia)
    engine = mbplanar.Engine(m)
    spec = DynamicsSpec(delta, 6.8)
    d = machine_dynamics(engine, spec, steps=720, simulate_motion=False)
    dT = d.dT_I
    assert d.inertia_first_group * delta * 6.8 ** 2 == pytest.approx(dT.max() - dT.min(), rel=1e-4)
    assert d.omega_max - d.omega_min == pytest.approx(delta * 6.8, rel=1e-3)


# -- command line -----------------------------------------------------------------------------------
def test_cli_dynamics_json(capsys):
    assert main(["dynamics", str(MODELS / "shaper.toml"), "--json", "--at", "140.76923076923077"]) == 0
    doc = json.loads(capsys.readouterr().out)
    for key in ("driving_moment", "resistance_work", "inertia_first_group", "omega_mean", "omega_min",
                "omega_max", "delta_target", "delta_simulated", "flywheel"):
        assert key in doc
    assert doc["inertia_first_group"] == pytest.approx(147.14, abs=0.01)
    assert doc["driving_moment"] == pytest.approx(102.06, abs=0.01)
    assert doc["omega_min"] == pytest.approx(7.453, abs=1e-3)
    assert doc["omega_max"] == pytest.approx(7.836, abs=1e-3)
    at = doc["at"][0]
    assert at["omega"] == pytest.approx(7.64558, rel=1e-5) and at["J_II"] == pytest.approx(2.18512, rel=1e-4)
    assert at["M_red"] == pytest.approx(-191.172 - 29.5447 + 2.31264, rel=1e-5)


def test_cli_dynamics_press_and_table(tmp_path, capsys):
    out = tmp_path / "press.csv"
    assert main(["dynamics", str(MODELS / "six_bar_press.toml"), "--json", "--steps", "720", "-o", str(out)]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["inertia_first_group"] == pytest.approx(1462, rel=2e-3)
    assert doc["driving_moment"] == pytest.approx(2263, rel=1e-3)
    lines = out.read_text().splitlines()
    assert len(lines) == 722 and "omega_sim[rad/s]" in lines[0] and "M_red.pressing[N*m]" in lines[0]


def test_cli_forces_uses_the_true_motion(capsys):
    assert main(["forces", str(MODELS / "shaper.toml"), "--at", "140.769", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["input"]["motion"].startswith("true motion")
    assert doc["input"]["omega"] == pytest.approx(7.64558, rel=1e-4)
    assert doc["input"]["input_inertia"] == pytest.approx(147.141, rel=1e-3)
    assert doc["balancing"]["O"] == pytest.approx(-102.06, abs=0.01)
    assert doc["reactions"]["O"]["fx"] == pytest.approx(1568.46, rel=1e-5)
    assert (doc["reactions"]["C"]["fx"], doc["reactions"]["C"]["fy"]) == pytest.approx((-488.511, 386.655), rel=1e-5)


@pytest.mark.parametrize("args, text", [
    (["dynamics", str(MODELS / "fourbar.toml")], "no [dynamics] section"),
    (["dynamics", str(MODELS / "shaper.toml"), "--delta", "1.5"], "--delta"),
    (["dynamics", str(MODELS / "shaper.toml"), "--steps", "3"], "--steps"),
])
def test_cli_dynamics_bad_input(capsys, args, text):
    assert main(args) == 2
    err = capsys.readouterr().err
    assert text in err and "Traceback" not in err


def test_dynamics_section_errors_name_the_key(tmp_path, capsys):
    text = (MODELS / "shaper.toml").read_text(encoding="utf-8")
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("motor_rpm = 1412.4", "motor_rmp = 1412.4"), encoding="utf-8")
    assert main(["dynamics", str(bad)]) == 2
    assert "dynamics.flywheel: unknown key(s) motor_rmp" in capsys.readouterr().err
    bad.write_text(text.replace("delta = 0.05", "delta = -0.05"), encoding="utf-8")
    assert main(["dynamics", str(bad)]) == 2
    assert "'delta'" in capsys.readouterr().err


def test_a_machine_without_loads_needs_no_flywheel_and_says_so(engine_of, capsys):
    with pytest.raises(mbplanar.MotionError, match="does not vary"):
        machine_dynamics(engine_of("fourbar"), DynamicsSpec(0.05, 10.0))
    assert main(["dynamics", str(MODELS / "fourbar.toml"), "--delta", "0.05"]) == 1


def test_dynamics_needs_a_crank(engine_of):
    doc = tomllib.loads((MODELS / "six_bar_press.toml").read_text(encoding="utf-8"))
    doc["dynamics"] = {"delta": 0.1, "omega_mean": "fast"}
    with pytest.raises(ModelError, match="dynamics: 'omega_mean' must be a number"):
        mbplanar.parse_model(doc)


def test_simulate_reports_a_stall(shaper):
    _, d = shaper
    import dataclasses
    weak = dataclasses.replace(d, driving_moment=0.2 * d.driving_moment,
                               inertia_first_group=0.05 * d.inertia_first_group)
    with pytest.raises(mbplanar.MotionError, match="stalls"):
        simulate(weak)


def test_sweep_at_the_true_motion_balances_with_the_driving_moment(tmp_path):
    """With ε from the equation of motion and J_I on the crank, the balancing moment is −M_dr at every
    position (power balance), whatever the loads and the links' inertia do there."""
    out = tmp_path / "true.csv"
    assert main(["sweep", str(MODELS / "shaper.toml"), "--steps", "24", "--true-motion", "-o", str(out)]) == 0
    lines = out.read_text().splitlines()
    header = lines[0].split(",")
    rows = np.array([[float(x) for x in line.split(",")] for line in lines[1:]])
    balancing = rows[:, header.index("O.balancing[N*m]")]
    assert np.allclose(balancing, -102.058, atol=2e-3)
    assert np.ptp(rows[:, header.index("1.omega[rad/s]")]) > 0.3      # the crank's speed does vary


def test_true_motion_needs_dynamics(capsys):
    assert main(["solve", str(MODELS / "fourbar.toml"), "--at", "10", "--true-motion"]) == 2
    assert "[dynamics]" in capsys.readouterr().err
    assert main(["solve", str(MODELS / "shaper.toml"), "--at", "10", "--true-motion", "--omega", "3"]) == 2
