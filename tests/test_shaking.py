"""Shaking force and moment on the frame, both ways; force balancing by counterweights: the four-bar's
full balance and the slider-crank's partial balance against their closed forms."""

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

import mbplanar
from mbplanar.forces._shaking import balance, inertia_shaking_force, shaking, shaking_from_loads

MODELS = Path(__file__).resolve().parent.parent / "models"


def _heavy_fourbar():
    d = tomllib.loads((MODELS / "fourbar.toml").read_text())
    d["links"][0].update(mass=1.0, inertia=0.002, centre="S1")
    d["links"][1].update(mass=3.0, inertia=0.03, centre="M")
    d["links"][2].update(mass=2.0, inertia=0.02, centre="S3")
    d["points"] += [{"name": "S1", "link": "1", "along": ["O", "A"], "fraction": 0.4},
                    {"name": "S3", "link": "3", "along": ["C", "B"], "fraction": 0.5, "offset": 0.02}]
    return mbplanar.Engine(mbplanar.parse_model(d, source="fourbar"))


@pytest.mark.parametrize("name", ["shaper", "six_bar_press", "squeezer"])
def test_shaking_both_ways(name, engine_of):
    """From the frame's pairs, drive and anchored loads, and from d'Alembert's sums of the loads."""
    engine = engine_of(name)
    phi = engine.phi_drawn[0] + np.linspace(0.0, 2 * math.pi, 13)
    motion = mbplanar.analyse(engine, phi, omega=5.0, epsilon=-2.0)
    ks = mbplanar.kinetostatics(engine, motion)
    for about in ((0.0, 0.0), (0.3, -0.2)):
        a, b = shaking(engine, ks, about), shaking_from_loads(ks, about)
        scale = max(1.0, np.max(a.magnitude))
        assert np.max(np.abs(a.force - b.force)) <= 1e-11 * scale
        assert np.max(np.abs(a.moment - b.moment)) <= 1e-11 * scale * max(1.0, engine.size)
        assert np.max(a.magnitude) > 0


def test_fourbar_full_force_balance():
    """Counterweights on the crank and the rocker cancel the shaking force: the balanced four-bar's
    shaking force, from its reactions, is at most 1e-9 of the unbalanced one's."""
    engine = _heavy_fourbar()
    bal = balance(engine, ["1", "3"])
    assert bal.rms_after <= 1e-12 * bal.rms_before
    phi = np.radians(np.arange(0.0, 360.0, 7.0))
    before = mbplanar.analyse(engine, phi, omega=12.0, epsilon=4.0)
    balanced = mbplanar.Engine(bal.mechanism)
    after = mbplanar.analyse(balanced, phi, omega=12.0, epsilon=4.0)
    f0 = shaking(engine, mbplanar.kinetostatics(engine, before)).magnitude
    f1 = shaking(balanced, mbplanar.kinetostatics(balanced, after)).magnitude
    assert np.max(f1) <= 1e-9 * np.max(f0)
    assert np.max(np.abs(inertia_shaking_force(balanced, after))) <= 1e-9 * np.max(f0)
    # the counterweights are real masses on the far side of the pivots
    assert all(cw.mass > 0 for cw in bal.counterweights)


def test_slider_crank_partial_balance():
    """A crank counterweight alone minimises the RMS of a central slider-crank's shaking force with the
    first moment m₁·r_S1 + m₃·r/2, opposite the crank (the rotating mass and half the reciprocating one;
    the slider's acceleration has only even harmonics besides the first, orthogonal to the
    counterweight's)."""
    d = tomllib.loads((MODELS / "slider_crank.toml").read_text())
    d["links"][0].update(mass=1.5, inertia=0.003, centre="S1")
    d["links"][2].update(mass=4.0, centre="B")
    d["points"] = [{"name": "S1", "link": "1", "along": ["O", "A"], "fraction": 0.3}]
    engine = mbplanar.Engine(mbplanar.parse_model(d, source="slider_crank"))
    bal = balance(engine, ["1"], radius=0.05, steps=720)
    (cw,) = bal.counterweights
    assert cw.first_moment == pytest.approx(1.5 * 0.03 + 4.0 * 0.1 / 2, rel=1e-10)
    assert cw.angle_deg == pytest.approx(180.0, abs=1e-8)
    assert cw.mass == pytest.approx(cw.first_moment / 0.05, rel=1e-12)
    assert math.dist(cw.at, (0.0, 0.0)) == pytest.approx(0.05, rel=1e-12)
    assert bal.rms_after < bal.rms_before
    balanced = mbplanar.Engine(bal.mechanism)
    f = inertia_shaking_force(balanced, mbplanar.analyse(balanced, bal.phi, omega=1.0, epsilon=0.0))
    assert math.sqrt(np.mean(np.sum(f * f, axis=1))) == pytest.approx(bal.rms_after, rel=1e-9)


def test_balance_rejects_bad_links():
    engine = _heavy_fourbar()
    with pytest.raises(mbplanar.ModelError, match="not a moving link"):
        balance(engine, ["0"])


def test_balance_command(tmp_path, capsys):
    import json

    from mbplanar.cli import main
    text = (MODELS / "fourbar.toml").read_text()
    for name, extra in (("1", "mass = 1.0, inertia = 0.002, centre = [0.03, 0.04]"),
                        ("3", "mass = 2.0, inertia = 0.02, centre = [0.31, 0.1]")):
        text = text.replace(f'{{ name = "{name}", length', f'{{ name = "{name}", {extra}, length')
    model = tmp_path / "heavy.toml"
    model.write_text(text.replace('{ name = "2", length = 0.30 }',
                                  '{ name = "2", length = 0.30, mass = 3.0, inertia = 0.03, centre = "M" }'))
    assert main(["balance", str(model), "--links", "1,3", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["after"]["shaking_force_max"] <= 1e-9 * doc["before"]["shaking_force_max"]
    assert [cw["link"] for cw in doc["counterweights"]] == ["1", "3"]
    assert set(doc["before"]["reaction_max"]) == {"O", "A", "B", "C"}
    assert main(["balance", str(model), "--links", "1", "--radius", "-1"]) == 2
