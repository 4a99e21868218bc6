"""The backend seam (`mbplanar.backends`): the engine's compiled backend answers first, numpy (the
reference) takes every batch it declines, in one place for kinematics and kinetostatics alike."""

import pathlib

import numpy as np
import pytest

import mbplanar
from mbplanar.backends import BACKENDS, load

MODELS = pathlib.Path(__file__).resolve().parent.parent / "models"


class _Spy:
    """A backend that records its calls and answers `answer` (None: declines)."""

    name = "spy"

    def __init__(self, answer=None):
        self.answer, self.calls = answer, []

    def kinematics(self, engine, phi, omega, epsilon, points, rates):
        self.calls.append(("kinematics", phi.shape))
        return self.answer

    def kinetostatics(self, engine, motion, input_inertia, loads, inertia):
        self.calls.append(("kinetostatics", len(motion.phi)))
        return self.answer


def _engine():
    return mbplanar.Engine(mbplanar.read_model(MODELS / "fourbar.toml"))


def test_a_declined_batch_is_numpys():
    phi = np.radians([10.0, 50.0, 200.0])
    reference = mbplanar.analyse(_engine(), phi)
    engine = _engine()
    engine.compiled = spy = _Spy()
    motion = mbplanar.analyse(engine, phi)
    forces = mbplanar.kinetostatics(engine, motion)
    assert spy.calls == [("kinematics", (3,)), ("kinetostatics", 3)]
    np.testing.assert_array_equal(motion.xy, reference.xy)
    np.testing.assert_array_equal(forces.balancing["O"],
                                  mbplanar.kinetostatics(reference.engine, reference).balancing["O"])


def test_an_accepted_batch_is_the_backends():
    engine = _engine()
    engine.compiled = _Spy(answer="from the backend")
    assert mbplanar.analyse(engine, [0.1]) == "from the backend"


def test_backends_are_loaded_by_name():
    assert set(BACKENDS) == {"numpy", "numba"} and load("numpy") is None
    with pytest.raises(ValueError, match="backend must be one of numpy, numba"):
        load("fortran")
    pytest.importorskip("numba")
    assert load("numba").name == "numba"
    assert mbplanar.Engine(mbplanar.read_model(MODELS / "fourbar.toml"), backend="numba").compiled is load("numba")
