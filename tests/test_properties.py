"""Laws that must hold for any mechanism (hypothesis): loop closure after a solve, velocity = derivative
of position, acceleration = derivative of velocity, no jump along a sweep, group-by-group = global."""

import math

import numpy as np
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import mbplanar
from mbplanar.kinematics import material_points

SETTINGS = settings(max_examples=12, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])


def _angle(v):
    return math.degrees(math.atan2(v[1], v[0]))


def _polar(draw, lo=0.25, hi=1.0):
    """A vector of length lo … hi in any direction."""
    length, angle = draw(st.floats(lo, hi)), draw(st.floats(-math.pi, math.pi))
    return length * np.array([math.cos(angle), math.sin(angle)])


def _turned(draw, v, lo=0.25, hi=1.0):
    """A vector of length lo … hi at an angle to v whose sine is at least 0.25 in magnitude, so that
    the pair it forms with v is well away from a dead point."""
    turn = draw(st.floats(0.26, math.pi - 0.26)) * draw(st.sampled_from([1.0, -1.0]))
    angle = math.atan2(v[1], v[0]) + turn
    return draw(st.floats(lo, hi)) * np.array([math.cos(angle), math.sin(angle)])


def _far_apart(*pts, gap=0.2):
    return min(np.linalg.norm(p - q) for i, p in enumerate(pts) for q in pts[i + 1:]) > gap


@st.composite
def mechanisms(draw):
    """A random mechanism in an exact drawn pose: four-bar, slider-crank, inverted slider-crank, or a
    six-bar whose second dyad slides on a guide carried by the moving rocker. Built from lengths and
    turning angles, so that the drawn pose is away from dead points by construction (drawing points
    and rejecting the bad ones would discard most draws)."""
    kind = draw(st.sampled_from(["fourbar", "slider_crank", "inverted", "sixbar"]))
    o = np.zeros(2)
    a = _polar(draw)
    m = mbplanar.Mechanism(kind)
    for name in ("1", "2", "3"):
        m.add_link(name)
    m.add_joint("O", "R", "0", "1", at=o)
    m.add_joint("A", "R", "1", "2", at=a)
    if kind == "inverted":
        # block 2 on the crank pin slides along rocker 3 (pivot C): guide through C and A
        c = a + _turned(draw, -a)
        assume(_far_apart(o, a, c))
        m.add_joint("Ap", "P", "3", "2", at=a, guide=_angle(a - c))
        m.add_joint("C", "R", "0", "3", at=c)
        return m, kind
    b = a + _polar(draw)
    if kind == "slider_crank":
        assume(_far_apart(o, a, b))
        m.add_joint("B", "R", "2", "3", at=b)
        m.add_joint("Bp", "P", "0", "3", at=b, guide=_angle(_turned(draw, b - a)))
        return m, kind
    c = b + _turned(draw, b - a)
    assume(_far_apart(o, a, b, c))
    m.add_joint("B", "R", "2", "3", at=b)
    m.add_joint("C", "R", "3", "0", at=c)
    if kind == "sixbar":
        e = b + _polar(draw, 0.0, 1.0)  # a point of the coupler 2
        f = e + _polar(draw)  # the slider 5 on a guide carried by the rocker 3
        assume(_far_apart(o, a, b, c, e, f))
        m.add_link("4")
        m.add_link("5")
        m.add_joint("E", "R", "2", "4", at=e)
        m.add_joint("F", "R", "4", "5", at=f)
        m.add_joint("Fp", "P", "3", "5", at=f, guide=_angle(_turned(draw, f - e)))
    return m, kind


def _engine(m):
    m.add_input("O", unit="rad")
    return mbplanar.Engine(m)


def _closure_residual(engine, motion):
    """Largest violation of any joint (m or rad) in the solved poses."""
    th, r = motion.frames.th, motion.frames.r
    zeros = np.zeros_like(th)
    worst = 0.0
    for j in engine.mech.joints.values():
        ia, ib = engine.link_index[j.links[0]], engine.link_index[j.links[1]]
        at = np.array([j.at])
        xa = material_points(th, r, zeros, np.zeros_like(r), zeros, np.zeros_like(r), np.array([ia]), at)[0][:, 0]
        xb = material_points(th, r, zeros, np.zeros_like(r), zeros, np.zeros_like(r), np.array([ib]), at)[0][:, 0]
        if j.kind == "R":
            worst = max(worst, float(np.abs(xa - xb).max()))
        else:
            g = math.radians(j.guide_deg)
            n0 = np.array([-math.sin(g), math.cos(g)])
            c, s = np.cos(th[:, ia]), np.sin(th[:, ia])
            n = np.stack([c * n0[0] - s * n0[1], s * n0[0] + c * n0[1]], -1)
            worst = max(worst, float(np.abs(np.sum(n * (xb - xa), -1)).max()),
                        float(np.abs(th[:, ib] - th[:, ia]).max()))
    return worst


def _reachable_input(engine, offset):
    """An input value towards drawn + offset, inside the stretch the mechanism reaches from its drawn
    pose (two thirds of the way to the last reached grid value), so that a small step either side is
    reachable too. Drawing the value and discarding unreachable ones would reject most non-Grashof draws."""
    walk = mbplanar.analyse(engine, engine.phi_drawn[0] + offset * np.linspace(0.0, 1.0, 31))
    return float(walk.phi[(2 * (len(walk.phi) - 1)) // 3, 0])


@SETTINGS
@given(mechanisms(), st.lists(st.floats(-1.5, 1.5), min_size=1, max_size=6))
def test_loop_closure_after_solve(mech_kind, offsets):
    mech, _ = mech_kind
    engine = _engine(mech)
    m = mbplanar.analyse(engine, engine.phi_drawn[0] + np.array(offsets))
    assert len(m.phi) >= 0
    if len(m.phi):
        assert _closure_residual(engine, m) < 1e-10


@SETTINGS
@given(mechanisms(), st.floats(-1.0, 1.0))
def test_velocity_and_acceleration_are_derivatives(mech_kind, offset):
    mech, _ = mech_kind
    engine = _engine(mech)
    h = 1e-5
    phi = _reachable_input(engine, offset)
    m = mbplanar.analyse(engine, [phi - h, phi, phi + h])
    assert len(m.phi) == 3
    scale = 1 + np.abs(m.vq[1]) + np.abs(m.aq[1])
    assume(scale.max() < 1e3)  # far from a dead point, where central differences are meaningful
    fd_v = (m.xy[2] - m.xy[0]) / (2 * h)
    fd_a = (m.vq[2] - m.vq[0]) / (2 * h)
    assert np.all(np.abs(fd_v - m.vq[1]) <= 1e-5 * scale)
    assert np.all(np.abs(fd_a - m.aq[1]) <= 1e-4 * scale * scale)
    fd_w = (m.angle[2] - m.angle[0]) / (2 * h)
    fd_e = (m.wq[2] - m.wq[0]) / (2 * h)
    link_scale = 1 + np.abs(m.wq[1]) + np.abs(m.eq[1])
    assert np.all(np.abs(fd_w - m.wq[1]) <= 1e-5 * link_scale)
    assert np.all(np.abs(fd_e - m.eq[1]) <= 1e-4 * link_scale * link_scale)
    fd_j = (m.value[2] - m.value[0]) / (2 * h)
    assert np.all(np.abs(fd_j - m.rate_q[1]) <= 1e-5 * (1 + np.abs(m.rate_q[1]) + np.abs(m.accel_q[1])))


@SETTINGS
@given(mechanisms())
def test_no_jump_along_a_sweep(mech_kind):
    mech, _ = mech_kind
    engine = _engine(mech)
    step = math.radians(1.0)
    phi = engine.phi_drawn[0] + np.arange(-180, 181) * step
    m = mbplanar.analyse(engine, phi)
    # reached positions are one contiguous stretch around the drawn pose
    got = np.round((m.phi[:, 0] - phi[0]) / step).astype(int)
    assert np.all(np.diff(got) == 1)
    # each move is bounded by the speeds at its ends (mean-value theorem, with room for curvature)
    moved = np.linalg.norm(np.diff(m.xy, axis=0), axis=-1)
    speed = np.maximum(np.linalg.norm(m.vq[1:], axis=-1), np.linalg.norm(m.vq[:-1], axis=-1))
    accel = np.maximum(np.linalg.norm(m.aq[1:], axis=-1), np.linalg.norm(m.aq[:-1], axis=-1))
    assert np.all(moved <= speed * step + accel * step * step + 1e-9)


@SETTINGS
@given(mechanisms(), st.lists(st.floats(-1.0, 1.0), min_size=1, max_size=5))
def test_group_by_group_equals_global_newton(mech_kind, offsets):
    mech, _ = mech_kind
    mech.add_input("O", unit="rad")
    grouped = mbplanar.Engine(mech)
    whole = mbplanar.Engine(mech, grouped=False)
    assert len(whole.blocks) < len(grouped.blocks) or len(grouped.blocks) == 2
    phi = grouped.phi_drawn[0] + np.array(offsets)
    a = mbplanar.analyse(grouped, phi)
    b = mbplanar.analyse(whole, phi)
    # compare where both reached (a bifurcation may end one block structure's walk a little earlier)
    common = np.intersect1d(a.phi[:, 0], b.phi[:, 0])
    assert len(common) >= min(len(np.unique(a.phi)), len(np.unique(b.phi))) - 1
    ia = [int(np.flatnonzero(a.phi[:, 0] == v)[0]) for v in common]
    ib = [int(np.flatnonzero(b.phi[:, 0] == v)[0]) for v in common]
    if len(common):
        assert np.abs(a.xy[ia] - b.xy[ib]).max() < 1e-12 * (1 + grouped.size)
        assert np.abs(a.vq[ia] - b.vq[ib]).max() < 1e-9 * (1 + np.abs(a.vq[ia]).max())
