"""Notebooks and pandas: DataFrames carry the CSV tables' columns and values, every result shows an inline SVG
diagram and a summary in Jupyter, the animation's player is inline, and the example notebook runs."""

from __future__ import annotations

import os
import sys
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

import mbplanar
import mbplanar.errors
from mbplanar.viz import Animation
from mbplanar.cli import main

ROOT = Path(__file__).resolve().parents[1]
LOADED = ROOT / "models" / "fourbar_loaded.toml"


@pytest.fixture(scope="module")
def engine():
    return mbplanar.Engine(mbplanar.read_model(LOADED))


@pytest.fixture(scope="module")
def motion(engine):
    return mbplanar.analyse(engine, np.radians(np.arange(0.0, 360.0, 30.0)), omega=10.0)


def csv_table(path):
    lines = Path(path).read_text().splitlines()
    return lines[0].split(","), np.array([[float(x) for x in ln.split(",")] for ln in lines[1:]])


def test_motion_frame_is_the_sweep_table(engine, motion, tmp_path):
    pytest.importorskip("pandas")
    out = tmp_path / "s.csv"
    assert main(["sweep", str(LOADED), "--step", "30", "--to", "330", "--omega", "10", "-o", str(out)]) == 0
    header, rows = csv_table(out)
    frame = motion.to_frame()
    forces = mbplanar.kinetostatics(engine, motion).to_frame()
    assert list(frame.columns) + list(forces.columns[1:]) == header     # the CSV: kinematics, then forces
    np.testing.assert_allclose(frame.to_numpy(), rows[:, :frame.shape[1]], rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(forces.to_numpy()[:, 1:], rows[:, frame.shape[1]:], rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(frame["phi[deg]"], np.arange(0.0, 360.0, 30.0), rtol=1e-14)


def test_dynamics_frame_is_the_dynamics_table(tmp_path):
    pytest.importorskip("pandas")
    shaper = ROOT / "models" / "shaper.toml"
    out = tmp_path / "d.csv"
    assert main(["dynamics", str(shaper), "--steps", "72", "-o", str(out)]) == 0
    header, rows = csv_table(out)
    dyn = mbplanar.machine_dynamics(mbplanar.Engine(mbplanar.read_model(shaper)), steps=72)
    frame = dyn.to_frame()
    assert list(frame.columns) == header
    np.testing.assert_allclose(frame.to_numpy(), rows, rtol=1e-9, atol=1e-9)


def test_a_frame_without_pandas_says_how_to_install_it(motion, monkeypatch):
    monkeypatch.setitem(sys.modules, "pandas", None)          # import pandas now fails
    with pytest.raises(mbplanar.MbplanarError, match=r"pip install mbplanar\[pandas\]"):
        motion.to_frame()


class _Shapes(HTMLParser):
    def __init__(self):
        super().__init__()
        self.tags, self.text = [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))

    def handle_data(self, data):
        self.text.append(data)


def parsed(page):
    p = _Shapes()
    p.feed(page)
    return p


def test_every_result_shows_a_diagram_where_the_solver_puts_the_joints(engine, motion):
    pin_b = motion.xy[0, motion.point("B")]
    shown = {"mechanism": engine.mech, "engine": engine, "motion": motion,
             "kinetostatics": mbplanar.kinetostatics(engine, motion)}
    for what, obj in shown.items():
        page = parsed(obj._repr_html_())
        assert [t for t, _ in page.tags].count("svg") == 1, what
        circles = [(float(a["cx"]), float(a["cy"])) for t, a in page.tags if t == "circle" and "cx" in a]
        if what in ("motion", "kinetostatics"):           # at the first position of the batch
            assert min(np.hypot(x - pin_b[0], y - pin_b[1]) for x, y in circles) < 1e-5, what
        assert "script" not in [t for t, _ in page.tags], what   # a still picture
        assert "http" not in obj._repr_html_()
    text = "".join(parsed(engine._repr_html_()).text)
    assert "I(0,1) → II(2,3)" in text and "DOF" in text
    forces_text = "".join(parsed(shown["kinetostatics"]._repr_html_()).text)
    assert "virtual-power residual" in forces_text and "balancing at O" in forces_text


def test_dynamics_and_check_show_their_results():
    engine = mbplanar.Engine(mbplanar.read_model(ROOT / "models" / "shaper.toml"))
    text = "".join(parsed(mbplanar.machine_dynamics(engine, steps=360)._repr_html_()).text)
    assert "first-group inertia J_I" in text and "147.1" in text
    text = "".join(parsed(mbplanar.check(engine)._repr_html_()).text)
    assert "full turn" in text and "yes" in text


def test_a_mechanism_that_cannot_be_assembled_says_why():
    mech = mbplanar.parse_model(LOADED.read_text().replace("length = 0.30, mass", "length = 0.01, mass"))
    with pytest.warns(mbplanar.errors.ModelWarning, match="length A-B = 0.01 m"):   # the sketch's warning
        page = mech._repr_html_()
    assert "cannot be assembled" in page and "<svg" not in page


def test_the_animation_plays_inline_with_its_player(engine):
    page = parsed(Animation(engine, frames=9)._repr_html_())
    tags = [t for t, _ in page.tags]
    assert tags.count("svg") == 1 and "button" in tags and "output" in tags and tags.count("script") == 2
    slider = next(a for t, a in page.tags if t == "input")
    assert slider["type"] == "range" and slider["max"] == "8"
    other = parsed(Animation(engine, frames=9)._repr_html_())
    ids = {a["id"] for t, a in page.tags + other.tags if t == "svg"}
    assert len(ids) == 2                                   # two animations in one notebook do not clash


def test_the_example_notebook_runs(monkeypatch):
    nbformat = pytest.importorskip("nbformat", reason="the notebook test needs nbformat (the [test] extra)")
    nbclient = pytest.importorskip("nbclient", reason="the notebook test needs nbclient (the [test] extra)")
    pytest.importorskip("ipykernel", reason="the notebook test needs ipykernel (the [test] extra)")
    path = ROOT / "docs" / "example.ipynb"
    nb = nbformat.read(path, as_version=4)
    assert all(not c.get("outputs") and c.get("execution_count") is None
               for c in nb.cells if c.cell_type == "code")           # stored without outputs
    monkeypatch.setenv("PYTHONPATH", str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))  # the kernel
    nbclient.NotebookClient(nb, timeout=120, kernel_name="python3",
                            resources={"metadata": {"path": str(path.parent)}}).execute()
    html = [o["data"]["text/html"] for c in nb.cells if c.cell_type == "code" for o in c.outputs
            if "data" in o and "text/html" in o["data"]]
    assert len(html) == 5                       # the engine, two DataFrames, the forces, the animation
    assert "<svg" in html[0] and "I(0,1) → II(2,3)" in html[0]
    assert "B.vx[m/s]" in html[1] and "O.balancing[N*m]" in html[2]
    assert "<svg" in html[3] and "<output>" in html[4] and "<button" in html[4]
    errors = [o for c in nb.cells for o in c.get("outputs", []) if o.get("output_type") == "error"]
    assert not errors
