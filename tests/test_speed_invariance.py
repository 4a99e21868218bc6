"""The optimised engine against independent closed forms (benchmarks/closed_forms.py) over a full turn:
positions, velocities and accelerations of the four-bar and the slider-crank, to 1e-9."""

import sys
from pathlib import Path

import numpy as np
import pytest

import mbplanar

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
import closed_forms as cf  # noqa: E402

PHI = np.radians(np.arange(0.0, 360.0, 0.5))


@pytest.mark.parametrize("name, closed, links", [("fourbar", cf.fourbar, ("1", "2", "3")),
                                                  ("slider_crank", cf.slider_crank, ("1", "2"))])
@pytest.mark.parametrize("omega, epsilon", [(1.0, 0.0), (3.0, -2.5)])
def test_engine_matches_closed_form_over_a_turn(name, closed, links, omega, epsilon):
    engine = mbplanar.Engine(mbplanar.read_model(ROOT / "models" / f"{name}.toml"))
    motion = mbplanar.analyse(engine, PHI, omega, epsilon)
    ref = closed(PHI, omega, epsilon)
    assert motion.success and len(motion.phi) == len(PHI)
    for k, link in enumerate(links, start=1):
        i = motion.link(link)
        # the engine's reference line of a link may point the other way: a constant offset (0 or π)
        offset = motion.angle[:, i] - ref[f"th{k}"]
        turn = np.angle(np.exp(1j * (offset - offset[0])))
        assert np.abs(turn).max() < 1e-9, link
        assert min(abs(np.angle(np.exp(1j * offset[0]))), abs(abs(np.angle(np.exp(1j * offset[0]))) - np.pi)) < 1e-9
        assert np.allclose(motion.w[:, i], ref[f"w{k}"], rtol=0, atol=1e-9), link
        assert np.allclose(motion.e[:, i], ref[f"e{k}"], rtol=0, atol=1e-9), link
    for point in ("A", "B"):
        p = motion.point(point)
        assert np.abs(motion.xy[:, p] - ref[point]).max() < 1e-9, point
        assert np.abs(motion.v[:, p] - ref[f"v{point}"]).max() < 1e-9, point
        assert np.abs(motion.a[:, p] - ref[f"a{point}"]).max() < 1e-9, point


def test_one_position_equals_the_same_position_in_a_sweep():
    engine = mbplanar.Engine(mbplanar.read_model(ROOT / "models" / "shaper.toml"))
    sweep = mbplanar.analyse(engine, PHI)
    one = mbplanar.analyse(engine, PHI[123:124])
    assert np.abs(one.xy[0] - sweep.xy[123]).max() < 1e-12
    assert np.abs(one.a[0] - sweep.a[123]).max() < 1e-9 * max(1.0, np.abs(sweep.a).max())
