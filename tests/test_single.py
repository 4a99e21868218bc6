"""`mbplanar.position`, one position: the row `analyse` gives, on both backends and every linkage model,
at random values, far away (many turns) and near motion limits; the kinematics kernel takes the ordinary
positions itself (compiled, or as plain Python on numpy); positions past a limit raise MotionError; bad
input raises ModelError; answers are the caller's own arrays."""

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import mbplanar
from mbplanar.errors import ModelError, MotionError
from mbplanar.kinematics import Position
from mbplanar.kinematics._single import ANALOGUES

FIELDS = [(f.name, None, None) for f in __import__("dataclasses").fields(Position)
          if f.name not in ("link_names", "point_names", "joint_names", "success", "message", "model")]

from conftest import MODELS, linkage_models
from test_change_points import closed_form_rocker_angles, fourbar

BACKENDS = ["numpy", pytest.param("numba", marks=pytest.mark.skipif(
    __import__("importlib").util.find_spec("numba") is None, reason="numba is not installed"))]
NAMES = sorted(p.stem for p in linkage_models())
_ENGINES = {}


def _engine(name: str, backend: str) -> mbplanar.Engine:
    """One engine per model and backend for this module (the atlas grows as the tests ask)."""
    if (name, backend) not in _ENGINES:
        _ENGINES[name, backend] = mbplanar.Engine(mbplanar.read_model(MODELS / f"{name}.toml"), backend=backend,
                                                  threads=1)
    return _ENGINES[name, backend]


def _assert_row(pos, motion, tol=1e-12):
    """Every field of `pos` equals row 0 of `motion` to `tol` relative to the field's largest value (1 at
    least); the instantaneous centres where the link turns (elsewhere they are NaN, or ~1/ω)."""
    assert motion.success and len(motion.phi) == 1
    w = motion.w[0]
    for name, _, _ in FIELDS:
        got, want = getattr(pos, name), getattr(motion, name)
        if want is None:
            assert got is None, name
            continue
        want = np.asarray(want)[0]
        if name == "ic":
            turning = np.abs(w) > 1e-6 * (1 + np.abs(w).max())
            got, want = got[turning], want[turning]
        assert got.shape == want.shape, name
        assert np.array_equal(np.isfinite(got), np.isfinite(want)), name
        finite = np.isfinite(want)
        scale = 1.0 + np.abs(want[finite]).max(initial=0.0)
        err = np.abs(got[finite] - want[finite]).max(initial=0.0) / scale
        assert err <= tol, f"{name}: {err:.3g}"


def _values(engine, rng, count):
    """Input values (SI) of one input: random over its sweep, its ends, and for a full-turn mechanism
    values many turns away both ways."""
    inp = engine.inputs[0]
    lo, hi = sorted(inp.to_si(v) for v in inp.default_sweep()[:2])
    values = list(rng.uniform(lo, hi, count)) + [lo, hi]
    if engine.period() is not None:
        phi0 = float(engine.phi_drawn[0])
        values += [phi0 + 2 * math.pi * 100 + rng.uniform(0, 6), phi0 - 2 * math.pi * 37 - rng.uniform(0, 6), 1000.0]
    return values


def _twins(name: str, backend: str):
    """The engine of `backend` and a numpy engine of the same model, both with the period looked for (so
    that their atlases grow alike: the same walks, the same nodes)."""
    engine, twin = _engine(name, backend), _engine(name, "numpy")
    for e in (engine, twin):
        if len(e.inputs) == 1:
            e.period()
    return engine, twin


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", NAMES)
def test_every_model_gives_the_row_of_analyse(name, backend):
    """To 1e-12 of the reference (numpy's batch path on an engine with the same atlas); the compiled
    path also to its own backend's `analyse`, to the two backends' agreement (1e-10)."""
    engine, twin = _twins(name, backend)
    rng = np.random.default_rng(17)
    if len(engine.inputs) != 1:  # several inputs: near the drawn pose, one value each
        for _ in range(2):
            phi = engine.phi_drawn + 0.02 * rng.standard_normal(len(engine.inputs))
            pos = mbplanar.position(engine, phi, omega=1.5, epsilon=-0.5)
            _assert_row(pos, mbplanar.analyse(twin, phi[None, :], 1.5, -0.5))
            assert pos.vq is None and pos.phi.shape == (len(engine.inputs),)
        return
    solved = 0
    for x in _values(engine, rng, 6):
        om, ep = rng.uniform(-3, 3, 2)
        motion = mbplanar.analyse(twin, [x], om, ep)
        if not motion.success:
            with pytest.raises(MotionError, match="cannot reach"):
                mbplanar.position(engine, x, om, ep)
            continue
        pos = mbplanar.position(engine, x, om, ep)
        _assert_row(pos, motion)
        if engine is not twin:
            _assert_row(pos, mbplanar.analyse(engine, [x], om, ep), tol=1e-10)
        solved += 1
    assert solved >= 6


@pytest.mark.parametrize("backend", BACKENDS)
def test_near_a_motion_limit_and_past_it(backend):
    """A hair before the located limit (rates ~1e5 there) the answer is the reference's to 1e-12; past it
    a MotionError names the limit and the range the input moves through."""
    engine, twin = _twins("crank_slider_rocker_locking", backend)
    inp = engine.inputs[0]
    for e in (engine, twin):
        mbplanar.analyse(e, [inp.to_si(v) for v in np.linspace(0, 360, 73)])  # walks to the limits
    atlas = engine.atlas()
    limit = atlas.limits[+1] if atlas.limits[+1] is not None else atlas.limits[-1]
    last = atlas.arrays()[0][-1 if limit is atlas.limits[+1] else 0]
    for x in (last, last - limit.direction * 1e-6, last - limit.direction * 1e-3):
        _assert_row(mbplanar.position(engine, float(x), 2.0, 0.3), mbplanar.analyse(twin, [x], 2.0, 0.3))
    with pytest.raises(MotionError, match="motion limit.*moves within"):
        mbplanar.position(engine, float(limit.phi[0]) + limit.direction * 1e-3)


def test_a_rocker_refuses_far_values_clearly():
    engine = mbplanar.Engine(mbplanar.read_model(Path(__file__).parent / "data" / "double_rocker.toml"))
    with pytest.raises(MotionError, match="cannot reach|beyond the range"):
        mbplanar.position(engine, 1e6)


def test_closed_form_of_the_four_bar():
    """The rocker's angle against the circle intersection, not against the engine's own batch path."""
    mech = fourbar(1.0, 3.0, 2.5, 3.0, 60.0)
    engine = mbplanar.Engine(mech)
    phi = np.radians([0.0, 77.0, 200.0, 333.0])
    want = closed_form_rocker_angles(1.0, 3.0, 2.5, 3.0, phi)[0]
    got = np.array([mbplanar.position(engine, x).angle[engine.link_index["3"]] for x in phi])
    np.testing.assert_allclose(np.angle(np.exp(1j * (got - want))), 0.0, atol=1e-12)


@pytest.fixture()
def compiled():
    pytest.importorskip("numba")
    return mbplanar.Engine(mbplanar.read_model(MODELS / "fourbar.toml"), backend="numba", threads=1)


@pytest.mark.parametrize("backend", BACKENDS)
def test_the_kernel_takes_ordinary_positions_itself(backend, monkeypatch):
    """No numpy for positions inside the walked atlas, on either backend (numpy's engine runs the kernel
    as plain Python); values many turns away are numpy's (reduced by the period): the answers still
    equal analyse's."""
    from mbplanar.kinematics import _motion
    engine = mbplanar.Engine(mbplanar.read_model(MODELS / "fourbar.toml"), backend=backend, threads=1)
    x = [float(engine.phi_drawn[0]) + d for d in (0.1, -2.0, 3.0, 2 * math.pi * 500 + 0.7, -2 * math.pi * 99 - 0.2)]
    expected = [mbplanar.analyse(engine, [v], 2.0, 0.5) for v in x]  # walks the atlas and finds the period
    for v, motion in zip(x[:3], expected):
        with monkeypatch.context() as patched:
            patched.setattr(_motion, "_reference", lambda *a: pytest.fail("the numpy path was taken"))
            _assert_row(mbplanar.position(engine, v, 2.0, 0.5), motion)
    for v, motion in zip(x[3:], expected[3:]):
        _assert_row(mbplanar.position(engine, v, 2.0, 0.5), motion)


def test_a_change_point_goes_to_the_reference():
    pytest.importorskip("numba")
    engine = mbplanar.Engine(fourbar(1.0, 2.0, 1.0, 2.0, 60.0), backend="numba", threads=1)
    phi = engine.phi_drawn[0] + np.radians(np.arange(0.0, 360.0, 5.0))
    motion = mbplanar.analyse(engine, phi)
    crossing = motion.crossings[0]
    for x in (crossing.phi[0], 0.5 * (crossing.bracket[0] + crossing.phi[0])):
        _assert_row(mbplanar.position(engine, float(x)), mbplanar.analyse(engine, [x]))


def test_answers_are_the_callers_own(compiled):
    a = mbplanar.position(compiled, 1.0)
    xy = a.xy.copy()
    b = mbplanar.position(compiled, 2.0)
    np.testing.assert_array_equal(a.xy, xy)
    assert not np.shares_memory(a.xy, b.xy)
    assert a.point_names == mbplanar.analyse(compiled, [1.0]).point_names
    assert a.xy[a.point("M")].shape == (2,) and a.angle.shape == (len(a.link_names),)


@pytest.mark.parametrize("backend", BACKENDS)
def test_bad_input_is_refused(backend):
    engine = _engine("fourbar", backend)
    for phi in (math.nan, math.inf, [1.0, 2.0], "x"):
        with pytest.raises(ModelError, match="phi"):
            mbplanar.position(engine, phi)
    with pytest.raises(ModelError, match="omega"):
        mbplanar.position(engine, 1.0, omega=math.inf)
    with pytest.raises(ModelError, match="epsilon"):
        mbplanar.position(engine, 1.0, epsilon=1e300)
    pos = mbplanar.position(engine, np.array([1.0]), omega=np.array(2.0))  # one number in an array is one
    assert pos.phi[0] == 1.0 and pos.omega[0] == 2.0


@settings(max_examples=25, deadline=None)
@given(st.floats(-40.0, 40.0), st.floats(-5.0, 5.0), st.floats(-5.0, 5.0))
def test_compiled_equals_numpy(x, om, ep):
    """The compiled lean path against numpy's batch path on another engine (to the agreement of the two
    backends: positions 1e-12 of the size, rates 1e-10 relative)."""
    pytest.importorskip("numba")
    fast = mbplanar.position(_engine("six_bar_press", "numba"), x, om, ep)
    ref = mbplanar.analyse(_engine("six_bar_press", "numpy"), [x], om, ep)
    _assert_row(fast, ref, tol=1e-10)
    assert set(ANALOGUES) <= {name for name, _, _ in FIELDS}


def test_document_of_a_position_is_that_of_its_motion():
    from mbplanar.io import document, partials_document
    engine = _engine("shaper", "numpy")
    x = engine.inputs[0].to_si(30.0)
    pos, motion = mbplanar.position(engine, x, 1.0, 0.0), mbplanar.analyse(engine, [x], 1.0, 0.0)
    assert document(pos, values=[30.0], units="model") == document(motion, values=[30.0], units="model")
    assert partials_document(engine, motion.phi, pos) == partials_document(engine, motion.phi)


def test_solve_command_on_the_compiled_backend(capsys):
    """`solve --backend numba` in a process that has the compiled kernels loaded goes through the compiled
    lean path and prints numpy's document (to the backends' agreement), with the same keys."""
    import json

    from mbplanar.cli import main
    pytest.importorskip("numba")
    import mbplanar.backends._numba_kinematics  # noqa: F401  (loaded: one position pays, `NumbaBackend.pays`)
    docs = []
    for backend in ("numpy", "numba"):
        assert main(["--backend", backend, "solve", str(MODELS / "six_bar_press.toml"), "--at", "1000",
                     "--omega", "3", "--json"]) == 0
        docs.append(json.loads(capsys.readouterr().out))

    def flat(doc, path=""):
        if isinstance(doc, dict):
            return {k: v for key, sub in doc.items() for k, v in flat(sub, f"{path}/{key}").items()}
        if isinstance(doc, list):
            return {k: v for i, sub in enumerate(doc) for k, v in flat(sub, f"{path}/{i}").items()}
        return {path: doc}

    ref, fast = flat(docs[0]), flat(docs[1])
    assert ref.keys() == fast.keys()
    for key, value in ref.items():
        if isinstance(value, float):
            assert fast[key] == pytest.approx(value, rel=1e-9, abs=1e-9), key
        else:
            assert fast[key] == value, key


@pytest.mark.parametrize("backend", BACKENDS)
def test_an_engine_that_solved_positions_still_pickles(backend):
    """(an engine goes to another process, a Dask worker, with the tables it has made)"""
    import pickle
    engine = mbplanar.Engine(mbplanar.read_model(MODELS / "slider_crank.toml"), backend=backend, threads=1)
    first = mbplanar.position(engine, 1.0, 2.0)
    again = pickle.loads(pickle.dumps(engine))
    again_first = mbplanar.position(again, 1.0, 2.0)
    for name, _, _ in FIELDS:
        assert getattr(again_first, name).tobytes() == getattr(first, name).tobytes(), name
