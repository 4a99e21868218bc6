"""Friction in the pairs (`mbplanar.friction`): μ = 0 changes nothing; the slider-crank with friction in
the slider only against the closed form; a crank's friction circle; the power the friction takes is what
the drive gives more; validation."""

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

import mbplanar
from mbplanar.forces import FrictionSpec, PairFriction, friction_kinetostatics, read_friction

MODELS = Path(__file__).resolve().parent.parent / "models"


def _engine(name, **extra):
    data = tomllib.loads((MODELS / f"{name}.toml").read_text())
    data.update(extra)
    return mbplanar.Engine(mbplanar.parse_model(data, source=f"{name}.toml"))


@pytest.mark.parametrize("name", ["shaper", "six_bar_press", "crank_slider_rocker"])
def test_zero_friction_changes_nothing(name):
    """Every pair listed with μ = 0 (the iteration runs, the friction loads are zero): the reactions and
    the balancing loads equal the plain kinetostatics to rounding."""
    engine = _engine(name)
    motion = mbplanar.analyse(engine, np.radians(np.arange(3.0, 360.0, 30.0)), omega=7.0, epsilon=2.0)
    plain = mbplanar.kinetostatics(engine, motion)
    spec = FrictionSpec(tuple(PairFriction(j, 0.0, 0.01, 0.05) for j in engine.mech.joints))
    fr = friction_kinetostatics(engine, motion, spec)
    assert fr.iterations == 1 and fr.converged
    for j, r in plain.reactions.items():
        scale = 1e-12 * max(1.0, np.max(np.hypot(r.fx, r.fy)))
        got = fr.kinetostatics.reactions[j]
        assert np.max(np.abs(got.fx - r.fx)) <= scale and np.max(np.abs(got.fy - r.fy)) <= scale
        assert np.max(np.abs(got.moment - r.moment)) <= scale * engine.size
    for j, q in plain.balancing.items():
        assert np.max(np.abs(fr.kinetostatics.balancing[j] - q)) <= 1e-12 * max(1.0, np.max(np.abs(q)))
    assert np.all(fr.losses == 0)


def test_slider_crank_closed_form():
    """Massless slider-crank, a constant resistance P against the slider, friction μ in the slider's
    guide only. The rod pushes the slider along e = (B − A)/l with T, the guide with N = −T·e_y and the
    friction μ·|N| against the sliding (sign s of the slider's velocity): T·e_x = s·(P + μ·|T·e_y|), so
    T = s·P / (e_x − sign(e_x)·μ·|e_y|) and the balancing moment M = T·(A × e); the efficiency is
    1 − μ·|tan β| (β the rod's angle to the guide)."""
    engine = _engine("slider_crank", loads=[{"type": "resistance", "joint": "Bp", "force": 1000.0}])
    motion = mbplanar.analyse(engine, np.radians(np.arange(5.0, 360.0, 10.0)), omega=10.0)
    mu, P = 0.2, 1000.0
    fr = friction_kinetostatics(engine, motion, FrictionSpec((PairFriction("Bp", mu),)))
    A, B = motion.xy[:, motion.point("A")], motion.xy[:, motion.point("B")]
    e = (B - A) / np.hypot(*(B - A).T)[:, None]
    s = np.sign(motion.v[:, motion.point("B"), 0])
    T = s * P / (e[:, 0] - np.sign(e[:, 0]) * mu * np.abs(e[:, 1]))
    M = T * (A[:, 0] * e[:, 1] - A[:, 1] * e[:, 0])
    assert fr.converged and fr.iterations < 30
    assert np.max(np.abs(fr.kinetostatics.balancing["O"] - M)) <= 1e-11 * np.max(np.abs(M))
    assert np.allclose(fr.efficiency, 1 - mu * np.abs(e[:, 1] / e[:, 0]), rtol=1e-11, atol=0)
    assert 0.9 < fr.cycle_efficiency < 1
    assert np.max(fr.kinetostatics.virtual_power_residual) < 1e-10


def test_friction_circle_of_a_crank():
    """A massless crank with a force F at its tip: the pin's reaction is −F, so the drive needs the
    load's moment plus μ·r·|F| in the sense of rotation."""
    m = mbplanar.parse_model({"links": [{"name": "1"}], "joints": [{"name": "O", "type": "R", "links": ["0", "1"],
                                                                    "at": [0.0, 0.0]}],
                              "points": [{"name": "A", "link": "1", "at": [0.2, 0.0]}], "input": {"joint": "O"},
                              "loads": [{"type": "force", "link": "1", "at": "A", "force": [30.0, -40.0]}]})
    engine = mbplanar.Engine(m)
    phi = np.radians([10.0, 100.0, 250.0])
    mu, r = 0.15, 0.01
    for omega in (3.0, -3.0):
        motion = mbplanar.analyse(engine, phi, omega=omega)
        fr = friction_kinetostatics(engine, motion, FrictionSpec((PairFriction("O", mu, r),)))
        A = motion.xy[:, motion.point("A")]
        load_moment = A[:, 0] * -40.0 - A[:, 1] * 30.0
        expected = -load_moment + math.copysign(mu * r * 50.0, omega)
        assert np.allclose(fr.kinetostatics.balancing["O"], expected, rtol=1e-13, atol=1e-13)
        assert np.allclose(fr.losses, -mu * r * 50.0 * abs(omega), rtol=1e-13)


def test_losses_are_what_the_drive_gives_more():
    """The drive's power with friction minus without it is the power the friction takes."""
    engine = _engine("six_bar_press")
    motion = mbplanar.analyse(engine, np.radians(np.arange(0.0, 360.0, 15.0)))
    spec = FrictionSpec(tuple(PairFriction(j, 0.1, 0.02 if engine.mech.joints[j].kind == "R" else 0.0, 0.2)
                              for j in engine.mech.joints))
    fr = friction_kinetostatics(engine, motion, spec)
    rate = motion.rate[:, motion.joint("O")]  # the crank's rate (the press turns clockwise)
    extra = (fr.kinetostatics.balancing["O"] - fr.ideal.balancing["O"]) * rate
    assert fr.converged
    assert np.all(fr.losses <= 0)
    assert np.allclose(extra, -fr.losses, rtol=1e-9, atol=1e-9 * np.max(np.abs(fr.losses)))
    assert np.max(fr.kinetostatics.virtual_power_residual) < 1e-10


def test_friction_section_is_validated():
    with pytest.raises(mbplanar.ModelError, match="pin_radius"):
        read_friction(_engine("fourbar", friction={"mu": 0.1}).mech)
    with pytest.raises(mbplanar.ModelError, match="'Z' is not a joint"):
        read_friction(_engine("fourbar", friction={"pairs": [{"joint": "Z", "mu": 0.1}]}).mech)
    with pytest.raises(mbplanar.ModelError, match="unknown key"):
        read_friction(_engine("fourbar", friction={"muu": 0.1}).mech)
    spec = read_friction(_engine("slider_crank", friction={"mu": 0.1, "pin_radius": 0.005,
                                                           "pairs": [{"joint": "O", "mu": 0.0}]}).mech)
    assert [p.joint for p in spec.pairs] == ["A", "B", "Bp"]


def test_forces_command_reports_friction(capsys):
    from mbplanar.cli import main
    assert main(["forces", str(MODELS / "slider_crank.toml"), "--at", "30", "--mu", "0.0"]) == 0
    assert "friction: 0 iterations" in capsys.readouterr().out
