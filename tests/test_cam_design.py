"""The cam command end to end: the seed's figures, sizing, timing from the linkage, files, forces,
bad input."""

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from mbplanar.cam import design, read_cam
from mbplanar.cam.dynamics import cam_forces
from mbplanar.cam.spec import DynamicsSpec, evaluate, parse_cam
from mbplanar.cli import main
from mbplanar.errors import ModelError

MODELS = Path(__file__).resolve().parent.parent / "models"
SHAPER_CAM = MODELS / "shaper_cam.toml"


@pytest.fixture(scope="module")
def seed_doc(capsys_module=None):
    from mbplanar.cam.present import _plain, document
    return _plain(document(design(read_cam(SHAPER_CAM))))


@pytest.fixture(scope="module")
def sized():
    return design(replace(read_cam(SHAPER_CAM), size=True))


def test_seed_design_figures(seed_doc):
    rise = seed_doc["phases"][0]
    assert round(rise["a_max"], 6) == 0.753706 and round(rise["v_max"], 6) == 0.184165
    assert round(seed_doc["v_max"], 6) == 0.184165
    assert round(seed_doc["follower"]["prime_radius"], 6) == 0.241791
    p = seed_doc["pressure_angle"]
    assert round(p["rise"]["extreme_deg"], 2) == 32.94 and round(p["return"]["extreme_deg"], 2) == -36.78
    assert not p["rise"]["exceeded"] and p["return"]["exceeded"]
    assert any("return" in w and "35" in w for w in seed_doc["warnings"])
    assert seed_doc["self_check"]["relative"] <= 1e-6
    ev = seed_doc["timing"]["events"]
    assert round(ev["fp1"]["value"], 3) == 28.0 and round(ev["fp2"]["value"], 3) == -23.684
    assert round(ev["ff_rab"]["value"], 3) == 221.538
    assert [r["direction"] for r in ev["fp1"]["roots"]] == ["falling", "rising"]
    assert abs(ev["fp1"]["stroke"] - 0.5) < 1e-9                      # H of the shaper


def test_sizing_gives_the_smallest_cam_meeting_both_limits(sized):
    lim = math.radians(35)
    assert abs(abs(sized.rise.value) - lim) < 1e-9 or abs(abs(sized.ret.value) - lim) < 1e-9
    assert abs(sized.rise.value) <= lim + 1e-9 and abs(sized.ret.value) <= lim + 1e-9
    assert sized.check.relative <= 1e-6
    r0 = sized.follower.prime_radius
    assert r0 < 0.241791                                           # smaller than the seed's cam
    # no neighbouring layout with a smaller r0 meets the limits: shrink a_w at every φ20 nearby
    from mbplanar.cam.design import pressure_extremes
    f, prog = sized.follower, sized.program
    phi = prog.grid(720)
    for dphi in np.radians([-1.0, -0.3, 0.0, 0.3, 1.0]):
        for scale in (0.999, 0.995):
            g = replace(f, arm_angle=f.arm_angle + dphi)
            g = replace(g, centre_distance=_a_w_for(g, scale * r0))
            rise, ret = pressure_extremes(g, prog, phi, lim, lim)
            assert max(abs(rise.value), abs(ret.value)) > lim


def _a_w_for(f, r0):
    """a_w that gives the roller-centre distance r0 at arm angle φ20 (the larger root)."""
    l, c = f.arm, math.cos(f.arm_angle)
    return l * c + math.sqrt(r0 ** 2 - l ** 2 * (1 - c * c))


def test_sizing_construction_data(sized):
    c = sized.sizing.construction
    v = sized.program.evaluate(sized.program.grid(3600))[1]
    assert c.curve.shape[1] == 2 and c.region.shape[0] >= 3
    # the seed's curve: x = −(l − v)cos ψ, y = (l − v) sin ψ
    s = sized.program.evaluate(np.array([0.2]))
    psi = s[0, 0] / 0.15
    assert np.isfinite(v).all() and abs(np.hypot(*c.centre) - sized.follower.centre_distance) < 1e-12
    del psi


def test_translating_sizing_meets_limits():
    spec = replace(read_cam(MODELS / "cam_roller.toml"), size=True, offset="free")
    d = design(spec)
    assert abs(abs(d.ret.value) - math.radians(35)) < 1e-9 or abs(abs(d.rise.value) - math.radians(30)) < 1e-9
    assert abs(d.rise.value) <= math.radians(30) + 1e-9 and abs(d.ret.value) <= math.radians(35) + 1e-9
    fixed = design(replace(spec, offset=0.0))
    assert fixed.follower.prime_radius >= d.follower.prime_radius - 1e-12   # a free offset never hurts


def test_flat_face_sizing():
    d = design(replace(read_cam(MODELS / "cam_flat.toml"), size=True))
    assert abs(d.geometry.rho_min - 0.005) < 1e-6 and np.all(d.geometry.rho_profile >= 0.005 - 1e-9)
    assert d.check.relative < 1e-6


def test_examples_self_check_and_envelope():
    for name in ("cam_roller", "cam_flat"):
        d = design(read_cam(MODELS / f"{name}.toml"))
        assert d.check.relative < 1e-6 and d.check.converged and not d.geometry.undercut


def test_forces_torque_by_power_and_by_moments():
    d = design(read_cam(MODELS / "cam_roller.toml"))
    fo, g = d.forces, d.geometry
    # the torque from the contact force's moment about the cam centre equals the power balance Q·v
    moment = g.contact_fixed[:, 0] * g.normal[:, 1] - g.contact_fixed[:, 1] * g.normal[:, 0]
    # contact on the pitch point's normal line: use the roller centre (the normal passes through it)
    b = g.contact_fixed + d.follower.roller * g.normal
    moment_b = b[:, 0] * g.normal[:, 1] - b[:, 1] * g.normal[:, 0]
    assert np.allclose(moment, moment_b, atol=1e-12)
    assert np.allclose(d.follower.rotation * fo.contact * moment, fo.torque, atol=1e-9 * np.abs(fo.torque).max())
    assert not fo.lift_off.any()
    fast = cam_forces(g, DynamicsSpec(speed=300.0, mass=0.8, spring_rate=2000, preload=40))
    assert fast.lift_off.any()
    d2 = design(replace(read_cam(MODELS / "cam_roller.toml"), dynamics=DynamicsSpec(300.0, 0.8, 2000, 40)))
    assert any("leaves the cam" in w for w in d2.warnings)


def test_cli_files(tmp_path, capsys, sized):
    ezdxf = pytest.importorskip("ezdxf")
    csv, dxf, svg = tmp_path / "p.csv", tmp_path / "p.dxf", tmp_path / "p.svg"
    assert main(["cam", str(SHAPER_CAM), "--size", "--json", "-o", str(csv), "--dxf", str(dxf),
                 "--svg", str(svg)]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["sized"] and doc["self_check"]["relative"] <= 1e-6
    d = sized
    rows = np.loadtxt(csv, delimiter=",", skiprows=1)
    assert np.allclose(rows[:, 4:6] * 1e-3, d.geometry.profile, atol=1e-9)
    from mbplanar.cam.export import dxf_chordal_error, dxf_deviation
    assert dxf_deviation(d.geometry, dxf) < 1e-6
    phi = d.geometry.phi
    mid = np.append(0.5 * (phi[:-1] + phi[1:]), 0.5 * (phi[-1] + 2 * np.pi))
    from mbplanar.cam.geometry import cam_geometry
    exact = cam_geometry(d.follower, mid, *d.program.evaluate(mid)[:3])
    assert dxf_chordal_error(dxf, exact.profile) < 1e-6              # what CAD draws, within 1 µm
    assert ezdxf.readfile(dxf).units == 4                            # millimetres
    assert svg.read_text().startswith("<svg") and "<path" in svg.read_text()


def test_cli_text_and_errors(tmp_path, capsys):
    assert main(["cam", str(SHAPER_CAM)]) == 0
    out = capsys.readouterr().out
    assert "+32.9400°" in out and "-36.7824°" in out and "warning" in out
    bad = tmp_path / "bad.toml"
    bad.write_text('[cam]\nfollower = "translating"\nbase_radius = 0.05\nroller = 0.01\nphases = [\n'
                   '{ kind = "rise", angle = 100, law = "cycloidal", stroke = 0.01 },\n'
                   '{ kind = "return", angle = 250, law = "cycloidal" }]\n')
    assert main(["cam", str(bad)]) == 2
    assert "add up to 350" in capsys.readouterr().err
    assert main(["cam", str(SHAPER_CAM), "--plot", "cam"]) == 2
    assert "--plot-output" in capsys.readouterr().err
    assert main(["cam", str(MODELS / "fourbar.toml")]) == 2
    assert "no [cam] section" in capsys.readouterr().err


@pytest.mark.parametrize("phases, message", [
    ('{ kind = "rise", angle = 100, law = "cycloidal", stroke = -0.01 }', "stroke must be positive"),
    ('{ kind = "rise", angle = 100, law = "bogus", stroke = 0.01 }', "unknown motion law"),
    ('{ kind = "rise", angle = "fp9", law = "cycloidal", stroke = 0.01 }', "unknown name 'fp9'"),
    ('{ kind = "jump", angle = 100 }', "kind must be"),
])
def test_bad_phases(phases, message):
    text = ('[cam]\nfollower = "translating"\nbase_radius = 0.05\nroller = 0.01\nphases = [' + phases
            + ', { kind = "return", angle = 100, law = "cycloidal" }, { kind = "dwell", angle = "rest" }]\n')
    import tomllib
    with pytest.raises(ModelError, match=message):
        design(parse_cam(tomllib.loads(text), "bad.toml"))


def test_limit_no_size_can_meet():
    spec = replace(read_cam(SHAPER_CAM), size=True, rise_limit=3.0, return_limit=3.0)
    with pytest.raises(ModelError, match="no size of the cam meets"):
        design(spec)


def test_roller_too_large_warns_with_numbers():
    from scipy.optimize import minimize_scalar

    from mbplanar.cam.geometry import cam_geometry
    d = design(replace(read_cam(SHAPER_CAM), roller_ratio=0.4))
    msg = next(w for w in d.warnings if "undercut" in w)

    def rho(x):
        return cam_geometry(d.follower, np.array([x]), *d.program.evaluate(np.array([x]))[:3]).rho_pitch[0]
    best = minimize_scalar(rho, bounds=(math.radians(15), math.radians(27)), method="bounded",
                           options={"xatol": 1e-10})
    assert abs(d.rho_min - best.fun) < 1e-9 and abs(d.rho_min_at - best.x) < 1e-4
    assert f"ρ_min = {best.fun:.6g}" in msg and "r = 0.0967" in msg


def test_swing_is_the_arc_over_the_arm():
    import tomllib
    data = tomllib.loads(SHAPER_CAM.read_text())
    data["cam"]["phases"][0] = {"kind": "rise", "angle": 28.0, "law": "constant_acceleration",
                                "swing": math.degrees(0.045 / 0.15)}
    del data["cam"]["model"], data["cam"]["events"], data["cam"]["start"], data["cam"]["window"]
    d = design(parse_cam(data, str(SHAPER_CAM)))
    assert abs(d.program.stroke - 0.045) < 1e-15
    data["cam"]["phases"][0]["stroke"] = 0.045
    with pytest.raises(ModelError, match="not both"):
        parse_cam(data, "x.toml")


def test_expressions():
    assert evaluate("abs(fp2) + 0.5*fp1 - 10", {"fp1": 28.0, "fp2": -23.684}, "x") == pytest.approx(27.684)
    with pytest.raises(ModelError, match="only numbers"):
        evaluate("__import__('os')", {}, "x")


def test_report_section(tmp_path):
    """A model with a [cam] section: the report's registered section shows the cam (same figures)."""
    pytest.importorskip("matplotlib")
    import mbplanar
    from mbplanar.cam import present
    from mbplanar.viz import _report as report
    present.register()
    assert "cam" in report.SECTIONS and list(report.SECTIONS).index("cam") == list(report.SECTIONS).index(
        "flywheel") + 1
    text = SHAPER_CAM.read_text().split("[cam]", 1)[1].replace('model = "shaper.toml"', "")
    model = tmp_path / "shaper_with_cam.toml"
    model.write_text((MODELS / "shaper.toml").read_text() + "\n[cam]" + text)
    engine = mbplanar.Engine(mbplanar.read_model(model))
    html = present.report_section(engine, report.ReportContext(engine, None, None, dpi=40))
    assert "+32.9400°" in html and html.count("<img") == 3
    plain = mbplanar.Engine(mbplanar.read_model(MODELS / "shaper.toml"))
    assert present.report_section(plain, None) is None


def test_pictures(tmp_path, sized):
    pytest.importorskip("matplotlib")
    from mbplanar.cam.plots import save_figure
    for what, suffix in (("motion", "png"), ("pressure", "png"), ("cam", "svg"), ("construction", "png"),
                         ("animation", "gif")):
        path = tmp_path / f"{what}.{suffix}"
        save_figure(sized, what, path, at=20.0, frames=4)
        assert path.stat().st_size > 1000
