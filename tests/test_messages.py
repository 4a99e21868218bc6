"""Messages that name the cause (issue 27, items 3 and 5 and its Docs bullets): each careless input of the
issue gives the right answer or a one-line error naming the row, joint or value, with its exit status.
The commands run in this process through `mbplanar.cli.main`."""

import contextlib
import csv
import io
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

import mbplanar
from mbplanar.cli import main
from mbplanar.errors import closest_names, did_you_mean

ROOT = Path(__file__).resolve().parent.parent
MODELS = ROOT / "models"
FOURBAR = (MODELS / "fourbar_loaded.toml").read_text(encoding="utf-8")


def run(*argv) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue()


def write(tmp_path, text, name="m.toml", encoding="utf-8") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding=encoding)
    return path


def one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("mbplanar: "), err
    return lines[0]


# -- a dangling link ----------------------------------------------------------------------------------
def test_a_link_on_one_pair_is_named(tmp_path):
    text = FOURBAR.replace('{ name = "3", length = 0.25', '{ name = "4" },\n  { name = "3", length = 0.25') \
        .replace('{ name = "C", type = "R"', '{ name = "E", type = "R", links = ["3", "4"], at = [0.3, 0.1] },\n'
                 '  { name = "C", type = "R"')
    code, _, err = run("info", write(tmp_path, text))
    assert code == 2
    assert "links '4': link '4' hangs on one pair (E, to link '3'), so it swings freely (DOF = 2 for 1 input(s))" \
        in one_line(err)


# -- a byte-order mark ---------------------------------------------------------------------------------
def test_a_byte_order_mark_is_read_in_toml_and_csv(tmp_path):
    model = write(tmp_path, FOURBAR, encoding="utf-8-sig")
    assert model.read_bytes().startswith(b"\xef\xbb\xbf")
    code, out, err = run("info", model)
    assert code == 0 and out.startswith("fourbar_loaded:"), err
    cam = write(tmp_path, (MODELS / "cam_roller.toml").read_text(encoding="utf-8"), "cam.toml", "utf-8-sig")
    assert run("cam", cam)[0] == 0
    rocker = (MODELS / "crank_slider_rocker.toml").read_text(encoding="utf-8")
    write(tmp_path, rocker, "rocker.toml", "utf-8-sig")
    table = (MODELS / "crank_slider_rocker_variants.csv").read_text(encoding="utf-8").splitlines()
    head = next(k for k, line in enumerate(table) if line.strip() and not line.startswith("#"))
    variants = write(tmp_path, "\n".join(table[head:head + 3]) + "\n", "v.csv", "utf-8-sig")  # (as Excel writes)
    code, out, err = run("study", tmp_path / "rocker.toml", "--variants", variants, "--json")
    assert code == 0, err
    assert [d["name"] for d in json.loads(out)["designs"]] == [next(csv.reader([r]))[0] for r in table[head + 1:head + 3]]


# -- a misspelt name: the closest existing names ---------------------------------------------------------
def test_closest_names():
    assert closest_names("S_2", ["A", "B", "S2", "S3"]) == ["S2"]
    assert closest_names("s3", ["A", "S3"]) == ["S3"]                    # case ignored
    assert did_you_mean("Q", ["A", "B"], "points") == "the points are A, B"


SPRING = FOURBAR.replace("moment = -5.0 },", 'moment = -5.0 },\n  { type = "spring", name = "spring", '
                         'at = ["S2", "S3"], stiffness = 100.0 },')


@pytest.mark.parametrize("old, new, expected", [
    ('at = ["S2", "S3"]', 'at = ["S2", "S33"]', r"loads\[1\] 'spring': 'S33' in 'at' is neither a point nor a joint "
                                                r"of the model; did you mean 'S3'\?"),
    ('link = "3", moment = -5.0', 'link = "33", moment = -5.0',
     r"loads\[0\] 'resistance': '33' is not a moving link of the model; did you mean '3'\?"),
    ('{ name = "S2", link = "2", along = ["A", "B"]', '{ name = "S2", link = "2", along = ["A", "b"]',
     r"points 'S2': 'b' is not a joint or point \(with 'at'\) of link '2'; did you mean 'B'\?"),
    ('joint = "O"  ', 'joint = "0"  ', r"inputs\[0\] \(joint '0'\): '0' is not a joint of the table; "
                                                     r"did you mean 'O'\?"),
    ('links = ["2", "3"], at = [0.3016', 'links = ["2", "3x"], at = [0.3016',
     r"joints\[2\] 'B': link '3x' is not in the links list \(ground is '0'\); did you mean '3'\?"),
])
def test_a_misspelt_name_gets_the_closest_ones(tmp_path, old, new, expected):
    assert old in SPRING
    code, _, err = run("info", write(tmp_path, SPRING.replace(old, new)))
    assert code == 2 and re.search(expected, one_line(err)), err


def test_a_cam_event_naming_a_missing_point(tmp_path):
    """Was a KeyError from cam/timing.py."""
    text = (MODELS / "shaper_cam.toml").read_text(encoding="utf-8").replace(
        'point = "D", coordinate = "x", fraction = 0.05, direction = "rising"',
        'point = "DD", coordinate = "x", fraction = 0.05, direction = "rising"')
    write(tmp_path, (MODELS / "shaper.toml").read_text(encoding="utf-8"), "shaper.toml")
    code, _, err = run("cam", write(tmp_path, text, "cam.toml"))
    assert code == 2
    assert "[cam] events[0] 'fp1': 'DD' is neither a joint nor a point of" in one_line(err)
    assert "did you mean 'D'" in err


def test_plot_points_and_balance_links_get_the_closest_names(tmp_path):
    code, _, err = run("plot", MODELS / "fourbar_loaded.toml", "trajectories", "--points", "S22", "-o",
                       tmp_path / "t.png")
    assert code == 2 and "no point or pair 'S22' to trace; did you mean 'S2'" in one_line(err)
    code, _, err = run("balance", MODELS / "fourbar_loaded.toml", "--links", "1,33")
    assert code == 2 and "'33' is not a moving link of the model; did you mean '3'?" in one_line(err)


# -- friction judged against plausible values and the model's size ------------------------------------
SLIDER = """
name = "slider"
links = [
  { name = "1", length = 0.1 },
  { name = "2", length = ROD, mass = 1.0, centre = "S2" },
  { name = "3", mass = 2.0, centre = "B" },
]
joints = [
  { name = "O",  type = "R", links = ["0", "1"], at = [0.0, 0.0] },
  { name = "A",  type = "R", links = ["1", "2"], at = [0.0707, 0.0707] },
  { name = "B",  type = "R", links = ["2", "3"], at = [BX, 0.0] },
  { name = "Bp", type = "P", links = ["0", "3"], at = [BX, 0.0], guide = 0.0 },
]
points = [{ name = "S2", link = "2", along = ["A", "B"], fraction = 0.5 }]
loads = [{ name = "work", type = "resistance", joint = "Bp", force = 1000.0 }]
[input]
joint = "O"
drawn_at = 45.0
omega = 10.0
[friction]
"""


def slider(rod=0.3, friction="mu = 0.1\npin_radius = 0.01"):
    bx = 0.0707 + math.sqrt(rod ** 2 - 0.0707 ** 2)
    return SLIDER.replace("ROD", repr(rod)).replace("BX", repr(bx)) + friction + "\n"


@pytest.mark.parametrize("friction, expected", [
    ("mu = 10\npin_radius = 0.01", "mu = 10 in O, A, B, Bp: friction coefficients lie in 0.01 … 1"),
    ("mu = 0.1\npin_radius = 10", "pin_radius = 10 m in O, A, B against a mechanism 0.3623 m across (27.6 × its "
                                  "size; plausible 0.001 … 0.25 ×): too large"),
])
def test_friction_out_of_scale_says_so_with_the_numbers(tmp_path, friction, expected):
    code, _, err = run("forces", write(tmp_path, slider(friction=friction)), "--at", "30")
    line = one_line(err)
    assert code == 2 and "did not converge in 100 iterations at phi = 30 deg" in line and expected in line
    assert "self-locking?" not in line


def test_a_self_locking_slider_crank(tmp_path):
    """Rod 0.11 m on a 0.1 m crank, μ = 0.5: the guide locks where |tan β| ≥ 1/μ = 2 (β the rod's angle), at
    φ = 80°: sin β = 0.1·sin 80°/0.11 = 0.895, tan β = 2.0; at 30° tan β = 0.52 and it moves."""
    path = write(tmp_path, slider(rod=0.11, friction="mu = 0.5\npin_radius = 0.005"))
    code, _, err = run("forces", path, "--at", "80")
    line = one_line(err.split("; warning:")[0] + "\n")
    assert code == 1 and "the mechanism self-locks there (mu up to 0.5; friction circles μ·r up to 0.0025 m)" in line
    assert run("forces", path, "--at", "30")[0] == 0


def test_report_marks_what_forces_refuses(tmp_path):
    """The efficiency of a self-locking model is left out where the iteration did not converge (it plotted
    1e-26), and the report says so; a model locked everywhere plots nothing and says why."""
    path = write(tmp_path, slider(rod=0.11, friction="mu = 0.5\npin_radius = 0.005"))
    code, _, err = run("report", path, "--frames", "2", "-o", tmp_path / "r.html")
    page = (tmp_path / "r.html").read_text(encoding="utf-8")
    assert code == 0
    assert re.search(r'<p class="warn">[^<]*did not converge in 100 iterations at \d+ of 181 positions[^<]*the '
                     r"mechanism self-locks there[^<]*the efficiency is left out there</p>", page)
    assert "the efficiency is left out there" in err
    engine = mbplanar.Engine(mbplanar.read_model(path))
    from mbplanar.viz._elementplots import efficiency_figure
    with pytest.warns(mbplanar.errors.ModelWarning, match="did not converge"):
        fig = efficiency_figure(engine, count=37)
    (line,) = [a for a in fig.axes[0].lines if a.get_gid() == "efficiency"]
    y = np.asarray(line.get_ydata(), float)
    assert np.nanmin(y) > 0.1 and np.isnan(y).any()  # no 1e-26


# -- plot of a section the model lacks ------------------------------------------------------------------
@pytest.mark.parametrize("what, section", [("efficiency", "friction"), ("simulation", "simulate"),
                                           ("friction", None)])
def test_plot_of_a_missing_section_exits_2_without_a_picture(tmp_path, what, section):
    picture = tmp_path / "p.png"
    code, _, err = run("plot", MODELS / "fourbar_loaded.toml", what, "-o", picture)
    expected = f"the model has no [{section}] section" if section else "did you mean 'efficiency'?"
    assert code == 2 and expected in one_line(err) and not picture.exists()


# -- scale: the floor and the ceiling as the engine handles them ----------------------------------------
def scaled(text, k):
    text = re.sub(r"at = \[([-\d.e]+), ([-\d.e]+)\]", lambda m: f"at = [{float(m[1]) * k!r}, {float(m[2]) * k!r}]", text)
    return re.sub(r"length = ([\d.e]+)", lambda m: f"length = {float(m[1]) * k!r}", text)


@pytest.mark.parametrize("k", [1e-13, 1.02e-100 / 0.392, 0.99e100 / 0.392])
def test_a_scaled_four_bar_gives_the_same_dimensionless_answers(tmp_path, k):
    """The four-bar's joints are 0.392 m apart at most: scaled to 1e-13 m (was "zero-length link") and to
    both ends of the range the docs promise (1e-100 … 1e100 m), through the table reader and the commands."""
    text = FOURBAR.split("loads =")[0] + "[input]\njoint = \"O\"\ndrawn_at = 60.0\n"
    ref = json.loads(run("solve", write(tmp_path, text, "ref.toml"), "--at", "75", "--json")[1])
    code, out, err = run("solve", write(tmp_path, scaled(text, k)), "--at", "75", "--json")
    assert code == 0, err
    got = json.loads(out)
    for name, p in ref["points"].items():
        assert got["points"][name]["x"] / k == pytest.approx(p["x"], rel=1e-12, abs=1e-12)
        assert got["points"][name]["vy"] / k == pytest.approx(p["vy"], rel=1e-12, abs=1e-12)
    assert got["links"]["3"]["angle"] == pytest.approx(ref["links"]["3"]["angle"], rel=1e-13)
    code, out, _ = run("check", tmp_path / "m.toml")
    assert code == 0 and "angle -92.865984° at 38.624833 deg" in out


@pytest.mark.parametrize("k, size", [(0.98e-100 / 0.392, r"9\.79e-101"), (1.02e100 / 0.392, r"1\.02e\+100")])
def test_beyond_the_range_is_refused(tmp_path, k, size):
    code, _, err = run("info", write(tmp_path, scaled(FOURBAR, k)))
    assert code == 2 and re.search(rf"scale out of range: the joints are up to {size} m apart; mbplanar works with "
                                   r"mechanisms from 1e-100 to 1e\+100 m", one_line(err))


def test_forces_of_a_tiny_mechanism_are_not_rounded_to_zero(tmp_path):
    """1e-13 m slider-crank: its reactions (the 1000 N load) and its balancing moment (~1e-11 N·m) are
    printed, not cleaned to 0 by an absolute round-off threshold."""
    path = write(tmp_path, scaled(slider(friction=""), 1e-13).replace("[friction]\n", ""))
    code, out, _ = run("forces", path, "--at", "30")
    moment = float(out.split("balancing moment at O: ")[1].split()[0])
    code0, out0, _ = run("forces", write(tmp_path, slider(friction="").replace("[friction]\n", ""), "big.toml"),
                         "--at", "30")
    inertia_free = float(out0.split("balancing moment at O: ")[1].split()[0])
    assert code == code0 == 0
    # the load's part scales with k; the inertia part (m·a·r ∝ k²) vanishes
    assert moment == pytest.approx(1e-13 * inertia_free, rel=0.05) and moment != 0


def test_every_length_a_thousand_times_too_small(tmp_path):
    """Lengths in metres in a table whose coordinates are in mm: the factor, not 'misses by 201 mm'."""
    text = scaled(FOURBAR, 1000.0).replace('ground = "0"', 'ground = "0"\nlength_unit = "mm"')
    text = re.sub(r"length = ([\d.e]+)", lambda m: f"length = {float(m[1]) / 1e3!r}", text)
    code, _, err = run("info", write(tmp_path, text))
    assert code == 2 and "every length given (3, links 1, 2, 3) is 1/1000 × what the sketch draws: the lengths and " \
        "the coordinates are in different units (both are read in length_unit 'mm')" in one_line(err)


@pytest.mark.parametrize("unit, scale", [("MM", 1e-3), ("Cm", 1e-2), ("in", 0.0254), ("IN", 0.0254)])
def test_length_unit_in_any_case_and_inches(tmp_path, unit, scale):
    text = FOURBAR.replace('ground = "0"', f'ground = "0"\nlength_unit = "{unit}"')
    mech = mbplanar.read_model(write(tmp_path, text))
    assert mech.units.length_scale == scale
    assert mech.joints["C"].at[0] == pytest.approx(0.3 * scale, rel=1e-15)


# -- check and report agree with sweep --------------------------------------------------------------------
def sweep_table(tmp_path, model, steps=7200):
    code, _, err = run("sweep", model, "--steps", steps, "-o", tmp_path / "s.csv")
    assert code == 0, err
    with open(tmp_path / "s.csv", newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


INCL = (ROOT / "tests" / "data" / "incl_slider.toml").read_text(encoding="utf-8")
BLOCK = '{ name = "Bp", type = "P", links = ["0", "3"], at = [0.116954, 0.116954], guide = 45 }'
OFF_SLOT = {  # the block's point off its slot line, three ways
    "point off the guide line": INCL.replace(BLOCK, BLOCK.replace("at = [0.116954, 0.116954]", "at = [0.15, 0.10]")),
    "guide through two points": INCL.replace(BLOCK, BLOCK.replace("guide = 45", 'guide = ["G1", "G2"]')).replace(
        "[input]", 'points = [{ name = "G1", link = "0", at = [0.0, 0.02] }, { name = "G2", link = "0", at = [0.2, 0.22] }]'
        "\n[input]"),
    "pin off the block's point": INCL.replace('at = [0.116954, 0.116954] },', "at = [0.14, 0.09] },", 1),
}


@pytest.mark.parametrize("model", [MODELS / "fourbar.toml", MODELS / "shaper.toml",
                                   ROOT / "tests" / "data" / "incl_slider.toml", *OFF_SLOT], ids=str)
def test_check_extremes_agree_with_a_fine_sweep(tmp_path, model):
    """Every extreme `check` gives (link angles, slider strokes) against the sweep's at 0.05°, its input
    value within one turn (398.6° read 38.6°); also for a block whose point lies off its slot line."""
    if model in OFF_SLOT:
        model = write(tmp_path, OFF_SLOT[model], "off.toml")
    code, out, _ = run("check", model, "--json")
    assert code == 0
    doc = json.loads(out)
    table = sweep_table(tmp_path, model)
    phi = table[next(iter(table))]
    for ext in doc["extremes"]:
        if ext["turns"]:
            continue
        column = f"{ext['name']}.angle[deg]" if ext["kind"] == "link" else f"{ext['name']}.value[m]"
        values = table[column]
        tol = 5e-5 if ext["kind"] == "link" else 1e-6  # the sweep misses an extreme by O(h²), h = 0.05°
        for key, at in (("minimum", "at_min"), ("maximum", "at_max")):
            assert 0 <= ext[at] < 360, column
            assert ext[key] == pytest.approx(values.min() if key == "minimum" else values.max(), abs=tol), column
            near = np.argmin(np.abs((phi - ext[at] + 180) % 360 - 180))  # the sample nearest where check says
            assert ext[key] == pytest.approx(values[near], abs=tol), column
        if ext["kind"] == "slider":
            assert ext["maximum"] - ext["minimum"] == pytest.approx(np.ptp(values), abs=2 * tol)


# -- the docs' bullets ------------------------------------------------------------------------------------
def test_balance_after_shaking_is_the_inertia_forces_alone():
    """fourbar_loaded has gravity: the counterweights on 1 and 3 balance its inertia forces fully, so the
    shaking force after is zero (it read 61.3 N, the machine's static weight m·g with the counterweights).
    Before: −Σ m·a_S of the coupler (2 kg) and rocker (1.5 kg) at ω = 10 rad/s, computed here by hand from
    the analysed centres' accelerations."""
    code, out, _ = run("balance", MODELS / "fourbar_loaded.toml", "--links", "1,3", "--json")
    doc = json.loads(out)
    assert code == 0 and doc["after"]["shaking_force_max"] < 1e-9 * doc["before"]["shaking_force_max"]
    engine = mbplanar.Engine(mbplanar.read_model(MODELS / "fourbar_loaded.toml"))
    phi = engine.phi_drawn[0] + np.linspace(0.0, 2 * math.pi, 360, endpoint=False)
    m = mbplanar.analyse(engine, phi)
    force = -(2.0 * m.a[:, m.point("S2")] + 1.5 * m.a[:, m.point("S3")])
    assert doc["before"]["shaking_force_max"] == pytest.approx(np.hypot(*force.T).max(), rel=1e-12)
    assert doc["before"]["shaking_force_rms"] == pytest.approx(np.sqrt(np.mean(np.sum(force ** 2, 1))), rel=1e-12)


def test_help_names_path_generation_under_synth():
    code, out, _ = run("--help")
    assert code == 0 and re.search(r"synth\s+synthesis: seed 001's guiding mechanism, function,\s+motion and path "
                                   r"generation", out)


def test_the_readme_picture_caption():
    """The README's shaper picture: −188.25 N·m at the model's ω, ε = 0, J_I = 0; `forces` without --omega
    takes the true motion and the flywheel and prints −102.06 N·m; docs/forces.md's split of the difference."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8") + (ROOT / "docs" / "forces.md").read_text(encoding="utf-8")
    shaper = MODELS / "shaper.toml"
    given = run("forces", shaper, "--at", "140.769", "--omega", "7.644542", "--epsilon", "0", "--json")[1]
    true = json.loads(run("forces", shaper, "--at", "140.769", "--json")[1])
    own = run("forces", shaper, "--at", "140.769", "--omega", true["input"]["omega"], "--epsilon",
              true["input"]["epsilon"], "--input-inertia", "0", "--json")[1]
    picture, own = json.loads(given)["balancing"]["O"], json.loads(own)["balancing"]["O"]
    flywheel = true["input"]["input_inertia"] * abs(true["input"]["epsilon"])
    assert f"{picture:.2f}".replace("-", "−") in readme and f"{true['balancing']['O']:.2f}".replace("-", "−") in readme
    assert f"ω = {true['input']['omega']:.4f} rad/s, ε = {true['input']['epsilon']:.4f}".replace("-", "−") in readme
    assert f"J_I = {true['input']['input_inertia']:.2f} kg·m²" in readme
    assert f"J_I·|ε| = {flywheel:.2f} N·m" in readme and f"by {own - picture:.2f} N·m" in readme
    assert own + flywheel == pytest.approx(true["balancing"]["O"], rel=1e-12)


# -- similar cases found beyond the examples ------------------------------------------------------
@pytest.mark.parametrize("args, expected", [
    (["--links", ""], "balance: give the links that get a counterweight (the moving links are 1, 2, 3)"),
    (["--links", "1,1"], "balance: link '1' is listed twice"),
    (["--links", "1,3", "--radius", "0.1,0.2,0.3"], "balance: 3 radii for 2 links: give one radius, or one per link"),
])
def test_balance_arguments(args, expected):
    code, _, err = run("balance", MODELS / "fourbar_loaded.toml", *args)   # (were a ValueError's words, or exit 0)
    assert code == 2 and one_line(err).endswith(expected)


def test_balance_without_masses():
    code, _, err = run("balance", MODELS / "fourbar.toml", "--links", "1")   # (printed 0 kg counterweights)
    assert code == 2 and "the model's links have no mass: nothing shakes the frame, nothing to balance" in one_line(err)


def test_dynamics_delta_at_a_zero_input_speed():
    """The squeezer's input has ω = 0: `dynamics --delta` divided by zero (a ZeroDivisionError)."""
    code, _, err = run("dynamics", MODELS / "squeezer.toml", "--delta", "0.1", "--steps", "36")
    assert code == 2 and "--delta without a [dynamics] section runs at the input's omega, which is 0 rad/s" in one_line(err)


def test_dynamics_at_gives_no_warning_of_its_own_positions(tmp_path):
    """A resistance idle over the cycle is warned about once, over the cycle's positions, not again over
    the two positions of `--at` (it said "does no work over the 2 positions")."""
    text = (ROOT / "tests" / "data" / "repro" / "whit_stroke_160.toml").read_text(encoding="utf-8").replace(
        "s = [-1, -0.9, -0.1, 0]", "s = [0, 0.1, 0.9, 1]")
    code, _, err = run("dynamics", write(tmp_path, text), "--delta", "0.05", "--steps", "72", "--at", "10,20")
    assert code == 0 and err.count("does no work") == 1 and "over the 73 positions" in err


@pytest.mark.parametrize("old, new, expected", [
    ('law = "constant_acceleration", k = 1.0, stroke = 0.045', 'law = "cycloid", stroke = 0.045',
     "[cam] phases[0]: unknown motion law 'cycloid'; did you mean 'cycloidal'?"),
    ('coordinate = "x", fraction = 0.05, direction = "rising"', 'coordinate = "z", fraction = 0.05, direction = "rising"',
     "[cam] events[0] 'fp1': timing: coordinate must be 'x' or 'y', got 'z'"),
])
def test_a_cam_file_error_names_the_file_and_row(tmp_path, old, new, expected):
    text = (MODELS / "shaper_cam.toml").read_text(encoding="utf-8")
    assert old in text
    write(tmp_path, (MODELS / "shaper.toml").read_text(encoding="utf-8"), "shaper.toml")
    path = write(tmp_path, text.replace(old, new, 1), "cam.toml")
    code, _, err = run("cam", path)
    assert code == 2 and one_line(err) == f"mbplanar: {path}: {expected}"


def test_a_table_header_above_the_lists(tmp_path):
    """`[plot]` written under `name = ...` takes the links and joints in (TOML): said so, not 'no joints'."""
    text = FOURBAR.replace('name = "fourbar_loaded"', 'name = "fourbar_loaded"\n[plot]\nscale = 1', 1)
    code, _, err = run("info", write(tmp_path, text))
    assert code == 2 and one_line(err).endswith("the 'joints' list is inside [plot]: a [table] header takes every key "
                                                "below it; move [plot] after the lists")


@pytest.mark.parametrize("model, far", [(MODELS / "crank_slider_rocker_locking.toml", "3"),
                                        (ROOT / "tests" / "data" / "double_rocker.toml", "100")])
def test_the_range_a_refusal_shows_can_be_asked_for(model, far):
    """The ends of 'the input moves within a … b' were rounded to the nearest digit, past the motion limit:
    `--at` with the value shown was refused (the engine resolves a position to ~3e-10 rad from a fold)."""
    code, _, err = run("solve", model, "--at", far)
    lo, hi = re.search(r"moves within (\S+) … (\S+) ", err).groups()
    assert code == 1
    for end in (lo, hi):
        assert run("solve", model, "--at", end)[0] == 0, end
