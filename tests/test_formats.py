"""Formats: the JSON Schema of the table (generated from the keys the readers declare), the bundled examples,
the mechanism as CAD (DXF, SVG) and the importers from Pyslvs, PMKS+ and pylinkage.

The imported mechanisms are checked against closed forms of their own geometry (a four-bar's output by the
intersection of two circles, a slider-crank's stroke x = r·cos θ + √(l² − r²·sin² θ)), the live pylinkage
linkage against pylinkage's own simulation; the drawing against `solve`'s coordinates."""

import importlib.util
import json
import math
import tomllib
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

import mbplanar
from conftest import MODELS, linkage_models
from mbplanar.cli import main
from mbplanar.errors import ModelError

ROOT = Path(__file__).resolve().parent.parent
PEERS = ROOT / "tests" / "data" / "peers"


# -- the schema ----------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def schema():
    from mbplanar.formats.schema import model_schema
    return model_schema()


@pytest.fixture(scope="module")
def validator(schema):
    jsonschema = pytest.importorskip("jsonschema")
    jsonschema.Draft7Validator.check_schema(schema)
    return jsonschema.Draft7Validator(schema)


def test_the_shipped_schema_is_the_generated_one(schema, capsys):
    """The package's model.schema.json is what the generator makes of the declared keys (regenerate it
    with `python -m mbplanar.formats.schema` after changing a key), and `mbplanar schema` prints it."""
    from mbplanar.formats.schema import render, schema_text
    assert schema_text() == render(schema), "model.schema.json is stale: python -m mbplanar.formats.schema"
    assert main(["schema"]) == 0
    assert capsys.readouterr().out == schema_text()


@pytest.mark.parametrize("path", sorted(MODELS.glob("*.toml")), ids=lambda p: p.name)
def test_every_bundled_model_is_valid_under_the_schema(validator, path):
    doc = tomllib.loads(path.read_text(encoding="utf-8"))
    errors = [f"{list(e.absolute_path)}: {e.message}" for e in validator.iter_errors(doc)]
    assert not errors, errors


@pytest.mark.parametrize("mutate, where", [
    (lambda d: d.update(lenght=1), []),
    (lambda d: d["links"][0].update(lenght=1), ["links", 0]),
    (lambda d: d["joints"][0].update(type="Q"), ["joints", 0, "type"]),
    (lambda d: d["joints"][0].update(at=[0.0]), ["joints", 0, "at"]),
    (lambda d: d["input"].update(steps=0), ["input", "steps"]),
    (lambda d: d["links"][0].update(mass=-1.0), ["links", 0, "mass"]),
    (lambda d: d.update(loads=[{"type": "force", "link": "1", "force": [1, 2], "moment": 3}]), ["loads", 0]),
    (lambda d: d.update(gravity={"g": -1}), ["gravity", "g"]),
    (lambda d: d.pop("joints"), []),
    (lambda d: d.update(inputs=[{"joint": "O"}]), []),
])
def test_the_schema_refuses_what_the_reader_refuses(validator, mutate, where):
    doc = tomllib.loads((MODELS / "fourbar.toml").read_text())
    mutate(doc)
    with pytest.raises(ModelError):
        mbplanar.Engine(mbplanar.parse_model(doc, source="bad.toml"))
    errors = list(validator.iter_errors(doc))
    assert errors and any(list(e.absolute_path)[:len(where)] == where for e in errors), [e.message for e in errors]


def test_every_declared_key_is_in_the_schema_with_its_unit_and_default(schema):
    from mbplanar.formats.schema import sections
    from mbplanar.model._keys import MISSING
    for section in sections().values():
        props = schema["definitions"].get(section.name, schema)["properties"]
        for key in section.keys:
            assert key.name in props, (section.name, key.name)
            if key.kind in ("table", "rows"):
                continue
            if key.unit:
                assert props[key.name]["x-unit"] == key.unit
            if key.default is not MISSING and key.name != "type":
                assert props[key.name]["default"] == key.default, (section.name, key.name)


def _keys_read(monkeypatch, run):
    """(section, key) of every key the table readers read while `run` runs."""
    from mbplanar.cam import spec
    from mbplanar.model import _table
    seen = set()
    raw, value, get = _table.Row.raw, _table.Row._value, spec._Table.get

    def record(row, key):
        seen.add((row.section.name if row.section is not None else None, key))

    monkeypatch.setattr(_table.Row, "raw", lambda self, key, *a: (record(self, key), raw(self, key, *a))[1])
    monkeypatch.setattr(_table.Row, "_value", lambda self, key, *a: (record(self, key), value(self, key, *a))[1])
    monkeypatch.setattr(spec._Table, "get", lambda self, key, *a, **k: (record(self, key), get(self, key, *a, **k))[1])
    run()
    return seen


def test_every_key_the_reader_accepts_is_in_the_schema(schema, monkeypatch):
    """Every key the readers read while reading every bundled model and cam, and every table of the tests'
    data, is a property of its section in the schema (the reader refuses any key it does not read)."""
    from mbplanar.cam.spec import read_cam
    from mbplanar.forces import read_friction
    from mbplanar.forces._simulation import read_simulate

    def run():
        for path in sorted(MODELS.glob("*.toml")) + sorted((ROOT / "tests" / "data").rglob("*.toml")):
            doc = tomllib.loads(path.read_text(encoding="utf-8"))
            try:
                if "joints" in doc:
                    mech = mbplanar.parse_model(doc, source=str(path))
                    read_friction(mech, mu=0.1)
                    if "simulate" in mech.extras:
                        read_simulate(mech)
                if "cam" in doc:
                    read_cam(path)
            except mbplanar.MbplanarError:
                pass                            # (the tests' bad tables: their good keys still count)

    seen = _keys_read(monkeypatch, run)
    assert len(seen) > 60
    for section, key in seen:
        assert section is not None, key
        assert key in schema["definitions"].get(section, schema)["properties"], (section, key)


def test_reading_an_undeclared_key_is_a_programming_error():
    from mbplanar.model._keys import LINK
    from mbplanar.model._table import Row
    row = Row({"name": "1", "colour": "red"}, "links[0]", "t.toml", LINK)
    assert row.get("name") == "1"
    with pytest.raises(KeyError, match="'colour' is read but not declared"):
        row.raw("colour")


def test_the_format_page_lists_every_key_of_the_model_sections():
    from mbplanar.model._keys import (CURVE, DOCUMENT, DYNAMICS, FLYWHEEL, GRAVITY, HIGHER, INPUT, JOINT, LINK, LOADS,
                                      POINT)
    page = (ROOT / "docs" / "format.md").read_text(encoding="utf-8")
    keys = {k.name for s in (DOCUMENT, LINK, JOINT, POINT, INPUT, GRAVITY, DYNAMICS, FLYWHEEL, *LOADS.values(),
                             *HIGHER.values(), CURVE) for k in s.keys} - {"comment"}
    missing = sorted(k for k in keys if f"`{k}`" not in page and f"`flywheel.{k}`" not in page)
    assert not missing, missing


def test_a_model_names_the_schema_for_editors(tmp_path):
    """A `#:schema` comment (taplo, Even Better TOML) is a TOML comment: the reader ignores it."""
    text = "#:schema ./model.schema.json\n" + (MODELS / "fourbar.toml").read_text()
    from mbplanar.model import read_model_text
    assert read_model_text(text, "f.toml").joints.keys() == mbplanar.read_model(MODELS / "fourbar.toml").joints.keys()


# -- the bundled examples -------------------------------------------------------------------------------
def test_the_examples_are_the_models_folder():
    from mbplanar.formats import list_examples
    found = {e.file: e for e in list_examples()}
    on_disk = {str(p.relative_to(MODELS)) for p in MODELS.rglob("*") if p.suffix in (".toml", ".csv")}
    assert set(found) == on_disk
    assert found["fourbar.toml"].kind == "model" and found["fourbar.toml"].title == "Crank-rocker four-bar"
    assert found["cam_roller.toml"].kind == "cam"
    assert found["synthesis/motion_3poses.toml"].kind == "synthesis"
    assert found["fourbar.toml"].text() == (MODELS / "fourbar.toml").read_text(encoding="utf-8")
    if Path(mbplanar.__file__).resolve().parent == ROOT / "mbplanar":   # (this checkout: an editable install)
        examples = importlib.import_module("mbplanar.examples")
        assert Path(examples.__file__).resolve().parent == MODELS.resolve()            # the folder itself, no copy


def test_examples_are_listed_and_copied_out(tmp_path, capsys):
    assert main(["examples", "--json"]) == 0
    listed = json.loads(capsys.readouterr().out)
    assert {"name": "fourbar", "file": "fourbar.toml", "kind": "model", "title": "Crank-rocker four-bar"} in listed
    assert main(["examples", "shaper_cam", "crank_slider_rocker", "-o", str(tmp_path)]) == 0
    written = {Path(p).name for p in capsys.readouterr().out.split()}
    assert written == {"shaper_cam.toml", "shaper.toml", "crank_slider_rocker.toml", "crank_slider_rocker_variants.csv"}
    assert (tmp_path / "shaper.toml").read_text() == (MODELS / "shaper.toml").read_text()
    before = (tmp_path / "shaper.toml").stat().st_mtime_ns
    assert main(["examples", "shaper", "-o", str(tmp_path)]) == 2               # (no overwriting)
    assert "not overwriting" in capsys.readouterr().err
    assert (tmp_path / "shaper.toml").stat().st_mtime_ns == before
    assert main(["examples", "nosuch", "-o", str(tmp_path)]) == 2
    assert "no bundled example 'nosuch'" in capsys.readouterr().err
    assert main(["examples", "-o", str(tmp_path / "all")]) == 0
    assert (tmp_path / "all" / "synthesis" / "path_model.toml").is_file()


# -- export ------------------------------------------------------------------------------------------------
def _solve(model, at):
    import contextlib
    import io
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["solve", str(model), "--at", at, "--json"]) == 0
    return json.loads(out.getvalue())


@pytest.mark.parametrize("model", linkage_models(), ids=lambda p: p.stem)
def test_the_dxf_audits_clean_and_its_joint_circles_sit_where_solve_puts_the_joints(model, tmp_path, capsys):
    ezdxf = pytest.importorskip("ezdxf")
    mech = mbplanar.read_model(model)
    engine = mbplanar.Engine(mech)
    for step in (5.0, -5.0, 0.0):                    # (a position near the drawn one that the branch reaches)
        values = [float(i.from_si(v)) + step for i, v in zip(engine.inputs, engine.phi_drawn)]
        if len(mbplanar.analyse(engine, np.array([[i.to_si(v) for i, v in zip(engine.inputs, values)]])).phi):
            break
    at = ",".join(repr(v) for v in values)
    out = tmp_path / "m.dxf"
    assert main(["export", str(model), "--at", at, "-o", str(out), "--steps", "60"]) == 0, capsys.readouterr().err
    doc = ezdxf.readfile(out)
    audit = doc.audit()
    assert not audit.errors and not audit.fixes
    assert {"LINKS", "JOINTS", "GROUND", "LABELS"} <= {layer.dxf.name for layer in doc.layers}
    assert doc.units == {"m": 6, "cm": 5, "mm": 4}[mech.units.length]
    centres = np.array([tuple(c.dxf.center)[:2] for c in doc.modelspace().query("CIRCLE[layer=='JOINTS']")])
    solved = _solve(model, at)["points"]
    scale = mech.units.length_scale
    for name, joint in mech.joints.items():
        if joint.kind == "R":
            xy = np.array([solved[name]["x"], solved[name]["y"]]) / scale
            assert np.min(np.linalg.norm(centres - xy, axis=1)) <= 1e-9 * max(1.0, np.abs(xy).max()), name
    if any(j.kind == "P" for j in mech.joints.values()):
        assert doc.modelspace().query("LINE[layer=='GUIDES']")


def test_the_path_is_the_points_positions_over_the_cycle(tmp_path, engine_of):
    pytest.importorskip("ezdxf")
    from mbplanar.formats.sheet import drawing, sweep_values
    engine = engine_of("fourbar")
    sheet = drawing(engine, np.radians([30.0]), paths=["M", "B"], steps=72)
    paths = [data for kind, layer, data in sheet.entities if layer == "PATHS"]
    assert len(paths) == 2 and all(closed for _, closed, _ in paths)
    motion = mbplanar.analyse(engine, sweep_values(engine, np.radians([30.0]), 72)[:-1])
    for (pts, _, _), name in zip(paths, ["M", "B"]):
        assert pts.shape == (72, 2)
        assert np.allclose(pts, motion.xy[:, motion.point(name)], rtol=0, atol=1e-12)


def test_the_svg_has_a_group_per_layer_and_the_joints_turned_over(tmp_path, capsys):
    out = tmp_path / "s.svg"
    assert main(["export", str(MODELS / "slider_crank.toml"), "--at", "30", "-o", str(out)]) == 0
    root = ET.parse(out).getroot()
    ns = {"s": "http://www.w3.org/2000/svg"}
    groups = {g.get("id"): g for g in root.findall("s:g", ns)}
    assert {"LINKS", "JOINTS", "GUIDES", "GROUND", "LABELS"} <= set(groups)
    solved = _solve(MODELS / "slider_crank.toml", "30")["points"]
    circles = [(float(c.get("cx")), -float(c.get("cy"))) for c in groups["JOINTS"].findall("s:circle", ns)]
    for name in ("O", "A", "B"):
        assert min(math.dist(c, (solved[name]["x"], solved[name]["y"])) for c in circles) < 1e-9


@pytest.mark.parametrize("argv, code, words", [
    (["export", "MODEL", "--at", "30", "-o", "OUT.png"], 2, "written as .dxf or .svg"),
    (["export", "MODEL", "--at", "30,40", "-o", "OUT.svg"], 2, "--at needs 1 finite value"),
    (["export", "MODEL", "--at", "30", "--paths", "Q", "-o", "OUT.svg"], 2, "no joint or point 'Q'"),
])
def test_a_bad_export_says_why_and_writes_nothing(argv, code, words, tmp_path, capsys):
    out = tmp_path / Path(argv[-1]).name
    argv = [str(MODELS / "fourbar.toml") if a == "MODEL" else str(out) if a.startswith("OUT") else a for a in argv]
    assert main(argv) == code
    assert words in capsys.readouterr().err
    assert not out.exists()


def test_an_unreachable_position_is_a_motion_error(tmp_path, capsys):
    out = tmp_path / "x.svg"
    assert main(["export", str(MODELS / "crank_slider_rocker_locking.toml"), "--at", "180", "-o", str(out)]) == 1
    assert "cannot reach" in capsys.readouterr().err and not out.exists()


def test_dxf_without_ezdxf_names_the_extra(tmp_path, monkeypatch, capsys):
    import builtins
    real = builtins.__import__
    monkeypatch.setattr(builtins, "__import__", lambda name, *a, **k: (_ for _ in ()).throw(ImportError(name))
                        if name == "ezdxf" else real(name, *a, **k))
    assert main(["export", str(MODELS / "fourbar.toml"), "-o", str(tmp_path / "x.dxf")]) == 2
    assert "pip install 'mbplanar[cad]'" in capsys.readouterr().err


# -- import: closed forms of the imported mechanisms -----------------------------------------------------
def _imported(tmp_path, name, fmt=None):
    from mbplanar.formats import import_model
    imp = import_model(PEERS / name, fmt)
    path = tmp_path / "imported.toml"
    path.write_text(imp.text, encoding="utf-8")
    return imp, mbplanar.Engine(mbplanar.read_model(path))


def _circles(a, ra, b, rb, side):
    """The intersection of circles (a, ra) and (b, rb) on the `side` (+1 left of a→b, −1 right)."""
    d = np.linalg.norm(b - a, axis=-1, keepdims=True)
    k = (ra * ra - rb * rb + d * d) / (2 * d)
    h = np.sqrt(ra * ra - k * k)
    u = (b - a) / d
    n = np.stack([-u[..., 1], u[..., 0]], axis=-1)
    return a + k * u + side * h * n


def _four_bar_check(engine, o, a, b, c, crank, coupler_b, points=()):
    """Positions of the imported four-bar (pivots o, c; crank tip a; coupler joint b) against the circles'
    intersection, over a whole turn; points rigid with the coupler keep their distances to a and b."""
    o, a0, b0, c = (np.array(v, float) for v in (o, a, b, c))
    r = np.linalg.norm(a0 - o)
    side = np.sign((b0 - a0)[0] * (c - a0)[1] - (b0 - a0)[1] * (c - a0)[0])
    th = np.radians(np.arange(0.0, 360.0, 7.5))
    m = mbplanar.analyse(engine, th)
    assert len(m.phi) == len(th)
    scale = engine.mech.units.length_scale
    a_xy = o + r * np.stack([np.cos(th), np.sin(th)], axis=-1)
    b_xy = _circles(a_xy, np.linalg.norm(b0 - a0), c, np.linalg.norm(b0 - c), -side)
    assert np.allclose(m.xy[:, m.point(crank)] / scale, a_xy, rtol=0, atol=1e-9 * r)
    assert np.allclose(m.xy[:, m.point(coupler_b)] / scale, b_xy, rtol=0, atol=1e-9 * r)
    for name, p0 in points:
        p = m.xy[:, m.point(name)] / scale
        for q0, q in ((a0, a_xy), (b0, b_xy)):
            assert np.allclose(np.linalg.norm(p - q, axis=1), np.linalg.norm(np.array(p0) - q0), atol=1e-9 * r)


def _slider_check(engine, o, a, slider, tip="A", guide_y=0.0):
    """x of the slider of a central slider-crank: r·cos θ + √(l² − (r·sin θ − y_g)²)."""
    o, a = np.array(o, float), np.array(a, float)
    r = np.linalg.norm(a - o)
    th = np.radians(np.arange(0.0, 360.0, 10.0))
    m = mbplanar.analyse(engine, th)
    scale = engine.mech.units.length_scale
    s0 = engine.mech.joints[slider].at[0] / scale
    length = math.hypot(s0 - a[0], guide_y - a[1])
    x = r * np.cos(th) + np.sqrt(length ** 2 - (r * np.sin(th) - guide_y) ** 2)
    assert np.allclose(m.xy[:, m.point(slider)][:, 0] / scale, x, rtol=0, atol=1e-9 * r)
    assert np.allclose(m.xy[:, m.point(slider)][:, 1] / scale, guide_y, atol=1e-9 * r)


def test_a_pyslvs_project_becomes_the_four_bar_it_draws(tmp_path):
    imp, engine = _imported(tmp_path, "fourbar.pyslvs")
    assert imp.format == "pyslvs-yaml" and imp.table["length_unit"] == "mm" and imp.table["ground"] == "ground"
    assert any("no unit" in n for n in imp.notes) and any("colours" in n for n in imp.notes)
    assert imp.table["input"]["joint"] == "P0"
    _four_bar_check(engine, (0, 0), (30, 40), (120, 80), (100, 0), "P1", "P2", [("P3", (80, 110))])


def test_a_compressed_pyslvs_project_reads_the_same(tmp_path):
    yaml = pytest.importorskip("yaml")
    import re
    data = yaml.safe_load((PEERS / "fourbar.pyslvs").read_text())
    compressed = re.sub(r"\s\s+", " ", yaml.safe_dump(data, default_flow_style=True))   # Pyslvs' C_YAML
    (tmp_path / "c.pyslvs").write_text(compressed)
    from mbplanar.formats import import_model
    one, other = import_model(tmp_path / "c.pyslvs").table, import_model(PEERS / "fourbar.pyslvs").table
    assert {k: v for k, v in one.items() if k not in ("name", "title")} == {
        k: v for k, v in other.items() if k not in ("name", "title")}


@pytest.mark.parametrize("name", ["slider_crank.txt", "slider_crank_rp.txt"])
def test_pyslvs_sliders_p_and_rp_give_the_slider_crank(tmp_path, name):
    imp, engine = _imported(tmp_path, name)
    assert imp.format == "pyslvs" and any("no input" in n for n in imp.notes)
    slider = "P3" if name == "slider_crank.txt" else "P2"
    _slider_check(engine, (0, 0), (15, 25.9808), slider)
    kinds = sorted(j["type"] for j in imp.table["joints"])
    assert kinds == ["P", "R", "R", "R"]                     # RP: a block, a prismatic and a revolute pair


def test_a_pyslvs_slot_on_a_moving_link_slides_on_the_fixed_pin(tmp_path):
    """The slotted lever: a slot of L2 through the fixed pin C, L2 pinned to the crank at A; its angle is
    the direction A→C."""
    imp, engine = _imported(tmp_path, "slotted_lever.txt")
    th = np.radians(np.arange(0.0, 360.0, 15.0))
    m = mbplanar.analyse(engine, th)
    a = 30 * np.stack([np.cos(th), np.sin(th)], axis=-1)
    expect = np.arctan2(0 - a[:, 1], 100 - a[:, 0])
    got = m.frames.th[:, engine.link_index["L2"]] - m.frames.th[0, engine.link_index["L2"]] + expect[0]
    assert np.allclose(np.angle(np.exp(1j * (got - expect))), 0, atol=1e-9)


@pytest.mark.parametrize("name, fmt", [("slider_crank_pmks.csv", "pmks-csv"), ("slider_crank_pmks.txt", "pmks-link")])
def test_a_pmks_file_and_link_give_the_slider_crank_with_its_force(tmp_path, name, fmt):
    imp, engine = _imported(tmp_path, name)
    assert imp.format == fmt and imp.table["length_unit"] == "cm" and imp.table["inertia_unit"] == "kg*cm^2"
    _slider_check(engine, (0, 0), (1.5, 2.59808), "c")
    (load,) = engine.mech.loads
    assert load.link == "bc" and np.allclose(load.force, (0.0, 10.0)) and np.allclose(load.at, (0.06, 0.01))
    assert engine.mech.links["ab"].mass == pytest.approx(0.001)               # 1 g
    assert engine.mech.inputs[0].omega == 10.0 and any("rad/s" in n for n in imp.notes)


def _compact_link(rows) -> str:
    """A PMKS+ compact link as its encoder writes it: numbers ×1000 in base 64 (a leading 0 for a
    negative one), flags packed in base-64 characters, '.'-separated sections, the checksum last."""
    digits = "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz_-"

    def n64(v, pad=0):
        v = int(math.floor(v))
        out, neg, v = "", v < 0, abs(v)
        while True:
            out = digits[v % 64] + out
            v //= 64
            if v == 0:
                break
        out = ("0" + out) if neg else out
        return out.rjust(pad, "0")

    dec = lambda v: n64(round(v * 1000))  # noqa: E731
    flags = lambda bits: n64(sum(1 << i for i, b in enumerate(bits) if b), math.ceil(len(bits) / 6))  # noqa: E731
    joints = "".join(f"{flags([k == 'P', inp, gr, False, True])}{jid},{jid},{dec(x)},{dec(y)},{dec(ang)}."
                     for jid, k, x, y, gr, inp, ang in rows["joints"])
    links = "".join(f"Y{k}{lid},{lid},{dec(1)},{dec(1)},{dec(cx)},{dec(cy)},4488cc,{''.join(j + ',' for j in js)},."
                    for lid, k, cx, cy, js in rows["links"])
    body = (f"{flags([False] * 8)}.{dec(1)}.{n64(10)},{n64(0)}.{n64(1)}{n64(1)}{n64(1)}." + joints + "." + links
            + "." + "" + "." + "3_")
    return body + "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"[len(body) % 62]


def test_a_pmks_compact_link_gives_the_slider_crank(tmp_path):
    bx, by, cx = 1.5, 2.598, 1.5 + math.sqrt(100 - 2.598 ** 2)
    rows = {"joints": [("a", "R", 0, 0, True, True, 0), ("b", "R", bx, by, False, False, 0),
                       ("c", "R", cx, 0, False, False, 0), ("d", "P", cx, 0, True, False, 0)],
            "links": [("ab", "R", bx / 2, by / 2, ["a", "b"]), ("bc", "R", (bx + cx) / 2, by / 2, ["b", "c"]),
                      ("cd", "P", 0, 0, ["c", "d"])]}
    (tmp_path / "sc.pmks").write_text("https://app.pmksplus.com/?" + _compact_link(rows))
    from mbplanar.formats import import_model
    imp = import_model(tmp_path / "sc.pmks")
    assert imp.format == "pmks-link" and imp.table["length_unit"] == "cm"
    engine = mbplanar.Engine(mbplanar.parse_model(imp.table, "sc.toml"))
    _slider_check(engine, (0, 0), (bx, by), "c")
    (tmp_path / "cut.pmks").write_text(_compact_link(rows)[:-3] + "A")
    with pytest.raises(ModelError, match="not a PMKS\\+ link|does not read"):
        import_model(tmp_path / "cut.pmks")


def test_a_pylinkage_linkage_json_gives_the_four_bar_and_its_fixed_point(tmp_path):
    imp, engine = _imported(tmp_path, "fourbar_pylinkage.json")
    doc = json.loads((PEERS / "fourbar_pylinkage.json").read_text())
    at = {j["name"]: (j["x"], j["y"]) for j in doc["joints"]}
    _four_bar_check(engine, (0, 0), at["B"], at["D"], (3, 0), "B", "D", [("E", at["E"])])
    assert any("per simulation step" in n for n in imp.notes)


def test_a_pylinkage_prismatic_joint_slides_on_its_line(tmp_path):
    imp, engine = _imported(tmp_path, "slider_crank_pylinkage.json")
    doc = json.loads((PEERS / "slider_crank_pylinkage.json").read_text())
    a = next((j["x"], j["y"]) for j in doc["joints"] if j["name"] == "A")
    _slider_check(engine, (0, 0), a, "P")


def test_a_pylinkage_mechanism_json_gives_the_four_bar(tmp_path):
    imp, engine = _imported(tmp_path, "fourbar_mechanism.json")
    doc = json.loads((PEERS / "fourbar_mechanism.json").read_text())
    at = {j["id"]: j["position"] for j in doc["joints"]}
    _four_bar_check(engine, at["O"], at["B"], at["D"], at["C"], "B", "D")


@pytest.mark.skipif(importlib.util.find_spec("pylinkage") is None, reason="pylinkage not installed (extra bench)")
def test_a_live_pylinkage_linkage_moves_as_pylinkage_moves_it():
    """The live object's positions over pylinkage's own simulation (its crank turning 0.1 rad a step)
    against mbplanar's analysis of the imported model at the same crank angles."""
    from pylinkage.actuators import Crank
    from pylinkage.components import Ground
    from pylinkage.dyads import FixedDyad, RRRDyad
    from pylinkage.simulation import Linkage
    from mbplanar.formats import import_object
    o1, o2 = Ground(0.0, 0.0, name="O1"), Ground(3.0, 0.0, name="O2")
    crank = Crank(anchor=o1, radius=1.0, angular_velocity=0.1, name="A")
    rocker = RRRDyad(crank.output, o2, distance1=3.0, distance2=2.0, name="B")
    point = FixedDyad(crank.output, rocker, distance=1.2, angle=0.4, name="P")
    linkage = Linkage([o1, o2, crank, rocker, point], name="four-bar")
    list(linkage.step(iterations=1, dt=0))
    imp = import_object(linkage)
    engine = mbplanar.Engine(mbplanar.parse_model(imp.table, "live.toml"))
    steps = np.array(list(linkage.step(iterations=40)), float)              # (40, 5, 2)
    th = math.atan2(steps[0, 2, 1], steps[0, 2, 0]) + 0.1 * np.arange(40)
    m = mbplanar.analyse(engine, th)
    for k, name in ((2, "A"), (3, "B"), (4, "P")):
        assert np.allclose(m.xy[:, m.point(name)], steps[:, k], rtol=0, atol=1e-9), name


# -- import: what cannot be read is refused, and nothing is written ---------------------------------------
@pytest.mark.parametrize("name, text, words", [
    ("model.stl", "solid x", "unknown file type '.stl'"),
    ("bad.txt", "M[J[R, P[0, 0], L[ground, L1]],\n  J[Q, P[1, 1], L[L1]]]", "line 2, column 5: expected a joint type"),
    ("bad2.txt", "M[J[P, P[0, 0], L[ground, L1]]]", "A[angle]"),
    ("drive.yml", "mechanism: M[J[R, P[0, 0], L[ground, L1]], J[R, P[1, 0], L[L1, L2]], J[R, P[2, 1], L[L2, L3]], "
                  "J[R, P[3, 0], L[ground, L3]]]\ninput:\n- - 1\n  - 2\n", "not a ground pivot"),
    ("off.csv", "joints\nid,x,y,links,type,ground,angle,input\na,0,0,ab,R,true,Null,true\n"
                "b,1,1,ab|bc,R,false,Null,false\nc,3,0,bc,P,false,0,false\n", "prismatic joint off the ground"),
    ("line.json", json.dumps({"joints": [
        {"type": "Static", "name": "O", "x": 0, "y": 0}, {"type": "Static", "name": "C", "x": 4, "y": 0},
        {"type": "Crank", "name": "A", "x": 1, "y": 0, "joint0": {"ref": "O"}, "distance": 1, "angle": 0.1},
        {"type": "Revolute", "name": "B", "x": 3, "y": 1, "joint0": {"ref": "A"}, "joint1": {"ref": "C"},
         "distance0": 2.236, "distance1": 1.414},
        {"type": "Prismatic", "name": "S", "x": 2, "y": 3, "joint0": {"ref": "A"}, "joint1": {"ref": "O"},
         "joint2": {"ref": "B"}, "revolute_radius": 3.2}]}), "which no one link holds"),
    ("rigid.txt", "M[J[R, P[0, 0], L[ground, L1]], J[R, P[1, 0], L[ground, L1]]]", "refused"),
])
def test_an_unreadable_peer_file_is_named_and_nothing_is_written(tmp_path, capsys, name, text, words):
    src, out = tmp_path / name, tmp_path / "out.toml"
    src.write_text(text, encoding="utf-8")
    assert main(["import", str(src), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert words in err and str(src) in err and "Traceback" not in err
    assert not out.exists()


def test_a_pyslvs_project_without_pyyaml_names_the_extra(tmp_path, monkeypatch, capsys):
    import builtins
    real = builtins.__import__
    monkeypatch.setattr(builtins, "__import__", lambda name, *a, **k: (_ for _ in ()).throw(ImportError(name))
                        if name == "yaml" else real(name, *a, **k))
    assert main(["import", str(PEERS / "fourbar.pyslvs"), "-o", str(tmp_path / "m.toml")]) == 2
    assert "pip install 'mbplanar[yaml]'" in capsys.readouterr().err and not (tmp_path / "m.toml").exists()


def test_the_import_command_writes_the_model_and_says_what_it_left_out(tmp_path, capsys):
    out = tmp_path / "m.toml"
    assert main(["import", str(PEERS / "slider_crank_pmks.csv"), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert "note: the input speed 10 taken as rad/s" in err
    text = out.read_text()
    assert text.startswith("# Imported from slider_crank_pmks.csv (a PMKS+ CSV file)") and "# - " in text
    assert main(["solve", str(out), "--at", "30"]) == 0


def test_every_imported_model_is_valid_under_the_schema(validator):
    from mbplanar.formats import import_model
    for path in sorted(PEERS.iterdir()):
        if path.suffix in (".yml", ".pyslvs") and importlib.util.find_spec("yaml") is None:
            continue
        table = import_model(path).table
        assert not list(validator.iter_errors(tomllib.loads(import_model(path).text))), path.name
        assert table["joints"]


# -- packaging -------------------------------------------------------------------------------------------
def test_the_all_extra_installs_every_extra_and_the_version_is_written_once():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    extras = project["optional-dependencies"]
    (everything,) = extras["all"]
    named = set(everything.split("[", 1)[1].rstrip("]").split(","))
    assert named == set(extras) - {"all"}
    assert "version" not in project and "version" in project["dynamic"]
    assert mbplanar.__version__ == importlib.metadata.version("mbplanar")


import importlib.metadata  # noqa: E402  (for the test above)
