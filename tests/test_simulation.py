"""Motion under given forces (`mbplanar.simulation`, `mbplanar simulate`): Andrews' squeezing mechanism
against the published consistent initial values and reference solution (Hairer & Wanner, Solving ODE
II, §VII.7; the Test Set for IVP Solvers, problem "andrews"), and the energy balance of any motion."""

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import mbplanar
from mbplanar.cli import main
from mbplanar.errors import ModelError
from mbplanar.forces._simulation import accelerations, read_simulate, simulate_motion
from mbplanar.model._model import Gravity

MODELS = Path(__file__).resolve().parent.parent / "models"

pytest.importorskip("numba")

# published consistent initial values: positions, accelerations of beta and Theta, multipliers 1-2
Q0 = [-0.0617138900142764496358948458001, 0.0, 0.455279819163070380255912382449,
      0.222668390165885884674473185609, 0.487364979543842550225598953530,
      -0.222668390165885884674473185609, 1.23054744454982119249735015568]
W0 = [14222.4439199541138705911625887, -10666.8329399655854029433719415, 0, 0, 0, 0, 0]
LAMBDA0 = [98.5668703962410896057654982170, -6.12268834425566265503114393122, 0, 0, 0, 0]
# published reference solution at t = 0.03 s: positions, velocities, accelerations, multipliers
REF = [0.1581077119629904e+02, -0.1575637105984298e+02, 0.4082224013073101e-01, -0.5347301163226948e+00,
       0.5244099658805304e+00, 0.5347301163226948e+00, 0.1048080741042263e+01,
       0.1139920302151208e+04, -0.1424379294994111e+04, 0.1103291221937134e+02, 0.1929337464421385e+02,
       0.5735699284790808e+00, -0.1929337464421385e+02, 0.3231791658026955e+00,
       -0.2463176316945196e+05, 0.5185037701610329e+05, 0.3241025686413781e+06, 0.5667493645176213e+06,
       0.1674362929479361e+05, -0.5667493645176222e+06, 0.9826520791458422e+04,
       0.1991753333731910e+03, -0.2975531228015052e+02, 0.2306654119098399e+02, 0.3145271365475927e+02,
       0.2264249232082739e+02, 0.1161740700019673e+02]

# the published coordinates in the model's terms: (link angle or joint value) per coordinate
COORDS = [("link", "1"), ("joint", "F"), ("link", "3"), ("joint", "G"), ("link", "5"), ("joint", "H"),
          ("link", "7")]
MULTIPLIERS = ["E23", "E24", "E26"]  # reactions on 3, 4, 6 from 2 at E: lambda (1, 2), (3, 4), (5, 6)


def _published(doc, k):
    """Positions, velocities, accelerations (7,) each and multipliers (6,) at output k of a JSON document."""
    keys = {"link": ("angle", "omega", "epsilon"), "joint": ("value", "rate", "accel")}
    out = [[doc[kind + "s"][name][keys[kind][i]][k] for kind, name in COORDS] for i in range(3)]
    lam = [doc["joints"][j][c][k] for j in MULTIPLIERS for c in ("fx", "fy")]
    return [np.array(x) for x in out] + [np.array(lam)]


@pytest.fixture(scope="module")
def squeezer_doc():
    import contextlib
    import io
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        assert main(["--backend", "numba", "simulate", str(MODELS / "squeezer.toml"), "--t", "0.03",
                     "--steps", "3", "--json"]) == 0
    return json.loads(buf.getvalue())


def test_squeezer_consistent_initial_values(squeezer_doc):
    q, v, w, lam = _published(squeezer_doc, 0)
    assert np.max(np.abs(q - Q0)) < 1e-14
    assert np.all(v == 0)
    assert np.max(np.abs(w - W0)) <= 1e-10 * np.max(np.abs(W0))
    assert np.max(np.abs(lam - LAMBDA0)) <= 1e-10 * np.max(np.abs(LAMBDA0))


def test_squeezer_reference_solution(squeezer_doc):
    """The reference of the test set at t = 0.03. It was computed by PSIDE at 1e-14, and is itself
    accurate to ~1.5e-9 rad in beta and Theta, ~5e-8 relative in the velocities and ~1.5e-6 relative
    in the accelerations and multipliers: integrating the published equations (index-1 form, DOP853
    at 1e-13) lands 1.16e-9 below its beta, and its own accelerations and multipliers solve its own
    equations at its own positions and velocities to 1.5e-6 (docs/forces.md). The bounds below are
    those accuracies; the velocities and the second derivatives are also checked norm-wise."""
    q, v, w, lam = _published(squeezer_doc, -1)
    ref = np.array(REF)
    assert squeezer_doc["t"][-1] == pytest.approx(0.03, abs=1e-15)
    assert np.max(np.abs(q - ref[:7])) < 2e-9
    assert np.max(np.abs(v - ref[7:14]) / np.abs(ref[7:14])) < 1e-7
    assert np.max(np.abs(v - ref[7:14])) < 1e-8 * np.max(np.abs(ref[7:14]))
    assert np.max(np.abs(w - ref[14:21]) / np.abs(ref[14:21])) < 2e-6
    assert np.max(np.abs(w - ref[14:21])) < 1e-6 * np.max(np.abs(ref[14:21]))
    assert np.max(np.abs(lam - ref[21:]) / np.abs(ref[21:])) < 2e-6
    assert np.max(np.abs(lam - ref[21:])) < 1e-6 * np.max(np.abs(ref[21:]))


def test_squeezer_balancing_moment_is_the_drive(squeezer_doc):
    """The prescribed motion with the published initial acceleration needs the published 0.033 N·m;
    along the computed motion the balancing moment is the drive."""
    engine = mbplanar.Engine(mbplanar.read_model(MODELS / "squeezer.toml"))
    motion = mbplanar.analyse(engine, np.array([Q0[0]]), omega=0.0, epsilon=W0[0])
    assert mbplanar.kinetostatics(engine, motion).balancing["O"][0] == pytest.approx(0.033, rel=1e-12)
    assert np.allclose(squeezer_doc["inputs"]["beta"]["balancing"], 0.033, rtol=1e-9)


def test_squeezer_energy_balance(squeezer_doc):
    e = squeezer_doc["energy"]
    total = np.array(e["kinetic"]) + np.array(e["potential"]) - np.array(e["drive_work"])
    assert np.max(np.abs(total - total[0])) < 1e-9 * max(e["kinetic"])


def _five_bar():
    """A two-input five-bar with masses and gravity."""
    m = mbplanar.Mechanism("five_bar")
    m.add_link("1", mass=1.0, inertia=0.01, centre="S1")
    m.add_link("2", mass=2.0, inertia=0.05, centre="S2")
    m.add_link("3", mass=1.5, inertia=0.04, centre="S3")
    m.add_link("4", mass=0.8, inertia=0.008, centre="S4")
    m.add_joint("O", "R", "0", "1", at=(0.0, 0.0))
    m.add_joint("A", "R", "1", "2", at=(0.0, 0.2))
    m.add_joint("B", "R", "2", "3", at=(0.3, 0.45))
    m.add_joint("C", "R", "3", "4", at=(0.5, 0.25))
    m.add_joint("D", "R", "4", "0", at=(0.4, 0.0))
    for name, link, p in (("S1", "1", (0.0, 0.1)), ("S2", "2", (0.15, 0.3)), ("S3", "3", (0.42, 0.36)),
                          ("S4", "4", (0.45, 0.12))):
        m.add_point(name, link, at=p)
    m.add_input("O", unit="rad")
    m.add_input("D", unit="rad")
    m.gravity = Gravity(9.81)
    return m


def test_two_dof_energy_is_conserved():
    """Several DOF through the generalised mass matrix: a five-bar falling under gravity from rest
    keeps T + V constant to the integrator's tolerance."""
    engine = mbplanar.Engine(_five_bar())
    spec = read_simulate(engine.mech, t=0.1, steps=4, rtol=1e-10, atol=1e-12)
    tr = simulate_motion(engine, spec)
    assert tr.success
    total = tr.energy["kinetic"] + tr.energy["potential"] - tr.energy["drive_work"]
    assert np.ptp(tr.phi[:, 0]) > 0.01  # it moved
    assert np.max(np.abs(total - total[0])) < 1e-8 * np.max(tr.energy["kinetic"])
    assert np.max(np.abs(tr.kinetostatics.virtual_power_residual)) < 1e-9


def test_one_dof_reduced_form():
    """With one input the equation is the reduced form J(φ)·φ̈ + ½·J′(φ)·φ̇² = M(φ, φ̇)."""
    from mbplanar.forces._dynamics import reduce
    engine = mbplanar.Engine(mbplanar.read_model(MODELS / "six_bar_press.toml"))
    spec = replace(read_simulate(engine.mech), torque=(0.0,), motor_slope=(0.0,))  # (no drive: [dynamics]'s)
    phi, om = 1.3, 4.0
    red = reduce(engine, [phi])
    J = red.J_II[0] + red.J_input[0]
    dJ = red.dJ_II[0]  # the input link's own inertia is constant
    # the press's loads do not depend on the speed's size, only on its sign (positive here)
    expected = (red.M_red[0] - 0.5 * dJ * om * om) / J
    assert accelerations(engine, [phi], [om], spec)[0] == pytest.approx(expected, rel=1e-10)
    slower = (red.M_red[0] - 0.5 * dJ * om * om) / (J + 2.5)  # a flywheel of 2.5 kg·m² on the crank
    assert accelerations(engine, [phi], [om], spec, input_inertia=[2.5])[0] == pytest.approx(slower, rel=1e-10)


def test_chattering_motion_stops_with_an_error():
    engine = mbplanar.Engine(mbplanar.read_model(MODELS / "squeezer.toml"))
    with pytest.raises(mbplanar.MotionError, match="50 evaluations reached"):
        simulate_motion(engine, replace(read_simulate(engine.mech), max_evaluations=50))


def test_bad_simulate_input():
    engine = mbplanar.Engine(mbplanar.read_model(MODELS / "squeezer.toml"))
    with pytest.raises(ModelError, match="method"):
        read_simulate(engine.mech, method="Euler")
    with pytest.raises(ModelError, match="one per input"):
        read_simulate(engine.mech, torque=[1.0, 2.0])
    with pytest.raises(ModelError, match="end time"):
        simulate_motion(engine, replace(read_simulate(engine.mech), t=None))
    assert math.isfinite(read_simulate(engine.mech).t)
