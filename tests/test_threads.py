"""Splitting a long batch over threads (`mbplanar.backends._threads`): the chunks cover the batch, the thread
count is the caller's or the environment's, and the compiled answers do not depend on it."""

import math

import numpy as np
import pytest

import mbplanar
from mbplanar.backends import _threads
from mbplanar.forces import kinetostatics

from conftest import MODELS
from test_change_points import fourbar


@pytest.mark.parametrize("batch", [1, 7, 2 * _threads.MIN_CHUNK - 1, 2 * _threads.MIN_CHUNK, 5000, 12345])
@pytest.mark.parametrize("threads", [1, 2, 3, 8])
def test_chunks_cover_the_batch(batch, threads):
    parts = _threads.chunks(batch, threads)
    assert parts[0].start == 0 and parts[-1].stop == batch
    assert all(a.stop == b.start for a, b in zip(parts, parts[1:]))
    assert 1 <= len(parts) <= threads
    if len(parts) > 1:
        assert min(p.stop - p.start for p in parts) >= _threads.MIN_CHUNK
    if batch >= threads * _threads.MIN_CHUNK:
        assert len(parts) == threads


def test_thread_count_from_the_environment(monkeypatch):
    monkeypatch.setenv("MBPLANAR_THREADS", "3")
    assert _threads.available() == 3
    assert len(_threads.chunks(10 * _threads.MIN_CHUNK)) == 3
    for bad in ("0", "-1", "two", "1.5"):
        monkeypatch.setenv("MBPLANAR_THREADS", bad)
        with pytest.raises(mbplanar.MbplanarError, match="MBPLANAR_THREADS must be a positive integer"):
            _threads.available()
    monkeypatch.delenv("MBPLANAR_THREADS")
    assert _threads.available() >= 1


def test_run_returns_every_result_in_order():
    assert _threads.run([lambda k=k: k * k for k in range(5)]) == [0, 1, 4, 9, 16]


def test_bad_thread_count_is_refused():
    mech = mbplanar.read_model(MODELS / "fourbar.toml")
    for bad in (0, -2, 1.5, "2"):
        with pytest.raises(ValueError, match="threads"):
            mbplanar.Engine(mech, threads=bad)


@pytest.mark.parametrize("name", ["shaper", "class4_group"])
def test_compiled_answers_do_not_depend_on_threads(name):
    pytest.importorskip("numba")
    mech = mbplanar.read_model(MODELS / f"{name}.toml")
    one, three = (mbplanar.Engine(mech, backend="numba", threads=t) for t in (1, 3))
    phi = one.phi_drawn[0] + np.linspace(0.0, 2 * math.pi, 3 * _threads.MIN_CHUNK + 17)
    a, b = mbplanar.analyse(one, phi, 3.0, 0.5), mbplanar.analyse(three, phi, 3.0, 0.5)
    assert a.records is not None and b.records is not None
    np.testing.assert_array_equal(b.records.view(np.float64), a.records.view(np.float64))  # NaN where NaN
    for name in ("xy", "v", "a", "vq", "aq", "w", "e", "rate", "accel", "ic"):
        np.testing.assert_array_equal(getattr(b, name), getattr(a, name), err_msg=name)
    ka, kb = kinetostatics(one, a), kinetostatics(three, b)
    for joint, r in ka.reactions.items():
        np.testing.assert_array_equal(kb.reactions[joint].fx, r.fx)
        np.testing.assert_array_equal(kb.reactions[joint].moment, r.moment)
    np.testing.assert_array_equal(kb.virtual_power_residual, ka.virtual_power_residual)


def test_a_chunk_that_needs_numpy_sends_the_whole_batch_there():
    """The change point of a parallelogram lies in the last of three chunks: the batch is numpy's."""
    pytest.importorskip("numba")
    mech = fourbar(1.0, 2.0, 1.0, 2.0, 60.0)
    ref, fast = mbplanar.Engine(mech), mbplanar.Engine(mech, backend="numba", threads=3)
    phi = ref.phi_drawn[0] + np.linspace(-2.0, 1.1 * math.pi - 1.0, 3 * _threads.MIN_CHUNK)
    a, b = mbplanar.analyse(ref, phi), mbplanar.analyse(fast, phi)
    assert b.crossings and b.records is None
    np.testing.assert_array_equal(b.xy, a.xy)


def test_cli_threads_option(tmp_path, capsys):
    from mbplanar.cli import main

    model = str(MODELS / "shaper.toml")
    assert main(["--threads", "0", "info", model]) == 2  # argparse's refusal is returned, not raised
    assert "positive integer" in capsys.readouterr().err
    pytest.importorskip("numba")
    ref, fast = tmp_path / "numpy.csv", tmp_path / "numba.csv"
    steps = str(3 * _threads.MIN_CHUNK)
    assert main(["sweep", model, "--steps", steps, "-o", str(ref)]) == 0
    assert main(["--backend", "numba", "--threads", "3", "sweep", model, "--steps", steps, "-o", str(fast)]) == 0
    a, b = (np.genfromtxt(p, delimiter=",", skip_header=1) for p in (ref, fast))
    assert a.shape == b.shape and len(a) >= 3 * _threads.MIN_CHUNK
    np.testing.assert_allclose(b, a, rtol=1e-9, atol=1e-9)
