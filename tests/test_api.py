"""The public API of `mbplanar/__init__.py`: every name in __all__ exists, and the README's Python
example runs through structure, check, kinetostatics and dynamics with the top-level names only."""

from pathlib import Path

import numpy as np

import mbplanar

MODELS = Path(__file__).resolve().parent.parent / "models"


def test_every_public_name_exists():
    for name in mbplanar.__all__:
        assert hasattr(mbplanar, name), name


def test_top_level_functions_cover_the_whole_analysis():
    engine = mbplanar.Engine(mbplanar.read_model(MODELS / "shaper.toml"))
    assert engine.topology.structure.mechanism_class == 2
    report = mbplanar.check(engine)
    assert isinstance(report, mbplanar.CheckReport) and report.full_turn
    motion = mbplanar.analyse(engine, np.radians([140.769]), 7.646, -0.577)
    result = mbplanar.kinetostatics(engine, motion, input_inertia=147.173)
    assert isinstance(result, mbplanar.Kinetostatics)
    assert abs(result.virtual_power_residual).max() < 1e-9
    dyn = mbplanar.machine_dynamics(engine, steps=720, simulate_motion=False)
    assert abs(dyn.inertia_first_group / 147.141 - 1) < 2e-3


def test_parse_model_takes_text_or_the_parsed_document():
    import tomllib
    text = (MODELS / "fourbar.toml").read_text()
    a, b = mbplanar.parse_model(text), mbplanar.parse_model(tomllib.loads(text))
    assert a.joints.keys() == b.joints.keys() and a.joints["B"].at == b.joints["B"].at


def test_solve_json_reports_the_input_as_typed_and_every_input(capsys):
    import json

    from mbplanar.cli import main
    assert main(["solve", str(MODELS / "slider_crank.toml"), "--at", "30", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["input"]["value"] == 30.0 and doc["inputs"] == [doc["input"]]
    assert abs(doc["input"]["value_si"] - np.radians(30.0)) < 1e-15
