"""Every command on every bundled model (models/*.toml: linkages and cam files) with the documented options
that apply to it: each run ends with exit status 0 and output, or with exit status 1 or 2 and a one-line
message that says why the command does not apply; never a traceback, never a NaN in the output.

The commands run in this process through `mbplanar.cli.main` (no interpreter start per run), on small
grids (`--steps`, `--frames`, a low `--dpi`): the whole matrix takes about half a minute.
"""

import contextlib
import io
import math
import re
import tomllib
from pathlib import Path

import pytest

import mbplanar
from mbplanar.cli import main
from mbplanar.viz._plotting import FIGURES

MODELS = sorted((Path(__file__).resolve().parent.parent / "models").glob("*.toml"))
NAN = re.compile(r"\bnan\b|\binf\b", re.IGNORECASE)


def run(argv) -> tuple[int, str, str]:
    """`mbplanar ARGV` in this process: exit status, standard output, standard error."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue()


def _values(engine, shift=0.0) -> str:
    """Every input's drawn value (model unit), moved by `shift` × its sweep's width, comma-separated."""
    out = []
    for inp, phi in zip(engine.inputs, engine.phi_drawn):
        lo, hi = inp.default_sweep()
        out.append(f"{inp.from_si(phi) + shift * (hi - lo):.12g}")
    return ",".join(out)


def linkage_runs(path: Path, tmp: Path) -> list[tuple[list, bool]]:
    """(argv, must succeed) of every command and option that applies to the linkage model `path`."""
    engine = mbplanar.Engine(mbplanar.read_model(path))
    mech = engine.mech
    at, near = _values(engine), _values(engine, 0.02)
    speeds = ",".join(f"{inp.omega:g}" for inp in engine.inputs)
    first_link = mech.moving_links[0]
    first_point = next(iter(mech.points), next(iter(mech.joints)))
    m = str(path)
    several = len(engine.inputs) > 1
    runs = [
        (["info", m], True), (["info", m, "--json"], True), (["info", m, "--units", "model"], True),
        (["solve", m, "--at", at], True), (["solve", m, "--at", near, "--json", "--units", "model"], True),
        (["solve", m, "--at", at, "--omega", "2", "--epsilon", "1"], True),
        (["check", m, "--json", "--units", "model"] if several else ["check", m], True),
        (["forces", m, "--at", at], False), (["forces", m, "--at", near, "--json", "--units", "model"], False),
        (["forces", m, "--at", at, "--mu", "0.05"], False),
        (["forces", m, "--at", at, "--omega", "3", "--epsilon", "1", "--input-inertia", "0.5"], False),
        (["dynamics", m, "--steps", "36"], False),
        (["dynamics", m, "--steps", "36", "--delta", "0.1", "--at", at, "--json", "-o", tmp / "d.csv"], False),
        (["simulate", m, "--t", "0.005", "--steps", "2", "--omega", speeds], False),
        (["simulate", m, "--t", "0.005", "--steps", "2", "--omega", speeds, "--json", "-o", tmp / "s.csv"], False),
        (["balance", m, "--links", first_link], False), (["balance", m, "--links", first_link, "--json"], False),
        (["animate", m, "--frames", "2", "-o", tmp / "a.html"], True),
        (["report", m, "--frames", "2", "-o", tmp / "r.html"], True),
        (["cam", m], False),
        (["export", m, "--steps", "12", "-o", tmp / "e.svg"], True),
        (["export", m, "--at", near, "--steps", "12", "--paths", first_point, "-o", tmp / "e.dxf"], True),
    ]
    if not several:
        runs.append((["check", m, "--json", "--units", "model"], True))
    if several:
        start, stop = _values(engine, -0.01), _values(engine, 0.01)
        runs += [(["sweep", m, "--from", start, "--to", stop, "--steps", "3", "-o", tmp / "w.csv"], True),
                 (["sweep", m, "--from", start, "--to", stop, "--steps", "2", "--grid", "--units", "model"], True)]
    else:
        runs += [(["sweep", m, "--steps", "4", "-o", tmp / "w.csv"], False),
                 (["sweep", m, "--steps", "3", "--angles", "rad", "--forces", "yes", "--units", "model"], False),
                 (["sweep", m, "--from", at, "--to", near, "--step", "0.1" if "deg" in engine.inputs[0].unit
                   else "0.001", "--omega", "2"], False)]
        if mech.dynamics is not None:
            runs.append((["sweep", m, "--steps", "3", "--true-motion"], True))
    for what in pictures(path):
        extra = {"diagram": ["--show", "all"], "trajectories": ["--points", first_point]}.get(what, [])
        runs.append((["plot", m, what, "--dpi", "10", "-o", tmp / f"{what}.png"] + extra, what == "diagram"))
    runs.append((["plot", m, "diagram", "--at", near, "--dpi", "10", "-o", tmp / "at.svg"], True))
    if MODELS.index(path) % 3 == 0:  # (a GIF on every third model: the HTML animation draws the same frames)
        runs.append((["animate", m, "--frames", "2", "--dpi", "10", "-o", tmp / "a.gif"], True))
    return runs


#: pictures the report draws with the same function as `plot` (tests/test_plotting.py renders every one
#: on every model): `plot` takes two of them per model in turn, so that each goes through the command on
#: three or four of the models while the whole matrix stays near half a minute
REPORTED = ("vectors", "trajectories", "kinematics", "analogues", "transmission", "forces", "shaking")


def pictures(path: Path) -> list[str]:
    """The pictures `plot` draws of the model `path` here: every one but those of `REPORTED`, of which two."""
    k = 2 * MODELS.index(path) % len(REPORTED)
    turn = {REPORTED[k], REPORTED[(k + 1) % len(REPORTED)]}
    return [what for what in FIGURES if what not in REPORTED or what in turn]


def cam_runs(path: Path, tmp: Path) -> list[tuple[list, bool]]:
    """Every linkage command given the cam file `path` (each must point to `mbplanar cam`), and `cam`."""
    m = str(path)
    runs = [([command, m], False) for command in ("info", "check", "dynamics", "simulate")]
    runs += [(["solve", m, "--at", "10"], False), (["sweep", m, "--steps", "2"], False),
             (["forces", m, "--at", "10"], False), (["balance", m, "--links", "1"], False),
             (["plot", m, "diagram", "-o", tmp / "p.png"], False),
             (["animate", m, "-o", tmp / "a.html"], False), (["report", m, "-o", tmp / "r.html"], False),
             (["export", m, "-o", tmp / "e.svg"], False)]
    return runs + [(["cam", m], True), (["cam", m, "--json"], True)]


def _is_cam_file(path: Path) -> bool:
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    return "cam" in data and not data.get("joints")


def _written(argv) -> list[Path]:
    """The files a run writes (its -o, and --output)."""
    return [Path(argv[k + 1]) for k, a in enumerate(argv) if a in ("-o", "--output")]


@pytest.mark.parametrize("path", MODELS, ids=lambda p: p.stem)
def test_every_command_ends_with_output_or_a_one_line_reason(path, tmp_path):
    cam = _is_cam_file(path)
    runs = cam_runs(path, tmp_path) if cam else linkage_runs(path, tmp_path)
    failures = []
    for argv, must in runs:
        for target in _written(argv):
            target.unlink(missing_ok=True)
        code, out, err = run(argv)
        words = " ".join(map(str, argv))
        if "Traceback" in out + err:
            failures.append(f"{words}: a traceback")
        elif code == 0:
            files = _written(argv)
            if not (out.strip() or files) or any(not f.exists() or f.stat().st_size == 0 for f in files):
                failures.append(f"{words}: exit 0 without output")
            elif NAN.search(out):
                failures.append(f"{words}: NaN or inf in the output: {NAN.search(out).group()}")
        elif code in (1, 2):
            lines = err.strip().splitlines()
            if must or len(lines) != 1 or not lines[0].startswith("mbplanar: "):
                failures.append(f"{words}: exit {code} with {err.strip()!r}")
            elif cam and argv[0] != "cam" and "this is a cam file: use `mbplanar cam" not in lines[0]:
                failures.append(f"{words}: a cam file without the pointer to `mbplanar cam`: {lines[0]}")
            elif any(f.exists() for f in _written(argv)) and not (argv[0] == "sweep" and code == 1):
                # (a sweep stopped by a motion limit keeps the rows before it, as documented)
                failures.append(f"{words}: exit {code} but wrote {_written(argv)}")
        else:
            failures.append(f"{words}: exit {code}")
    assert not failures, "\n".join(failures)


def test_a_cam_file_given_to_a_linkage_command_points_to_cam():
    code, _, err = run(["solve", "models/shaper_cam.toml", "--at", "10"])
    assert code == 2 and err.strip() == ("mbplanar: models/shaper_cam.toml: this is a cam file: use "
                                         "`mbplanar cam models/shaper_cam.toml` (the linkage commands read a "
                                         "table of pairs)")


# -- two inputs: what report, plot, animate and dynamics mean (docs/multi_input.md) --------------------
FIVE_BAR = Path(__file__).resolve().parent.parent / "models" / "five_bar.toml"


def test_path_analogues_are_the_derivative_along_the_input_path():
    """The five-bar's analogues along its input path (both cranks over 0 … 360°, so dφ2/dφ1 = 1) against
    central differences of the positions along that path."""
    import numpy as np
    from mbplanar.viz._plotting import path_analogues, path_rates
    mech = mbplanar.read_model(FIVE_BAR)
    mech.inputs[1] = mbplanar.model.Input(**{**vars(mech.inputs[1]), "sweep": (100.0, 160.0)})  # half as fast
    engine = mbplanar.Engine(mech)
    rates = path_rates(engine)
    assert rates.tolist() == pytest.approx([1.0, 60.0 / 360.0], rel=1e-15)
    s = np.radians([70.0, 80.0, 95.0])[:, None]
    h = 1e-5
    phi = lambda d: np.column_stack([s[:, 0] + d, np.radians(110.0) + rates[1] * (s[:, 0] + d - np.radians(70.0))])  # noqa: E731
    motion = mbplanar.analyse(engine, phi(0.0))
    w, e, v, a = path_analogues(engine, motion)
    up, down = mbplanar.analyse(engine, phi(h)), mbplanar.analyse(engine, phi(-h))
    assert np.abs(v - (up.xy - down.xy) / (2 * h)).max() < 1e-9
    assert np.abs(a - (up.xy - 2 * motion.xy + down.xy) / h ** 2).max() < 1e-4
    assert np.abs(w - (np.unwrap(up.angle - down.angle)) / (2 * h)).max() < 1e-9


def test_two_inputs_through_report_plot_animate_and_dynamics(tmp_path):
    code, _, err = run(["report", FIVE_BAR, "--frames", "2", "-o", tmp_path / "r.html"])
    page = (tmp_path / "r.html").read_text(encoding="utf-8")
    assert code == 0, err
    assert "<th>phi1 [deg]</th><th>phi2 [deg]</th>" in page               # every input's column
    assert "along the input path: d/dphi1 with phi2 moving 1× as fast" in page
    assert "grid points (19 × 19) reached on the drawn branch" in page     # check's region
    assert "reduce a machine to its one crank" in page                    # the flywheel: one crank
    assert run(["plot", FIVE_BAR, "analogues", "--dpi", "10", "-o", tmp_path / "a.png"])[0] == 0
    assert run(["animate", FIVE_BAR, "--frames", "2", "-o", tmp_path / "a.html"])[0] == 0
    code, _, err = run(["dynamics", FIVE_BAR, "--delta", "0.05"])
    assert code == 2 and "reduces a machine to its one crank; this model has 2 inputs (phi1, phi2)" in err \
        and "`mbplanar simulate`" in err


def test_negative_values_after_an_option():
    """`--at -10,105` (issue 27): argparse took it for an option."""
    code, out, err = run(["solve", FIVE_BAR, "--at", "-10,105"])
    assert code == 0, err
    assert out.startswith("five_bar: phi1 = -10 deg")
    code, out, _ = run(["sweep", FIVE_BAR, "--from", "-10,100", "--to", "-5,105", "--steps", "1"])
    assert code == 0 and out.splitlines()[1].startswith("-10,100,") and out.splitlines()[2].startswith("-5,105,")
    assert math.isclose(float(run(["solve", "models/fourbar.toml", "--at", "-1e-3", "--json"])[1]
                              .split('"value": ')[1].split(",")[0]), -1e-3)
