"""Two degrees of freedom: a five-bar driven by both ground cranks, against the closed form."""

import math

import numpy as np

import mbplanar


def _fivebar():
    m = mbplanar.Mechanism("fivebar")
    for name in ("1", "2", "3"):
        m.add_link(name)
    m.add_link("4", angle=("E", "B"))  # crank EB: its angle is measured from E
    o, e = np.array([0.0, 0.0]), np.array([0.4, 0.0])
    a = o + 0.15 * np.array([math.cos(1.2), math.sin(1.2)])
    b = e + 0.15 * np.array([math.cos(1.9), math.sin(1.9)])
    # coupler point P: circle intersection, upper branch
    d = b - a
    dist = np.linalg.norm(d)
    along = dist / 2
    h = math.sqrt(0.35 ** 2 - along ** 2)
    p = a + along * d / dist + h * np.array([-d[1], d[0]]) / dist
    m.add_joint("O", "R", "0", "1", at=o)
    m.add_joint("A", "R", "1", "2", at=a)
    m.add_joint("P", "R", "2", "3", at=p)
    m.add_joint("B", "R", "3", "4", at=b)
    m.add_joint("E", "R", "0", "4", at=e)
    m.add_input("O", unit="rad", drawn_at=1.2)
    m.add_input("E", unit="rad", drawn_at=1.9)
    return m


def test_fivebar_two_inputs_closed_form():
    engine = mbplanar.Engine(_fivebar())
    assert engine.topology.dof == 2
    phi = np.array([[1.2, 1.9], [1.3, 1.8], [1.5, 1.7], [1.1, 2.1]])
    m = mbplanar.analyse(engine, phi, omega=[1.0, 0.5], epsilon=[0.0, 0.0])
    assert len(m.phi) == 4
    a = 0.15 * np.stack([np.cos(phi[:, 0]), np.sin(phi[:, 0])], -1)
    b = np.array([0.4, 0.0]) + 0.15 * np.stack([np.cos(phi[:, 1]), np.sin(phi[:, 1])], -1)
    d = b - a
    dist = np.linalg.norm(d, axis=-1)
    h = np.sqrt(0.35 ** 2 - (dist / 2) ** 2)
    p = a + d / 2 + h[:, None] * np.stack([-d[:, 1], d[:, 0]], -1) / dist[:, None]
    assert np.abs(m.xy[:, m.point("P")] - p).max() < 1e-9
    # velocity of P by central differences of the closed form along (omega1, omega2) = (1, 0.5)
    step = 1e-6
    m2 = mbplanar.analyse(engine, phi + step * np.array([1.0, 0.5]))
    m0 = mbplanar.analyse(engine, phi - step * np.array([1.0, 0.5]))
    fd = (m2.xy[:, m2.point("P")] - m0.xy[:, m0.point("P")]) / (2 * step)
    assert np.abs(m.v[:, m.point("P")] - fd).max() < 1e-6


# -- the two-input five-bar through every command ------------------------------------------------------
import json  # noqa: E402
import re  # noqa: E402
from pathlib import Path  # noqa: E402

import pytest  # noqa: E402

from mbplanar.cli import main  # noqa: E402

FIVE_BAR = Path(__file__).resolve().parent.parent / "models" / "five_bar.toml"
CRANK, COUPLER, GROUND = 0.15, 0.35, 0.4


def _p_closed_form(phi1, phi2, coupler=COUPLER):
    """P of the five-bar (upper branch) from the crank angles (rad), (B, 2)."""
    a = CRANK * np.stack([np.cos(phi1), np.sin(phi1)], -1)
    b = np.array([GROUND, 0.0]) + CRANK * np.stack([np.cos(phi2), np.sin(phi2)], -1)
    d = b - a
    dist = np.linalg.norm(d, axis=-1)
    h = np.sqrt(coupler ** 2 - (dist / 2) ** 2)
    return a + d / 2 + h[:, None] * np.stack([-d[:, 1], d[:, 0]], -1) / dist[:, None]


def _csv(text):
    lines = text.strip().splitlines()
    header = lines[0].split(",")
    rows = np.array([[float(x) if x else np.nan for x in line.split(",")] for line in lines[1:]])
    return header, rows


def test_sweep_path_and_grid(capsys):
    assert main(["sweep", str(FIVE_BAR), "--from", "60,100", "--to", "90,130", "--steps", "6"]) == 0
    header, rows = _csv(capsys.readouterr().out)
    assert header[:2] == ["phi1[deg]", "phi2[deg]"] and len(rows) == 7
    p = _p_closed_form(np.radians(rows[:, 0]), np.radians(rows[:, 1]))
    assert np.abs(rows[:, [header.index("P.x[m]"), header.index("P.y[m]")]] - p).max() < 1e-12
    assert main(["sweep", str(FIVE_BAR), "--from", "60,100", "--to", "90,130", "--steps", "3,2", "--grid"]) == 0
    header, rows = _csv(capsys.readouterr().out)
    assert len(rows) == 12  # (3 + 1) × (2 + 1), the first input varying slowest
    assert np.allclose(rows[:, 0], np.repeat([60, 70, 80, 90], 3)) and np.allclose(rows[:3, 1], [100, 115, 130])
    p = _p_closed_form(np.radians(rows[:, 0]), np.radians(rows[:, 1]))
    assert np.abs(rows[:, [header.index("P.x[m]"), header.index("P.y[m]")]] - p).max() < 1e-12
    assert main(["sweep", str(FIVE_BAR), "--from", "60", "--to", "90"]) == 2
    assert "needs 2 value(s)" in capsys.readouterr().err


def test_solve_json_partials_against_finite_differences(capsys):
    at = np.radians([75.0, 105.0])
    assert main(["solve", str(FIVE_BAR), "--at", "75,105", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    part = doc["partials"]
    assert part["inputs"] == ["phi1", "phi2"]
    h = 1e-4  # central differences of the closed form: error ~h² · third derivative ≈ 1e-9

    def p(d1, d2):
        return _p_closed_form(np.array([at[0] + d1]), np.array([at[1] + d2]))[0]

    first = [(p(h, 0) - p(-h, 0)) / (2 * h), (p(0, h) - p(0, -h)) / (2 * h)]
    second = {"phi1,phi1": (p(h, 0) - 2 * p(0, 0) + p(-h, 0)) / h ** 2,
              "phi2,phi2": (p(0, h) - 2 * p(0, 0) + p(0, -h)) / h ** 2,
              "phi1,phi2": (p(h, h) - p(h, -h) - p(-h, h) + p(-h, -h)) / (4 * h * h)}
    for name, fd in zip(("phi1", "phi2"), first):
        got = part["first"][name]["points"]["P"]
        assert np.allclose([got["x"], got["y"]], fd, atol=1e-8)
    for key, fd in second.items():
        got = part["second"][key]["points"]["P"]
        assert np.allclose([got["x"], got["y"]], fd, atol=2e-6), key
    # the cranks' own angles: ∂θ1/∂φ1 = 1, ∂θ1/∂φ2 = 0, no second derivatives
    assert part["first"]["phi1"]["links"]["1"] == pytest.approx(1.0)
    assert part["first"]["phi2"]["links"]["1"] == pytest.approx(0.0, abs=1e-15)
    assert part["second"]["phi1,phi2"]["links"]["4"] == pytest.approx(0.0, abs=1e-12)


def test_forces_one_balancing_moment_per_input(capsys):
    """Virtual work: the balancing moments M_k = −F·∂P/∂φ_k of the 100 N load at P."""
    assert main(["forces", str(FIVE_BAR), "--at", "75,105", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert [i["name"] for i in doc["inputs"]] == ["phi1", "phi2"]
    h = 1e-6
    at = np.radians([75.0, 105.0])
    force = np.array([0.0, -100.0])
    for joint, k in (("O", 0), ("E", 1)):
        d = np.zeros(2)
        d[k] = h
        dp = (_p_closed_form(*(at + d)[:, None]) - _p_closed_form(*(at - d)[:, None]))[0] / (2 * h)
        assert doc["balancing"][joint] == pytest.approx(-force @ dp, abs=1e-6)
    assert abs(doc["virtual_power_residual"]) < 1e-12


def test_plot_and_animate_at_two_values(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    out = tmp_path / "d.svg"
    assert main(["plot", str(FIVE_BAR), "diagram", "--at", "80,100", "-o", str(out)]) == 0
    assert "phi1 = 80 deg, phi2 = 100 deg" in out.read_text()
    assert main(["plot", str(FIVE_BAR), "diagram", "--at", "80", "-o", str(tmp_path / "x.svg")]) == 2
    assert not (tmp_path / "x.svg").exists()
    assert main(["animate", str(FIVE_BAR), "--frames", "4", "-o", str(tmp_path / "a.html")]) == 0
    assert "phi2 = " in (tmp_path / "a.html").read_text()


def test_check_region_and_its_singular_curve(tmp_path):
    """Couplers of 0.3 m: the region ends where A, P and B line up (|AB| = 0.6 m)."""
    text = FIVE_BAR.read_text().replace("length = 0.35", "length = 0.30")
    p = _p_closed_form(np.radians([70.0]), np.radians([110.0]), coupler=0.3)[0]
    text = re.sub(r'name = "P", type = "R", links = \["2", "3"\], at = \[[^\]]*\]',
                  f'name = "P", type = "R", links = ["2", "3"], at = [{float(p[0])!r}, {float(p[1])!r}]', text)
    path = tmp_path / "five_bar_short.toml"
    path.write_text(text)
    from mbplanar.analysis import check_region
    region = check_region(mbplanar.Engine(mbplanar.read_model(path)), samples=9)
    g1, g2 = np.meshgrid(np.radians(region.grid[0]), np.radians(region.grid[1]), indexing="ij")
    ab = np.hypot(GROUND + CRANK * (np.cos(g2) - np.cos(g1)), CRANK * (np.sin(g2) - np.sin(g1)))
    assert not region.reachable[ab > 0.6].any() and region.reachable.sum() > 0.7 * region.reachable.size
    folds = [s for s in region.singular if "A, P, B in line" in s.kind]
    assert folds
    for s in folds:
        a1, a2 = np.radians(s.at)
        dist = math.hypot(GROUND + CRANK * (math.cos(a2) - math.cos(a1)), CRANK * (math.sin(a2) - math.sin(a1)))
        assert dist == pytest.approx(0.6, abs=1e-9)
