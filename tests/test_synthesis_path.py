"""Path generation: a small target from a known coupler curve, checked by mbplanar; reproducible with a seed."""

import numpy as np
import pytest

import mbplanar
from mbplanar.errors import ModelError
from mbplanar.synthesis.path import synthesise_path

_M = mbplanar.analyse(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), np.radians(np.arange(0, 360, 30.0)))
TARGETS = _M.xy[:, _M.point("M")]


@pytest.fixture(scope="module")
def result():
    return synthesise_path(TARGETS, seed=1, popsize=6, maxiter=8, time_limit=1e6, refine=1)


def test_errors_are_the_models_own(result):
    engine = mbplanar.Engine(mbplanar.parse_model(result.toml))
    m = mbplanar.analyse(engine, result.phi)
    np.testing.assert_allclose(np.hypot(*(m.xy[:, m.point("P")] - TARGETS).T), result.errors, atol=1e-12)
    assert result.defects.ok and result.defects.full_turn
    assert mbplanar.check(engine).full_turn
    dense = mbplanar.analyse(engine, result.phi[0] + np.linspace(0, 2 * np.pi, 3601))
    p = dense.xy[:, dense.point("P")]
    nearest = np.min(np.hypot(p[:, None, 0] - TARGETS[:, 0], p[:, None, 1] - TARGETS[:, 1]), axis=0)
    assert np.all(result.errors <= nearest + 1e-12)           # the refined angles are the nearest points


def test_same_seed_same_design(result):
    again = synthesise_path(TARGETS, seed=1, popsize=6, maxiter=8, time_limit=1e6, refine=1)
    np.testing.assert_array_equal(again.design, result.design)


def test_too_few_points():
    with pytest.raises(ModelError, match="at least 5"):
        synthesise_path(TARGETS[:4])
