"""Early and precise validation: every section is checked when the table is read (file, row, key), a
rigid chain says "DOF = 0", sketches that contradict their own numbers warn with the numbers, the
library checks its arguments, and errors compose "source: where: message" once."""

import math
import pickle
import tomllib
import warnings
from pathlib import Path

import numpy as np
import pytest

import mbplanar
from conftest import linkage_models
from mbplanar.errors import ModelError, ModelWarning, MotionError

HERE = Path(__file__).resolve().parent
MODELS = HERE.parent / "models"
REPRO = HERE / "data" / "repro"


def _doc(name="fourbar.toml", folder=MODELS):
    return tomllib.loads((folder / name).read_text(encoding="utf-8"))


def _parse(doc, source="t.toml"):
    return mbplanar.parse_model(doc, source)


# -- errors -------------------------------------------------------------------------------------------
def test_errors_compose_source_where_message_once():
    err = ModelError("'g' must be a number", source="m.toml", where="gravity")
    assert str(err) == "m.toml: gravity: 'g' must be a number"
    assert str(ModelError("plain")) == "plain" and ModelError("x", where="w").source is None
    again = pickle.loads(pickle.dumps(err))
    assert str(again) == str(err) and again.where == "gravity" and again.exit_code == 2
    assert MotionError("m").exit_code == 1


def test_every_error_class_lives_in_errors():
    from mbplanar import errors
    from mbplanar.viz import PlotUnavailable
    assert PlotUnavailable is errors.PlotUnavailable and issubclass(PlotUnavailable, errors.MbplanarError)


# -- every section at read time -------------------------------------------------------------------------
@pytest.mark.parametrize("edit, words", [
    (lambda d: d.update(loads=[{"type": "force", "link": "2", "at": "Q", "force": [0, -1]}]),
     "t.toml: loads[0] (force): 'at' = 'Q' is neither a point nor a joint"),
    (lambda d: d.update(loads=[{"type": "force", "link": "2", "force": [0, -1]}]),
     "t.toml: loads[0] (force): no 'at' and link '2' has no 'centre'"),
    (lambda d: d["links"][1].update(mass=2.0),
     "t.toml: links[1] '2': a link with mass (2 kg) needs a 'centre' point"),
    (lambda d: d["links"][1].update(centre="C"),
     "t.toml: links[1] '2': centre 'C' is not a joint or point of this link"),
    (lambda d: d.update(gravity={"g": -9.81}), "t.toml: gravity: 'g' must be >= 0"),
    (lambda d: d.update(gravity={"g": 9.81, "dir": 0}), "t.toml: gravity: unknown key(s) dir"),
    (lambda d: d.update(dynamics={"omega_mean": 3.0}), "t.toml: dynamics: missing 'delta'"),
    (lambda d: d.update(dynamics={"delta": 2.0}), "t.toml: dynamics: 'delta' = 2.0 must be between 0 and 1"),
    (lambda d: d.update(dynamics={"delta": 0.1, "flywheel": {"shaft": 1}}),
     "t.toml: dynamics.flywheel: unknown key(s) shaft"),
    (lambda d: d.update(dynamics={"delta": 0.1, "omega_mean": 3, "rpm_mean": 30}),
     "t.toml: dynamics: give either 'omega_mean' (rad/s) or 'rpm_mean' (rev/min), not both"),
    (lambda d: d["input"].update(rpm=60), "t.toml: inputs[0] (joint 'O'): give either 'omega'"),
])
def test_a_broken_section_fails_when_the_table_is_read(edit, words):
    doc = _doc()
    doc["input"]["omega"] = 10.0
    edit(doc)
    with pytest.raises(ModelError) as info:
        _parse(doc)
    assert str(info.value).startswith(words)


def test_info_fails_on_a_broken_load_row(tmp_path):
    """`info` (which computes nothing with loads) refuses a broken load row, exit 2, one line."""
    from test_units import run
    text = (MODELS / "fourbar.toml").read_text(encoding="utf-8")
    path = tmp_path / "bad.toml"
    row = 'loads = [{ type = "force", link = "2", at = "B", force = [1] }]\n'
    path.write_text(text.replace("[input]", row + "[input]"), encoding="utf-8")
    code, out, err = run("info", path)
    assert code == 2 and out == "" and err.count("\n") == 1
    assert f"{path}: loads[0] (force): 'force' must be [x, y]" in err


def test_a_prismatic_input_takes_no_rpm():
    doc = _doc("slider_crank.toml")
    doc["input"] = {"joint": "Bp", "rpm": 60, "sweep": [-0.1, 0.1]}
    with pytest.raises(ModelError, match="'rpm' is a revolute input's speed"):
        _parse(doc)


# -- structure ----------------------------------------------------------------------------------------
def test_a_rigid_triangle_says_dof_zero():
    mech = mbplanar.parse_model("""
        links = [ { name = "1", length = 1.0 }, { name = "2", length = 1.0 } ]
        joints = [
          { name = "O", type = "R", links = ["0", "1"], at = [0, 0] },
          { name = "B", type = "R", links = ["1", "2"], at = [0.5, 0.86] },
          { name = "C", type = "R", links = ["2", "0"], at = [1.0, 0] },
        ]
        [input]
        joint = "O"
        drawn_at = 60
        """, "tri.toml")
    with pytest.raises(ModelError, match=r"^tri.toml: DOF = 0 \(structural count 3·n − 2·p = 3·2 − 2·3"):
        mbplanar.Engine(mech)


def test_a_zero_length_link_is_refused():
    doc = _doc()
    doc["links"][1].pop("length")
    doc["joints"][2]["at"] = doc["joints"][1]["at"]       # B drawn on A: link 2 has no length
    with pytest.raises(ModelError, match=r"t.toml: links\[1\] '2': zero-length link: its joints A, B"):
        _parse(doc)


def test_a_length_joining_a_point_to_itself_is_refused():
    doc = _doc()
    doc["links"][2] = {"name": "3", "lengths": [["B", "B", 0.25]]}
    with pytest.raises(ModelError, match=r"links\[2\] '3': lengths\[0\] joins point 'B' to itself"):
        _parse(doc)


# -- sketches that contradict their numbers -----------------------------------------------------------
def _warnings_of(make):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        make()
    return [str(w.message) for w in caught if issubclass(w.category, ModelWarning)]


def test_a_length_far_from_the_sketch_warns_with_the_numbers():
    doc = _doc()
    doc["links"][2]["length"] = 0.3
    drawn = math.dist(doc["joints"][2]["at"], doc["joints"][3]["at"])          # B–C as drawn: 0.250005
    got = _warnings_of(lambda: mbplanar.Engine(_parse(doc)))
    assert got == [f"t.toml: links '3': length B-C = 0.3 m, but the sketch draws {drawn:.6g} m "
                   f"({100 * (0.3 - drawn) / drawn:+.1f} % of it); the assembly moves the joints to the length"]


def test_a_length_within_ten_percent_is_silent():
    doc = _doc()
    doc["links"][2]["length"] = 0.27                      # 7.4 % off: a rough sketch
    assert _warnings_of(lambda: mbplanar.Engine(_parse(doc))) == []


def test_radians_typed_for_degrees_warn_and_name_the_input_reference():
    doc = _doc()
    doc["input"]["drawn_at"] = math.radians(60.0)        # 1.047 "degrees"
    sketch = math.degrees(math.atan2(*reversed(doc["joints"][1]["at"])))       # O→A as drawn: 59.9993°
    (got,) = _warnings_of(lambda: mbplanar.Engine(_parse(doc)))
    assert got.startswith(f"t.toml: inputs[0] (joint 'O'): drawn_at = 1.0472 deg, but the sketch is drawn at "
                          f"{sketch:.6g} deg ({sketch - math.radians(60.0):.3g}° apart)")
    assert "the angle from the x axis to line O→A of link '1', counter-clockwise (sense = 1), less zero = 0 deg" \
        in got


def test_the_drawn_models_are_silent():
    for path in linkage_models():
        assert _warnings_of(lambda: mbplanar.Engine(mbplanar.read_model(path))) == [], path.name


# -- the library checks its arguments -----------------------------------------------------------------
@pytest.mark.parametrize("kw, words", [
    ({"omega": math.nan}, "omega must be finite"),
    ({"omega": 1e300}, r"omega must be finite and at most 1e\+100 in size, got 1e\+300"),
    ({"epsilon": math.inf}, "epsilon must be finite"),
    ({"omega": "fast"}, "omega must be a number"),
])
def test_analyse_checks_its_speeds(engine_of, kw, words):
    with pytest.raises(ModelError, match=words):
        mbplanar.analyse(engine_of("fourbar"), np.array([0.5]), **kw)


def test_analyse_checks_the_input_values(engine_of):
    with pytest.raises(ModelError, match="phi must be finite"):
        mbplanar.analyse(engine_of("fourbar"), np.array([0.5, math.nan]))


@pytest.mark.parametrize("inertia", [-1.0, math.nan, [1.0, 2.0]])
def test_kinetostatics_checks_input_inertia(engine_of, inertia):
    engine = engine_of("shaper")
    motion = mbplanar.analyse(engine, np.array([0.5]))
    with pytest.raises(ModelError, match="input_inertia must be a finite number >= 0"):
        mbplanar.kinetostatics(engine, motion, inertia)


def test_python_loads_are_checked_like_rows():
    mech = mbplanar.read_model(MODELS / "fourbar.toml")
    load = mech.add_load("force", link="2", at="M", force=[0.0, -10.0])
    assert load.point == "M" and load.force == (0.0, -10.0) and mech.loads == (load,)
    with pytest.raises(ModelError, match=r"loads\[1\] \(moment\): '9' is not a moving link"):
        mech.add_load("moment", link="9", moment=1.0)
    assert mech.set_gravity(9.81).g == 9.81


# -- the command line: exit status and one line ------------------------------------------------------
def _variant(tmp_path, name, old, new, folder=REPRO):
    text = (folder / name).read_text(encoding="utf-8")
    assert old in text
    path = tmp_path / f"v_{name}"
    path.write_text(text.replace(old, new), encoding="utf-8")
    return path


CASES = [
    # (model, old text, new text, command, exit status, words of the one stderr line)
    ("whit_stroke_0.16.toml", "", "", ["forces", "--at", "250"], 0,
     "warning: {path}: loads[0] 'cutting': the s diagram spans 0.16 mm"),
    ("whit_stroke_160.toml", "s = [-1, -0.9, -0.1, 0]", "s = [0, 0.1, 0.9, 1]", ["dynamics", "--delta", "0.05",
                                                                                  "--steps", "72"], 0,
     "warning: {path}: cutting: the resistance does no work over the 73 positions: it acts (backward) over s ="),
    ("inertia_mm.toml", 'length_unit = "mm"', 'length_unit = "mm"\ninertia_unit = "g*mm^2"', ["info"], 2,
     "{path}: inertia_unit must be one of 'kg*m^2', 'kg*cm^2', 'kg*mm^2', 'kg*in^2' (in any case), got 'g*mm^2'"),
    ("inertia_m.toml", "omega = 10.0", "omega = 10.0\nrpm = 95.5", ["info"], 2,
     "{path}: inputs[0] (joint 'O'): give either 'omega' (rad/s) or 'rpm' (rev/min), not both"),
    ("whit_stroke_160.toml", "", "", ["solve", "--at", "30", "--omega", "nan"], 2,
     "{path}: analyse: omega must be finite"),
    ("whit_stroke_160.toml", "", "", ["forces", "--at", "30", "--input-inertia", "-2"], 2,
     "{path}: kinetostatics: input_inertia must be a finite number >= 0"),
    ("inertia_m.toml", ', centre = "A"', "", ["info"], 2,
     "{path}: links[1] '2': a link with mass (1 kg) needs a 'centre' point"),
]


@pytest.mark.parametrize("name, old, new, command, code, words", CASES)
def test_cli_cases(tmp_path, name, old, new, command, code, words):
    from test_units import run
    path = _variant(tmp_path, name, old, new) if old else REPRO / name
    got, _, err = run(command[0], path, *command[1:])
    lines = err.strip().splitlines()
    assert got == code and len(lines) == 1, err
    assert lines[0].startswith("mbplanar: " + words.format(path=path)), lines[0]
