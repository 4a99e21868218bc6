"""Motion laws against closed forms and finite differences; programs' continuity flags."""

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from mbplanar.cam import laws as L
from mbplanar.errors import ModelError


@pytest.mark.parametrize("name, expected", [
    ("cycloidal", (2.0, 2 * math.pi, 4 * math.pi ** 2)),
    ("polynomial_345", (15 / 8, 10 / math.sqrt(3), 60.0)),
    ("simple_harmonic", (math.pi / 2, math.pi ** 2 / 2, math.pi ** 3 / 2)),
    ("polynomial_4567", (35 / 16, 84 / 5 * math.sqrt(5) / 5, 52.5)),
])
def test_peak_coefficients_closed_forms(name, expected):
    got = L.make_law(name).peaks()
    assert np.allclose(got, expected, rtol=0, atol=1e-9 if name != "polynomial_4567" else 1e-11 + 1e-9)


def test_modified_sine_and_trapezoid_published():
    cv, ca, cj = L.modified_sine().peaks()
    assert (round(cv, 2), round(ca, 2), round(cj, 2)) == (1.76, 5.53, 69.47)
    # closed forms: C_a = 4π²/(π + 4), C_j = 4π·C_a
    assert abs(ca - 4 * math.pi ** 2 / (math.pi + 4)) < 1e-9
    assert abs(cj - 16 * math.pi ** 3 / (math.pi + 4)) < 1e-9
    cv, ca, cj = L.modified_trapezoid().peaks()
    assert abs(cv - 2.0) < 1e-9 and abs(ca - 2 * math.pi / (math.pi + 2) * 4) < 1e-9
    assert (round(ca, 3), round(cj, 2)) == (4.888, 61.43)


@pytest.mark.parametrize("k", [0.5, 1.0, 2.0])
def test_constant_acceleration_seed_law(k):
    """a_q1 = 2(k+1)h/φ², v_max = a_q1·φ/(k+1); s = a_q1·φ²/2 on the first piece (not a_q1/k·φ²)."""
    law = L.constant_acceleration(k)
    cv, ca, cj = law.peaks()
    assert abs(cv - 2) < 1e-12 and abs(ca - 2 * (k + 1) * max(1, 1 / k)) < 1e-9
    assert cj == math.inf and law.jumps == (2,)
    u = np.array([0.3 / (k + 1)])
    assert abs(law.derivatives(u)[0, 0] - 2 * (k + 1) * u[0] ** 2 / 2) < 1e-14


@pytest.mark.parametrize("name", [n for n in L.LAWS if n != "dwell"])
def test_law_ends_and_derivatives_by_finite_differences(name):
    law = L.make_law(name)
    y = law.derivatives(np.array([0.0, 1.0]))
    assert abs(y[0, 0]) < 1e-14 and abs(y[0, 1] - 1) < 1e-12
    u = np.linspace(0.013, 0.987, 41)
    h = 1e-6
    d = law.derivatives(u)
    for order in (1, 2, 3):
        fd = (law.derivatives(u + h)[order - 1] - law.derivatives(u - h)[order - 1]) / (2 * h)
        near = np.min(np.abs(u[:, None] - np.array(law.breakpoints + (2.0,))[None, :]), axis=1) > 2 * h
        assert np.allclose(fd[near], d[order][near], rtol=1e-5, atol=1e-5 * max(1, np.abs(d[order]).max()))


def test_polynomial_through_reproduces_345_and_4567():
    assert np.allclose(L.polynomial_through((0, 0, 0), (1, 0, 0)).coefficients, L.polynomial_345().coefficients)
    assert np.allclose(L.polynomial_through((0, 0, 0, 0), (1, 0, 0, 0)).coefficients,
                       L.polynomial_4567().coefficients, atol=1e-9)


def _seed_program(law_name="constant_acceleration"):
    d = math.radians
    law = L.make_law(law_name)
    return L.program([("rise", law, d(28), 0.045), ("dwell", L.dwell(), d(15), 0),
                      ("return", law, d(28), 0.045), ("dwell", L.dwell(), d(289), 0)])


def test_continuity_flags():
    jumps = _seed_program().continuity()
    assert {j.order for j in jumps} == {2}                      # acceleration jumps: infinite jerk only
    assert sorted(round(math.degrees(j.angle), 9) for j in jumps) == [0, 14, 28, 43, 57, 71]
    assert not _seed_program("cycloidal").continuity()          # cycloidal: smooth to the jerk
    assert {j.order for j in _seed_program("simple_harmonic").continuity()} == {2}
    assert {j.order for j in _seed_program("constant_velocity").continuity()} == {1}


def test_program_must_cover_360():
    d = math.radians
    with pytest.raises(ModelError, match="add up to 350"):
        L.program([("rise", L.cycloidal(), d(100), 0.01), ("return", L.cycloidal(), d(250), 0.01)])


@settings(max_examples=25, deadline=None)
@given(st.sampled_from([n for n in L.LAWS if n != "dwell"]), st.floats(10, 170), st.floats(1e-3, 0.1))
def test_segment_scaling(name, beta_deg, h):
    """A rise's v, a, j are the law's derivatives divided by β, β², β³; a return is its mirror."""
    beta = math.radians(beta_deg)
    law = L.make_law(name)
    rise = L.Segment("rise", law, 0.0, beta, 0.0, h)
    ret = L.Segment("return", law, 0.0, beta, h, 0.0)
    u = np.linspace(0.05, 0.95, 6)                   # clear of the laws' breakpoints
    r, b = rise.evaluate(u * beta), ret.evaluate((1 - u) * beta)
    assert np.allclose(r[0], b[0], atol=1e-15) and np.allclose(r[1], -b[1]) and np.allclose(r[2], b[2])
    assert abs(rise.peaks[0] - h * law.peaks()[0] / beta) < 1e-12


def test_polynomial_segment_through_physical_values():
    """A polynomial phase through (s, v, a) in metres: through (0,0,0) → (h,0,0) it is the 3-4-5 rise;
    with end velocities it matches them."""
    beta, h = math.radians(80), 0.02
    poly = L.Segment.through(0.3, beta, (0.0, 0.0, 0.0), (h, 0.0, 0.0))
    rise = L.Segment("rise", L.polynomial_345(), 0.3, beta, 0.0, h)
    phi = 0.3 + np.linspace(0, beta, 9)
    assert np.allclose(poly.evaluate(phi), rise.evaluate(phi), atol=1e-12)
    ramp = L.Segment.through(0.0, beta, (0.0, 0.01, 0.0), (h, 0.02, -0.05))
    ends = ramp.evaluate(np.array([0.0, beta]))
    assert np.allclose(ends[:3, 0], (0.0, 0.01, 0.0), atol=1e-14)
    assert np.allclose(ends[:3, 1], (h, 0.02, -0.05), atol=1e-12)
