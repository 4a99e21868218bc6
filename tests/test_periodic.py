"""Input values far from the drawn pose: a full-turn branch is periodic, so far values are solved one
period back and moved on by whole turns (bounded work); a rocker stops at its limit; values beyond the
floating-point resolution of a turn are refused."""

import math
from pathlib import Path

import numpy as np
import pytest

import mbplanar
from mbplanar.cli import main
from mbplanar.errors import ModelError

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data"


def _engine(path):
    return mbplanar.Engine(mbplanar.read_model(path))


@pytest.mark.parametrize("model", ["fourbar.toml", "shaper.toml", "six_bar_press.toml"])
def test_far_values_equal_near_ones_and_the_walk_stays_short(model):
    engine = _engine(ROOT / "models" / model)
    x = np.radians([10.0, 123.0, 250.0])
    turns = 1000
    far = mbplanar.analyse(engine, x + 2 * math.pi * turns)
    near = mbplanar.analyse(mbplanar.Engine(engine.mech), x)
    assert far.success and near.success
    assert np.abs(far.xy - near.xy).max() < 1e-11 * engine.size
    assert np.abs(far.vq - near.vq).max() < 1e-9 * engine.size
    assert np.abs(far.aq - near.aq).max() < 1e-8 * engine.size
    # link angles stay on the unwrapped branch: whole turns apart, as the walk would give them
    d = (far.angle - near.angle) / (2 * math.pi)
    assert np.abs(d - np.round(d)).max() < 1e-10
    crank = far.link(engine.mech.joints[engine.inputs[0].joint].other(engine.mech.ground))
    assert np.allclose(np.abs(d[:, crank]), turns)  # (a clockwise input turns the other way)
    # bounded work: the atlas spans at most the walk's reach, not a thousand turns
    grid = engine.atlas().arrays()[0]
    assert grid[-1] - grid[0] <= 2 * 2 * math.pi * 2 + 1e-9
    assert engine.period() == pytest.approx(2 * math.pi)


def test_rocker_refuses_far_values_at_its_limit():
    engine = _engine(DATA / "double_rocker.toml")
    m = mbplanar.analyse(engine, [1e6])
    assert not m.success and m.limits and m.limits[0].direction == 1
    assert engine.period() is None
    lo, hi = engine.reach()
    assert math.degrees(hi) == pytest.approx(91.79078466, abs=1e-7)
    assert math.degrees(lo) == pytest.approx(-91.79078466, abs=1e-7)


def test_values_beyond_the_float_resolution_of_a_turn_are_refused():
    engine = _engine(ROOT / "models" / "fourbar.toml")
    with pytest.raises(ModelError, match="position within a turn is lost"):
        mbplanar.analyse(engine, [1e20], rates=False)


def test_cli_reduces_degrees_exactly(capsys):
    """1e20 is exactly representable and 10^20 mod 360 = 280: the answer is the one at 280°."""
    model = str(ROOT / "models" / "fourbar.toml")
    assert main(["solve", model, "--at", "1e20", "--json"]) == 0
    captured = capsys.readouterr()
    assert "equivalent 280 deg" in captured.err
    import json
    far = json.loads(captured.out)
    assert main(["solve", model, "--at", "280", "--json"]) == 0
    near = json.loads(capsys.readouterr().out)
    assert far["input"]["value"] == 1e20
    for name, p in near["points"].items():
        for k, v in p.items():
            assert far["points"][name][k] == pytest.approx(v, abs=1e-14)


def test_cli_rocker_far_value_names_the_range(capsys):
    assert main(["solve", str(DATA / "double_rocker.toml"), "--at", "1e20"]) == 1
    err = capsys.readouterr().err
    assert "moves within -91.79078447 … 91.79078447 deg" in err and "Traceback" not in err
