"""Springs, dampers, torques between links and switched rows (`mbplanar.forces`); the link's angle offset
and a centre of mass by coordinates (`mbplanar.model`)."""

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import mbplanar
from mbplanar.forces._dynamics import reduce
from mbplanar.forces._loads import evaluate_loads, read_loads, spring_energy

MODELS = Path(__file__).resolve().parent.parent / "models"


def _fourbar(loads, backend="numpy", **points):
    d = tomllib.loads((MODELS / "fourbar.toml").read_text())
    d["links"][0].update(mass=1.0, inertia=0.002, centre=[0.03, 0.04])
    d["links"][1].update(mass=3.0, inertia=0.03, centre="M")
    d["links"][2].update(mass=2.0, inertia=0.02, centre=[0.31, 0.1])
    d["points"] += [{"name": "K", "link": "0", "at": [0.1, 0.35]},
                    {"name": "Q", "link": "3", "along": ["C", "B"], "fraction": 0.7}]
    d["loads"] = loads
    d.update(points)
    return mbplanar.Engine(mbplanar.parse_model(d, source="fourbar"), backend=backend)


SPRING = {"type": "spring", "name": "s", "at": ["K", "M"], "stiffness": 2000.0, "free_length": 0.1,
          "preload": 15.0}


@settings(max_examples=12, deadline=None)
@given(k=st.floats(0.0, 1e4), free=st.floats(0.0, 0.5), pre=st.floats(-50, 50), c=st.floats(0.0, 200.0),
       cr=st.floats(0.0, 5.0), m=st.floats(-20.0, 20.0), omega=st.floats(-20.0, 20.0), eps=st.floats(-50, 50))
def test_virtual_power_balances_with_elements(k, free, pre, c, cr, m, omega, eps):
    """Springs, linear and rotational dampers and torques between links keep the virtual-power balance
    of the kinetostatics, and their reduced moment is their power per unit input speed."""
    loads = [{"type": "spring", "at": ["K", "M"], "stiffness": k, "free_length": free, "preload": pre},
             {"type": "damper", "at": ["Q", "M"], "damping": c},
             {"type": "damper", "joint": "B", "damping": cr},
             {"type": "torque", "links": ["1", "3"], "moment": m}]
    engine = _fourbar(loads)
    motion = mbplanar.analyse(engine, np.radians([15.0, 140.0, 260.0]), omega=omega, epsilon=eps)
    ks = mbplanar.kinetostatics(engine, motion)
    assert np.all(ks.virtual_power_residual < 1e-10)


def test_spring_reduced_moment_is_minus_the_energy_slope():
    """M_red = −dV/dφ for a spring (linear and tabulated), by central differences of its energy."""
    table = {"type": "spring", "name": "t", "at": ["K", "Q"], "length": [0.0, 0.2, 0.5],
             "force": [-10.0, 40.0, 400.0]}
    engine = _fourbar([SPRING, table])
    phi, h = np.radians(np.arange(0.0, 360.0, 30.0)), 1e-6
    red = reduce(engine, phi)
    for load in read_loads(engine.mech):
        energy = [spring_energy(engine, mbplanar.analyse(engine, phi + d), load) for d in (h, -h)]
        slope = (energy[0] - energy[1]) / (2 * h)
        assert np.allclose(red.moments[load.name], -slope, rtol=1e-6, atol=1e-6 * np.max(np.abs(slope)))


def test_damper_and_torque_reduced_moments():
    loads = [{"type": "damper", "name": "d", "at": ["K", "M"], "damping": 30.0},
             {"type": "damper", "name": "r", "joint": "B", "damping": 2.0},
             {"type": "torque", "name": "m", "links": ["1", "3"], "moment": 5.0}]
    engine = _fourbar(loads)
    phi, h, omega = np.radians(np.arange(0.0, 360.0, 45.0)), 1e-6, 3.0
    red = reduce(engine, phi, omega)
    motion = mbplanar.analyse(engine, phi, omega=1.0)
    K = np.array([0.1, 0.35])
    length = lambda x: np.hypot(*(mbplanar.analyse(engine, x).xy[:, motion.point("M")] - K).T)  # noqa: E731
    dl = (length(phi + h) - length(phi - h)) / (2 * h)
    assert np.allclose(red.moments["d"], -30.0 * dl * dl * omega, rtol=1e-6, atol=1e-9)
    rel = motion.wq[:, motion.link("3")] - motion.wq[:, motion.link("2")]
    assert np.allclose(red.moments["r"], -2.0 * rel * rel * omega, rtol=1e-12, atol=1e-14)
    assert np.allclose(red.moments["m"], 5.0 * (motion.wq[:, motion.link("3")] - 1.0), rtol=1e-12, atol=1e-14)


def test_switched_force():
    """A force switched on a joint's rate acts only while the rate has the sign asked."""
    row = {"type": "force", "name": "f", "link": "2", "at": "M", "force": [0.0, -100.0], "switch": "C",
           "when": "forward"}
    engine = _fourbar([row])
    motion = mbplanar.analyse(engine, np.radians(np.arange(0.0, 360.0, 10.0)), omega=2.0)
    (value,) = [ld for ld in evaluate_loads(engine, motion, gravity=False)]
    on = motion.rate[:, motion.joint("C")] >= 0
    assert on.any() and (~on).any()
    assert np.all(value.force[on, 1] == -100.0) and np.all(value.force[~on] == 0.0)
    pointed = dict(row, switch="M", switch_direction=90.0, when="backward")
    engine = _fourbar([pointed])
    motion = mbplanar.analyse(engine, np.radians(np.arange(0.0, 360.0, 10.0)), omega=2.0)
    (value,) = evaluate_loads(engine, motion, gravity=False)
    on = motion.v[:, motion.point("M"), 1] <= 0
    assert np.all(value.force[on, 1] == -100.0) and np.all(value.force[~on] == 0.0)


def test_compiled_kinetostatics_falls_back_for_elements():
    pytest.importorskip("numba")
    phi = np.radians(np.arange(0.0, 360.0, 40.0))
    out = []
    for backend in ("numpy", "numba"):
        engine = _fourbar([SPRING, {"type": "damper", "joint": "B", "damping": 2.0}], backend)
        out.append(mbplanar.kinetostatics(engine, mbplanar.analyse(engine, phi, omega=30.0, epsilon=5.0)))
    for j, r in out[0].reactions.items():
        assert np.allclose(out[1].reactions[j].fx, r.fx, rtol=1e-10, atol=1e-10)
    assert np.allclose(out[1].balancing["O"], out[0].balancing["O"], rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("row,words", [
    ({"type": "spring", "at": ["K", "M"]}, "missing 'stiffness'"),
    ({"type": "spring", "at": ["K"], "stiffness": 1.0}, "'at' must be [P, Q]"),
    ({"type": "spring", "at": [[0, 0], "M"], "stiffness": 1.0}, "say on which links"),
    ({"type": "spring", "at": ["K", "M"], "stiffness": -1.0}, "must be >= 0"),
    ({"type": "spring", "at": ["K", "M"], "length": [0.2, 0.1], "force": [1, 2]}, "increasing"),
    ({"type": "spring", "at": ["K", "M"], "stiffness": 1.0, "length": [0.1, 0.2], "force": [1, 2]},
     "either a table"),
    ({"type": "damper", "joint": "Z", "damping": 1.0}, "not a revolute joint"),
    ({"type": "damper", "at": ["K", "M"], "damping": -1.0}, "'damping' must be >= 0"),
    ({"type": "torque", "links": ["1", "1"], "moment": 1.0}, "two different links"),
    ({"type": "torque", "links": ["1", "9"], "moment": 1.0}, "'9' in 'links'"),
    ({"type": "force", "link": "2", "force": [1, 0], "switch": "Z", "when": "forward"}, "neither a joint"),
    ({"type": "force", "link": "2", "force": [1, 0], "switch": "B", "when": "always"}, "needs 'when'"),
    ({"type": "force", "link": "2", "force": [1, 0], "switch": "B", "when": "forward",
      "switch_direction": 3.0}, "applies to a point"),
])
def test_bad_element_rows(row, words):
    with pytest.raises(mbplanar.ModelError) as info:
        read_loads(_fourbar([row]).mech)
    assert "loads[0]" in str(info.value) and words in str(info.value)


def test_angle_offset_and_centre_by_coordinates():
    d = tomllib.loads((MODELS / "fourbar.toml").read_text())
    plain = mbplanar.Engine(mbplanar.parse_model(d))
    d["links"][2].update(angle_offset=90.0, mass=1.0, centre=[0.31, 0.12])
    shifted = mbplanar.Engine(mbplanar.parse_model(d))
    phi = np.radians([0.0, 100.0])
    a, b = mbplanar.analyse(plain, phi), mbplanar.analyse(shifted, phi)
    k, j = a.link("3"), a.joint("B")
    assert np.allclose(b.angle[:, k] - a.angle[:, k], math.pi / 2, rtol=0, atol=1e-14)
    assert np.allclose(b.value[:, j] - a.value[:, j], math.pi / 2, rtol=0, atol=1e-14)
    assert shifted.mech.links["3"].centre == "3:centre"
    assert mbplanar.parse_model(d).points["3:centre"].at == (0.31, 0.12)
    assert shifted.mech.points["3:centre"].link == "3"  # the fourbar is a sketch: it moves with its link
    with pytest.raises(mbplanar.ModelError, match="angle_offset"):
        d["links"][2]["angle_offset"] = "right"
        mbplanar.parse_model(d)


def test_guide_loads_oppose_the_motion_running_backwards():
    """A resistance and a guide friction oppose the slider's real motion for either sense of the input."""
    d = tomllib.loads((MODELS / "slider_crank.toml").read_text())
    d["loads"] = [{"type": "resistance", "name": "r", "joint": "Bp", "force": 100.0},
                  {"type": "friction", "name": "f", "joint": "Bp", "force": 10.0}]
    engine = mbplanar.Engine(mbplanar.parse_model(d))
    for omega in (5.0, -5.0):
        motion = mbplanar.analyse(engine, np.radians(np.arange(5.0, 360.0, 20.0)), omega=omega)
        v = motion.v[:, motion.point("B"), 0]
        for value in evaluate_loads(engine, motion, gravity=False):
            assert np.all(value.force[:, 0] * v < 0)


def test_element_rows_follow_the_length_unit():
    """The same mechanism and elements written in mm (and N·mm) give the same reactions as in m."""
    def model(scale, moment_scale):
        d = tomllib.loads((MODELS / "fourbar.toml").read_text())
        for link in d["links"]:
            link["length"] *= scale
        for j in d["joints"]:
            j["at"] = [x * scale for x in j["at"]]
        d["points"][0]["offset"] *= scale
        d["links"][1].update(mass=3.0, inertia=0.03, centre="M")
        d["points"].append({"name": "K", "link": "0", "at": [0.1 * scale, 0.35 * scale]})
        d["loads"] = [{"type": "spring", "at": ["K", "M"], "stiffness": 2000.0, "free_length": 0.1 * scale,
                       "preload": 5.0},
                      {"type": "spring", "name": "t", "at": [[0.0, 0.3 * scale], "M"], "links": ["0", "2"],
                       "length": [0.0, 0.5 * scale], "force": [0.0, 100.0]},
                      {"type": "torque", "links": ["1", "3"], "moment": 2.0 * moment_scale},
                      {"type": "damper", "joint": "B", "damping": 0.5 * moment_scale}]
        if scale != 1:
            d.update(length_unit="mm", moment_unit="N*mm")
        return mbplanar.Engine(mbplanar.parse_model(d))
    phi = np.radians([20.0, 200.0])
    a, b = (mbplanar.kinetostatics(e, mbplanar.analyse(e, phi, omega=3.0)) for e in (model(1, 1), model(1000, 1000)))
    for j, r in a.reactions.items():
        assert np.allclose(b.reactions[j].fx, r.fx, rtol=1e-9, atol=1e-9)
    assert np.allclose(b.balancing["O"], a.balancing["O"], rtol=1e-9)
