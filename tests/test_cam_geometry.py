"""Exact geometry: envelope, pressure angle against closed forms, curvature and undercut, self-check."""

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from mbplanar.cam import laws as L
from mbplanar.cam.followers import Follower
from mbplanar.cam.geometry import cam_geometry
from mbplanar.cam.selfcheck import self_check
from mbplanar.errors import ModelError

D = math.radians


def seed_program(k=1.0, law=None):
    law = law or L.constant_acceleration(k)
    return L.program([("rise", law, D(28), 0.045), ("dwell", L.dwell(), D(15), 0),
                      ("return", law, D(28), 0.045), ("dwell", L.dwell(), D(289), 0)])


def seed_follower(**kw):
    args = dict(centre_distance=0.2973, arm=0.15, arm_angle=D(54), roller=0.06)
    args.update(kw)
    return Follower("oscillating", "roller", 1, **args)


def geometry(f, prog, samples=1440):
    phi = prog.grid(samples)
    return cam_geometry(f, phi, *prog.evaluate(phi)[:3])


def test_seed_pressure_angle_matches_the_seed_formula():
    prog = seed_program()
    g = geometry(seed_follower(), prog)
    psi = g.s / 0.15
    seed = np.arctan((g.v + 0.2973 * np.cos(D(54) + psi) - 0.15) / (0.2973 * np.sin(D(54) + psi)))
    assert np.max(np.abs(g.pressure - seed)) < 1e-12
    assert abs(seed_follower().prime_radius - 0.241791) < 5e-7       # √(a_w² + l² − 2 a_w l cos φ20)


@pytest.mark.parametrize("rotation", [1, -1])
@pytest.mark.parametrize("offset", [0.0, 0.012, -0.02])
def test_translating_pressure_angle_closed_form(rotation, offset):
    """tan(σθ) = (σv − e)/(s0 + s), s0 = √(r0² − e²) (instant centre of cam and follower)."""
    prog = seed_program(law=L.cycloidal())
    f = Follower("translating", "roller", rotation, base_radius=0.09, offset=offset, roller=0.015)
    g = geometry(f, prog, 720)
    s0 = math.sqrt(0.09 ** 2 - offset ** 2)
    expected = rotation * np.arctan((rotation * g.v - offset) / (s0 + g.s))
    assert np.max(np.abs(g.pressure - expected)) < 1e-12


def test_flat_face_profile_is_the_envelope():
    """Translating flat face: ρ = r_b + s + a, contact at σv from the axis, pressure angle 0."""
    prog = seed_program(law=L.modified_sine())
    for rotation in (1, -1):
        f = Follower("translating", "flat", rotation, base_radius=0.9)
        g = geometry(f, prog, 720)
        assert np.allclose(g.rho_profile, 0.9 + g.s + g.a, atol=1e-12)
        assert np.allclose(g.contact_fixed[:, 0], rotation * g.v, atol=1e-12)
        assert np.allclose(g.contact_fixed[:, 1], 0.9 + g.s, atol=1e-12)
        assert np.max(np.abs(g.pressure)) < 1e-12


def test_pitch_curvature_by_finite_differences():
    prog = seed_program(law=L.polynomial_345())
    f = seed_follower()
    phi = np.linspace(0.05, 0.6, 23)
    g = cam_geometry(f, phi, *prog.evaluate(phi)[:3])
    h = 1e-5
    gp = cam_geometry(f, phi + h, *prog.evaluate(phi + h)[:3])
    gm = cam_geometry(f, phi - h, *prog.evaluate(phi - h)[:3])
    d1 = (gp.pitch - gm.pitch) / (2 * h)
    d2 = (gp.pitch - 2 * g.pitch + gm.pitch) / h ** 2
    cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    rho = -np.linalg.norm(d1, axis=1) ** 3 / cross
    assert np.allclose(rho, g.rho_pitch, rtol=1e-5)
    assert np.allclose(g.profile_d1, (gp.profile - gm.profile) / (2 * h), atol=1e-8)


def test_undercut_detected_and_self_check_fails():
    prog = seed_program()
    ok = geometry(seed_follower(roller=0.06), prog)
    assert not ok.undercut and abs(ok.rho_min / 0.06 - 1.2632) < 1e-3
    bad = geometry(seed_follower(roller=0.4 * 0.241791), prog)       # the seed's upper roller
    assert bad.undercut and bad.rho_min < bad.follower.roller
    check = self_check(bad, prog)
    assert check.relative > 1e-3 and check.interference > 1e-4


FOLLOWERS = [
    seed_follower(),
    Follower("oscillating", "roller", -1, centre_distance=0.3, arm=0.15, arm_angle=D(50), roller=0.04),
    Follower("oscillating", "knife", 1, centre_distance=0.3, arm=0.15, arm_angle=D(50)),
    Follower("translating", "roller", 1, base_radius=0.12, offset=0.02, roller=0.02),
    Follower("translating", "knife", -1, base_radius=0.12, offset=-0.01),
    Follower("translating", "flat", 1, base_radius=0.9),
]


@pytest.mark.parametrize("f", FOLLOWERS, ids=lambda f: f"{f.motion}-{f.contact}-{f.rotation}")
def test_self_check_every_follower(f):
    prog = seed_program()
    check = self_check(geometry(f, prog), prog)
    assert check.converged and check.relative < 1e-6 and check.interference < 1e-9


def test_oscillating_flat_face():
    prog = L.program([("rise", L.cycloidal(), D(90), 0.015), ("dwell", L.dwell(), D(30), 0),
                      ("return", L.cycloidal(), D(90), 0.015), ("dwell", L.dwell(), D(150), 0)])
    through = Follower("oscillating", "flat", 1, centre_distance=0.2, arm=0.15, arm_angle=D(60))
    g = geometry(through, prog, 720)
    assert np.max(np.abs(g.pressure)) < 1e-12           # face through the pivot: force ⟂ arm
    for f in (through, Follower("oscillating", "flat", -1, centre_distance=0.2, arm=0.15, arm_angle=D(60),
                                face_offset=0.05)):
        check = self_check(geometry(f, prog, 720), prog)
        assert check.relative < 1e-6


def _random_program(draw):
    laws = st.sampled_from(["cycloidal", "polynomial_345", "polynomial_4567", "modified_sine",
                            "modified_trapezoid", "constant_acceleration"])
    rise, ret = draw(laws), draw(laws)
    a_rise, a_dwell, a_ret = draw(st.floats(40, 150)), draw(st.floats(0, 60)), draw(st.floats(40, 150))
    h = draw(st.floats(0.005, 0.03))
    rows = [("rise", L.make_law(rise), D(a_rise), h)]
    if a_dwell > 1:
        rows.append(("dwell", L.dwell(), D(a_dwell), 0))
    rows += [("return", L.make_law(ret), D(a_ret), h),
             ("dwell", L.dwell(), 2 * math.pi - D(a_rise + a_ret + (a_dwell if a_dwell > 1 else 0)), 0)]
    return L.program(rows)


@settings(max_examples=8, deadline=None)
@given(st.data())
def test_envelope_touches_the_roller_and_self_check(data):
    """The profile point lies at distance r from the roller centre, on the normal; the follower run on
    the profile repeats the law to 1e-6 of the stroke (random programs, base radius large enough)."""
    prog = _random_program(data.draw)
    r0 = data.draw(st.floats(0.08, 0.15))
    e = data.draw(st.floats(-0.02, 0.02))
    roller = data.draw(st.floats(0.005, 0.02))
    f = Follower("translating", "roller", data.draw(st.sampled_from([1, -1])), base_radius=r0, offset=e,
                 roller=roller)
    g = geometry(f, prog, 720)
    assert np.allclose(np.linalg.norm(g.pitch - g.profile, axis=1), roller, atol=1e-14)
    t = g.profile_d1 / np.linalg.norm(g.profile_d1, axis=1, keepdims=True)
    assert np.max(np.abs(np.sum((g.pitch - g.profile) * t, axis=1))) < 1e-12
    if not g.undercut:
        check = self_check(g, prog)
        assert check.relative < 1e-6


def test_follower_errors():
    with pytest.raises(ModelError, match="offset"):
        Follower("translating", "roller", 1, base_radius=0.05, offset=0.06, roller=0.01)
    with pytest.raises(ModelError, match="roller radius"):
        Follower("translating", "roller", 1, base_radius=0.05, roller=-0.01)
    with pytest.raises(ModelError, match="arm angle"):
        Follower("oscillating", "roller", 1, centre_distance=0.3, arm=0.1, arm_angle=D(200), roller=0.01)


@settings(max_examples=4, deadline=None)
@given(st.data())
def test_self_check_random_oscillating(data):
    """Oscillating roller followers on random programs: the profile is the envelope and the follower run
    on it repeats the law to 1e-6 of the stroke (where there is no undercut)."""
    prog = _random_program(data.draw)
    f = Follower("oscillating", "roller", data.draw(st.sampled_from([1, -1])),
                 centre_distance=data.draw(st.floats(0.2, 0.35)), arm=data.draw(st.floats(0.1, 0.2)),
                 arm_angle=D(data.draw(st.floats(30, 80))), roller=data.draw(st.floats(0.005, 0.02)))
    g = geometry(f, prog, 720)
    assert np.allclose(np.linalg.norm(g.pitch - g.profile, axis=1), f.roller, atol=1e-14)
    if not g.undercut:
        assert self_check(g, prog).relative < 1e-6


def test_flat_face_that_turns_with_the_cam_is_refused():
    """An oscillating flat face cannot be driven where dψ/dφ reaches the cam's own turn (σ = +1)."""
    prog = seed_program()                                 # dψ/dφ = v/l up to 1.23
    f = Follower("oscillating", "flat", 1, centre_distance=0.2973, arm=0.15, arm_angle=D(54))
    with pytest.raises(ModelError, match="turns with the cam"):
        geometry(f, prog, 720)
    with pytest.raises(ModelError, match="passes the cam centre"):
        Follower("oscillating", "flat", 1, centre_distance=0.2, arm=0.15, arm_angle=D(60), face_offset=0.3)
