"""The compiled kinetostatics (numba) gives the numpy kinetostatics' answers: reactions, balancing loads,
the loads that acted, the virtual-power residual and the singular positions, on every model with force
data, on random mechanisms with random masses and loads, and it leaves to numpy what it does not take
(input inertia, loads given by the caller, a numpy Motion). Skipped without numba."""

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import mbplanar
from conftest import linkage_models
from mbplanar.forces import kinetostatics
from mbplanar.forces import evaluate_loads, has_force_data
from mbplanar.forces._loads import joint_rate_sign

pytest.importorskip("numba")

from conftest import MODELS  # noqa: E402
from test_kinetostatics import _equilibrium_residual, _random_mass_and_loads  # noqa: E402
from test_properties import mechanisms  # noqa: E402

FORCE_MODELS = sorted(p.stem for p in linkage_models() if has_force_data(mbplanar.read_model(p)))


def _motions(mech, phi, omega=2.5, epsilon=-0.7):
    ref_engine = mbplanar.Engine(mech)
    fast_engine = mbplanar.Engine(mech, backend="numba")
    ref = mbplanar.analyse(ref_engine, phi, omega, epsilon)
    fast = mbplanar.analyse(fast_engine, phi, omega, epsilon)
    assert fast.records is not None, "the compiled kinematics declined the batch"  # (higher pairs too)
    return (ref_engine, ref), (fast_engine, fast)


def _assert_same(ref, fast, rtol=1e-9):
    """Every reaction, balancing load and load to `rtol` of the largest of its kind; the same singular
    positions; residuals of the same (round-off) size."""
    np.testing.assert_array_equal(fast.singular, ref.singular)
    ok = ~ref.singular
    forces = [(r.fx, r.fy, r.moment) for r in ref.reactions.values()]
    scale = max([1.0] + [np.max(np.abs(a[ok])) for triple in forces for a in triple])
    for name, r in ref.reactions.items():
        f = fast.reactions[name]
        assert (f.on, f.source) == (r.on, r.source)
        for part in ("fx", "fy", "moment"):
            np.testing.assert_allclose(getattr(f, part), getattr(r, part), rtol=0, atol=rtol * scale,
                                       err_msg=f"{name}.{part}")
    for name, q in ref.balancing.items():
        np.testing.assert_allclose(fast.balancing[name], q, rtol=0, atol=rtol * max(1.0, np.max(np.abs(q[ok]))))
    assert [ld.name for ld in fast.loads] == [ld.name for ld in ref.loads]
    for a, b in zip(ref.loads, fast.loads):
        assert a.link == b.link
        for part in ("force", "point", "moment"):
            x, y = getattr(a, part), getattr(b, part)
            np.testing.assert_allclose(y, x, rtol=0, atol=rtol * (1.0 + np.max(np.abs(x))), err_msg=f"{a.name}.{part}")
    assert np.all(fast.virtual_power_residual[ok] < 1e-9)
    np.testing.assert_allclose(fast.virtual_power_residual[ok], ref.virtual_power_residual[ok], rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", FORCE_MODELS)
@pytest.mark.parametrize("inertia", [True, False])
def test_every_model_same_as_numpy(name, inertia):
    mech = mbplanar.read_model(MODELS / f"{name}.toml")
    engine = mbplanar.Engine(mech)
    if len(engine.inputs) != 1:
        pytest.skip("several inputs: the numpy path only")
    inp = engine.inputs[0]
    lo, hi = (inp.to_si(v) for v in inp.default_sweep()[:2])
    (ref_engine, ref), (fast_engine, fast) = _motions(mech, np.linspace(lo, hi, 721))
    _assert_same(kinetostatics(ref_engine, ref, inertia=inertia), kinetostatics(fast_engine, fast, inertia=inertia),
                 rtol=1e-6 if ref.limits else 1e-9)  # the locking model's last rows: rates ~1e6


def test_shaper_guide_loads_switch_with_the_stroke():
    """The cutting force acts on the working stroke only: both paths switch it at the same rows."""
    mech = mbplanar.read_model(MODELS / "shaper.toml")
    engine = mbplanar.Engine(mech)
    (ref_engine, ref), (fast_engine, fast) = _motions(mech, engine.phi_drawn[0] + np.linspace(0, 2 * math.pi, 1441))
    a, b = kinetostatics(ref_engine, ref), kinetostatics(fast_engine, fast)
    cut_ref = next(ld for ld in a.loads if ld.name == "cutting").force
    cut_fast = next(ld for ld in b.loads if ld.name == "cutting").force
    on = np.hypot(*cut_ref.T) > 0
    assert 0 < on.sum() < len(on)  # a working stroke and a return stroke
    np.testing.assert_array_equal(np.hypot(*cut_fast.T) > 0, on)
    _assert_same(a, b)
    assert _equilibrium_residual(fast_engine, fast, b) < 1e-8


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mechanisms(), st.data())
def test_random_mechanisms_same_as_numpy(mech_kind, data):
    """Four-bars, slider-cranks, inverted slider-cranks and six-bars with a dyad on a moving guide, with
    random masses, centres, forces and moments, gravity, and a resistance on a prismatic pair."""
    mech, _ = mech_kind
    mech.add_input("O", unit="rad")
    _random_mass_and_loads(mech, data.draw, ("1", "2", "3"))
    prismatic = [j.name for j in mech.joints.values() if j.kind == "P"]
    if prismatic:
        mech.add_load("resistance", joint=prismatic[0], force=300.0,
                      when=data.draw(st.sampled_from(["forward", "backward", "always"])))
        carrier = mech.joints[prismatic[-1]].carrier
        if carrier != mech.ground:  # (a guide force on the carrier: the opposite of the slider's)
            mech.add_load("friction", joint=prismatic[-1], link=carrier, force=80.0)
    try:
        engine = mbplanar.Engine(mech)
    except mbplanar.MbplanarError:
        assume(False)
    phi = engine.phi_drawn[0] + np.linspace(0.0, 2 * math.pi, 200)
    (ref_engine, ref), (fast_engine, fast) = _motions(mech, phi, data.draw(st.floats(0.5, 20.0)),
                                                      data.draw(st.floats(-5.0, 5.0)))
    assume(len(ref.phi) > 0)
    # away from dead points, where the balancing moment grows without bound
    keep = np.all(np.abs(ref.wq) < 50, axis=1)
    for name in dict.fromkeys(prismatic[:1] + prismatic[-1:]):  # and where a loaded slider's rate is round-off,
        rate = joint_rate_sign(ref, name)   # where "forward" and the friction's sense are either answer
        keep &= np.abs(rate) > 1e-9 * max(1e-300, np.max(np.abs(rate)))
    a, b = (dataclasses.replace(r, singular=r.singular | ~keep)
            for r in (kinetostatics(ref_engine, ref), kinetostatics(fast_engine, fast)))
    _assert_same(a, b, rtol=1e-7)


def test_what_the_compiled_path_does_not_take_is_numpy():
    """Input inertia and loads given by the caller go to numpy; so does a numpy Motion on a compiled
    engine: the answers are numpy's, bit for bit."""
    mech = mbplanar.read_model(MODELS / "shaper.toml")
    engine = mbplanar.Engine(mech)
    phi = engine.phi_drawn[0] + np.linspace(0, 2 * math.pi, 97)
    (ref_engine, ref), (fast_engine, fast) = _motions(mech, phi)
    with_inertia = kinetostatics(fast_engine, fast, input_inertia=0.4)
    assert with_inertia.loads[-1].name.startswith("input inertia")
    _assert_same(kinetostatics(ref_engine, fast, input_inertia=0.4), with_inertia)
    given_loads = evaluate_loads(fast_engine, fast)[:1]
    a, b = kinetostatics(ref_engine, fast, loads=given_loads), kinetostatics(fast_engine, fast, loads=given_loads)
    for name, r in a.reactions.items():
        np.testing.assert_array_equal(b.reactions[name].fx, r.fx)
    np.testing.assert_array_equal(kinetostatics(fast_engine, ref).reactions["F"].fx,
                                  kinetostatics(ref_engine, ref).reactions["F"].fx)



@pytest.mark.parametrize("batch", [2, 319, 321, 383, 385, 800])
def test_batches_across_chunks_same_as_numpy(batch, monkeypatch):
    """The kernel takes the positions a chunk at a time: a batch much shorter than a chunk, one position
    either side of a chunk's end, several chunks; on a class III group (its dense part pivots position
    by position), the six-bar press (a guide load) and the class IV group (a longer program)."""
    from mbplanar.backends import _numba_kinetostatics as nk
    monkeypatch.setattr(nk, "WORK_BYTES", 400 * 1024)  # (a 512 KiB L2 cache's, whatever this machine's)
    assert nk.CHUNKS == (384, 320, 256, 128) and nk.chunk_of(100) == 384 and nk.chunk_of(156) == 320  # (straddled)
    for name in ("class3_triad", "six_bar_press", "class4_group"):
        mech = mbplanar.read_model(MODELS / f"{name}.toml")
        engine = mbplanar.Engine(mech)
        phi = engine.phi_drawn[0] + np.linspace(0.0, 2 * math.pi, batch, endpoint=False)
        (ref_engine, ref), (fast_engine, fast) = _motions(mech, phi)
        _assert_same(kinetostatics(ref_engine, ref), kinetostatics(fast_engine, fast))


def test_one_compiled_kernel_for_every_model():
    """The models differ in the kernel's program (data), not in its code: numba compiles one kernel."""
    from mbplanar.backends import _numba_kinetostatics
    for name in FORCE_MODELS:
        mech = mbplanar.read_model(MODELS / f"{name}.toml")
        engine = mbplanar.Engine(mech, backend="numba")
        if len(engine.inputs) == 1:
            kinetostatics(engine, mbplanar.analyse(engine, engine.phi_drawn[0] + np.linspace(0.0, 1.0, 5)))
    assert len(_numba_kinetostatics._kernel.signatures) == 1


def test_prismatic_input_same_as_numpy(tmp_path):
    """A slider-crank driven at its slider: the balancing load is a force along the guide (its lever is
    a feature of its own), the same as numpy's."""
    text = (MODELS / "slider_crank.toml").read_text()
    for link, extra in (('"1", length = 0.1', 'mass = 1.5, inertia = 0.01, centre = "A"'),
                        ('"2", length = 0.3', 'mass = 2.0, inertia = 0.03, centre = "B"'),
                        ('"3"', 'mass = 4.0, centre = "B"')):
        text = text.replace(f"{{ name = {link} }}", f"{{ name = {link}, {extra} }}")
    text = text.replace('joint = "O"\ndrawn_at = 45.0', 'joint = "Bp"\ndrawn_at = 0.0')
    (tmp_path / "driven_slider.toml").write_text(text)
    mech = mbplanar.read_model(tmp_path / "driven_slider.toml")
    assert mech.joints[mbplanar.Engine(mech).inputs[0].joint].kind == "P"
    engine = mbplanar.Engine(mech)
    (ref_engine, ref), (fast_engine, fast) = _motions(mech, engine.phi_drawn[0] + np.linspace(-0.1, 0.1, 200), 0.5, 0.1)
    a, b = kinetostatics(ref_engine, ref), kinetostatics(fast_engine, fast)
    assert np.all(np.abs(a.balancing["Bp"]) > 0)
    _assert_same(a, b)


def test_a_held_result_keeps_its_values_and_a_dropped_one_lends_its_block():
    """The kernel writes into an output block of an earlier call only when no result holds any array of
    it: a result kept while later calls run keeps its values; once dropped, its block is written again."""
    mech = mbplanar.read_model(MODELS / "six_bar_press.toml")
    engine = mbplanar.Engine(mech, backend="numba", threads=1)
    phi = engine.phi_drawn[0] + np.linspace(0.0, 2 * math.pi, 300, endpoint=False)
    first, second = mbplanar.analyse(engine, phi), mbplanar.analyse(engine, phi + 0.5)
    held = kinetostatics(engine, first)
    fx, point = held.reactions["B"].fx.copy(), held.loads[-1].point.copy()
    for _ in range(3):
        later = kinetostatics(engine, second)
        assert not np.shares_memory(later.reactions["B"].fx, held.reactions["B"].fx)
    np.testing.assert_array_equal(held.reactions["B"].fx, fx)
    np.testing.assert_array_equal(held.loads[-1].point, point)
    block = id(held.reactions["B"].fx.base)
    del held
    again = kinetostatics(engine, first)
    assert id(again.reactions["B"].fx.base) == block  # (still kept by the plan: not a new array at its address)
    np.testing.assert_array_equal(again.reactions["B"].fx, fx)


def test_work_bytes_from_the_l2_cache_size(tmp_path):
    """The work matrix takes four fifths of the L2 cache sysfs names, 512 KiB's where it names none."""
    from mbplanar.backends._numba_kinetostatics import _l2_bytes
    size = tmp_path / "size"
    for text, want in (("512K\n", 512 * 1024), ("2M", 2 * 1024 ** 2), ("1024K", 1024 ** 2), ("", 512 * 1024),
                       ("big", 512 * 1024)):
        size.write_text(text)
        assert _l2_bytes(str(size)) == want
    assert _l2_bytes(str(tmp_path / "none")) == 512 * 1024


def test_work_matrix_starts_a_cache_line():
    """The kernel's work matrix starts on a 64-byte line whatever numpy's allocator gives (zeros, the
    shape asked for), and its rows stay on lines."""
    from mbplanar.backends import _numba_kinetostatics as nk
    for rows in (1, 7, 98, 156, 400):
        (work,) = nk._scratch(rows)
        assert work.shape == (rows + 2, nk.chunk_of(rows)) and not work.any() and work.flags.c_contiguous
        assert work.ctypes.data % nk.LINE == 0 and work.strides[0] % nk.LINE == 0
    for shape in ((3,), (5, 8), (2, 3, 4)):
        assert nk.aligned_zeros(shape).ctypes.data % nk.LINE == 0


def test_constant_and_repeated_load_values_are_not_written_twice():
    """Gravity's force and zero moment are the program's constants and the centre of a link is written
    once for its gravity and its d'Alembert load; the loads still read as numpy's, each force its own."""
    mech = mbplanar.read_model(MODELS / "six_bar_press.toml")
    (ref_engine, ref), (fast_engine, fast) = _motions(mech, np.linspace(0.0, 2 * math.pi, 40, endpoint=False))
    a, b = kinetostatics(ref_engine, ref), kinetostatics(fast_engine, fast)
    _assert_same(a, b)
    loads = {ld.name: ld for ld in b.loads}
    gravity, inertia = loads["G3"], loads["inertia of 3"]
    assert np.shares_memory(gravity.point, inertia.point)
    assert not np.shares_memory(gravity.force, inertia.force)
    assert not np.shares_memory(gravity.force, b.reactions["B"].fx)
    np.testing.assert_array_equal(gravity.force, np.broadcast_to(gravity.force[0], gravity.force.shape))
    np.testing.assert_array_equal(gravity.moment, 0.0)


def test_dense_rows_in_their_usual_pivot_order_give_the_same_numbers(monkeypatch):
    """The class IV group's dense part (6 moment rows) starts in the order its LU's partial pivoting
    usually ends with (`pivot_orders`, a permutation of its rows), so the kernel's pivot steps seldom
    swap; the pivots, and so every number, are those of the rows in the table's order."""
    from mbplanar.forces import _program
    from mbplanar.forces._kinetostatics import pivot_orders, plan_of
    mech = mbplanar.read_model(MODELS / "class4_group.toml")
    phi = mbplanar.Engine(mech).phi_drawn[0] + np.linspace(0.0, 2 * math.pi, 90, endpoint=False)
    (ref_engine, ref), (fast_engine, fast) = _motions(mech, phi)
    orders = pivot_orders(fast_engine, fast)
    dense = [i for i, blk in enumerate(plan_of(fast_engine).blocks) if len(blk.rest_rows) >= 3]
    assert dense and sorted(orders) == dense
    assert all(sorted(orders[i]) == list(range(len(plan_of(fast_engine).blocks[i].rest_rows))) for i in dense)
    assert any(orders[i] != tuple(range(len(orders[i]))) for i in dense)  # (the usual order is not the table's)
    learnt = kinetostatics(fast_engine, fast)
    monkeypatch.setattr(_program, "pivot_orders", lambda engine, motion: {})
    plain_engine = mbplanar.Engine(mech, backend="numba")
    plain = kinetostatics(plain_engine, mbplanar.analyse(plain_engine, phi, 2.5, -0.7))
    for name, r in plain.reactions.items():
        for part in ("fx", "fy", "moment"):
            np.testing.assert_array_equal(getattr(learnt.reactions[name], part), getattr(r, part))
    _assert_same(kinetostatics(ref_engine, ref), learnt)


def test_the_kernel_is_looked_up_once_per_program():
    """A program keeps the compiled kernel the backend looked up (per read-only flag of the records),
    calls it again with the same answers, and a pickled program leaves it behind; the backend gets the
    program, the records and the inputs, not the engine (and the higher pairs' force directions, arrays
    the result's contact forces are made of)."""
    import dataclasses
    import pickle
    from mbplanar.forces._kinetostatics import KinetostaticsJob, plan_of
    from mbplanar.forces._program import program_for
    mech = mbplanar.read_model(MODELS / "six_bar_press.toml")
    engine = mbplanar.Engine(mech, backend="numba", threads=1)
    motion = mbplanar.analyse(engine, engine.phi_drawn[0] + np.linspace(0.0, 1.0, 20))
    first = kinetostatics(engine, motion).reactions["B"].fx.copy()
    program = program_for(engine, plan_of(engine), motion, True)
    assert list(program.store["entries"]) == [True]
    found = program.store["entries"][True]
    np.testing.assert_array_equal(kinetostatics(engine, motion).reactions["B"].fx, first)
    assert program.store["entries"] == {True: found}
    assert pickle.loads(pickle.dumps(program)).store == {}
    assert {f.name for f in dataclasses.fields(KinetostaticsJob)} == {"program", "why", "records", "inputs", "threads",
                                                                     "directions"}  # (arrays: the contact forces')
