"""Pictures: every model draws every picture; the drawing sits where the solver says; animations have
the requested frames; the report is one valid, offline HTML file (tests/test_browser.py opens it in a browser)."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

import mbplanar
from conftest import linkage_models
from mbplanar.forces import machine_dynamics
from mbplanar import analyse

pytest.importorskip("matplotlib")
from PIL import Image  # noqa: E402  (Pillow comes with the [plot] extra)

from mbplanar.viz import _plotting as plotting  # noqa: E402
from mbplanar.viz import html_animation  # noqa: E402
from mbplanar.cli import main  # noqa: E402
from mbplanar.viz import SECTIONS, register_section, report_html  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
MODELS = [str(p) for p in linkage_models()]


def engine(name):
    return mbplanar.Engine(mbplanar.read_model(ROOT / "models" / f"{name}.toml"))


def artists(fig, gid):
    return [a for ax in fig.axes for a in ax.get_children() if a.get_gid() == gid]


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    import matplotlib.pyplot as plt
    plt.close("all")


# -- every model, every picture ---------------------------------------------------------------------
@pytest.mark.parametrize("model", MODELS, ids=lambda p: Path(p).stem)
def test_every_model_renders_every_picture(model, tmp_path):
    eng = mbplanar.Engine(mbplanar.read_model(model))
    for what in plotting.FIGURES:
        if what == "dynamics" and len(eng.inputs) > 1:  # the flywheel of one crank
            with pytest.raises(mbplanar.ModelError, match=r"reduces a machine to its one crank; this model has 2"):
                plotting.make_figure(eng, what, count=13)
            continue
        missing = {"dynamics": "dynamics", "efficiency": "friction", "simulation": "simulate",
                   "accuracy": "tolerances"}.get(what)   # (accuracy: registered by `plot`, tests/test_accuracy.py)
        if missing and missing not in eng.mech.extras and not (what == "dynamics" and eng.mech.dynamics):
            with pytest.raises(mbplanar.ModelError, match=rf"no \[{missing}\] section"):
                plotting.make_figure(eng, what, count=13)
            continue
        options = plotting.show_options("all") if what == "diagram" else {}  # every arrow and centre
        fig = plotting.make_figure(eng, what, count=13, **options)
        fig.set_dpi(30)
        fig.canvas.draw()  # layout and every artist, as savefig does (writing files is tested by the CLI)
        pixels = np.asarray(fig.canvas.buffer_rgba())[..., :3]
        assert min(pixels.shape[:2]) > 50 and (pixels.min(axis=-1) < 100).mean() > 0.001, what  # not blank
    gif = tmp_path / "a.gif"
    plotting.write_gif(eng, gif, 3, dpi=30)
    with Image.open(gif) as im:
        assert im.n_frames == 3
    page = html_animation(eng, 4)
    assert "<svg" in page and "http" not in page


# -- content: the drawing is where the solver says ---------------------------------------------------
@pytest.mark.parametrize("name,at", [("fourbar", 123.0), ("shaper", 200.0), ("six_bar_press", 10.0)])
def test_joint_markers_sit_at_the_solved_positions(name, at):
    eng = engine(name)
    motion = analyse(eng, np.array([eng.inputs[0].to_si(at)]))
    fig = plotting.diagram_figure(eng, at)
    for j in eng.mech.joints.values():
        solved = motion.xy[0, motion.point(j.name)]
        if j.kind == "R":
            (marker,) = artists(fig, f"joint:{j.name}")
            np.testing.assert_allclose(marker.get_xydata()[0], solved, atol=1e-12)
        else:
            (block,) = artists(fig, f"slider:{j.name}")
            np.testing.assert_allclose(block.get_xy()[:4].mean(axis=0), solved, atol=1e-12)


def test_fourbar_diagram_keeps_the_link_lengths():
    """The drawn pins of the four-bar are the given lengths apart at any position (closed form)."""
    eng = engine("fourbar")
    for at in (0.0, 77.0, 250.0):
        fig = plotting.diagram_figure(eng, at)
        p = {n: artists(fig, f"joint:{n}")[0].get_xydata()[0] for n in "OABC"}
        assert math.dist(p["O"], p["A"]) == pytest.approx(0.10, abs=1e-12)
        assert math.dist(p["A"], p["B"]) == pytest.approx(0.30, abs=1e-12)
        assert math.dist(p["B"], p["C"]) == pytest.approx(0.25, abs=1e-12)
        angle = math.degrees(math.atan2(p["A"][1] - p["O"][1], p["A"][0] - p["O"][0]))
        assert (angle - at) % 360 == pytest.approx(0, abs=1e-9) or (angle - at) % 360 == pytest.approx(360)
        bar = artists(fig, "link:1")[0].get_xydata()
        assert {tuple(np.round(x, 12)) for x in bar} == {tuple(np.round(p["O"], 12)), tuple(np.round(p["A"], 12))}


def test_crank_pin_trajectory_is_a_circle():
    fig = plotting.trajectories_figure(engine("fourbar"), count=40)
    (line,) = artists(fig, "trajectory:A")
    xy = line.get_xydata()
    assert len(xy) == 41  # the closed curve: 40 positions and the first again
    np.testing.assert_allclose(np.linalg.norm(xy, axis=1), 0.10, atol=1e-12)


def test_trajectories_of_chosen_points_only(tmp_path):
    eng = engine("six_bar_press")
    fig = plotting.trajectories_figure(eng, points=["H", "S3"], count=12)
    traced = sorted(a.get_gid() for ax in fig.axes for a in ax.get_lines() if str(a.get_gid()).startswith("trajectory:"))
    assert traced == ["trajectory:H", "trajectory:S3"]
    press = str(ROOT / "models" / "six_bar_press.toml")
    assert main(["plot", press, "trajectories", "--points", "H,nowhere", "-o", str(tmp_path / "t.png")]) == 2
    assert main(["plot", press, "kinematics", "--points", "H", "-o", str(tmp_path / "t.png")]) == 2


def test_velocity_arrows_are_the_solved_velocities_to_one_scale():
    eng = engine("six_bar_press")
    motion = plotting.position_motion(eng, 40.0)
    fig = plotting.diagram_figure(eng, 40.0, vectors=("v",))
    (q,) = artists(fig, "vectors:v")
    scene = mbplanar.viz.build_scene(eng, motion)
    names = plotting.moving_points(eng, scene)
    v = motion.v[0, [motion.point(n) for n in names]]
    arrows = np.column_stack([q.U, q.V])
    k = arrows / np.where(np.abs(v) > 1e-9, v, np.nan)
    assert np.nanstd(k) < 1e-9 * np.nanmean(k)  # one scale for every point
    np.testing.assert_allclose(np.column_stack([q.X, q.Y]), motion.xy[0, [motion.point(n) for n in names]], atol=1e-12)


@pytest.mark.parametrize("name,at", [("shaper", 200.0), ("six_bar_press", 40.0)])
def test_reaction_arrows_point_along_the_computed_reactions(name, at):
    """One arrow per pair, from the pair's point along F_ij, one scale for all (model's input speed)."""
    from mbplanar.forces import kinetostatics
    eng = engine(name)
    motion = analyse(eng, np.array([eng.inputs[0].to_si(at)]), eng.inputs[0].omega, eng.inputs[0].epsilon)
    result = kinetostatics(eng, motion)
    fig = plotting.diagram_figure(eng, at, reactions=True, count=13)
    scales = []
    for joint, r in result.reactions.items():
        force = np.array([r.fx[0], r.fy[0]])
        (q,) = artists(fig, f"reaction:{joint}")
        np.testing.assert_allclose([q.X[0], q.Y[0]], motion.xy[0, motion.point(joint)], atol=1e-12)
        arrow = np.array([q.U[0], q.V[0]])
        assert abs(arrow[0] * force[1] - arrow[1] * force[0]) <= 1e-9 * np.linalg.norm(arrow) * np.linalg.norm(force)
        assert arrow @ force > 0  # the same way, not the opposite
        scales.append(np.linalg.norm(arrow) / np.linalg.norm(force))
    np.testing.assert_allclose(scales, scales[0], rtol=1e-9)
    biggest = max(np.hypot(r.fx[0], r.fy[0]) for r in result.reactions.values())
    assert biggest * scales[0] == pytest.approx(0.3 * eng.size)
    shown = " ".join(t.get_text() for t in fig.axes[0].texts)
    assert all(f"F{r.on}{r.source}" in shown for r in result.reactions.values())
    assert not artists(plotting.diagram_figure(eng, at, count=13), f"reaction:{joint}")  # only when asked


def test_a_model_without_loads_says_so():
    from mbplanar.viz import SECTIONS
    eng = engine("fourbar")
    fig = plotting.diagram_figure(eng, 30.0, reactions=True, count=13)
    assert not [a for a in fig.axes[0].get_children() if str(a.get_gid()).startswith("reaction:")]
    assert any("no masses" in t.get_text() for t in fig.axes[0].get_legend().get_texts())
    assert artists(plotting.forces_figure(eng, count=13), "noloads")
    assert "no loads" in SECTIONS["reactions"].function(eng, None)


def test_forces_plot_draws_the_reactions_against_the_coordinate():
    from mbplanar.forces import kinetostatics
    eng = engine("six_bar_press")
    fig = plotting.forces_figure(eng, count=24)
    inp = eng.inputs[0]
    reached = analyse(eng, inp.to_si(np.arange(24) * 15.0))  # the figure's positions, in degrees
    result = kinetostatics(eng, reached)
    magnitudes = {line.get_label(): line.get_xydata() for line in fig.axes[0].get_lines()}
    for joint, r in result.reactions.items():
        xy = magnitudes[f"F{r.on}{r.source} ({joint})"]
        np.testing.assert_allclose(xy[:, 0], np.arange(24) * 15.0, atol=1e-9)
        np.testing.assert_allclose(xy[:, 1], np.hypot(r.fx, r.fy), rtol=1e-9, atol=1e-9)
        (hodograph,) = artists(fig, f"hodograph:{joint}")
        np.testing.assert_allclose(hodograph.get_xydata(), np.column_stack([r.fx, r.fy]), rtol=1e-9, atol=1e-9)
    (balancing,) = artists(fig, f"balancing:{inp.joint}")
    np.testing.assert_allclose(balancing.get_xydata()[:, 1], result.balancing[inp.joint], rtol=1e-9, atol=1e-9)
    mean = [line for line in fig.axes[2].get_lines() if line.get_label().startswith("cycle mean")]
    assert mean and mean[0].get_ydata()[0] == pytest.approx(np.mean(result.balancing[inp.joint]))


def test_pressure_angle_of_the_slider_crank_by_the_sine_rule():
    eng = engine("slider_crank")
    j = eng.mech.joints
    r, rod = math.dist(j["O"].at, j["A"].at), math.dist(j["A"].at, j["B"].at)
    phi = np.radians([10.0, 75.0, 200.0, 300.0])
    (theta,) = plotting.pressure_series(eng, analyse(eng, phi)).values()
    np.testing.assert_allclose(theta, np.degrees(np.abs(np.arcsin(r * np.sin(phi) / rod))), atol=1e-9)


def test_kinematic_plot_shows_the_crank_turning_with_the_coordinate():
    eng = engine("fourbar")
    fig = plotting.kinematics_figure(eng, count=37)
    ax = fig.axes[0]
    line = next(line for line in ax.get_lines() if line.get_label() == "1")
    x, y = line.get_xydata().T
    np.testing.assert_allclose(np.diff(y), np.diff(x), atol=1e-9)  # φ1 = φ for the crank


def test_transmission_angle_of_the_fourbar_by_the_cosine_rule():
    eng = engine("fourbar")
    phi = np.radians([0.0, 90.0, 180.0])
    motion = analyse(eng, phi)
    (mu,) = plotting.transmission_series(eng, motion).values()
    O, C = np.array([0.0, 0.0]), np.array([0.3, 0.0])
    A = 0.1 * np.column_stack([np.cos(phi), np.sin(phi)])
    diag = np.linalg.norm(C - A, axis=1)  # A–C diagonal
    expected = np.degrees(np.arccos((0.3 ** 2 + 0.25 ** 2 - diag ** 2) / (2 * 0.3 * 0.25)))
    np.testing.assert_allclose(mu, expected, atol=1e-9)


# -- animations ---------------------------------------------------------------------------------------
def test_gif_has_the_requested_frames_over_a_full_turn(tmp_path):
    eng = engine("six_bar_press")
    motion = plotting.write_gif(eng, tmp_path / "press.gif", 7, dpi=30)
    with Image.open(tmp_path / "press.gif") as im:
        assert im.n_frames == 7
    step = np.diff(motion.phi[:, 0])
    np.testing.assert_allclose(step, 2 * math.pi / 7, rtol=1e-12)  # one cycle, no repeated end frame


def test_locking_model_animates_up_to_its_limit(tmp_path):
    eng = engine("crank_slider_rocker_locking")
    motion = plotting.write_gif(eng, tmp_path / "lock.gif", 5, dpi=30)
    with Image.open(tmp_path / "lock.gif") as im:
        assert im.n_frames == 5
    assert motion.limits and motion.phi[-1, 0] <= motion.limits[0].phi[0] + 1e-12


def test_html_animation_holds_every_frame_and_no_url():
    page = html_animation(engine("shaper"), 9)
    start = page.index('<script type="application/json">') + len('<script type="application/json">')
    data = json.loads(page[start:page.index("</script>", start)])
    assert data["frames"] == 9 and len(data["phi"]) == 9
    assert all(len(track) == 9 for track in data["xy"])
    assert "http" not in page and "<svg" in page


# -- report --------------------------------------------------------------------------------------------
class _Checker(HTMLParser):
    VOID = {"meta", "img", "input", "br", "hr", "link", "source", "col", "wbr", "area", "base", "embed"}
    SVG_VOID = {"polyline", "polygon", "circle", "line", "path", "rect"}

    def __init__(self):
        super().__init__()
        self.stack, self.errors, self.ids, self.urls = [], [], set(), []

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if "id" in attrs:
            self.ids.add(attrs["id"])
        for key in ("src", "href"):
            if key in attrs:
                self.urls.append(attrs[key])
        if tag not in self.VOID:
            self.stack.append(tag)

    def handle_startendtag(self, tag, attrs):
        self.handle_starttag(tag, attrs)
        if tag not in self.VOID:
            self.stack.pop()

    def handle_endtag(self, tag):
        if not self.stack or self.stack[-1] != tag:
            self.errors.append(f"</{tag}> closes <{self.stack[-1] if self.stack else None}>")
        else:
            self.stack.pop()


@pytest.fixture(scope="module")
def shaper_report():
    return report_html(engine("shaper"), positions=6, frames=6, dpi=40)


def test_report_is_valid_html_with_every_section_and_no_url(shaper_report):
    checker = _Checker()
    checker.feed(shaper_report)
    checker.close()
    assert not checker.errors and not checker.stack
    # the report's own sections (the cam's and the synthesis', registered by other tests, need their tables)
    own = {key for key, s in SECTIONS.items() if s.function.__module__ == "mbplanar.viz._report"}
    assert own <= checker.ids
    assert not [u for u in checker.urls if "http" in u]
    assert all(u.startswith(("data:image/png;base64,", "#")) for u in checker.urls)
    assert shaper_report.count("<img") >= 5


def test_report_tables_come_from_the_engine(shaper_report):
    eng = engine("shaper")
    s = eng.topology.structure
    assert f"W = {eng.topology.dof}" in shaper_report and s.formula in shaper_report
    for g in s.groups:
        assert ", ".join(g.links) in shaper_report
    assert "Flywheel: not computed yet" not in shaper_report
    d = machine_dynamics(eng)
    assert "Energy–mass method and flywheel" in shaper_report
    assert f"{d.inertia_first_group:.6g}" in shaper_report and f"{d.driving_moment:.6g}" in shaper_report


def _table(page, caption):
    """Rows (lists of cell strings) of the table with `caption` in an HTML page."""
    start = page.index(f"<caption>{caption}")
    body = page[start:page.index("</table>", start)]
    rows = body.split("<tbody>")[1].split("</tr>")
    return [[c.split("</td>")[0] for c in row.split("<td>")[1:]] for row in rows if "<td>" in row]


def test_report_motion_section_is_the_check_report(shaper_report):
    import html as html_module

    from mbplanar.analysis import check, format_report
    # line by line up to the first " at ": where a tied extreme is reached may differ in the last digit
    for line in html_module.escape(format_report(check(engine("shaper")))).splitlines():
        assert line.split(" at ")[0] in shaper_report
    assert "the input turns fully" in shaper_report


def test_report_reactions_are_the_kinetostatics_at_the_models_speed(shaper_report):
    from mbplanar.forces import kinetostatics
    eng = engine("shaper")
    section = shaper_report[shaper_report.index('<section id="reactions">'):]
    section = section[:section.index("</section>")]
    inp = eng.inputs[0]
    rows = _table(section, "Balancing load")
    values = np.array([float(r[0]) for r in rows])
    assert len(rows) == 6  # the table positions
    result = kinetostatics(eng, analyse(eng, inp.to_si(values), inp.omega, inp.epsilon))
    np.testing.assert_allclose([float(r[1]) for r in rows], result.balancing[inp.joint], rtol=1e-5, atol=1e-9)
    for joint, r in result.reactions.items():
        rows = _table(section, f"F{r.on}{r.source}: pair {joint} ")
        got = np.array([[float(c) if c != "—" else np.nan for c in row[1:5]] for row in rows])
        np.testing.assert_allclose(got[:, :3], np.column_stack([r.fx, r.fy, r.magnitude]), rtol=1e-5, atol=1e-6)
        big = r.magnitude > 1e-6
        turn = (got[big, 3] - r.direction_deg[big] + 180) % 360 - 180
        np.testing.assert_allclose(turn, 0, atol=1e-3)
    residual = float(section.split("the table is <b>")[1].split("</b>")[0])
    assert 0 <= residual < 1e-12
    assert section.count("<img") == 2  # the diagram with reaction arrows, the plots over the cycle


def test_report_hook_replaces_a_placeholder(monkeypatch):
    from mbplanar.viz import _report as report
    monkeypatch.setattr(report, "SECTIONS", dict(report.SECTIONS))
    register_section("reactions", "Reactions", lambda e, ctx: "<p>R12 = 42 N</p>")
    register_section("extra", "Extra", lambda e, ctx: None, after="plots")
    keys = list(report.SECTIONS)
    assert keys.index("extra") == keys.index("plots") + 1
    assert keys.index("reactions") == keys.index("animation") + 1 == keys.index("flywheel") - 1  # in place
    assert report.SECTIONS["reactions"].function(None, None) == "<p>R12 = 42 N</p>"


def test_a_registered_figure_is_a_what_of_the_plot_command(monkeypatch, tmp_path):
    monkeypatch.setattr(plotting, "FIGURES", dict(plotting.FIGURES))
    seen = []

    def picture(eng, at=None, **options):
        seen.append(at)
        return plotting.require_matplotlib().figure(figsize=(2, 2))

    plotting.register_figure("dynamics", picture, "a test picture")
    out = tmp_path / "d.png"
    assert main(["plot", str(ROOT / "models" / "fourbar.toml"), "dynamics", "--at", "30", "-o", str(out)]) == 0
    assert seen == [30.0] and out.stat().st_size > 0


# -- command line ----------------------------------------------------------------------------------------
def test_cli_writes_pictures_and_refuses_bad_requests(tmp_path, capsys):
    shaper = str(ROOT / "models" / "shaper.toml")
    assert main(["plot", shaper, "diagram", "--at", "100", "--dpi", "30", "-o", str(tmp_path / "d.svg")]) == 0
    svg = (tmp_path / "d.svg").read_text()
    assert svg.lstrip().startswith("<?xml") and 'id="reaction:' not in svg and 'id="vectors:' not in svg
    assert main(["plot", shaper, "diagram", "--at", "100", "--show", "velocities,reactions", "--dpi", "30",
                 "-o", str(tmp_path / "r.svg")]) == 0
    svg = (tmp_path / "r.svg").read_text()
    assert 'id="reaction:F"' in svg and 'id="vectors:v"' in svg and 'id="vectors:a"' not in svg
    assert main(["plot", shaper, "diagram", "--show", "speeds", "-o", str(tmp_path / "x.png")]) == 2
    assert "velocities, accelerations, reactions, centres" in capsys.readouterr().err
    assert main(["plot", shaper, "kinematics", "--show", "all", "-o", str(tmp_path / "x.png")]) == 2
    assert main(["animate", shaper, "--frames", "4", "-o", str(tmp_path / "a.html")]) == 0
    assert main(["plot", shaper, "diagram", "-o", str(tmp_path / "d.txt")]) == 2
    assert main(["plot", shaper, "nonsense", "-o", str(tmp_path / "d.png")]) == 2
    assert "diagram" in capsys.readouterr().err
    assert main(["animate", shaper, "--frames", "1", "-o", str(tmp_path / "a.gif")]) == 2


def test_cli_says_how_to_install_matplotlib(monkeypatch, tmp_path, capsys):
    for mod in [m for m in sys.modules if m == "matplotlib" or m.startswith("matplotlib.")]:
        monkeypatch.delitem(sys.modules, mod)
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    fourbar = str(ROOT / "models" / "fourbar.toml")
    for command in (["plot", fourbar, "diagram"], ["report", fourbar], ["animate", fourbar, "--frames", "3"]):
        suffix = {"plot": "png", "report": "html", "animate": "gif"}[command[0]]
        assert main(command + ["-o", str(tmp_path / f"x.{suffix}")]) == 2
        assert "pip install mbplanar[plot]" in capsys.readouterr().err
    assert main(["animate", fourbar, "--frames", "3", "-o", str(tmp_path / "a.html")]) == 0  # no matplotlib needed
    assert "<svg" in (tmp_path / "a.html").read_text()


def test_matplotlib_is_imported_only_for_a_picture():
    code = ("import sys, mbplanar, mbplanar.cli, mbplanar.viz\n"
            "from mbplanar.cli import main\n"
            "assert main(['info', 'models/fourbar.toml']) == 0\n"
            "assert not [m for m in sys.modules if m.split('.')[0] in ('matplotlib', 'PIL')], 'imported'\n")
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr


def test_dynamics_figure_draws_the_computed_curves():
    eng = engine("six_bar_press")
    d = machine_dynamics(eng, steps=360)
    fig = plotting.dynamics_figure(eng, 99.1, dynamics=d)
    axes = fig.axes
    by_label = {(k, line.get_label()): line for k, ax in enumerate(axes) for line in ax.get_lines()}
    np.testing.assert_allclose(by_label[(0, "J_II")].get_ydata(), d.J_II)
    np.testing.assert_allclose(by_label[(1, "pressing")].get_ydata(), d.reduced.moments["pressing"])
    np.testing.assert_allclose(by_label[(3, "ΔT_I = A_Σ − T_II")].get_ydata(), d.dT_I)
    np.testing.assert_allclose(by_label[(4, "energy–mass method")].get_ydata(), d.omega)
    np.testing.assert_allclose(by_label[(5, "simulated")].get_ydata(), d.simulation.epsilon)
    np.testing.assert_allclose(by_label[(4, "energy–mass method")].get_xdata(), np.degrees(d.phi))
    marks = [line for line in axes[0].get_lines() if np.allclose(line.get_xdata(), 99.1)]
    assert marks   # --at marks the position


def test_rocking_input_swings_between_its_dead_points_and_back():
    """A non-Grashof four-bar driven by a rocker (limits at ±91.79°): the pictures' cycle covers the
    whole range, up and back, so the trajectory's closing segment is one step, not a chord."""
    cycle_motion = plotting.cycle_motion
    data = Path(__file__).resolve().parent / "data" / "double_rocker.toml"
    engine = mbplanar.Engine(mbplanar.read_model(data))
    motion = cycle_motion(engine, 36)
    phi = np.degrees(motion.phi[:, 0])
    assert len(phi) == 36 and len(motion.limits) == 2
    assert phi.min() == pytest.approx(-91.79078466, abs=1e-6) and phi.max() == pytest.approx(91.79078466, abs=1e-6)
    assert np.argmax(phi) == 18 and np.all(np.diff(phi[:19]) > 0) and np.all(np.diff(phi[18:]) < 0)
    b = motion.xy[:, motion.point("B")]
    steps = np.linalg.norm(np.diff(np.vstack([b, b[:1]]), axis=0), axis=1)
    assert steps[-1] <= 1.01 * steps[:-1].max()
