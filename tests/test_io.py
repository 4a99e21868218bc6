"""Results as data (`mbplanar.io`): `document` and `table` pick the builder by the result's type, and the
command line prints exactly what they build."""

import csv
import io
import json
import pathlib

import numpy as np
import pytest

import mbplanar
from mbplanar.cli import main
from mbplanar.io import (document, forces_columns, info_document, partials_document, solve_document, sweep_table,
                         table)

MODELS = pathlib.Path(__file__).resolve().parent.parent / "models"


@pytest.fixture(scope="module")
def shaper():
    return mbplanar.Engine(mbplanar.read_model(MODELS / "shaper.toml"))


def test_document_of_an_engine_is_the_info_document(shaper, capsys):
    assert document(shaper) == info_document(shaper)
    assert main(["info", str(MODELS / "shaper.toml"), "--json"]) == 0
    assert json.loads(capsys.readouterr().out) == json.loads(json.dumps(document(shaper, units="si")))


def test_document_of_a_motion_is_what_solve_prints(shaper, capsys):
    inp = shaper.inputs[0]
    motion = mbplanar.analyse(shaper, [inp.to_si(30.0)], omega=1.0, epsilon=0.0)  # the CLI's default
    doc = document(motion, values=[30.0])
    assert doc == solve_document(shaper, motion, 0, [30.0])
    assert main(["solve", str(MODELS / "shaper.toml"), "--at", "30", "--json"]) == 0
    expected = dict(document(motion, values=[30.0], units="si"), partials=partials_document(shaper, motion.phi))
    assert json.loads(capsys.readouterr().out) == json.loads(json.dumps(expected))
    assert "units" in document(motion, units="model") and "units" not in doc


def test_table_of_a_motion_and_of_its_forces_are_the_sweep_columns(shaper, tmp_path):
    inp = shaper.inputs[0]
    values = np.linspace(0.0, 360.0, 13)
    motion = mbplanar.analyse(shaper, inp.to_si(values), omega=1.0, epsilon=0.0)  # the CLI's default
    header, cols = table(motion)
    assert (header, cols.tolist()) == (sweep_table(shaper, motion, "deg")[0], sweep_table(shaper, motion, "deg")[1].tolist())
    result = mbplanar.kinetostatics(shaper, motion)
    f_header, f_cols = table(result)
    assert f_header == forces_columns(shaper, result)[0] and f_header[-1] == "virtual_power_residual"
    assert f_cols.shape == (len(motion.phi), len(f_header))
    out = tmp_path / "sweep.csv"
    assert main(["sweep", str(MODELS / "shaper.toml"), "--steps", "12", "--forces", "yes", "-o", str(out)]) == 0
    with open(out, newline="") as f:
        written = list(csv.reader(f))
    assert written[0] == header + f_header and len(written) == 14
    np.testing.assert_allclose([float(x) for x in written[5][:len(header)]], cols[4], rtol=1e-11, atol=1e-12)


def test_results_without_a_builder_are_refused(shaper):
    with pytest.raises(TypeError, match="no document for a str"):
        document("motion")
    with pytest.raises(TypeError, match="no table for a Engine"):
        table(shaper)


def test_true_motion_lives_beside_machine_dynamics():
    from mbplanar.forces import machine_dynamics, true_motion
    assert true_motion.__module__ == machine_dynamics.__module__
    assert io  # (the standard library's io is not shadowed by mbplanar.io)


def test_every_builder_is_found_by_the_home_of_its_public_class():
    """The builders are keyed by "module:name" (io imports no result type): each key names the class the
    public API exports, so a class moved to another module fails here, not silently in `document`."""
    import importlib

    from mbplanar.io import _export
    public = {"Engine": mbplanar.Engine, "Motion": mbplanar.Motion, "Position": mbplanar.Position,
              "Kinetostatics": mbplanar.Kinetostatics, "Dynamics": mbplanar.Dynamics,
              "CheckReport": mbplanar.CheckReport, "Accuracy": mbplanar.accuracy.Accuracy}
    homes = set(_export.DOCUMENTS) | set(_export.TABLES) | {_export.POSITION}
    assert {home.split(":")[1] for home in homes} == set(public)
    for home in homes:
        module, name = home.split(":")
        assert getattr(importlib.import_module(module), name) is public[name], home


def test_document_and_table_of_every_result_type(shaper):
    """Each type reaches its own builder (a subclass its parent's), with the builder's options."""
    inp = shaper.inputs[0]
    position = mbplanar.position(shaper, inp.to_si(30.0))
    assert document(position, values=[30.0]) == solve_document(shaper, position, 0, [30.0])
    motion = mbplanar.analyse(shaper, inp.to_si(np.array([30.0, 60.0])))

    class Recorded(type(motion)):
        pass
    assert document(Recorded(**vars(motion)), row=1) == solve_document(shaper, motion, 1)
    forces = mbplanar.kinetostatics(shaper, motion)
    assert document(forces, row=1)["balancing"] == {n: float(q[1]) for n, q in forces.balancing.items()}
    header, cols = table(forces, units="model")
    assert header == forces_columns(shaper, forces)[0] and np.array_equal(cols, forces_columns(shaper, forces)[1])
    dyn = mbplanar.machine_dynamics(shaper, steps=72, simulate_motion=False)
    assert document(dyn, engine=shaper)["steps"] == 72
    header, cols = table(dyn)
    assert cols.shape == (73, len(header))
    with pytest.raises(TypeError, match="needs its engine"):
        document(dyn)
    report = mbplanar.check(shaper, samples=72)
    assert document(report) == json.loads(json.dumps(document(report)))
    assert "units" in document(report, engine=shaper, units="model")


def test_io_imports_no_result_type():
    """`mbplanar.io` loads no layer below it at import: the command that prints one kind of result loads
    only that result's code (`mbplanar solve` neither the forces nor the analysis)."""
    import os
    import subprocess
    import sys
    probe = "import json, sys, mbplanar.io\nprint(json.dumps(sorted(sys.modules)))"
    out = subprocess.run([sys.executable, "-c", probe], cwd=MODELS.parent, capture_output=True, text=True, check=True,
                         env=dict(os.environ, PYTHONPATH=str(MODELS.parent)))
    loaded = {m.split(".")[1] for m in json.loads(out.stdout) if m.startswith("mbplanar.") and "." in m}
    assert loaded <= {"io", "model", "errors", "_lazy"}, loaded
