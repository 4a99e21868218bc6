"""Tolerances as data (`mbplanar.engine.Tolerances`): validated, frozen, and read by both backends, the
compiled kernels receiving them as an argument rather than as constants frozen into numba's cache."""

import dataclasses
import math
import pathlib

import numpy as np
import pytest

import mbplanar
from mbplanar.engine import Tolerances
from mbplanar.engine._tolerances import KernelTol

MODELS = pathlib.Path(__file__).resolve().parent.parent / "models"


@pytest.mark.parametrize("change, field", [({"closure": -1e-13}, "closure"), ({"h_min": math.nan}, "h_min"),
                                           ({"max_newton": 1.5}, "max_newton"), ({"fold_iterations": -1},
                                                                                  "fold_iterations"),
                                           ({"singular": True}, "singular"), ({"polish": 1e-12}, "polish"),
                                           ({"h_start": 1.0}, "h_start")])
def test_bad_tolerances_are_refused_by_name(change, field):
    with pytest.raises(ValueError, match=field):
        Tolerances(**change)


def test_tolerances_are_frozen_and_checked_by_the_engine():
    tol = Tolerances(closure=1e-12)
    with pytest.raises(dataclasses.FrozenInstanceError):
        tol.closure = 1.0
    mech = mbplanar.read_model(MODELS / "fourbar.toml")
    assert mbplanar.Engine(mech, tol=tol).tol is tol and mbplanar.Engine(mech).tol == Tolerances()
    with pytest.raises(ValueError, match="tol must be"):
        mbplanar.Engine(mech, tol={"closure": 1e-12})
    kernel = tol.kernel()
    assert isinstance(kernel, KernelTol) and kernel._fields == tuple(f.name for f in dataclasses.fields(tol))
    assert kernel == tuple(getattr(tol, name) for name in kernel._fields) and type(kernel.max_newton) is int


def _both(tol, phi):
    mech = mbplanar.read_model(MODELS / "fourbar.toml")
    return (mbplanar.analyse(mbplanar.Engine(mech, tol=tol), phi),
            mbplanar.analyse(mbplanar.Engine(mech, tol=tol, backend="numba"), phi))


def test_a_changed_closure_tolerance_reaches_the_compiled_kernel():
    """With a loose closure tolerance and a coarse atlas both backends accept the interpolated guess
    without a Newton step, so both land ~1e-7 away from the default answer, and on the same point: a
    kernel holding its own 1e-13 would iterate on and differ from numpy by that much."""
    pytest.importorskip("numba")
    phi = np.linspace(0.1, 6.0, 40)
    reference = mbplanar.analyse(mbplanar.Engine(mbplanar.read_model(MODELS / "fourbar.toml")), phi)
    loose, fast = _both(Tolerances(closure=1e-6, polish=1e-6, h_dense=math.radians(10)), phi)
    assert fast.records is not None, "the compiled kernel took the batch"
    assert np.abs(loose.xy - reference.xy).max() > 1e-8
    np.testing.assert_allclose(fast.xy, loose.xy, rtol=0, atol=1e-14)
    np.testing.assert_allclose(fast.w, loose.w, rtol=0, atol=1e-12)


def test_no_newton_step_fails_alike_on_both_backends():
    pytest.importorskip("numba")
    slow, fast = _both(Tolerances(max_newton=0), np.linspace(0.1, 6.0, 12))
    assert not slow.success and not fast.success and len(slow.phi) == len(fast.phi)
