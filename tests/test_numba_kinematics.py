"""The compiled backend (numba) gives the numpy engine's answers: on every model, on random mechanisms,
past a motion limit, and where it hands the batch back to numpy (a change point). Skipped without
numba."""

import math
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import mbplanar
from mbplanar.errors import MbplanarError

pytest.importorskip("numba")

from test_change_points import fourbar  # noqa: E402
from test_properties import mechanisms  # noqa: E402
from conftest import MODELS, linkage_models  # noqa: E402

POSITIONS = ("angle", "xy", "value")
RATES = ("w", "e", "v", "a", "rate", "accel", "wq", "eq", "vq", "aq", "rate_q", "accel_q")


def _compiled(m):
    """Whether the compiled kernel made the Motion (its records: every output is asked for)."""
    return m.records is not None


def _pair(mech):
    return mbplanar.Engine(mech), mbplanar.Engine(mech, backend="numba")


def _model_sweep(name, n):
    """Both engines of a model file and n values over its default sweep (skipped for several inputs)."""
    ref_engine, fast_engine = _pair(mbplanar.read_model(MODELS / f"{name}.toml"))
    if len(ref_engine.inputs) != 1:
        pytest.skip("several inputs: the numpy path only")
    inp = ref_engine.inputs[0]
    lo, hi = (inp.to_si(v) for v in inp.default_sweep()[:2])
    return ref_engine, fast_engine, np.linspace(lo, hi, n)


def _assert_same(ref, fast, size, rate_tol=1e-8):
    """Positions to 1e-10 of the size; rates and accelerations to `rate_tol` relative (both paths stop
    Newton at the same residual, so near a dead point, where the rates grow without bound, they differ
    by the conditioning times that residual)."""
    assert fast.success == ref.success and len(fast.phi) == len(ref.phi)
    assert [lim.phi[0] for lim in fast.limits] == [lim.phi[0] for lim in ref.limits]
    np.testing.assert_array_equal(fast.phi, ref.phi)
    for name in POSITIONS:
        np.testing.assert_allclose(getattr(fast, name), getattr(ref, name), rtol=0, atol=1e-10 * size,
                                   err_msg=name)
    for name in RATES:
        x, y = getattr(ref, name), getattr(fast, name)
        scale = 1.0 + np.max(np.abs(x), axis=tuple(range(1, x.ndim)), keepdims=True)
        np.testing.assert_allclose(y / scale, x / scale, rtol=0, atol=rate_tol, err_msg=name)
    for name in ("th", "r", "w", "v", "e", "a"):
        x, y = getattr(ref.frames, name), getattr(fast.frames, name)
        scale = 1.0 + np.max(np.abs(x), axis=tuple(range(1, x.ndim)), keepdims=True)
        np.testing.assert_allclose(y / scale, x / scale, rtol=0, atol=rate_tol, err_msg=f"frames[{name}]")
    finite = np.isfinite(ref.ic)
    assert np.array_equal(finite, np.isfinite(fast.ic))


@pytest.mark.parametrize("name", sorted(p.stem for p in linkage_models()))
def test_every_model_same_as_numpy(name):
    ref_engine, fast_engine, phi = _model_sweep(name, 721)
    ref = mbplanar.analyse(ref_engine, phi, omega=2.5, epsilon=-0.7)
    fast = mbplanar.analyse(fast_engine, phi, omega=2.5, epsilon=-0.7)
    # the locking model's last rows lie a hair before its fold, where the rates are ~1e6
    _assert_same(ref, fast, ref_engine.size, rate_tol=1e-6 if ref.limits else 1e-8)


@settings(max_examples=15, deadline=None)
@given(mechanisms(), st.floats(-math.pi, math.pi))
def test_random_mechanisms_same_as_numpy(mech_kind, start):
    mech, _ = mech_kind
    mech.add_input("O", unit="rad")
    ref_engine, fast_engine = _pair(mech)
    phi = ref_engine.phi_drawn[0] + start + np.linspace(0.0, 2 * math.pi, 400)
    ref, fast = mbplanar.analyse(ref_engine, phi), mbplanar.analyse(fast_engine, phi)
    _assert_same(ref, fast, ref_engine.size, rate_tol=1e-6)
    # positions only (to 1e-11 of the size: see test_asked_points_and_positions_only_same_as_numpy)
    ref, fast = mbplanar.analyse(ref_engine, phi, rates=False), mbplanar.analyse(fast_engine, phi, rates=False)
    assert len(fast.phi) == len(ref.phi) and _compiled(fast)
    for field in POSITIONS:
        np.testing.assert_allclose(getattr(fast, field), getattr(ref, field), rtol=0, atol=1e-11 * ref_engine.size,
                                   err_msg=field)


def test_change_point_goes_to_numpy():
    """Positions between the nodes around a change point need the interpolant's rates: the compiled
    path declines the batch and the answer is numpy's, exactly."""
    ref_engine, fast_engine = _pair(fourbar(1.0, 2.0, 1.0, 2.0, 60.0))
    phi = ref_engine.phi_drawn[0] + np.radians(np.arange(0.0, 720.0, 0.5))
    ref, fast = mbplanar.analyse(ref_engine, phi), mbplanar.analyse(fast_engine, phi)
    assert fast.crossings and len(fast.crossings) == len(ref.crossings)
    for name in POSITIONS + RATES:
        np.testing.assert_array_equal(getattr(fast, name), getattr(ref, name))


def test_one_position_and_past_the_limit():
    ref_engine, fast_engine = _pair(mbplanar.read_model(MODELS / "crank_slider_rocker_locking.toml"))
    inp = ref_engine.inputs[0]
    for values in ([inp.to_si(0.5)], [inp.to_si(v) for v in (0.5, 1.0, 1.9, 2.5)]):
        ref, fast = mbplanar.analyse(ref_engine, values), mbplanar.analyse(fast_engine, values)
        _assert_same(ref, fast, ref_engine.size)


def test_sweeps_inside_and_beyond_the_atlas_already_walked():
    """One compiled engine, sweeps inside the atlas' nodes (its kernel tables kept), then beyond them (the
    atlas grows, the tables are made again), then inside again: each the numpy engine's answer, and the
    kernel made each one."""
    ref_engine, fast_engine = _pair(mbplanar.read_model(MODELS / "fourbar.toml"))
    phi0 = float(ref_engine.phi_drawn[0])
    for lo, hi in ((0.0, 1.0), (0.2, 0.8), (-3.0, 7.0), (0.0, 1.0), (-3.0, 7.0)):
        values = phi0 + np.linspace(lo, hi, 40)
        ref, fast = mbplanar.analyse(ref_engine, values), mbplanar.analyse(fast_engine, values)
        assert _compiled(fast)
        _assert_same(ref, fast, ref_engine.size)
    locking_ref, locking_fast = _pair(mbplanar.read_model(MODELS / "crank_slider_rocker_locking.toml"))
    inp = locking_ref.inputs[0]
    for ends in ((0.5, 1.0), (0.5, 2.5), (0.6, 0.9), (0.5, 2.5)):  # (past the limit: rows dropped alike)
        values = np.linspace(*(inp.to_si(v) for v in ends), 30)
        _assert_same(mbplanar.analyse(locking_ref, values), mbplanar.analyse(locking_fast, values), locking_ref.size)


def test_unknown_backend_is_refused(monkeypatch):
    mech = mbplanar.read_model(MODELS / "fourbar.toml")
    with pytest.raises(ValueError, match="backend"):
        mbplanar.Engine(mech, backend="fortran")
    monkeypatch.setitem(sys.modules, "numba", None)  # as without numba installed
    with pytest.raises(MbplanarError, match=r"pip install 'mbplanar\[fast\]'"):
        mbplanar.Engine(mech, backend="numba")


def test_cli_backend_option_gives_the_same_table(tmp_path):
    from mbplanar.cli import main

    model = str(MODELS / "shaper.toml")
    ref, fast = tmp_path / "numpy.csv", tmp_path / "numba.csv"
    assert main(["sweep", model, "--steps", "24", "-o", str(ref)]) == 0
    assert main(["--backend", "numba", "sweep", model, "--steps", "24", "-o", str(fast)]) == 0
    a, b = (np.genfromtxt(p, delimiter=",", skip_header=1) for p in (ref, fast))
    assert a.shape == b.shape and len(a) >= 24
    np.testing.assert_allclose(b, a, rtol=1e-9, atol=1e-9)


def test_every_output_written_by_the_kernel_in_one_pass():
    """The kernel writes every array of the Motion straight into it in one pass: the angles, the points,
    the real rates and their analogues, the joints and the instantaneous centres, with the frames and
    joint analogues as views of its records; v = v_q·ω and a = a_q·ω² + v_q·ε hold bit for bit, and
    nothing is left to compute when a field is read (a frozen record)."""
    mech = mbplanar.read_model(MODELS / "shaper.toml")
    ref_engine, engine = _pair(mech)
    phi = engine.phi_drawn[0] + np.linspace(0.0, 6.0, 50)
    m, ref = mbplanar.analyse(engine, phi, omega=2.0, epsilon=0.5), mbplanar.analyse(ref_engine, phi, 2.0, 0.5)
    assert not {"xy", "vq", "aq", "w", "v", "a", "rate", "ic"} & set(m.records.dtype.names)
    assert all(getattr(m, name) is not None for name in mbplanar.kinematics.OUTPUTS)
    assert np.may_share_memory(m.records, m.wq) and np.may_share_memory(m.records, m.frames.r)
    np.testing.assert_allclose(m.xy, ref.xy, rtol=0, atol=1e-12)
    np.testing.assert_allclose(m.aq, ref.aq, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(m.v, m.vq * 2.0)
    np.testing.assert_array_equal(m.a, m.aq * 4.0 + m.vq * 0.5)
    np.testing.assert_array_equal(m.rate, m.rate_q * 2.0)
    with pytest.raises(AttributeError, match="no attribute 'speed'"):
        m.speed  # noqa: B018
    with pytest.raises(AttributeError):
        m.xy = m.v  # (frozen)


# the compiled answers on what a caller asks for: some points, positions only. Positions to 1e-11 of
# the size: numpy's own batch corrector moves a position by up to ~2e-12 depending on the other positions
# of its batch (it steps the converged ones while others have not converged; the compiled kernel is
# numpy solving one position: see test_differences_are_numpys_batch_coupling)
@pytest.mark.parametrize("name", sorted(p.stem for p in linkage_models()))
def test_asked_points_and_positions_only_same_as_numpy(name):
    ref_engine, fast_engine, phi = _model_sweep(name, 181)
    every = mbplanar.analyse(ref_engine, phi[:1]).point_names
    asked = every[::-2]  # every other point, in another order
    for kw in (dict(points=asked), dict(rates=False), dict(points=asked[:1], rates=False)):
        ref, fast = mbplanar.analyse(ref_engine, phi, 1.5, 0.4, **kw), mbplanar.analyse(fast_engine, phi, 1.5, 0.4, **kw)
        assert _compiled(fast), "the compiled path declined the batch"  # (higher pairs too)
        assert fast.point_names == ref.point_names == kw.get("points", every)
        for field in POSITIONS:
            np.testing.assert_allclose(getattr(fast, field), getattr(ref, field), rtol=0,
                                       atol=1e-11 * ref_engine.size, err_msg=f"{kw}: {field}")
        if kw.get("rates", True):
            _assert_same(ref, fast, ref_engine.size, rate_tol=1e-6 if ref.limits else 1e-8)
        else:
            for field in ("v", "wq", "rate", "ic", "w"):
                assert getattr(fast, field) is None and getattr(ref, field) is None


def test_differences_are_numpys_batch_coupling():
    """Where the compiled kernel and numpy's batch differ (jansen: ~1e-12), the kernel gives exactly what
    numpy gives for that position alone."""
    ref_engine, fast_engine = _pair(mbplanar.read_model(MODELS / "jansen.toml"))
    phi = ref_engine.phi_drawn[0] + np.linspace(0.0, 2 * math.pi, 361)
    ref, fast = mbplanar.analyse(ref_engine, phi, rates=False), mbplanar.analyse(fast_engine, phi, rates=False)
    worst = np.argsort(np.abs(ref.angle - fast.angle).max(axis=1))[-3:]
    for row in worst:
        alone = mbplanar.analyse(ref_engine, phi[row:row + 1], rates=False)
        np.testing.assert_array_equal(fast.angle[row], alone.angle[0])
        np.testing.assert_array_equal(fast.xy[row], alone.xy[0])



def test_outputs_asked_for_and_the_rest_none():
    """``outputs=`` asks for some arrays: the others are None on both backends, and the kernel writes
    no records where neither the frames nor the joints' values and analogues are asked for."""
    ref_engine, engine = _pair(mbplanar.read_model(MODELS / "shaper.toml"))
    phi = engine.phi_drawn[0] + np.linspace(0.0, 6.0, 40)
    for outputs in (["v", "a"], ["vq"], ["value"], ["frames", "ic"], []):
        m, ref = (mbplanar.analyse(e, phi, 2.0, outputs=outputs) for e in (engine, ref_engine))
        for name in mbplanar.kinematics.OUTPUTS:
            assert (getattr(m, name) is None) == (getattr(ref, name) is None) == (name not in outputs), name
        assert (m.records is None) == (not {"value", "frames"} & set(outputs))
        np.testing.assert_allclose(m.xy, ref.xy, rtol=0, atol=1e-12)
        for name in outputs:
            x, y = getattr(ref, name), getattr(m, name)
            if name == "frames":
                x, y = x.r, y.r
            np.testing.assert_allclose(y, x, rtol=0, atol=1e-9 * (1 + np.nanmax(np.abs(x))), err_msg=name)
    with pytest.raises(MbplanarError, match="'speed' is not one of"):
        mbplanar.analyse(engine, phi, outputs=["speed"])


def test_kinetostatics_of_a_motion_without_frames_is_refused():
    engine = mbplanar.Engine(mbplanar.read_model(MODELS / "fourbar_loaded.toml"), backend="numba")
    phi = engine.phi_drawn[0] + np.linspace(0.0, 6.0, 40)
    with pytest.raises(MbplanarError, match="frames"):
        mbplanar.kinetostatics(engine, mbplanar.analyse(engine, phi, outputs=["v", "a"]))
    m = mbplanar.analyse(engine, phi)
    assert m.records is not None and mbplanar.kinetostatics(engine, m).success


def test_one_compiled_kernel_for_every_request():
    """Positions only or with rates, every point or some, every output or some, on one thread or two,
    and one position: the sweep kernel takes the same argument types every time, so numba compiles it
    once (one signature, the first use's compile) and a process never pays twice."""
    from mbplanar.backends import _numba_kinematics

    mech = mbplanar.read_model(MODELS / "fourbar.toml")
    one, two = (mbplanar.Engine(mech, backend="numba", threads=t) for t in (1, 2))
    phi = one.phi_drawn[0] + np.linspace(0.0, 2 * np.pi, 900)
    made = [mbplanar.analyse(one, phi[:40], rates=False), mbplanar.analyse(one, phi[:40]),
            mbplanar.analyse(one, phi[:40], points=["M"]), mbplanar.analyse(two, phi, rates=False),
            mbplanar.analyse(two, phi, 2.0, -1.0, points=["B", "M"])]
    assert all(_compiled(m) for m in made)
    assert made[0].value.shape == (40, len(mech.joints))
    mbplanar.analyse(one, phi[:40], outputs=["v"])
    mbplanar.position(one, float(phi[3]))
    assert len(_numba_kinematics._sweep.signatures) == 1, _numba_kinematics._sweep.signatures
