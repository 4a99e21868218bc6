"""Function generation (Freudenstein): exact precision points checked by mbplanar's analysis of the
written model, random 3-position problems solved exactly (hypothesis), and clear errors."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import mbplanar
from mbplanar.errors import ModelError
from mbplanar.synthesis.freudenstein import (FunctionTask, evaluate_expression, freudenstein_coefficients,
                                            synthesise_angle_pairs, synthesise_function)


def _rocker_angles(a, b, c, d, phi):
    """ψ of a four-bar (ground d on x, crank a at φ from (0,0), rocker c from (d,0)), one circuit."""
    ax, ay = a * np.cos(phi), a * np.sin(phi)
    dx, dy = d - ax, -ay
    dist = np.hypot(dx, dy)
    along = (b * b - c * c + dist * dist) / (2 * dist)
    h = np.sqrt(b * b - along * along)
    bx = ax + along * dx / dist - h * dy / dist
    by = ay + along * dy / dist + h * dx / dist
    return np.arctan2(by, bx - d)


def _model_psi(result, phi):
    """ψ of the written model (its text read back) at the model's input values, by mbplanar."""
    engine = mbplanar.Engine(mbplanar.parse_model(result.toml))
    shift = result.defects.node_phi[0] - result.design["sense"] * result.phi[0]
    m = mbplanar.analyse(engine, shift + result.design["sense"] * np.asarray(phi))
    assert len(m.phi) == len(phi)
    return m.value[:, m.joint("B0")] - (math.pi if result.design["rocker_reversed"] else 0.0)


@settings(max_examples=12, deadline=None)
@given(a=st.floats(0.1, 0.3), b=st.floats(0.8, 1.2), c=st.floats(0.8, 1.2),
       start=st.floats(0.0, 2 * math.pi), gaps=st.lists(st.floats(0.2, 1.2), min_size=2, max_size=2))
def test_random_three_position_problems_are_solved_exactly(a, b, c, start, gaps):
    """Angle pairs of a Grashof crank-rocker (no dead point for the crank): the synthesis gives back
    its lengths and the model meets every pair to 1e-9."""
    phi = start + np.r_[0.0, np.cumsum(gaps)]
    psi = _rocker_angles(a, b, c, 1.0, phi)
    r = synthesise_angle_pairs(phi, psi, ground=1.0)
    assert (r.design["a"], r.design["b"], r.design["c"]) == pytest.approx((a, b, c), abs=1e-9)
    assert np.max(np.abs(r.point_errors_deg)) < 1e-7          # degrees: 1e-9 rad
    got = _model_psi(r, phi)
    assert np.max(np.abs(np.remainder(got - psi + math.pi, 2 * math.pi) - math.pi)) < 1e-9


def test_function_generator_meets_its_chebyshev_points_and_reports_the_structural_error():
    task = FunctionTask("1/x", (1.0, 2.0), (30.0, 120.0), (60.0, 150.0), 3)
    r = synthesise_function(task)
    x = task.precision_x()
    np.testing.assert_allclose(x, 1.5 - 0.5 * np.cos(np.pi * np.array([1, 3, 5]) / 6))
    wanted = task.psi_of_y(task.y(x))
    got = _model_psi(r, task.phi(x))
    assert np.max(np.abs(got - wanted)) < 1e-9
    # the structural error over the range, independently: the model's ψ(φ) against the function
    xs = np.linspace(1.0, 2.0, 101)
    err = np.degrees(_model_psi(r, task.phi(xs)) - task.psi_of_y(task.y(xs)))
    assert np.max(np.abs(err)) == pytest.approx(np.max(np.abs(r.range_error_deg)), rel=0.02)
    assert 0.05 < np.max(np.abs(err)) < 0.2                  # between the points the error is not zero


def test_least_squares_over_more_points():
    task = FunctionTask("1/x", (1.0, 2.0), (30.0, 120.0), (60.0, 150.0), 6)
    r = synthesise_function(task)
    assert r.defects.ok
    k, res = freudenstein_coefficients(r.phi, r.psi_target)
    assert np.all(np.abs(res) > 0)                            # not exact, but the best fit:
    m = np.column_stack([np.cos(r.psi_target), -np.cos(r.phi), np.ones(6)])
    assert np.allclose(m.T @ (m @ k - np.cos(r.phi - r.psi_target)), 0, atol=1e-12)


def test_bad_input_is_a_clear_error():
    with pytest.raises(ModelError, match="at least 3"):
        synthesise_angle_pairs([0.1, 0.2], [1.0, 1.1])
    with pytest.raises(ModelError, match="same value at both ends"):
        synthesise_function(FunctionTask("x*(1-x)", (0.0, 1.0), (0, 90), (0, 90)))
    with pytest.raises(ModelError, match="not allowed"):
        evaluate_expression("__import__('os')", 1.0)
    with pytest.raises(ModelError, match="not finite"):
        evaluate_expression("log(x)", np.array([-1.0, 1.0]))
    with pytest.raises(ModelError, match="no feasible design"):      # the classic log10 task hits a dead point
        synthesise_function(FunctionTask("log10(x)", (1.0, 10.0), (45.0, 105.0), (135.0, 225.0)))
