"""Pictures of the force elements and of the forces: springs and dampers on the diagram, applied loads,
the shaking hodograph, the efficiency, the simulated motion."""

import tomllib
from pathlib import Path

import numpy as np
import pytest

import mbplanar

pytest.importorskip("matplotlib")
from mbplanar.viz import _plotting as plotting  # noqa: E402
from mbplanar.viz._elementplots import spring_path  # noqa: E402

MODELS = Path(__file__).resolve().parent.parent / "models"


@pytest.fixture(autouse=True)
def _close():
    yield
    import matplotlib.pyplot as plt
    plt.close("all")


def _gids(fig, prefix):
    return [a for ax in fig.axes for a in ax.get_children() if str(a.get_gid()).startswith(prefix)]


def test_spring_path_joins_its_ends():
    path = spring_path((0.0, 0.0), (3.0, 4.0), turns=5, width=0.1)
    assert np.allclose(path[0], (0, 0)) and np.allclose(path[-1], (3, 4))
    d = np.array([3.0, 4.0]) / 5.0
    offsets = path[:, 0] * -d[1] + path[:, 1] * d[0]  # across the axis
    assert np.isclose(np.max(np.abs(offsets)), 0.5) and len(path) == 2 * 5 + 3


def test_diagram_draws_springs_dampers_and_loads():
    data = tomllib.loads((MODELS / "shaper.toml").read_text())
    data["loads"] = data.get("loads", []) + [
        {"type": "damper", "name": "dash", "at": [[0.0, 0.0], "S5"], "links": ["0", "5"], "damping": 10.0},
        {"type": "torque", "name": "tq", "links": ["1", "3"], "moment": 5.0}]
    data = mbplanar.parse_model(data)
    engine = mbplanar.Engine(data)
    fig = plotting.make_figure(engine, "diagram", **plotting.show_options("loads"))
    assert _gids(fig, "damper:dash") and _gids(fig, "torque:tq") and _gids(fig, "load:cutting")
    squeezer = mbplanar.Engine(mbplanar.read_model(MODELS / "squeezer.toml"))
    fig = plotting.make_figure(squeezer, "diagram")
    (line,) = [a for a in _gids(fig, "spring:spring") if hasattr(a, "get_xydata")]
    xy = line.get_xydata()
    assert np.allclose(xy[0], (0.014, 0.072), atol=1e-12)  # from C on the frame ...
    assert len(xy) > 10  # ... as a zigzag


def test_shaking_and_efficiency_figures(tmp_path):
    from mbplanar.cli import main
    engine = mbplanar.Engine(mbplanar.read_model(MODELS / "six_bar_press.toml"))
    fig = plotting.make_figure(engine, "shaking", count=37)
    (hod,) = [a for a in _gids(fig, "hodograph:shaking")]
    assert len(hod.get_xydata()) == 37
    crank = tomllib.loads((MODELS / "slider_crank.toml").read_text())
    crank.update(loads=[{"type": "resistance", "joint": "Bp", "force": 100.0}],
                 friction={"pairs": [{"joint": "Bp", "mu": 0.2}]})
    crank = mbplanar.parse_model(crank)
    fig = plotting.make_figure(mbplanar.Engine(crank), "efficiency", count=37)
    (eta,) = _gids(fig, "efficiency")
    y = eta.get_ydata()
    y = y[np.isfinite(y)]  # not at the dead points, where the drive gives no power
    assert len(y) >= 30 and np.all((y > 0.8) & (y <= 1.0)) and np.min(y) < 0.99
    # a model without [friction] has no efficiency to draw: exit 2, no picture (issue 27)
    assert main(["plot", str(MODELS / "slider_crank.toml"), "efficiency", "-o", str(tmp_path / "e.png")]) == 2
    assert not (tmp_path / "e.png").exists()
