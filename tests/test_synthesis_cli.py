"""`mbplanar synth`: model files that mbplanar reads, JSON summaries, clear errors (exit 2)."""

import importlib.util
import json
from pathlib import Path

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


def _targets_csv(tmp_path, timed=False):
    m = mbplanar.analyse(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), np.radians(np.arange(0, 360, 40.0)))
    rows = m.xy[:, m.point("M")]
    path = tmp_path / "targets.csv"
    lines = ["x,y,phi_deg" if timed else "x,y"]
    lines += [f"{float(x)!r},{float(y)!r}" + (f",{40.0 * k}" if timed else "") for k, (x, y) in enumerate(rows)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path, rows


def test_path_writes_a_model_carrying_its_summary(tmp_path, capsys):
    targets, rows = _targets_csv(tmp_path)
    model = tmp_path / "best.toml"
    code, out, err = _run(capsys, ["synth", "path", str(targets), "--starts", "1", "--shapes", "1024", "--keep", "2",
                                   "--seed", "2", "--min-transmission", "20", "-o", str(model), "--json"])
    assert code == 0, err
    doc = json.loads(out)
    assert {"design", "errors", "rms_error", "max_error", "defects", "evaluations", "seconds", "seed", "starts",
            "constraints", "timed", "point"} <= set(doc)
    assert doc["defects"]["ok"] and doc["seed"] == 2 and doc["constraints"]["transmission_deg"] >= 20.0
    mech = mbplanar.read_model(model)                 # an ordinary model, with its [synthesis] table
    s = mech.extras["synthesis"]
    assert s["rms_error"] == doc["rms_error"] and s["errors"] == doc["errors"]
    engine = mbplanar.Engine(mech)
    m = mbplanar.analyse(engine, np.radians(doc["target_phi_deg"]))
    assert np.all(np.hypot(*(m.xy[:, m.point("P")] - rows).T) >= np.array(doc["errors"]) - 1e-12)
    if importlib.util.find_spec("matplotlib"):
        from mbplanar.synthesis.report import register, report_section
        from mbplanar.viz import _report
        register()
        keys = list(_report.SECTIONS)
        assert keys.index("synthesis") == keys.index("model") + 1
        cycle = mbplanar.analyse(engine, np.radians(np.arange(0.0, 360.0, 10.0)))
        body = report_section(engine, _report.ReportContext(engine, cycle, cycle, dpi=40))
        assert "target points against the analysed path" in body and f"{doc['rms_error']:.6g}" in body
        assert report_section(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), None) is None


def test_path_on_a_models_parameters_from_toml(tmp_path, capsys):
    from mbplanar.study.run import load_template
    engine = mbplanar.Engine(mbplanar.parse_model(load_template("models/fourbar_design.toml").bind({"m": 0.3, "h": 0.08})))
    m = mbplanar.analyse(engine, engine.phi_drawn[0] + np.radians(np.arange(0, 360, 36.0)))
    spec = tmp_path / "spec.toml"
    spec.write_text(f"targets = {m.xy[:, m.point('M')].tolist()}\n[model]\n"
                    f'file = "{Path.cwd() / "models/fourbar_design.toml"}"\npoint = "M"\n'
                    "[parameters]\nm = [0.0, 1.0]\nh = [-0.1, 0.1]\n[search]\nstarts = 1\ngenerations = 10\n"
                    "popsize = 6\n", encoding="utf-8")
    code, out, err = _run(capsys, ["synth", "path", str(spec), "--json", "--progress", "-o", str(tmp_path / "o.toml")])
    assert code == 0, err
    doc = json.loads(out)
    assert abs(doc["design"]["m"] - 0.3) < 1e-9 and abs(doc["design"]["h"] - 0.08) < 1e-9 and doc["max_error"] < 1e-9
    assert doc["point"] == "M" and doc["defects"]["ok"]
    assert "1/1" in err or "100%" in err                      # the progress bar, asked for
    written = load_template(str(tmp_path / "o.toml"))         # the model with its new parameter values
    assert written.defaults()["m"] == doc["design"]["m"]
    code, _, err = _run(capsys, ["synth", "path", str(spec), "--model", "models/fourbar.toml"])
    assert code == 2 and "mb" in err and "parameter" in err


@pytest.mark.parametrize("argv, message", [
    (["synth", "path", "t.csv", "--vary", "a=0:1"], "need a model"),
    (["synth", "path", "t.csv", "--pivot", "A0=1,2,3"], "NAME=XMIN,YMIN,XMAX,YMAX"),
    (["synth", "path", "t.csv", "--min-transmission", "120"], "min_transmission_deg"),
    (["synth", "path", "t.csv", "--starts", "0"], "starts must be a whole number"),
    (["synth", "path", "spec.toml"], "unknown key(s) target"),
    (["synth", "path", "t.csv", "--model", "m.toml", "--point", "M", "--vary", "a=1"], "NAME=LOWER:UPPER"),
])
def test_path_bad_input_exits_2(tmp_path, capsys, monkeypatch, argv, message):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "t.csv").write_text("0,0\n1,0\n1,1\n0,1\n0.5,1.5\n", encoding="utf-8")
    (tmp_path / "spec.toml").write_text("target = [[0, 0]]\n", encoding="utf-8")
    code, _, err = _run(capsys, argv)
    assert code == 2
    assert message in err and "Traceback" not in err


FAST = ["--starts", "1", "--shapes", "512", "--keep", "1"]


def test_path_defaults_are_reported_and_can_be_dropped(tmp_path, capsys):
    """The four-bar's designer defaults are in force, said to be defaults, and met; each can be changed
    or dropped, and the summary says so."""
    targets, _ = _targets_csv(tmp_path)
    code, out, err = _run(capsys, ["synth", "path", str(targets), *FAST, "--json"])
    assert code == 0, err
    c = json.loads(out)["constraints"]
    assert (c["full_turn"], c["min_transmission_deg"], c["max_ratio"]) == (True, 30.0, 10.0)
    assert c["sources"] == {"full_turn": "default", "min_transmission_deg": "default", "max_ratio": "default"}
    assert c["transmission_deg"] >= 30.0 and c["ratio"] <= 10.0
    code, out, err = _run(capsys, ["synth", "path", str(targets), *FAST, "--min-transmission", "none",
                                   "--max-ratio", "20", "--json"])
    assert code == 0, err
    c = json.loads(out)["constraints"]
    assert c["min_transmission_deg"] is None and c["max_ratio"] == 20.0
    assert c["sources"] == {"full_turn": "default", "min_transmission_deg": "off", "max_ratio": "given"}
    code, out, _ = _run(capsys, ["synth", "path", str(targets), *FAST])
    assert "transmission angle ≥ 30°, link ratio ≤ 10 (default: full turn, transmission angle, link ratio)" in out
    assert "achieved: smallest transmission" in out


def test_path_out_of_order_target_gets_a_design_and_a_warning(tmp_path, capsys):
    m = mbplanar.analyse(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), np.radians([0, 30, 60, 90, 89.6,
                                                                                                   150, 210, 270, 320]))
    path = tmp_path / "t.csv"
    path.write_text("\n".join(f"{float(x)!r},{float(y)!r}" for x, y in m.xy[:, m.point("M")]) + "\n", encoding="utf-8")
    code, out, err = _run(capsys, ["synth", "path", str(path), *FAST, "--json"])
    assert code == 0, err
    assert "mbplanar: warning: targets 4 and 5 are met out of order: 5 lies" in err
    doc = json.loads(out)
    assert doc["success"] and doc["order"]["steps_back"][0]["from"] == 4 and doc["warnings"]


@pytest.mark.parametrize("text, message", [
    ("x,y\n0,0\n1,0\n", "at least 3 target points, got 2"),
    ("0,0\n1,0\nnan,1\n0,1\n", "row 3: needs 2 finite numbers"),
    ("x,y\n0.5,0.5\n0.5,0.5\n0.5,0.5\n0.5,0.5\n", "rows 1-4 are all the one point (0.5, 0.5)"),
    ("x_mm,y_mm\n0,0\n100,0\n100,100\n0,100\n", "row 1: the header names the unit 'mm'"),
    ("x [in],y [in]\n0,0\n1,0\n1,1\n", "row 1: the header names the unit 'in'"),
])
def test_path_bad_targets_name_the_row(tmp_path, capsys, text, message):
    (tmp_path / "t.csv").write_text(text, encoding="utf-8")
    code, _, err = _run(capsys, ["synth", "path", str(tmp_path / "t.csv"), *FAST])
    assert code == 2 and message in err and "Traceback" not in err, err


def test_path_targets_in_another_unit_than_the_model(tmp_path, capsys):
    """models/fourbar_design.toml is drawn in metres (about 0.5 m); targets written in millimetres are
    refused, naming the row farthest off."""
    path = tmp_path / "t.csv"
    path.write_text("130,210\n60,220\n-10,180\n-50,120\n-30,60\n20,60\n90,100\n150,170\n", encoding="utf-8")
    code, _, err = _run(capsys, ["synth", "path", str(path), "--model", "models/fourbar_design.toml", "--point", "M",
                                 "--vary", "m=0:1"])
    assert code == 2 and "row 1: (130, 210) m" in err and "is it in another unit?" in err, err
    code, _, err = _run(capsys, ["synth", "path", str(path), "--model", "models/fourbar_design.toml", "--point", "M",
                                 "--vary", "m=0:1", "--budget", "5"])
    assert code == 2
