"""One unit system everywhere (issue 27, item 2): every length, angle, stroke, free length, radius, pose
and target read from a model, a variant table, a target file or an option goes through the model's
units, and a value 100 times off the drawing warns with the numbers (`mbplanar.model._scale`), the
boundary included. Each careless input of the issue gives the right answer or a warning or error
naming the file, the row and the value, with the right exit status.

The right answers are those of the same model written without the slip (the units' invariance,
`tests/test_units.py`), or closed forms: an inch is 0.0254 m exactly.
"""

import csv
import io
import json
import math
import tomllib
import warnings
from pathlib import Path

import pytest

import mbplanar
from mbplanar.errors import ModelError, ModelWarning
from mbplanar.model._scale import SCALE_FACTOR, out_of_scale, warn_scale

from test_units import rescale, run, to_toml

HERE = Path(__file__).resolve().parent
MODELS = HERE.parent / "models"
REPRO = HERE / "data" / "repro"


def _doc(name):
    return tomllib.loads((MODELS / name).read_text(encoding="utf-8"))


def _write(tmp_path, name, doc) -> Path:
    path = tmp_path / name
    path.write_text(to_toml(doc), encoding="utf-8")
    return path


def _warnings_of(make):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = make()
    return result, [str(w.message) for w in caught if issubclass(w.category, ModelWarning)]


# -- the rule and its boundary ------------------------------------------------------------------------
@pytest.mark.parametrize("ratio, flagged", [
    (100.0, True), (100.0 * (1 - 1e-12), True), (99.99, False), (1.0, False),
    (0.01, True), (0.0100001, False), (1e-6, True), (1e6, True)])
def test_a_value_100_times_off_is_flagged_the_boundary_included(ratio, flagged):
    assert SCALE_FACTOR == 100.0
    for size in (1e-3, 0.3, 7.0):
        assert out_of_scale(ratio * size, size) is flagged
    assert not out_of_scale(0.0, 1.0) and not out_of_scale(1.0, 0.0)   # nothing to judge


def test_the_warning_gives_the_numbers():
    _, got = _warnings_of(lambda: warn_scale("--radius", 5.0, 0.04, "mm", 1e-3, source="x.toml"))
    assert got == ["x.toml: --radius 5000 mm while the drawing spans 40 mm (125 times that): is it in another "
                   "unit? (lengths here are read in mm)"]


# -- length_unit in any case, and inches ---------------------------------------------------------------
@pytest.mark.parametrize("spelling", ["MM", "Mm", "mm", " mm "])
def test_length_unit_in_any_case(spelling):
    doc = rescale(_doc("fourbar.toml"), "mm")
    doc["length_unit"], doc["inertia_unit"], doc["moment_unit"] = spelling, "KG*MM^2", "n*mm"
    mech = mbplanar.parse_model(doc)
    assert (mech.units.length, mech.units.inertia, mech.units.moment) == ("mm", "kg*mm^2", "N*mm")


def test_a_model_in_inches_gives_the_same_si_answers(tmp_path):
    """The four-bar written in inches (every length / 0.0254): positions, velocities and the reactions
    equal the metre model's; `--units model` shows them in inches."""
    doc = _doc("fourbar_loaded.toml")
    k = 1 / 0.0254
    import test_units                  # (its rescaler, taught the inch for this test)
    test_units.LENGTH["in"] = 0.0254
    try:
        inch = rescale(doc, "in")
    finally:
        del test_units.LENGTH["in"]
    assert inch["length_unit"] == "in" and inch["joints"][1]["at"][0] == pytest.approx(doc["joints"][1]["at"][0] * k)
    m_file, in_file = _write(tmp_path, "m.toml", doc), _write(tmp_path, "in.toml", inch)
    out = {}
    for name, path in (("m", m_file), ("in", in_file)):
        code, text, err = run("forces", path, "--at", "75", "--json")
        assert code == 0, err
        out[name] = json.loads(text)
    for joint, r in out["m"]["reactions"].items():
        assert out["in"]["reactions"][joint]["fx"] == pytest.approx(r["fx"], rel=1e-9, abs=1e-12)
    assert out["in"]["balancing"]["O"] == pytest.approx(out["m"]["balancing"]["O"], rel=1e-9)
    code, text, _ = run("solve", in_file, "--at", "75", "--json", "--units", "model")
    code_m, text_m, _ = run("solve", m_file, "--at", "75", "--json")
    x_in, x_m = json.loads(text)["points"]["A"]["x"], json.loads(text_m)["points"]["A"]["x"]
    assert code == code_m == 0 and json.loads(text)["units"]["length"] == "in"
    assert x_in == pytest.approx(x_m / 0.0254, rel=1e-12)


# -- a spring's free length in metres in a mm file -----------------------------------------------------
def test_a_spring_free_length_in_metres_in_a_mm_file_warns(tmp_path):
    """Andrews' squeezer in mm with the spring's free length left at 0.07785 (metres): the balancing
    torque comes out wrong; the warning names the row and the numbers."""
    good = rescale(_doc("squeezer.toml"), "mm")
    slip = json.loads(json.dumps(good))
    slip["loads"][0]["free_length"] = 0.07785
    good_path, slip_path = _write(tmp_path, "good.toml", good), _write(tmp_path, "slip.toml", slip)
    at = "0.3"   # rad
    code, text, err = run("forces", good_path, "--at", at, "--json")
    assert code == 0 and err == ""
    code_slip, text_slip, err_slip = run("forces", slip_path, "--at", at, "--json")
    assert code_slip == 0
    assert (f"warning: {slip_path}: loads[0] 'spring': free_length = 0.07785 mm while the drawing spans"
            in err_slip and "is it in another unit? (lengths here are read in mm)" in err_slip)
    good_q, slip_q = json.loads(text)["balancing"]["O"], json.loads(text_slip)["balancing"]["O"]
    assert abs(slip_q - good_q) > abs(good_q)     # a wrong answer: what the warning is for


def test_a_spring_length_table_in_the_wrong_unit_warns():
    doc = _doc("squeezer.toml")
    doc["loads"][0] = {"type": "spring", "name": "table", "at": ["C", "D"], "length": [10.0, 100.0],
                       "force": [0.0, 300.0]}   # millimetre numbers in a metre model
    _, got = _warnings_of(lambda: mbplanar.parse_model(doc, "sq.toml"))
    assert got and got[0].startswith("sq.toml: loads[0] 'table': the spring's 'length' table reaches 100 m "
                                     "while the drawing spans")


def test_a_load_point_far_from_the_drawing_warns():
    doc = _doc("fourbar_loaded.toml")
    doc["loads"] = [{"type": "force", "link": "2", "at": [300.0, 100.0], "force": [0.0, -10.0]}]
    _, got = _warnings_of(lambda: mbplanar.parse_model(doc, "f.toml"))
    assert got and got[0].startswith("f.toml: loads[0] (force): 'at' = [300, 100] m lies ")
    assert "times that): is it in another unit?" in got[0]


# -- link lengths and extents --------------------------------------------------------------------------
def _fourbar_with_crank(length):
    """The four-bar (metres, ground 0.3 m) with its crank drawn `length` long, the coupler and rocker
    drawn to close it (exact coordinates)."""
    a = (length * math.cos(1.0), length * math.sin(1.0))
    c = (0.3, 0.0)
    # B: the coupler 0.3 from A and the rocker 0.25 from C
    d = math.dist(a, c)
    along = (d * d + 0.3 ** 2 - 0.25 ** 2) / (2 * d)
    h = math.sqrt(0.3 ** 2 - along ** 2)
    u = ((c[0] - a[0]) / d, (c[1] - a[1]) / d)
    b = (a[0] + along * u[0] - h * u[1], a[1] + along * u[1] + h * u[0])
    return {"links": [{"name": "1"}, {"name": "2"}, {"name": "3"}],
            "joints": [{"name": "O", "type": "R", "links": ["0", "1"], "at": [0.0, 0.0]},
                       {"name": "A", "type": "R", "links": ["1", "2"], "at": list(a)},
                       {"name": "B", "type": "R", "links": ["2", "3"], "at": list(b)},
                       {"name": "C", "type": "R", "links": ["3", "0"], "at": list(c)}],
            "input": {"joint": "O"}}


def test_a_tenth_of_a_millimetre_crank_in_a_model_drawn_in_metres_warns():
    doc = _fourbar_with_crank(1e-4)
    _, got = _warnings_of(lambda: mbplanar.parse_model(doc, "tiny.toml"))
    assert len(got) == 1 and got[0].startswith("tiny.toml: links[0] '1': it is drawn O-A = 0.0001 m while the "
                                               "drawing spans")
    doc["links"][0]["length"] = 1e-4      # the same as a length
    _, got = _warnings_of(lambda: mbplanar.parse_model(doc, "tiny.toml"))
    assert got[0].startswith("tiny.toml: links[0] '1': its length = 0.0001 m while the drawing spans")


def test_the_link_scale_boundary():
    """The drawing spans |O–C| or |O–B| (the largest joint distance); a crank of exactly 1/100 of it warns,
    one a little longer does not."""
    mech = mbplanar.parse_model(_fourbar_with_crank(0.004))
    size = max(math.dist(p.at, q.at) for p in mech.joints.values() for q in mech.joints.values())
    for crank, flagged in ((size / 100, True), (size / 100 * 1.001, False)):
        _, got = _warnings_of(lambda: mbplanar.parse_model(_fourbar_with_crank(crank)))
        mech = mbplanar.parse_model(_fourbar_with_crank(crank))
        size = max(math.dist(p.at, q.at) for p in mech.joints.values() for q in mech.joints.values())
        assert bool(got) is out_of_scale(crank, size), (crank, got)
    assert out_of_scale(size / 100, size) and not out_of_scale(size / 100 * 1.001, size)


# -- a length 10 % off its drawing ---------------------------------------------------------------------
@pytest.mark.parametrize("factor, warns", [(1.10, True), (0.90, True), (1.0999, False), (0.9001, False)])
def test_a_length_exactly_ten_percent_off_its_drawing_warns(factor, warns):
    """The rocker drawn 0.25 m long (exact coordinates) given a length `factor` times that: 10 % off
    the drawing, either way, warns (the assembly moves a joint); within 10 % is a rough sketch."""
    doc = _doc("fourbar.toml")
    drawn = math.dist(doc["joints"][2]["at"], doc["joints"][3]["at"])
    doc["links"][2]["length"] = drawn * factor
    _, got = _warnings_of(lambda: mbplanar.Engine(mbplanar.parse_model(doc, "t.toml")))
    sketch = [g for g in got if "but the sketch draws" in g]
    assert bool(sketch) is warns, got
    if warns:
        assert f"({100 * (factor - 1):+.1f} % of it)" in sketch[0]


# -- a cam's stroke in metres in a mm file -------------------------------------------------------------
def test_a_cam_stroke_in_metres_in_a_mm_file_warns(tmp_path):
    text = (MODELS / "cam_roller.toml").read_text(encoding="utf-8")
    slip = tmp_path / "cam.toml"
    slip.write_text(text.replace("stroke = 20.0", "stroke = 0.02").replace('length_unit = "mm"',
                                                                             'length_unit = "MM"'), encoding="utf-8")
    code, out, err = run("cam", slip, "--json")
    assert code == 0 and json.loads(out)["phases"][0]["stroke"] == pytest.approx(2e-5)
    assert err.strip() == (f"mbplanar: warning: {slip}: [cam] phases[0]: its stroke = 0.02 mm while base_radius = "
                           "50 mm (1/2.5e+03 of that): is it in another unit? (lengths here are read in mm)")


def test_cam_units_model_shows_the_cams_unit():
    code, si, _ = run("cam", MODELS / "cam_roller.toml", "--json")
    code_m, mm, _ = run("cam", MODELS / "cam_roller.toml", "--json", "--units", "model")
    si, mm = json.loads(si), json.loads(mm)
    assert code == code_m == 0 and si["units"]["length"] == "m" and mm["units"]["length"] == "mm"
    assert mm["phases"][0]["stroke"] == pytest.approx(20.0, rel=1e-12)
    assert mm["follower"]["base_radius"] == pytest.approx(1000 * si["follower"]["base_radius"], rel=1e-12)
    assert mm["curvature"]["rho_min"] == pytest.approx(1000 * si["curvature"]["rho_min"], rel=1e-12)
    assert mm["pressure_angle"] == si["pressure_angle"]


# -- variant tables ------------------------------------------------------------------------------------
SEED002 = MODELS / "crank_slider_rocker.toml"
ROWS = [("1", 1.0, 1.0, 1.0, 0.5, 4.7, 5.7), ("7", 1.0, 1.2, 0.8, 0.5, 1.9, 3.5)]


def _table(tmp_path, header, rows, name="v.csv") -> Path:
    path = tmp_path / name
    path.write_text("\n".join([",".join(header)] + [",".join(str(c) for c in r) for r in rows]) + "\n")
    return path


def _study(table, *extra):
    code, out, err = run("study", SEED002, "--variants", table, "--json", "--no-progress", *extra)
    return code, (json.loads(out) if code == 0 else None), err


def test_variant_lengths_in_mm_and_angles_in_degrees_warn(tmp_path):
    header = ["variant", "l2", "l3", "l4", "phi20", "phi30", "phi40"]
    mm = [(r[0], *(1000 * v for v in r[1:4]), *r[4:]) for r in ROWS]
    code, _, err = _study(_table(tmp_path, header, mm))
    assert code == 0
    table = tmp_path / "v.csv"
    assert (f"warning: {table}: column 'l2' (length in m): 2 of 2 rows are 100 times or more, or 1/100 or less, "
            f"of the parameter's declared 1 m: in another unit? (first: line 2, 1000 m); a header 'l2[mm]' gives "
            "the column in mm") in err
    deg = [(*r[:4], *(round(math.degrees(v), 3) for v in r[4:])) for r in ROWS]
    code, _, err = _study(_table(tmp_path, header, deg, "d.csv"))
    assert code == 0 and (f"warning: {tmp_path / 'd.csv'}: column 'phi30' (angle in rad): 2 of 2 rows are more than "
                          "a turn in radians: degrees? (first: line 2, 269.29 rad); a header 'phi30[deg]' gives the "
                          "column in deg") in err


def test_variant_header_units_give_the_same_study(tmp_path):
    """The same designs given in metres and radians, or in mm and degrees with the units in the header:
    the same study, to rounding, and no warning."""
    header = ["variant", "l2", "l3", "l4", "phi20", "phi30", "phi40"]
    code, plain, err = _study(_table(tmp_path, header, ROWS, "si.csv"))
    assert code == 0 and err == ""
    other = [(r[0], *(1000 * v for v in r[1:4]), *(math.degrees(v) for v in r[4:])) for r in ROWS]
    code, given, err = _study(_table(tmp_path, ["variant", "l2[mm]", "l3[MM]", "l4[mm]", "phi20[deg]", "phi30[deg]",
                                                "phi40[Deg]"], other, "units.csv"))
    assert code == 0 and err == ""
    for a, b in zip(plain["designs"], given["designs"]):
        assert a["full_turn"] == b["full_turn"] and a["parameters"] == pytest.approx(b["parameters"], rel=1e-12)
        assert a["transmission_min_deg"] == pytest.approx(b["transmission_min_deg"], rel=1e-9, abs=1e-9)


def test_a_header_unit_of_the_wrong_kind_is_refused(tmp_path):
    code, _, err = _study(_table(tmp_path, ["variant", "l2[deg]"], [("1", 1.0)]))
    assert code == 2 and "column 'l2[deg]': parameter 'l2' is a length in m; 'deg' is not a unit for it" in err


def test_a_negative_length_in_a_variant_row_names_the_row_and_column(tmp_path):
    table = _table(tmp_path, ["variant", "l2", "l3"], [("a", 1.0, 1.2), ("b", -1.0, 1.2)])
    code, _, err = _study(table)
    assert code == 2
    assert err.strip() == (f"mbplanar: {table}: line 3: column 'l2': -1 m is a length (joints[2] 'C' at length) and "
                           "must not be negative")


def test_a_parameter_used_as_a_length_and_as_an_angle_is_refused():
    doc = _doc("crank_slider_rocker.toml")
    doc["joints"][5]["at"]["length"] = "phi30"        # B at { from C, length phi30, angle phi30 }
    with pytest.raises(ModelError, match=r"parameter 'phi30' is in rad, which does not fit a length here"):
        mbplanar.parse_model(doc, "p.toml")
    doc["parameters"]["phi30"] = 1.9                 # no unit: used as a length and as an angle
    with pytest.raises(ModelError, match=r"p.toml: parameters.phi30: used as a length \(joints\[5\] 'B' at length\) "
                                         r"and as an angle \(joints\[5\] 'B' at angle\)"):
        mbplanar.parse_model(doc, "p.toml")


# -- motion synthesis: poses in radians ----------------------------------------------------------------
POSES = [[0.0, 0.0, 0.0], [0.4, 0.15, 20.0], [0.8, 0.1, 45.0], [1.0, -0.2, 70.0]]   # motion_4poses.csv


def test_motion_poses_in_radians_warn_and_angle_unit_reads_them(tmp_path):
    deg = tmp_path / "deg.toml"
    deg.write_text(f"poses = {POSES}\n")
    rad = tmp_path / "rad.toml"
    rad.write_text(f"poses = {[[x, y, math.radians(a)] for x, y, a in POSES]}\n")
    code, out_deg, err = run("synth", "motion", deg, "--json")
    assert code == 0 and "radians?" not in err
    code, _, err = run("synth", "motion", rad, "--json")
    assert "warning: " in err and f"{rad}: the poses turn through 1.222° in all" in err and "radians?" in err
    rad.write_text(f'angle_unit = "rad"\nposes = {[[x, y, math.radians(a)] for x, y, a in POSES]}\n')
    code, out_rad, err = run("synth", "motion", rad, "--json")
    assert code == 0 and "radians?" not in err
    a, b = json.loads(out_deg), json.loads(out_rad)
    assert b["design"]["crank"] == pytest.approx(a["design"]["crank"], rel=1e-9)


def test_motion_poses_in_mm_with_length_unit(tmp_path):
    """The same poses in mm with length_unit = "mm": the same design (SI); `--units model` shows it in mm."""
    m, mm = tmp_path / "m.toml", tmp_path / "mm.toml"
    m.write_text(f"poses = {POSES}\n")
    mm.write_text('length_unit = "mm"\n' + f"poses = {[[1000 * x, 1000 * y, a] for x, y, a in POSES]}\n")
    code, a, _ = run("synth", "motion", m, "--json")
    code_mm, b, _ = run("synth", "motion", mm, "--json")
    code_u, c, _ = run("synth", "motion", mm, "--json", "--units", "model")
    a, b, c = json.loads(a), json.loads(b), json.loads(c)
    assert code == code_mm == code_u == 0
    assert b["design"]["crank"] == pytest.approx(a["design"]["crank"], rel=1e-9)
    assert c["design"]["crank"] == pytest.approx(1000 * a["design"]["crank"], rel=1e-9)
    assert c["units"]["length"] == "mm" and c["error_unit"] == "mm"


# -- options in the model's units: balance --radius, simulate, study ------------------------------------
def test_balance_radius_follows_units_and_is_judged_against_the_drawing(tmp_path):
    doc = _doc("fourbar_loaded.toml")
    m_file, mm_file = _write(tmp_path, "m.toml", doc), _write(tmp_path, "mm.toml", rescale(doc, "mm"))
    code, a, _ = run("balance", m_file, "--links", "1", "--radius", "0.05", "--json")
    code_mm, b, _ = run("balance", mm_file, "--links", "1", "--radius", "50", "--units", "model", "--json")
    a, b = json.loads(a), json.loads(b)
    assert code == code_mm == 0 and b["units"]["length"] == "mm"
    assert b["counterweights"][0]["mass"] == pytest.approx(a["counterweights"][0]["mass"], rel=1e-9)
    assert b["counterweights"][0]["at"] == pytest.approx([1000 * v for v in a["counterweights"][0]["at"]], rel=1e-9)
    assert b["before"]["shaking_moment_max"] == pytest.approx(1000 * a["before"]["shaking_moment_max"], rel=1e-9)
    code, _, err = run("balance", mm_file, "--links", "1", "--radius", "50")       # 50 m
    assert code == 0 and f"warning: {mm_file}: --radius 50 m while the drawing spans" in err


def test_simulate_units_model(tmp_path):
    """Andrews' squeezer in mm (moments in N·mm): `simulate --units model` shows the same motion, the drive
    in N·mm, and the CSV headers name the units."""
    doc = _doc("squeezer.toml")
    mm = rescale(doc, "mm")
    mm["simulate"]["torque"] *= 1000                 # N·mm
    m_file, mm_file = _write(tmp_path, "m.toml", doc), _write(tmp_path, "mm.toml", mm)
    code, si, _ = run("simulate", m_file, "--t", "0.002", "--steps", "4", "--json")
    code_mm, model, _ = run("simulate", mm_file, "--t", "0.002", "--steps", "4", "--json", "--units", "model",
                            "-o", tmp_path / "mm.csv")
    si, model = json.loads(si), json.loads(model)
    assert code == code_mm == 0 and model["units"]["moment"] == "N*mm"
    beta = si["inputs"]["beta"]
    assert model["inputs"]["beta"]["phi"] == pytest.approx(beta["phi"], rel=1e-9)
    assert model["inputs"]["beta"]["drive"] == pytest.approx([1000 * v for v in beta["drive"]], rel=1e-9)
    rows = list(csv.reader(io.StringIO((tmp_path / "mm.csv").read_text())))
    assert rows[0][:5] == ["t[s]", "beta[rad]", "beta.omega[rad/s]", "beta.epsilon[rad/s2]", "beta.drive[N*mm]"]
    assert float(rows[-1][4]) == pytest.approx(1000 * beta["drive"][-1], rel=1e-9)


def test_study_units_model(tmp_path):
    doc = _doc("crank_slider_rocker.toml")
    mm = rescale(doc, "mm")
    mm_file = _write(tmp_path, "mm.toml", mm)
    table = _table(tmp_path, ["variant", "l2[m]", "l3[m]"], [("a", 1.0, 1.2)])
    code, si, _ = run("study", SEED002, "--variants", table, "--json", "--no-progress")
    code_mm, model, err = run("study", mm_file, "--variants", table, "--json", "--no-progress", "--units", "model")
    assert code == code_mm == 0, err
    si, model = json.loads(si), json.loads(model)
    a = next(e for e in si["designs"][0]["extremes"] if e["kind"] == "slider")
    b = next(e for e in model["designs"][0]["extremes"] if e["kind"] == "slider")
    assert model["units"]["length"] == "mm" and b["stroke"] == pytest.approx(1000 * a["stroke"], rel=1e-9)


# -- slips beyond the list ---------------------------------------------------------------------
def test_gravity_in_mm_per_s2_warns():
    doc = _doc("shaper.toml")
    doc["gravity"]["g"] = 9810.0
    _, got = _warnings_of(lambda: mbplanar.parse_model(doc, "s.toml"))
    assert got == ["s.toml: gravity: g = 9810 m/s² is 1e+03 times the earth's 9.81 m/s²: is it in another unit? "
                   "(g is in m/s² whatever the length_unit)"]


def test_an_inertia_in_kg_mm2_in_a_kg_m2_file_warns():
    """The shaper's lever (20 kg, 1.1 kg·m²: a radius of gyration of 0.23 m) with its inertia written in
    kg·mm² (1.1e6) but no inertia_unit: a radius of gyration of 235 m."""
    doc = _doc("shaper.toml")
    doc["links"][2]["inertia"] = 1.1e6
    _, got = _warnings_of(lambda: mbplanar.parse_model(doc, "s.toml"))
    assert len(got) == 1 and got[0].startswith("s.toml: links[2] '3': its radius of gyration sqrt(inertia/mass) = "
                                               "234.5 m while the drawing spans")
    assert "is 'inertia' in another unit? (inertias here are read in kg*m^2" in got[0]


def test_a_point_placed_100_drawings_away_warns():
    doc = _doc("fourbar.toml")
    doc["points"][0]["offset"] = 50.0            # 50 mm meant, in a metre model
    _, got = _warnings_of(lambda: mbplanar.parse_model(doc, "f.toml"))
    assert got and got[0].startswith("f.toml: links[1] '2': point 'M' has offset = 50 m while the drawing spans")


def test_a_sliding_input_sweep_in_the_wrong_unit_warns():
    text = (REPRO / "boom_at_xy_mm.toml").read_text(encoding="utf-8")
    doc = tomllib.loads(text)
    doc["input"]["sweep"] = [0.45, 0.55]          # metres, in a mm model
    _, got = _warnings_of(lambda: mbplanar.parse_model(doc, "b.toml"))
    assert got and got[0].startswith("b.toml: inputs[0] (joint 'Cp'): the sweep [0.45, 0.55] mm spans 0.1 mm while "
                                     "the drawing spans")


def test_seed001_in_mm_gives_the_same_design(tmp_path):
    """The documented walking-foot target on the seed's chain, written in mm: the design in mm is the
    metre design × 1000."""
    code, si, _ = run("synth", "seed001", "--json")
    mm = tmp_path / "mm.toml"
    mm.write_text('length_unit = "MM"\n[chain]\na = 623.4\nb = 2562.8\npivot = [-1000.0, -666.8]\n'
                  "[target]\nx_start = 0.0\ny0 = -2600.0\nlength = 1000.0\nheight = 200.0\n")
    code_mm, model, _ = run("synth", "seed001", mm, "--json", "--units", "model")
    si, model = json.loads(si), json.loads(model)
    assert code == code_mm == 0 and model["units"]["length"] == "mm"
    assert model["design"]["l"] == pytest.approx(1000 * si["design"]["l"], rel=1e-9)
    assert model["design"]["gamma_deg"] == pytest.approx(si["design"]["gamma_deg"], rel=1e-9)


def test_lengths_in_metres_in_a_mm_drawing_say_so_when_the_pose_cannot_be_assembled(tmp_path):
    """The four-bar drawn in mm with its link lengths left in metres: every length is one factor off the
    sketch, refused as bad input (exit 2) naming the factor before any assembly is tried, and the one line
    goes on with the scale warnings (they used to be lost with the error)."""
    doc = _doc("fourbar.toml")
    mm = rescale(doc, "mm")
    for link, original in zip(mm["links"], doc["links"]):
        link["length"] = original["length"]
    path = _write(tmp_path, "f.toml", mm)
    code, _, err = run("info", path)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1
    assert "every length given (3, links 1, 2, 3) is 1/1000 × what the sketch draws" in lines[0]
    assert f"; warning: {path}: links[0] '1': its length = 0.1 mm while the drawing spans" in lines[0]
