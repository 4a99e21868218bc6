"""`mbplanar gear pair` and `mbplanar gear planetary`: the issue's commands give what they promise, bad
requests get one line naming the value and exit 2; the [gears] section of a model drives them and the
report; the gears' docstring examples run."""

from __future__ import annotations

import doctest
import importlib
import json
import math
import tomllib
from pathlib import Path

import pytest

from mbplanar.cli import main

ROOT = Path(__file__).resolve().parents[1]


def run(argv, capsys):
    code = main(argv)
    out = capsys.readouterr()
    return code, out.out, out.err


def test_pair_auto_gives_geometry_checks_shifts_contour_and_dxf(tmp_path, capsys):
    """The issue's command: `mbplanar gear pair --module 10 --teeth 12,30 --shift auto`, with the block
    contour's picture and a DXF of both gears."""
    ezdxf = pytest.importorskip("ezdxf")
    pytest.importorskip("matplotlib")
    dxf, png = tmp_path / "pair.dxf", tmp_path / "contour.png"
    code, out, err = run(["gear", "pair", "--module", "10", "--teeth", "12,30", "--shift", "auto",
                          "--plot", "contour", "--plot-output", str(png), "--dxf", str(dxf), "--json"], capsys)
    assert code == 0, err
    doc = json.loads(out)
    assert doc["teeth"] == [12, 30] and doc["module"] == 0.01 and doc["success"]
    assert doc["choice"]["criterion"] == "balanced"
    x1, x2 = doc["shifts"]
    assert abs(doc["gears"][0]["sliding"]["root"] - doc["gears"][1]["sliding"]["root"]) < 1e-9
    assert all(c["ok"] for c in doc["checks"]) and {c["name"] for c in doc["checks"]} == {
        "undercut", "pointed tip", "interference", "contact ratio"}
    assert doc["contact_ratio"] >= 1.2 - 1e-9 and doc["centre_distance"] > 0.21
    assert all(p["check"]["success"] for p in doc["profiles"])
    assert doc["contour"]["area"] > 0 and png.stat().st_size > 10_000
    layers = {e.dxf.layer for e in ezdxf.readfile(dxf).modelspace()}
    assert {"GEAR1", "GEAR2"} <= layers
    code, text, _ = run(["gear", "pair", "--module", "10", "--teeth", "12,30", "--shift", "auto"], capsys)
    assert code == 0 and "ε_α = 1.200000" in text and "self-check" in text and f"x1 = {x1:.6f}" in text


def test_pair_given_shifts_and_exports(tmp_path, capsys):
    code, out, _ = run(["gear", "pair", "--module", "3", "--teeth", "12,24", "--shift", "0.6,0.36", "--json",
                        "-o", str(tmp_path / "p.csv"), "--svg", str(tmp_path / "p.svg")], capsys)
    doc = json.loads(out)
    assert code == 0 and doc["choice"] is None and abs(doc["working_pressure_angle_deg"] - 26.08856) < 1e-5
    assert (tmp_path / "p.csv").read_text().startswith("gear,piece,part,x[mm],y[mm]")
    assert (tmp_path / "p.svg").read_text().startswith("<svg")


def test_pair_internal_and_fixed_centre_distance(capsys):
    code, out, _ = run(["gear", "pair", "--module", "2", "--teeth", "20,62", "--internal", "--shift", "0,0.2",
                        "--ring-tip", "cut", "--json"], capsys)
    doc = json.loads(out)
    assert code == 0 and doc["internal"] and doc["ring_tip"] == "cut"
    code, out, _ = run(["gear", "pair", "--module", "10", "--teeth", "12,30", "--centre-distance", "215",
                        "--criterion", "contact", "--json"], capsys)
    doc = json.loads(out)
    assert code == 0 and abs(doc["centre_distance"] - 0.215) < 1e-12


@pytest.mark.parametrize("argv, message", [
    (["pair", "--module", "10", "--teeth", "0,30"], "tooth number z1 must be a whole number ≥ 1, got 0"),
    (["pair", "--module", "0", "--teeth", "12,30"], "--module must be > 0 (mm), got 0"),
    (["pair", "--module", "-2", "--teeth", "12,30"], "--module must be > 0 (mm), got -2"),
    (["pair", "--module", "10", "--teeth", "12.5,30"], "tooth numbers are whole numbers, got '12.5'"),
    (["pair", "--module", "10", "--teeth", "12,30", "--shift", "0,0"],
     "--shift 0,0 lies outside the block contour of z = 12, 30: gear 1 (z = 12) is undercut"),
    (["pair", "--module", "10", "--teeth", "12,30", "--shift", "1.2,0"], "tip is too thin"),
    (["pair", "--module", "10", "--teeth", "12,30", "--criterion", "sum"], "needs --shift-sum"),
    (["pair", "--teeth", "12,30"], "needs --module and --teeth"),
    (["planetary", "--ratio", "0.5"], "--ratio 0.5: no scheme reaches it"),
    (["planetary", "--ratio", "1.5", "--scheme", "A"], "--ratio 1.5: no scheme reaches it"),
    (["planetary", "--ratio", "4", "--scheme", "A", "--planets", "5", "--tolerance", "0", "--max-teeth", "57"],
     "no set of tooth numbers gives 4"),
    (["planetary", "--ratio", "7", "--planets", "0"], "--planets must be a whole number ≥ 1, got 0"),
    (["planetary", "--ratio", "7", "--scheme", "A", "--choose", "99"], "--choose 99: there are"),
    (["planetary", "--ratio", "7", "--stage", "12,30"], "--stage needs --stage-module"),
])
def test_bad_requests_exit_2_with_the_value(argv, message, capsys):
    code, out, err = run(["gear"] + argv, capsys)
    assert code == 2 and out == ""
    assert err.startswith("mbplanar: ") and message in err and len(err.strip().splitlines()) == 1


def test_force_prints_a_failing_pair(capsys):
    code, out, _ = run(["gear", "pair", "--module", "10", "--teeth", "12,30", "--shift", "0,0", "--force"], capsys)
    assert code == 0 and "FAIL undercut 1" in out


def test_planetary_lists_sets_and_writes_the_model(tmp_path, capsys):
    """`mbplanar gear planetary --ratio R --scheme ...`: the admissible tooth numbers, and the chosen train
    as a model whose gear joints give Willis' ratio (solved in tests/test_gears_planetary.py)."""
    model, csv = tmp_path / "train.toml", tmp_path / "trains.csv"
    code, out, err = run(["gear", "planetary", "--ratio", "7", "--scheme", "A", "--planets", "3", "-o", str(model),
                          "--csv", str(csv), "--json", "--rpm", "1412.4"], capsys)
    assert code == 0, err
    doc = json.loads(out)
    best = doc["trains"][0]
    assert best["teeth"] == [19, 47, 113] or best["teeth"][0] + 2 * best["teeth"][1] == best["teeth"][2]
    assert doc["chosen"]["teeth"] == best["teeth"] and doc["chosen"]["model"] == str(model)
    assert all(abs(t["ratio"] - 7) <= 0.07 for t in doc["trains"])
    table = tomllib.loads(model.read_text())
    assert [j["type"] for j in table["joints"]].count("gear") == 2
    assert abs(table["input"]["omega"] - 1412.4 * 2 * math.pi / 60) < 1e-12
    assert len(csv.read_text().splitlines()) == doc["count"] + 1
    code, text, _ = run(["gear", "planetary", "--ratio", "7", "--scheme", "A"], capsys)
    assert code == 0 and "chosen: scheme A" in text


def test_model_file_drives_both_commands(tmp_path, capsys):
    """models/shaper.toml's [gears]: the pair 12/30 and the planetary train of the whole drive
    n_d/n₁ = 23.54·60/73 with the pair after it."""
    code, out, err = run(["gear", "planetary", str(ROOT / "models" / "shaper.toml"), "--json",
                          "-o", str(tmp_path / "drive.toml")], capsys)
    assert code == 0, err
    doc = json.loads(out)
    whole = 23.54 * 60 / 73
    assert abs(abs(doc["chosen"]["total_ratio"]) - whole) <= 0.01 * whole
    assert doc["chosen"]["stage"]["teeth"] == [12, 30]
    code, out, _ = run(["gear", "pair", str(ROOT / "models" / "shaper.toml"), "--json"], capsys)
    assert code == 0 and json.loads(out)["teeth"] == [12, 30]


def test_report_gains_a_gears_section():
    pytest.importorskip("matplotlib")
    import mbplanar
    from mbplanar.gears.report import register, report_section
    from mbplanar.viz._report import ReportContext
    engine = mbplanar.Engine(mbplanar.read_model(ROOT / "models" / "shaper.toml"))
    register()
    from mbplanar.viz._report import SECTIONS
    assert "gears" in SECTIONS
    html = report_section(engine, ReportContext(engine, None, None, dpi=30))
    assert html.count("<img") == 3 and "Spur pair" in html and "Planetary train" in html
    plain = mbplanar.Engine(mbplanar.read_model(ROOT / "models" / "fourbar.toml"))
    assert report_section(plain, None) is None


@pytest.mark.parametrize("module", ["involute", "rack", "pair", "shifts", "profile", "planetary", "trainmodel",
                                    "spec", "__init__"])
def test_docstring_examples_run(module, monkeypatch):
    monkeypatch.chdir(ROOT)
    name = "mbplanar.gears" if module == "__init__" else f"mbplanar.gears.{module}"
    failed, tried = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS)
    assert failed == 0 and tried > 0


def test_tutorial_sessions_are_what_the_commands_print(tmp_path, capsys, monkeypatch):
    """docs/gears.md's console blocks, run as shown (rounding noise below 1e-10 made equal, as
    docs/sessions.py does for the README's)."""
    import re
    import shlex
    import sys
    sys.path.insert(0, str(ROOT / "docs"))
    from sessions import _without_noise
    (tmp_path / "models").symlink_to(ROOT / "models")
    monkeypatch.chdir(tmp_path)
    text = (ROOT / "docs" / "gears.md").read_text(encoding="utf-8")
    blocks = re.findall(r"^```console\n\$ (mbplanar gear .*?)\n(.*?)^```", text, flags=re.S | re.M)
    assert len(blocks) == 2
    for command, shown in blocks:
        code, out, err = run(shlex.split(command)[1:], capsys)
        assert code == 0, err
        assert _without_noise(out.splitlines()) == _without_noise(shown.splitlines()), command
    shown_joints = re.search(r"^joints = \[\n.*?^\]\n", text, flags=re.S | re.M).group(0)
    written = (tmp_path / "drive.toml").read_text(encoding="utf-8")
    assert shown_joints in written                            # the model shown is the one written
