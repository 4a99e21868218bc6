"""The backend seam (`mbplanar.engine._backend.dispatch`): the one place that picks who computes a job.
A backend says whether it can run a request and whether it should (True or the reason), dispatch runs
the first that says yes to both and logs every answer; numpy (the reference) takes what all decline."""

import logging
import pathlib
import re

import numpy as np
import pytest

import mbplanar
from mbplanar.backends import BACKENDS, load
from mbplanar.engine._backend import candidates, planned

MODELS = pathlib.Path(__file__).resolve().parent.parent / "models"
PACKAGE = pathlib.Path(mbplanar.__file__).parent


class _Spy:
    """A backend that records what it is asked and answers as told."""

    name = "spy"

    def __init__(self, should=True, can=True, run=None):
        self.should, self.can, self.answer, self.calls = should, can, run, []

    def should_run(self, job, size):
        self.calls.append(("should_run", job, size))
        return self.should

    def can_run(self, job, request):
        self.calls.append(("can_run", job))
        return self.can

    def run(self, job, request):
        self.calls.append(("run", job))
        return self.answer(job, request) if callable(self.answer) else self.answer


def _engine(backend="numpy"):
    return mbplanar.Engine(mbplanar.read_model(MODELS / "fourbar_loaded.toml"), backend=backend, threads=1)


def _with(engine, spy):
    engine.prepared["backends"] = [spy]  # (what `candidates` asks, in order)
    return engine


def test_every_decline_is_numpys_and_says_why(caplog):
    phi = np.radians([10.0, 50.0, 200.0])
    reference = _engine()
    ref = mbplanar.analyse(reference, phi)
    caplog.set_level(logging.DEBUG, logger="mbplanar.backends")
    for spy in (_Spy(should="it does not pay"), _Spy(can="not this kind"), _Spy(run="a position it cannot vouch for")):
        engine = _with(_engine(), spy)
        motion = mbplanar.analyse(engine, phi)
        forces = mbplanar.kinetostatics(engine, motion)
        np.testing.assert_array_equal(motion.xy, ref.xy)
        np.testing.assert_array_equal(forces.balancing["O"], mbplanar.kinetostatics(reference, ref).balancing["O"])
        reason = next(v for v in (spy.should, spy.can, spy.answer) if isinstance(v, str))
        assert f"kinematics of 3: spy declines: {reason}" in caplog.text
        assert f"kinetostatics of 3: spy declines: {reason}" in caplog.text
        if spy.should is not True:  # (asked first: a backend that should not run is not asked whether it can)
            assert not any(call[0] == "can_run" for call in spy.calls)
    assert "kinematics of 3: numpy" in caplog.text


def test_an_accepted_request_is_the_backends(caplog):
    """A backend that runs the kernel as plain Python (whatever the size): its answer is the Motion."""
    python = load("numpy")
    phi = np.radians([10.0, 50.0, 200.0])
    ref = mbplanar.analyse(_engine(), phi)
    spy = _Spy(run=python.run)
    caplog.set_level(logging.DEBUG, logger="mbplanar.backends")
    motion = mbplanar.analyse(_with(_engine(), spy), phi)
    assert [c[0] for c in spy.calls] == ["should_run", "can_run", "run"]
    assert "kinematics of 3: spy" in caplog.text
    np.testing.assert_allclose(motion.xy, ref.xy, rtol=0, atol=1e-12)
    np.testing.assert_allclose(motion.aq, ref.aq, rtol=0, atol=1e-9)


def test_one_position_on_numpy_is_the_kernel_as_plain_python(caplog):
    """An engine on numpy asks the kernels as plain Python for one position (and numpy for more): the
    answer is numpy's own for that position, bit for bit."""
    engine = _engine()
    caplog.set_level(logging.DEBUG, logger="mbplanar.backends")
    one = mbplanar.analyse(engine, [0.3])
    assert "kinematics of 1: python" in caplog.text
    caplog.clear()
    many = mbplanar.analyse(engine, [0.3, 0.3])
    assert "python declines: 2 positions" in caplog.text
    for name in ("xy", "v", "a", "vq", "aq", "angle", "w", "e", "value", "rate", "accel", "ic"):
        np.testing.assert_array_equal(getattr(one, name)[0], getattr(many, name)[0], err_msg=name)


def test_backends_are_loaded_by_name():
    assert set(BACKENDS) == {"numpy", "numba"} and load("numpy").name == "python"
    with pytest.raises(ValueError, match="backend must be one of numpy, numba"):
        load("fortran")
    assert [b.name for b in candidates(_engine())] == ["python"]
    pytest.importorskip("numba")
    assert load("numba").name == "numba"
    assert [b.name for b in candidates(_engine("numba"))] == ["numba", "python"]


def test_compiled_only_where_it_pays(monkeypatch):
    """The command line plans its work (one command per process): the numba backend declines a plan too
    small to repay numba's own start, unless numba is loaded already; without a plan (a program using
    the library) it always runs."""
    pytest.importorskip("numba")
    from mbplanar.backends import _numba
    numba = load("numba")
    assert numba.should_run("kinematics", 10) is True
    monkeypatch.delitem(__import__("sys").modules, "numba")
    with planned(1):
        assert "pays from 500000" in numba.should_run("kinematics", 1)
    with planned(_numba.PAYS_FROM):
        assert numba.should_run("kinetostatics", 1) is True
    assert planned.positions is None
    assert "no compiled simulation" in numba.should_run("simulation", 10)


def test_one_place_picks():
    """No module but the seam chooses a backend by its name, or switches one off."""
    for path in PACKAGE.rglob("*.py"):
        text = path.read_text(encoding="utf-8")
        assert not re.search(r"\.backend\s*==", text), path
        assert "compiled = None" not in text, path
