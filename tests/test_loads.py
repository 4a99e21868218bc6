"""Load laws, each on its own, against values computed another way (point kinematics, np.interp of the
seed's diagram), and the checks of the `loads` rows."""

import tomllib
from pathlib import Path

import numpy as np
import pytest

import mbplanar
from mbplanar.forces import evaluate_loads
from mbplanar.forces._loads import read_loads


def _engine(path, loads=None, gravity=None):
    """The model at `path` with its `loads` rows and `[gravity]` replaced (through the table reader)."""
    doc = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    if loads is not None:
        doc["loads"] = loads
    if gravity is not None:
        doc["gravity"] = gravity
    elif loads is not None:
        doc.pop("gravity", None)
    return mbplanar.Engine(mbplanar.parse_model(doc, str(path)))


def _one(engine, motion):
    """The model's load rows evaluated without gravity."""
    return evaluate_loads(engine, motion, gravity=False)


PHI = np.radians(np.arange(0.0, 360.0, 7.5))


def test_constant_force_moves_with_its_point():
    engine = _engine("models/fourbar.toml", [{"type": "force", "link": "2", "at": "M", "force": [3.0, -4.0]}])
    motion = mbplanar.analyse(engine, PHI[:10])
    (ld,) = _one(engine, motion)
    np.testing.assert_allclose(ld.force, np.tile([3.0, -4.0], (10, 1)))
    np.testing.assert_allclose(ld.point, motion.xy[:, motion.point("M")], atol=1e-12)
    assert ld.link == engine.link_index["2"] and np.all(ld.moment == 0)


def test_force_at_drawn_coordinates():
    """[x, y] is the material point at those coordinates in the exact drawn pose (here: B's)."""
    exact_b = list(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")).mech.joints["B"].at)
    engine = _engine("models/fourbar.toml", [{"type": "force", "link": "3", "at": exact_b, "force": [1, 0]}])
    motion = mbplanar.analyse(engine, PHI[:5])
    (ld,) = _one(engine, motion)
    np.testing.assert_allclose(ld.point, motion.xy[:, motion.point("B")], atol=1e-12)


def test_weight_along_gravity_direction():
    engine = _engine("models/fourbar.toml", [{"type": "weight", "link": "2", "at": "M", "weight": 90}])
    motion = mbplanar.analyse(engine, PHI[:3])
    np.testing.assert_allclose(_one(engine, motion)[0].force, np.tile([0.0, -90.0], (3, 1)), atol=1e-12)
    engine = _engine("models/fourbar.toml", [{"type": "weight", "link": "2", "at": "M", "weight": 90}],
                     gravity={"g": 9.81, "direction": 0.0})
    np.testing.assert_allclose(_one(engine, motion)[0].force, np.tile([90.0, 0.0], (3, 1)), atol=1e-12)


def test_moment():
    engine = _engine("models/fourbar.toml", [{"type": "moment", "link": "3", "moment": -7.5}])
    motion = mbplanar.analyse(engine, PHI[:4])
    (ld,) = _one(engine, motion)
    np.testing.assert_allclose(ld.moment, -7.5)
    np.testing.assert_allclose(ld.force, 0.0)


def test_gravity_on_heavy_links_at_their_centres():
    engine = _engine("models/shaper.toml", [], gravity={"g": 9.81})
    motion = mbplanar.analyse(engine, PHI)
    loads = evaluate_loads(engine, motion)
    by_link = {engine.links[ld.link]: ld for ld in loads}
    assert set(by_link) == {"3", "5"}
    np.testing.assert_allclose(by_link["3"].force[:, 1], -196.2)   # G3 of REFERENCE.md
    np.testing.assert_allclose(by_link["5"].force[:, 1], -637.65)  # G5
    np.testing.assert_allclose(by_link["3"].point, motion.xy[:, motion.point("S3")], atol=1e-12)


def test_shaper_cutting_force_diagram():
    """F_Cx = −fP(s_D) with s_D = x_D(f) − x_D(0) only while v_qDx > 0 (REFERENCE.md, seed 000)."""
    engine = mbplanar.Engine(mbplanar.read_model("models/shaper.toml"))
    rows = read_loads(engine.mech)
    motion = mbplanar.analyse(engine, PHI)
    cutting = evaluate_loads(engine, motion, loads=rows[:1], gravity=False)[0]
    xd = motion.xy[:, motion.point("D"), 0]
    xd0 = mbplanar.analyse(engine, np.array([0.0])).xy[0, motion.point("D"), 0]
    SS = 0.5 * np.array([0, 0.05, 0.2, 0.75, 0.85, 0.95, 1])
    PP = np.array([0, 0, 1100, 1100, 2000, 0, 0])
    working = motion.vq[:, motion.point("D"), 0] > 0
    expected = np.where(working, -np.interp(xd - xd0, SS, PP), 0.0)
    np.testing.assert_allclose(cutting.force[:, 0], expected, atol=1e-6)
    np.testing.assert_allclose(cutting.force[:, 1], 0.0, atol=1e-9)
    np.testing.assert_allclose(cutting.point[:, 1], 0.322103 - 0.095, atol=1e-6)
    assert working.any() and (~working).any() and np.any(expected < -1500)
    # at the reference position f = 140.769 the diagram gives 1100 N (REFERENCE.md: reduced −191.172)
    m = mbplanar.analyse(engine, np.radians([140.769]))
    f = evaluate_loads(engine, m, loads=rows[:1], gravity=False)[0].force[0, 0]
    assert f * m.vq[0, m.point("D"), 0] == pytest.approx(-191.172, rel=1e-4)


def test_friction_opposes_the_slider_velocity():
    engine = mbplanar.Engine(mbplanar.read_model("models/shaper.toml"))
    motion = mbplanar.analyse(engine, PHI)
    friction = evaluate_loads(engine, motion, loads=read_loads(engine.mech)[1:2], gravity=False)[0]
    vx = motion.vq[:, motion.point("D"), 0]
    np.testing.assert_allclose(friction.force[:, 0], -170.0 * np.sign(vx))
    np.testing.assert_allclose(friction.point[:, 1], 0.322103, atol=1e-6)


def test_constant_resistance_on_one_stroke():
    """Seed 003: 9000 N on H opposing +x only while v_qHx >= 0."""
    engine = mbplanar.Engine(mbplanar.read_model("models/six_bar_press.toml"))
    motion = mbplanar.analyse(engine, PHI)
    rows = [ld for ld in read_loads(engine.mech) if ld.kind == "resistance"]
    (res,) = evaluate_loads(engine, motion, loads=rows, gravity=False)
    vx = motion.vq[:, motion.point("H"), 0]
    np.testing.assert_allclose(res.force[:, 0], np.where(vx >= 0, -9000.0, 0.0))
    assert (vx >= 0).any() and (vx < 0).any()
    np.testing.assert_allclose(res.point, motion.xy[:, motion.point("Hp")], atol=1e-12)


def test_backward_stroke_pushes_the_other_way():
    loads = [{"type": "resistance", "joint": "F", "force": 50.0, "when": "backward"}]
    engine = _engine("models/shaper.toml", loads)
    motion = mbplanar.analyse(engine, PHI)
    (ld,) = _one(engine, motion)
    vx = motion.vq[:, motion.point("D"), 0]
    np.testing.assert_allclose(ld.force[:, 0], np.where(vx <= 0, 50.0, 0.0))


@pytest.mark.parametrize("row,words", [
    ({"type": "rocket", "link": "2"}, "'type' must be one of"),
    ({"type": "force", "link": "9", "force": [1, 0]}, "'9' is not a moving link"),
    ({"type": "force", "link": "2", "force": [1]}, "'force' must be [x, y]"),
    ({"type": "force", "link": "2", "force": [1, 0], "colour": 3}, "unknown key(s) colour"),
    ({"type": "force", "link": "2", "at": "S5", "force": [1, 0]}, "is on link '5'"),
    ({"type": "moment", "link": "3", "moment": "1+2"}, "'moment' must be a number"),
    ({"type": "resistance", "joint": "A", "force": 10}, "not a prismatic joint"),
    ({"type": "resistance", "joint": "F", "s": [0, 1], "force": [1, 2, 3]}, "equal length"),
    ({"type": "resistance", "joint": "F", "s": [0, 1, 1], "force": [1, 2, 3]}, "increase strictly"),
    ({"type": "resistance", "joint": "F", "force": 10, "when": "sometimes"}, "'when' must be one of"),
    ({"type": "friction", "joint": "F"}, "missing 'force'"),
])
def test_bad_rows_name_the_row(row, words):
    """A bad row fails when the table is read (not later, in the force analysis)."""
    with pytest.raises(mbplanar.ModelError) as info:
        _engine("models/shaper.toml", [{"type": "moment", "link": "3", "moment": 1.0}, row])
    assert str(info.value).startswith("models/shaper.toml: loads[1]") and words in str(info.value)


def test_bad_gravity():
    with pytest.raises(mbplanar.ModelError, match="gravity: 'g' must be a number"):
        _engine("models/shaper.toml", [], gravity={"g": "9.81"})


def test_cli_reports_bad_loads_with_exit_2(tmp_path, capsys):
    from mbplanar.cli import main
    text = open("models/shaper.toml").read().replace('"friction"', '"frictoin"')
    path = tmp_path / "bad.toml"
    path.write_text(text)
    assert main(["forces", str(path), "--at", "140"]) == 2
    err = capsys.readouterr().err
    assert "loads[1]" in err and "Traceback" not in err
