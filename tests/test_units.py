"""One unit system: `length_unit` applies to every length of a table, inertia and moments follow
their own keys, speeds may be given in rpm; every command gives the same SI results whatever units a
model is written in, and prints its units.

The reproductions (tests/data/repro) are checked against closed forms written here from the drawings'
geometry, not against mbplanar's own output.
"""

import contextlib
import copy
import csv
import io
import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

import mbplanar
from mbplanar import analyse, kinetostatics
from mbplanar.cli import main

from conftest import linkage_models

HERE = Path(__file__).resolve().parent
MODELS = linkage_models()
REPRO = HERE / "data" / "repro"
REPROS = sorted(REPRO.glob("*.toml"))


# -- a scaler: the same model written in other units ------------------------------------------------
LENGTH = {"m": 1.0, "cm": 1e-2, "mm": 1e-3}


class _Lengths:
    """Scales lengths of a document by k: a number, or a parameter's name (its value in `[parameters]`
    is scaled once), or a polar placement `{from, length, angle}` (its length)."""

    def __init__(self, doc, k):
        self.params, self.k, self.done = doc.get("parameters", {}), k, set()

    def __call__(self, value):
        if isinstance(value, str):
            if value not in self.done:
                self.params[value] *= self.k
                self.done.add(value)
            return value
        if isinstance(value, dict):
            return {**value, "length": self(value["length"])}
        if isinstance(value, list):
            return [self(v) for v in value]
        return value * self.k


def _scaled_pair(value, k):
    return [v * k for v in value]


def _rescale_higher(row: dict, length):
    """A higher pair's lengths: its point (unless named), radii, module, radius, and its curve's centre,
    radius, points and a file's offset (a file of mbplanar cam is in mm whatever the model's unit)."""
    if isinstance(row.get("at"), list):
        row["at"] = length(row["at"])
    for key in ("radii", "module", "radius"):
        if key in row:
            row[key] = length(row[key])
    for key in ("profile", "path"):
        curve = row.get(key)
        if curve is None:
            continue
        for name in ("centre", "radius", "offset"):
            if name in curve:
                curve[name] = length(curve[name])
        if "points" in curve:
            curve["points"] = [length(p) for p in curve["points"]]


def rescale(doc: dict, unit: str) -> dict:
    """The TOML document `doc` rewritten with `length_unit = unit`: every length divided by the new
    unit's size; in mm also inertias in kg·mm² and moments in N·mm (the explicit keys)."""
    doc = copy.deepcopy(doc)
    k = LENGTH[doc.get("length_unit", "m")] / LENGTH[unit]
    doc["length_unit"] = unit
    ki = km = 1.0
    if unit == "mm":
        doc["inertia_unit"], doc["moment_unit"] = "kg*mm^2", "N*mm"
        ki, km = 1e6, 1e3
    length = _Lengths(doc, k)
    for link in _rows(doc, "links"):
        if "length" in link:
            link["length"] = length(link["length"])
        link["lengths"] = [[p, q, length(v)] for p, q, v in link.get("lengths", [])]
        if "inertia" in link:
            link["inertia"] *= ki
        if isinstance(link.get("centre"), list):
            link["centre"] = _scaled_pair(link["centre"], k)
    for joint in _rows(doc, "joints"):
        if joint["type"] in ("gear", "rack", "cam", "slot"):  # a higher pair: its places, radii and curve
            _rescale_higher(joint, length)
            continue
        joint["at"] = length(joint["at"])
    for point in _rows(doc, "points"):
        if "at" in point:
            point["at"] = length(point["at"])
        for key in ("distance", "offset"):
            if key in point:
                point[key] = length(point[key])
    prismatic_inputs = {}
    for inp in ([doc["input"]] if "input" in doc else doc.get("inputs", [])):
        joint = next(j for j in _rows(doc, "joints") if j["name"] == inp["joint"])
        if joint["type"].upper() == "P" and "unit" not in inp:   # its unit follows length_unit
            prismatic_inputs[inp["joint"]] = inp
            for key in ("zero", "drawn_at"):
                if key in inp:
                    inp[key] *= k
            if "sweep" in inp:
                inp["sweep"] = _scaled_pair(inp["sweep"], k)
    for load in doc.get("loads", []):
        if load.get("type") in ("spring", "damper", "torque"):  # elements between two links
            _rescale_element(load, k, km)
            continue
        if isinstance(load.get("at"), list):
            load["at"] = _scaled_pair(load["at"], k)
        if "stroke" in load:
            load["stroke"] *= k
        elif isinstance(load.get("s"), list):
            load["s"] = _scaled_pair(load["s"], k)
        if load.get("type") == "moment":
            load["moment"] *= km
        if "zero_at" in load and prismatic_inputs:
            load["zero_at"] *= k
    dyn = doc.get("dynamics")
    if dyn:
        for key in ("driving_moment", "motor_slope"):
            if key in dyn:
                dyn[key] *= km
        for key in ("shaft_inertia", "motor_inertia"):
            if key in dyn.get("flywheel", {}):
                dyn["flywheel"][key] *= ki
    return doc


def _rescale_element(load: dict, k: float, km: float):
    """A spring's or damper's ends and lengths in the new length unit; a torque's and a rotational
    damper's moments in the new moment unit (stiffness and linear damping stay SI)."""
    if isinstance(load.get("at"), list):
        load["at"] = [_scaled_pair(end, k) if isinstance(end, list) else end for end in load["at"]]
    for key in ("free_length",):
        if key in load:
            load[key] *= k
    if isinstance(load.get("length"), list):
        load["length"] = _scaled_pair(load["length"], k)
    if load["type"] == "torque" or (load["type"] == "damper" and "joint" in load):
        key = "moment" if load["type"] == "torque" else "damping"
        load[key] *= km


def _rows(doc, key):
    rows = doc.get(key, [])
    return list(rows.values()) if isinstance(rows, dict) else rows


def to_toml(doc: dict) -> str:
    """A TOML text of `doc`: one `key = value` line per top-level key, inline tables below."""
    return "\n".join(f"{_key(k)} = {_value(v)}" for k, v in doc.items()) + "\n"


def _key(k):
    return k if str(k).replace("_", "").isalnum() else json.dumps(str(k))


def _value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }"


# -- running the CLI in-process --------------------------------------------------------------------
def run(*argv) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue()


COMMANDS = ("info", "solve", "forces", "sweep", "check", "dynamics")


def _command_lines(path: Path, doc: dict, commands=COMMANDS) -> dict:
    """Each command's SI output (parsed) for the model file `path`: (exit status, document)."""
    engine = mbplanar.Engine(mbplanar.parse_model(copy.deepcopy(doc), str(path)))
    inp = engine.inputs[0]
    lo, hi = inp.default_sweep()
    at = lo + 0.3 * (hi - lo)
    if inp.drawn_at is not None:
        at = inp.drawn_at + 0.05 * (hi - lo)
    out = {}
    argsets = {
        "info": ["info", path, "--json"],
        "solve": ["solve", path, "--at", repr(at), "--json"],
        "forces": ["forces", path, "--at", repr(at), "--json"],
        "sweep": ["sweep", path, "--steps", "4", "--from", repr(at), "--to", repr(at + 0.1 * (hi - lo))],
        "check": ["check", path, "--json"],
        "dynamics": ["dynamics", path, "--steps", "36", "--json"],
    }
    for name in commands:
        code, text, _ = run(*argsets[name])
        if code == 0 and name == "sweep":
            rows = list(csv.reader(io.StringIO(text)))
            out[name] = (code, {h: [float(r[i]) if r[i] else None for r in rows[1:]]
                                for i, h in enumerate(rows[0])})
        else:
            out[name] = (code, json.loads(text) if code == 0 else None)
    return out


def _leaves(obj, path=()):
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield from _leaves(v, path + (k,))
    elif isinstance(obj, list):
        for k, v in enumerate(obj):
            yield from _leaves(v, path + (k,))
    else:
        yield path, obj


# Values that are round-off by nature (zero up to 1e-16 of the model's numbers), say which units a
# model was written in, or where `check` found an extreme that the motion reaches at two places
# (a tie broken by round-off: crank_slider_rocker_locking's link 3 at both ends of its range).
_SKIP = {"virtual_power_residual", "units", "value", "unit", "at_min", "at_max"}


_FORCE_KEYS = {"reactions", "balancing", "loads", "fx", "fy", "moment", "magnitude"}


def _group(path) -> str:
    """The kind of a leaf, for its tolerance: forces and moments together (a moment that is round-off
    is small next to the forces), else the leaf's own key (a CSV column by its unit)."""
    names = [p for p in path if isinstance(p, str)]
    if any(n in _FORCE_KEYS or "[N" in n for n in names):
        return "force"
    last = names[-1] if names else ""
    return last[last.find("["):] if "[" in last else last


def _same(a, b, where):
    """Every number of the two documents equal to a tight tolerance relative to its own kind (1e-8;
    1e-5 for the simulated steady state, whose secant iteration stops at |Δω| < 1e-7·ω_m)."""
    la, lb = dict(_leaves(a)), dict(_leaves(b))
    assert la.keys() == lb.keys(), where
    scale = {}
    for path, value in la.items():
        if isinstance(value, float):
            scale[_group(path)] = max(scale.get(_group(path), 0.0), abs(value))
    for path, x in la.items():
        y = lb[path]
        if any(p in _SKIP for p in path if isinstance(p, str)):
            continue
        if not (isinstance(x, float) or isinstance(y, float)):
            assert x == y, (where, path)
        elif x is None or y is None:
            assert x == y, (where, path)
        elif min(abs(x), abs(y)) < 1e8:   # larger: a point at infinity (an instant centre of a translation)
            tol = 1e-9 * scale[_group(path)] + 1e-12
            rel = 1e-5 if {"simulation", "delta_simulated"} & set(path) else 1e-8
            assert x == pytest.approx(y, rel=rel, abs=tol), (where, path, x, y)


@pytest.mark.parametrize("path", MODELS + REPROS, ids=lambda p: p.stem)
def test_scale_invariance_of_every_command(path, tmp_path):
    """The model in metres, in mm (with inertia in kg·mm² and moments in N·mm) and in cm: every
    command's JSON or CSV output is the same in SI units (in cm the cheaper commands only: the length
    scale is the same law, and the suite's time is counted)."""
    doc = tomllib.loads(path.read_text(encoding="utf-8"))
    for joint in _rows(doc, "joints"):   # a curve's file, relative to the model: where the copy can read it
        for key in ("profile", "path"):
            if "file" in joint.get(key, {}):
                joint[key]["file"] = str(path.parent / joint[key]["file"])
    results = {}
    for unit, commands in (("m", COMMANDS), ("mm", COMMANDS), ("cm", ("info", "solve", "forces", "sweep"))):
        scaled = rescale(doc, unit)
        file = tmp_path / f"{path.stem}_{unit}.toml"
        file.write_text(to_toml(scaled), encoding="utf-8")
        results[unit] = _command_lines(file, scaled, commands)
    for unit in ("cm", "mm"):
        for command, (other_code, other) in results[unit].items():
            code, value = results["m"][command]
            assert other_code == code, (path.stem, unit, command)
            if code == 0:
                _same(value, other, (path.stem, unit, command))


# -- the reproductions, against closed forms --------------------------------------------------------
def _engine(name):
    return mbplanar.Engine(mbplanar.read_model(REPRO / name))


def test_boom_load_at_coordinates_are_in_length_unit():
    """Boom O–A–T at 30°, cylinder C0 = (500, −200) mm to A (600 mm from O), 5 kN down at T (2000 mm
    from O): the cylinder force F balances the payload about O, F·(r_A × u) = 5000·x_T."""
    from scipy.optimize import brentq
    c0, length = np.array([0.5, -0.2]), 0.500385
    theta = brentq(lambda t: math.dist(0.6 * np.array([math.cos(t), math.sin(t)]), c0) - length, 0.3, 0.7)
    a = 0.6 * np.array([math.cos(theta), math.sin(theta)])
    u = (a - c0) / length
    force = 5000 * 2.0 * math.cos(theta) / (a[0] * u[1] - a[1] * u[0])      # 17066.02 N
    engine = _engine("boom_at_xy_mm.toml")
    motion = analyse(engine, np.array([length]), 0.0, 0.0)
    result = kinetostatics(engine, motion)
    # the payload's drawn point (1732.05, 1000) mm is a sketch point; 1e-6 covers its drafting error
    assert result.balancing["Cp"][0] == pytest.approx(force, rel=1e-6)
    code, out, _ = run("forces", REPRO / "boom_at_xy_mm.toml", "--at", "500.385", "--omega", "0", "--json")
    assert code == 0 and json.loads(out)["balancing"]["Cp"] == pytest.approx(force, rel=1e-6)


def _ram_x(phi):
    """Whitworth: ram position x_D (m) for crank angle φ (rad), from the drawing's dimensions."""
    a = 0.1 * np.array([np.cos(phi), np.sin(phi)])
    o4 = np.array([0.0, 0.04])
    t = np.arctan2(a[1] - o4[1], a[0] - o4[0])
    c = o4 - 0.08 * np.array([np.cos(t), np.sin(t)])
    return c[0] + np.sqrt(0.3 ** 2 - (c[1] - 0.04) ** 2)


def _derivative(f, x, h=1e-4):
    return (-f(x + 2 * h) + 8 * f(x + h) - 8 * f(x - h) + f(x - 2 * h)) / (12 * h)


@pytest.mark.parametrize("phi_deg", [200.0, 250.0, 300.0])
def test_whitworth_resistance_stroke_is_in_length_unit(phi_deg):
    """`stroke = 160` in a mm table is 0.16 m: the balancing moment (no inertia) is −F(s)·dx_D/dφ on
    the return stroke, s = x_D(φ) − x_D(156.42°), F the diagram [0, 2000, 2000, 0] at s/0.16 m =
    [−1, −0.9, −0.1, 0]."""
    phi = math.radians(phi_deg)
    s = _ram_x(phi) - _ram_x(math.radians(156.42))
    rate = _derivative(_ram_x, phi)
    size = np.interp(s, 0.16 * np.array([-1, -0.9, -0.1, 0]), [0, 2000, 2000, 0]) if rate <= 0 else 0.0
    expected = -size * rate
    engine = _engine("whit_stroke_160.toml")
    motion = analyse(engine, np.array([phi]), 2 * math.pi, 0.0)
    got = kinetostatics(engine, motion, inertia=False).balancing["O2"][0]
    assert got == pytest.approx(expected, rel=1e-8, abs=1e-9)
    assert abs(got) > 50.0 or phi_deg == 200.0    # the working stroke is loaded


def test_inertia_is_kg_m2_whatever_the_length_unit():
    """inertia = 0.01 means kg·m² in a mm table too: the balancing moment of a four-bar whose coupler
    (I = 0.01 kg·m², mass at the crank pin) is driven at constant ω₁ is I·ω₂·ε₂/ω₁ (the rate of its
    kinetic energy), ω₂, ε₂ by differentiating the closed-form coupler angle."""
    def coupler_angle(phi):
        a = 0.1 * np.array([math.cos(phi), math.sin(phi)])
        d = np.array([0.3, 0.0]) - a
        dist = math.hypot(*d)
        along = (0.3 ** 2 - 0.25 ** 2 + dist ** 2) / (2 * dist)
        b = a + along * d / dist + math.sqrt(0.3 ** 2 - along ** 2) * np.array([-d[1], d[0]]) / dist
        return math.atan2(b[1] - a[1], b[0] - a[0])
    phi, w1, h = math.radians(100.0), 10.0, 1e-3
    w2 = _derivative(coupler_angle, phi, h) * w1
    e2 = (-coupler_angle(phi + 2 * h) + 16 * coupler_angle(phi + h) - 30 * coupler_angle(phi)
          + 16 * coupler_angle(phi - h) - coupler_angle(phi - 2 * h)) / (12 * h * h) * w1 * w1
    expected = 0.01 * w2 * e2 / w1                                      # −0.00346948 N·m
    for name in ("inertia_mm.toml", "inertia_m.toml"):
        engine = _engine(name)
        assert engine.mech.links["2"].inertia == 0.01
        motion = analyse(engine, np.array([phi]), w1, 0.0)
        assert kinetostatics(engine, motion).balancing["O"][0] == pytest.approx(expected, rel=1e-7)


def test_inertia_unit_key_converts():
    text = (REPRO / "inertia_mm.toml").read_text().replace('length_unit = "mm"',
                                                           'length_unit = "mm"\ninertia_unit = "kg*mm^2"')
    text = text.replace("inertia = 0.01", "inertia = 10000.0")
    assert mbplanar.parse_model(text).links["2"].inertia == pytest.approx(0.01, rel=1e-15)


@pytest.mark.parametrize("text, message", [
    ('inertia_unit = "g*mm^2"', "inertia_unit must be one of"),
    ('moment_unit = "kN*m"', "moment_unit must be one of"),
    ('length_unit = "ft"', "length_unit must be one of"),
])
def test_unknown_unit_keys_are_refused(text, message):
    model = (REPRO / "inertia_m.toml").read_text().replace('ground = "0"', f'ground = "0"\n{text}')
    with pytest.raises(mbplanar.ModelError, match=message):
        mbplanar.parse_model(model, "t.toml")


def test_rpm_is_an_alternative_to_omega():
    base = (REPRO / "inertia_m.toml").read_text()
    mech = mbplanar.parse_model(base.replace("omega = 10.0", "rpm = 65"))
    assert mech.inputs[0].omega == pytest.approx(65 * 2 * math.pi / 60, rel=1e-15)
    with pytest.raises(mbplanar.ModelError, match="inputs\\[0\\].*either 'omega'.*or 'rpm'"):
        mbplanar.parse_model(base.replace("omega = 10.0", "omega = 10.0\nrpm = 65"), "t.toml")


def test_prismatic_input_unit_follows_length_unit():
    text = (REPRO / "boom_at_xy_mm.toml").read_text().replace("\nunit = \"mm\"\n", "\n")
    inp = mbplanar.parse_model(text).inputs[0]
    assert inp.unit == "mm" and inp.to_si(500.385) == pytest.approx(0.500385, rel=1e-15)


# -- output units -------------------------------------------------------------------------------------
def _json(*argv):
    code, out, err = run(*argv)
    assert code == 0, err
    return json.loads(out)


def test_model_units_output_is_si_divided_by_the_unit():
    """--units model: lengths in mm (×1000), speeds in mm/s, moments in N·mm, forces still N."""
    boom = REPRO / "boom_at_xy_mm.toml"
    si = _json("forces", boom, "--at", "520", "--json")
    mm = _json("forces", boom, "--at", "520", "--json", "--units", "model")
    assert si["units"]["length"] == "m" and mm["units"] == {**si["units"], "system": "model", "length": "mm",
                                                             "velocity": "mm/s", "acceleration": "mm/s^2"}
    assert mm["balancing"]["Cp"] == si["balancing"]["Cp"]
    for a, b in zip(si["loads"], mm["loads"]):
        assert (b["x"], b["y"], b["fx"]) == pytest.approx((1000 * a["x"], 1000 * a["y"], a["fx"]), rel=1e-15)
    assert mm["input"]["omega"] == pytest.approx(1000 * si["input"]["omega"], rel=1e-15)   # m/s → mm/s
    si = _json("solve", boom, "--at", "520", "--json")
    mm = _json("solve", boom, "--at", "520", "--json", "--units", "model")
    assert mm["points"]["T"]["ax"] == pytest.approx(1000 * si["points"]["T"]["ax"], rel=1e-15)
    assert mm["joints"]["Cp"]["value"] == pytest.approx(1000 * si["joints"]["Cp"]["value"], rel=1e-15)
    assert mm["links"]["boom"] == si["links"]["boom"]
    # analogues per mm of the input: dx/dL unchanged, d²x/dL² per mm
    assert mm["analogues"]["points"]["T"]["vx"] == pytest.approx(si["analogues"]["points"]["T"]["vx"], rel=1e-15)
    assert mm["analogues"]["points"]["T"]["ax"] == pytest.approx(si["analogues"]["points"]["T"]["ax"] / 1000,
                                                                 rel=1e-15)


def test_model_units_of_moments_and_inertia(tmp_path):
    """A shaper in mm with inertia in kg·mm² and moments in N·mm: --units model gives them back in
    those units; SI output is the model in metres'."""
    doc = tomllib.loads((MODELS[0].parent / "shaper.toml").read_text(encoding="utf-8"))
    path = tmp_path / "shaper_mm.toml"
    path.write_text(to_toml(rescale(doc, "mm")), encoding="utf-8")
    si = _json("dynamics", path, "--steps", "36", "--json", "--at", "30")
    mm = _json("dynamics", path, "--steps", "36", "--json", "--at", "30", "--units", "model")
    assert mm["units"]["moment"] == "N*mm" and mm["units"]["inertia"] == "kg*mm^2"
    assert mm["driving_moment"] == pytest.approx(1e3 * si["driving_moment"], rel=1e-14)
    assert mm["inertia_first_group"] == pytest.approx(1e6 * si["inertia_first_group"], rel=1e-14)
    assert mm["at"][0]["J_II"] == pytest.approx(1e6 * si["at"][0]["J_II"], rel=1e-14)
    assert mm["resistance_work"] == si["resistance_work"]                                  # J
    code, out, _ = run("dynamics", path, "--steps", "36", "--units", "model")
    assert code == 0 and "N·mm" in out and "kg·mm²" in out


@pytest.mark.parametrize("command", ["info", "solve", "forces", "check", "dynamics"])
def test_every_json_document_names_its_units(command):
    argv = [command, MODELS[0].parent / "shaper.toml", "--json"]
    if command in ("solve", "forces"):
        argv += ["--at", "30"]
    doc = _json(*argv, "--units", "model")
    assert doc["units"]["system"] == "model" and doc["units"]["force"] == "N"


def test_sweep_headers_follow_the_units():
    code, out, _ = run("sweep", MODELS[0].parent / "jansen.toml", "--steps", "2", "--units", "model")
    header = out.splitlines()[0].split(",")
    assert code == 0 and "O.x[cm]" in header and "O.ax[cm/s^2]" in header and "O.x[m]" not in header
    si = list(csv.reader(io.StringIO(run("sweep", MODELS[0].parent / "jansen.toml", "--steps", "2")[1])))
    cm = list(csv.reader(io.StringIO(out)))
    k = si[0].index("O.x[m]")
    assert float(cm[2][k]) == pytest.approx(100 * float(si[2][k]), rel=1e-11)
