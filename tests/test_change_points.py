"""Change points (Grashof's equality s + l = p + q): two assembly branches cross where all links line
up. The engine must go straight through on the smooth branch (never stop as at a dead point, never
jump to the crossing branch), give finite rates there, and report where the change points are."""

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import mbplanar
from mbplanar.cli import main

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))
from closed_forms import circle_meet  # noqa: E402  (the dyad's closed form)


def fourbar(crank, coupler, rocker, ground, phi_deg, crossed=False):
    """A four-bar O-A-B-C (ground O(0,0), C(ground, 0)) drawn exactly at crank angle phi_deg, on the
    open (B above the line AC) or crossed assembly."""
    a = np.array([crank * math.cos(math.radians(phi_deg)), crank * math.sin(math.radians(phi_deg))])
    c = np.array([ground, 0.0])
    b = circle_meet(a[None], c[None], coupler, rocker, +1 if not crossed else -1)[0]
    m = mbplanar.Mechanism("changepoint")
    for name in ("1", "2", "3"):
        m.add_link(name)
    m.add_joint("O", "R", "0", "1", at=(0.0, 0.0))
    m.add_joint("A", "R", "1", "2", at=tuple(a))
    m.add_joint("B", "R", "2", "3", at=tuple(b))
    m.add_joint("C", "R", "3", "0", at=tuple(c))
    m.add_input("O", unit="rad")
    return m


def closed_form_rocker_angles(crank, coupler, rocker, ground, phi):
    """Both roots of the rocker's angle for crank angles phi (B,): (2, B); the direction of its
    reference line B → C (its first two revolute joints, as the engine reports it)."""
    a = np.stack([crank * np.cos(phi), crank * np.sin(phi)], -1)
    c = np.array([ground, 0.0])
    out = []
    for side in (+1, -1):
        b = circle_meet(a, np.broadcast_to(c, a.shape), coupler, rocker, side)
        out.append(np.arctan2(c[1] - b[:, 1], c[0] - b[:, 0]))
    return np.array(out)


def wrap(x):
    return (x + np.pi) % (2 * np.pi) - np.pi


@pytest.mark.parametrize("direction", [+1, -1])
def test_parallelogram_stays_a_parallelogram_through_its_change_points(direction):
    engine = mbplanar.Engine(fourbar(1.0, 2.0, 1.0, 2.0, 60.0))
    phi = engine.phi_drawn[0] + direction * np.radians(np.arange(0.0, 721.0, 0.5))
    m = mbplanar.analyse(engine, phi)
    assert m.success and len(m.phi) == len(phi)
    coupler, rocker = m.link("2"), m.link("3")
    assert np.abs(wrap(m.angle[:, coupler])).max() < 1e-11          # the coupler translates
    assert np.abs(wrap(m.angle[:, rocker] - np.pi - m.phi[:, 0])).max() < 1e-11  # rocker (line B→C) ∥ crank
    assert np.abs(m.wq[:, coupler]).max() < 1e-9
    assert np.abs(m.wq[:, rocker] - 1).max() < 1e-9
    assert np.abs(m.eq).max() < 1e-7
    # the change points: the crank in line with the ground, every half turn, located to 1e-9 rad
    found = np.sort([c.phi[0] for c in m.crossings])
    expected = np.arange(math.ceil(phi.min() / np.pi), math.floor(phi.max() / np.pi) + 1) * np.pi
    assert len(found) == len(expected)
    assert np.abs(found - expected).max() < 1e-9
    assert all(set(c.links) == {"2", "3"} for c in m.crossings)


def test_antiparallelogram_keeps_its_crossed_branch():
    crank, coupler, rocker, ground = 1.0, 2.0, 1.0, 2.0
    engine = mbplanar.Engine(fourbar(crank, coupler, rocker, ground, 60.0, crossed=True))
    phi = engine.phi_drawn[0] + np.radians(np.arange(0.0, 360.5, 0.5))
    m = mbplanar.analyse(engine, phi)
    assert m.success
    roots = closed_form_rocker_angles(crank, coupler, rocker, ground, m.phi[:, 0])
    theta = m.angle[:, m.link("3")]
    err = np.abs(wrap(roots - theta[None, :])).min(axis=0)
    assert err.max() < 1e-9                                     # always one of the two assemblies
    parallel = np.abs(wrap(theta - np.pi - m.phi[:, 0])) < 1e-6
    assert parallel.sum() <= 2                                  # and not the parallelogram (but at the change points)
    h = np.diff(m.phi[:, 0])
    fd = wrap(np.diff(theta)) / h                               # smooth: rates = derivative of the angle
    mid = 0.5 * (m.wq[1:, m.link("3")] + m.wq[:-1, m.link("3")])
    assert np.abs(fd - mid).max() < 1e-4 * (1 + np.abs(mid).max())


def test_general_change_point_fourbar_goes_through_smoothly():
    crank, coupler, rocker, ground = 2.0, 3.0, 3.0, 4.0        # s + l = 6 = p + q
    engine = mbplanar.Engine(fourbar(crank, coupler, rocker, ground, 90.0))
    phi = engine.phi_drawn[0] + np.radians(np.arange(0.0, 360.25, 0.25))
    m = mbplanar.analyse(engine, phi)
    assert m.success
    assert len(m.crossings) == 1 and abs(wrap(m.crossings[0].phi[0] - np.pi)) < 1e-9  # all links in line
    roots = closed_form_rocker_angles(crank, coupler, rocker, ground, m.phi[:, 0])
    theta = m.angle[:, m.link("3")]
    assert np.abs(wrap(roots - theta[None, :])).min(axis=0).max() < 1e-9
    # smooth through the change point: the first analogue is the derivative of the angle, and the
    # second that of the first (central differences on the 0.25° grid)
    h = np.radians(0.25)
    w, e = m.wq[:, m.link("3")], m.eq[:, m.link("3")]
    assert np.abs(wrap(theta[2:] - theta[:-2]) / (2 * h) - w[1:-1]).max() < 1e-4
    assert np.abs((w[2:] - w[:-2]) / (2 * h) - e[1:-1]).max() < 1e-3
    assert np.all(np.isfinite(m.eq)) and np.abs(m.eq).max() < 10


def test_drawn_at_a_change_point_is_an_error_naming_the_group():
    with pytest.raises(mbplanar.MotionError, match="singular position of the group of links 2, 3"):
        mbplanar.Engine(fourbar(1.0, 2.0, 1.0, 2.0, 0.0)).atlas()


def test_check_and_sweep_report_change_points(tmp_path, capsys):
    path = tmp_path / "parallelogram.toml"
    path.write_text("""
name = "parallelogram"
ground = "0"
links = [ { name = "1" }, { name = "2" }, { name = "3" } ]
joints = [
  { name = "O", type = "R", links = ["0", "1"], at = [0.0, 0.0] },
  { name = "A", type = "R", links = ["1", "2"], at = [0.5, 0.8660254037844386] },
  { name = "B", type = "R", links = ["2", "3"], at = [2.5, 0.8660254037844386] },
  { name = "C", type = "R", links = ["3", "0"], at = [2.0, 0.0] },
]
[input]
joint = "O"
""")
    report = mbplanar.check(mbplanar.Engine(mbplanar.read_model(path)))
    assert report.full_turn and not report.limits
    assert sorted(round(c.phi, 6) for c in report.change_points) == [180.0, 360.0]
    assert main(["sweep", str(path), "--step", "45", "-o", str(tmp_path / "out.csv")]) == 0
    assert "change point at phi = 180 deg" in capsys.readouterr().err
    rows = np.genfromtxt(tmp_path / "out.csv", delimiter=",", names=True)
    assert len(rows) == 9 and np.all(np.isfinite(rows.view((float, len(rows.dtype.names)))))


@settings(max_examples=40, deadline=None)
@given(st.floats(0.2, 1.0), st.floats(0.05, 1.0), st.floats(0.05, 1.0), st.permutations([0, 1, 2]),
       st.floats(0.0, 360.0), st.booleans(), st.sampled_from([1.0, 10.0, 45.0]))
def test_random_change_point_fourbars_stay_on_their_smooth_branch(s, u, v, order, phi0, crossed, step):
    """Crank = the shortest link s; coupler, rocker and ground a permutation of p, q, l = p + q − s
    (Grashof's equality): the crank turns fully, passing change points, at any step of the sweep.
    p and q stay apart from s and from each other: the parallelogram and the kite (two pairs of equal
    links) are tested above; their near-misses put two change points within 1e-6 of each other."""
    p = s + u * (2.0 - s)
    q = p + v * (2.0 - p)
    lengths = np.array([p, q, p + q - s])[list(order)]
    coupler, rocker, ground = lengths
    a = np.array([s * math.cos(math.radians(phi0)), s * math.sin(math.radians(phi0))])
    d_ac = np.linalg.norm(a - np.array([ground, 0.0]))
    cos_b = (coupler ** 2 + rocker ** 2 - d_ac ** 2) / (2 * coupler * rocker)
    assume(abs(cos_b) < 0.95)                     # drawn away from the change and dead points
    engine = mbplanar.Engine(fourbar(s, coupler, rocker, ground, phi0, crossed))
    phi = engine.phi_drawn[0] + np.radians(np.arange(0.0, 720.0 + step / 2, step))
    m = mbplanar.analyse(engine, phi)
    assert m.success and len(m.crossings) >= 2
    roots = closed_form_rocker_angles(s, coupler, rocker, ground, m.phi[:, 0])
    theta = m.angle[:, m.link("3")]
    err = np.abs(wrap(roots - theta[None, :])).min(axis=0)
    # at a change point the two roots merge: the closure equations (and the closed form's square root
    # of ~0) fix the angle only to ~sqrt(machine epsilon) there
    near = np.min([np.abs(m.phi[:, 0] - c.phi[0]) for c in m.crossings], axis=0) < 1e-3
    assert err[~near].max(initial=0.0) < 1e-9 and err.max() < 1e-6
    # the coupler point B moves continuously: each move bounded by the speeds and accelerations at its ends
    b = m.xy[:, m.point("B")]
    moved = np.linalg.norm(np.diff(b, axis=0), axis=-1)
    speed = np.maximum(np.linalg.norm(m.vq[1:, m.point("B")], axis=-1), np.linalg.norm(m.vq[:-1, m.point("B")], axis=-1))
    accel = np.maximum(np.linalg.norm(m.aq[1:, m.point("B")], axis=-1), np.linalg.norm(m.aq[:-1, m.point("B")], axis=-1))
    h = math.radians(step)
    assert np.all(moved <= speed * h + accel * h * h + 1e-9)
    # the assembly (which closed-form root) changes only across a change point: the smooth branch
    # goes from one assembly to the other there (so a single change point per turn makes the motion
    # repeat after two turns), and nowhere else
    which = np.argmin(np.abs(wrap(roots - theta[None, :])), axis=0)
    apart = np.flatnonzero(np.abs(wrap(roots[0] - roots[1])) > 1e-6)
    for i, j in zip(apart[:-1], apart[1:]):
        if which[i] != which[j]:
            assert any(m.phi[i, 0] <= c.phi[0] <= m.phi[j, 0] for c in m.crossings)


def test_chain_of_parallelograms_passes_its_singular_configurations():
    """IFToMM's N-four-bar benchmark geometry (N = 4 parallelograms of unit bars side by side): every
    group passes a change point when the bars lie horizontal; the bars stay parallel and the couplers
    horizontal over two turns, and the isosceles slider-crank (r = l, where the slider can stand still
    while crank and rod turn together) keeps x_B = 2r·cos φ."""
    n = 4
    m = mbplanar.Mechanism("n_four_bar")
    for k in range(n + 1):
        m.add_link(f"b{k}")
        m.add_joint(f"O{k}", "R", "0", f"b{k}", at=(float(k), 0.0))
    for k in range(n):
        m.add_link(f"c{k}")
        m.add_joint(f"A{k}", "R", f"b{k}", f"c{k}", at=(k + 0.5, math.sqrt(0.75)))
        m.add_joint(f"B{k}", "R", f"c{k}", f"b{k + 1}", at=(k + 1.5, math.sqrt(0.75)))
    m.add_input("O0", unit="rad")
    engine = mbplanar.Engine(m)
    assert engine.topology.structure.formula.count("II(") == n
    motion = mbplanar.analyse(engine, engine.phi_drawn[0] + np.radians(np.arange(0.0, 721.0, 1.0)))
    assert motion.success
    bars = [motion.link(f"b{k}") for k in range(n + 1)]
    assert np.abs(wrap(motion.angle[:, bars] - motion.angle[:, bars[:1]])).max() < 1e-11
    assert np.abs(wrap(motion.angle[:, [motion.link(f"c{k}") for k in range(n)]])).max() < 1e-11
    assert np.abs(motion.eq).max() < 1e-7

    r = 0.1
    s = mbplanar.Mechanism("isosceles_slider_crank")
    for name in ("1", "2", "3"):
        s.add_link(name)
    a, b = (r * math.cos(0.7), r * math.sin(0.7)), (2 * r * math.cos(0.7), 0.0)
    s.add_joint("O", "R", "0", "1", at=(0.0, 0.0))
    s.add_joint("A", "R", "1", "2", at=a)
    s.add_joint("B", "R", "2", "3", at=b)
    s.add_joint("Bp", "P", "0", "3", at=b, guide=0.0)
    s.add_input("O", unit="rad")
    engine = mbplanar.Engine(s)
    motion = mbplanar.analyse(engine, engine.phi_drawn[0] + np.radians(np.arange(0.0, 361.0, 1.0)))
    assert motion.success and len(motion.crossings) == 2
    assert np.abs(motion.xy[:, motion.point("B"), 0] - 2 * r * np.cos(motion.phi[:, 0])).max() < 1e-12
    assert np.abs(motion.vq[:, motion.point("B"), 0] + 2 * r * np.sin(motion.phi[:, 0])).max() < 1e-9
