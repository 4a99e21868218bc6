"""`mbplanar synth`: model files that mbplanar reads, JSON summaries, clear errors (exit 2)."""

import importlib.util
import json

import numpy as np
import pytest

import mbplanar
from mbplanar.cli import main


def _run(capsys, argv):
    code = main(argv)
    out = capsys.readouterr()
    return code, out.out, out.err


def test_seed001_writes_a_model_and_a_summary(tmp_path, capsys):
    model = tmp_path / "best.toml"
    code, out, _ = _run(capsys, ["synth", "seed001", "-o", str(model), "--json"])
    assert code == 0
    doc = json.loads(out)
    assert {"problem", "design", "errors", "max_error", "rms_error", "delta1", "delta2", "defects",
            "evaluations", "seconds", "model"} <= set(doc)
    assert doc["defects"]["ok"] and doc["max_error"] < 1e-9 and len(doc["errors"]) == 3
    engine = mbplanar.Engine(mbplanar.read_model(model))
    assert mbplanar.check(engine).full_turn


def test_function_from_csv_and_toml(tmp_path, capsys):
    csv = tmp_path / "pairs.csv"
    csv.write_text("phi_deg,psi_deg\n40,100\n70,115\n100,125\n", encoding="utf-8")
    code, out, err = _run(capsys, ["synth", "function", str(csv), "--json"])
    assert code == 0, err
    doc = json.loads(out)
    assert doc["max_error"] < 1e-7 and doc["defects"]["ok"]
    code, out, err = _run(capsys, ["synth", "function", "models/synthesis/function_reciprocal.toml", "--json"])
    assert code == 0, err
    assert json.loads(out)["structural_error"]["max_deg"] > 0


def test_motion_from_csv_with_curve(tmp_path, capsys):
    curve = tmp_path / "curve.csv"
    picture = ["--plot", str(tmp_path / "m.png")] if importlib.util.find_spec("matplotlib") else []
    code, out, err = _run(capsys, ["synth", "motion", "models/synthesis/motion_4poses.csv", "--json",
                                   "--curve", str(curve), "-o", str(tmp_path / "m.toml"), *picture])
    assert code == 0, err
    assert not picture or (tmp_path / "m.png").read_bytes()[:4] == b"\x89PNG"
    doc = json.loads(out)
    assert doc["max_error"] < 1e-9 and doc["max_angle_error_deg"] < 1e-7
    rows = np.loadtxt(curve, delimiter=",", skiprows=1)
    assert rows.shape[1] == 6 and len(rows) > 100


@pytest.mark.parametrize("argv, message", [
    (["synth", "motion", "one_pose.csv"], "2 to 5 poses"),
    (["synth", "function", "two.csv"], "at least 3"),
    (["synth", "function", "missing.toml"], "cannot read"),
    (["synth", "seed001", "far.toml"], "reach"),
    (["synth", "function", "bad.csv"], "row 2"),
    (["synth", "seed001", "typo.toml"], "unknown key(s) heigth"),
])
def test_bad_input_exits_2_with_a_message(tmp_path, capsys, monkeypatch, argv, message):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "one_pose.csv").write_text("0,0,0\n", encoding="utf-8")
    (tmp_path / "two.csv").write_text("10,20\n30,40\n", encoding="utf-8")
    (tmp_path / "bad.csv").write_text("10,20\n30,x\n", encoding="utf-8")
    (tmp_path / "typo.toml").write_text("[target]\nheigth = 0.3\n", encoding="utf-8")
    (tmp_path / "far.toml").write_text("[target]\nx_start = 10.0\ny0 = 0.0\n", encoding="utf-8")
    code, out, err = _run(capsys, argv)
    assert code == 2
    assert message in err and "Traceback" not in err


@pytest.mark.parametrize("argv", [["seed001", "--form", "b"], ["function", "models/synthesis/function_reciprocal.toml"],
                                  ["motion", "models/synthesis/motion_3poses.toml"]])
def test_pictures(tmp_path, capsys, argv):
    pytest.importorskip("matplotlib")
    picture = tmp_path / "p.png"
    code, _, err = _run(capsys, ["synth", *argv, "--plot", str(picture)])
    assert code == 0, err
    assert picture.read_bytes()[:4] == b"\x89PNG"
