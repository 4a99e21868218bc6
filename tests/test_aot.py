"""The kernels built ahead of time (`mbplanar.backends._aot`, ``mbplanar compile``): built once for this
module, they give the just-in-time kernels' results bit for bit on several models, load in a new process
without numba, and a stale, broken or switched-off module falls back to numba's kernels."""

import os
import shutil
import subprocess
import sys
import sysconfig
from collections import namedtuple
from pathlib import Path

import numpy as np
import pytest

import mbplanar
from mbplanar.errors import MbplanarError

numba = pytest.importorskip("numba")
pytest.importorskip("numba.pycc")

from mbplanar.backends import _aot, _jit  # noqa: E402

MODELS = Path(__file__).resolve().parent.parent / "models"
ROOT = MODELS.parent
COMPARED = ("fourbar_loaded", "slider_crank", "six_bar_press", "class4_group")


def _has_compiler() -> bool:
    return shutil.which((sysconfig.get_config_var("CC") or "cc").split()[0]) is not None


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """The module built into a cache folder of its own; afterwards the rest of the run uses numba's kernels."""
    if not _has_compiler():
        pytest.skip("no C compiler: the kernels cannot be built ahead of time")
    before = os.environ.get("MBPLANAR_CACHE_DIR")
    os.environ["MBPLANAR_CACHE_DIR"] = str(tmp_path_factory.mktemp("aot-cache"))
    try:
        yield _aot.build()
    finally:
        if before is None:
            os.environ.pop("MBPLANAR_CACHE_DIR", None)
        else:
            os.environ["MBPLANAR_CACHE_DIR"] = before
        _jit.forget()


@pytest.fixture(autouse=True)
def looked_up_again():
    """Each test finds the kernels afresh, and leaves them to be found afresh."""
    _jit.forget()
    yield
    _jit.forget()


def _results(name: str) -> dict:
    """Every output of the kernels on model `name` (a sweep with and without rates, its kinetostatics, one
    position) on a new engine, with the kernels `_jit` finds now."""
    engine = mbplanar.Engine(mbplanar.read_model(MODELS / f"{name}.toml"), backend="numba", threads=1)
    phi = engine.phi_drawn[0] + np.linspace(0.0, 2 * np.pi, 90, endpoint=False)
    m, bare = mbplanar.analyse(engine, phi, 3.0, -2.0), mbplanar.analyse(engine, phi, rates=False)
    out = dict(xy=m.xy, v=m.v, a=m.a, w=m.w, e=m.e, vq=m.vq, ic=m.ic, rate=m.rate,
               rows=m.records.view(np.float64), bare=bare.xy, value=bare.value)
    assert m.records is not None  # (the compiled path took the sweep)
    if engine.mech.loads or any(link.mass for link in engine.mech.links.values()):
        k = mbplanar.kinetostatics(engine, m)
        out.update(balancing=np.asarray(list(k.balancing.values())[0]), residual=k.virtual_power_residual,
                   reactions=np.array([(r.fx, r.fy, r.moment) for r in k.reactions.values()]))
    one = mbplanar.position(engine, float(phi[7]))
    out.update(one_xy=np.asarray(one.xy), one_a=np.asarray(one.a))
    return out


def _kernel_functions() -> set:
    """Whether the compiled functions the kernels use now are the built module's (a set of bools)."""
    from mbplanar.backends import _numba_kinematics, _numba_kinetostatics
    found = set()
    for kernel in (_numba_kinematics._sweep, _numba_kinetostatics._kernel):
        found.update(getattr(f, "__module__", None) == _aot.MODULE for f in kernel._entries.values())
    return found


def test_built_kernels_equal_numbas_bit_for_bit(built, monkeypatch):
    assert (built / _aot.MANIFEST).is_file() and _aot.available()
    _jit.forget()
    mine = {name: _results(name) for name in COMPARED}
    assert _kernel_functions() == {True}  # the built module's functions, not numba's
    monkeypatch.setenv("MBPLANAR_AOT", "0")
    _jit.forget()
    theirs = {name: _results(name) for name in COMPARED}
    assert _kernel_functions() == {False}
    for name in COMPARED:
        assert mine[name].keys() == theirs[name].keys()
        for key, value in mine[name].items():
            assert np.array_equal(value, theirs[name][key], equal_nan=True), (name, key)


def test_a_new_process_runs_them_without_numba(built):
    script = ("import sys, numpy as np, mbplanar\n"
              "e = mbplanar.Engine(mbplanar.read_model(sys.argv[1]), backend='numba', threads=2)\n"
              "m = mbplanar.analyse(e, e.phi_drawn[0] + np.linspace(0, 6.2, 1000))\n"
              "k = mbplanar.kinetostatics(e, m)\n"
              "print('numba' in sys.modules, m.records is not None, repr(float(m.a.sum() + k.balancing['O'].sum())))")
    env = dict(os.environ, MBPLANAR_CACHE_DIR=str(built.parent.parent), PYTHONPATH=str(ROOT))
    out = subprocess.run([sys.executable, "-c", script, str(MODELS / "fourbar_loaded.toml")], env=env,
                         capture_output=True, text=True, check=True)
    imported, compiled, total = out.stdout.split()
    assert (imported, compiled) == ("False", "True"), out.stderr
    assert out.stderr == ""  # (no compile notice)
    engine = mbplanar.Engine(mbplanar.read_model(MODELS / "fourbar_loaded.toml"))
    m = mbplanar.analyse(engine, engine.phi_drawn[0] + np.linspace(0, 6.2, 1000))
    reference = m.a.sum() + mbplanar.kinetostatics(engine, m).balancing["O"].sum()
    assert float(total) == pytest.approx(reference, rel=1e-12, abs=1e-9)


def test_stale_broken_or_switched_off_modules_are_not_loaded(built, monkeypatch, tmp_path):
    assert _aot.available()
    monkeypatch.setenv("MBPLANAR_AOT", "0")
    _aot.reset()
    assert not _aot.available()
    monkeypatch.delenv("MBPLANAR_AOT")
    # the code changed: another key, another folder; the old module is not looked at
    monkeypatch.setattr(_aot, "_code_stamp", lambda: "edited")
    _aot.reset()
    assert _aot.folder() != built and not _aot.available()
    # the manifest's key does not match this copy: not loaded
    monkeypatch.setattr(_aot, "folder", lambda: built)
    _aot.reset()
    assert not _aot.available()
    monkeypatch.undo()
    # a broken module with the right key: not loaded, and the kernels compile with numba
    broken = tmp_path / "broken"
    broken.mkdir(mode=0o700)
    shutil.copy(built / _aot.MANIFEST, broken / _aot.MANIFEST)
    (broken / next(p.name for p in built.iterdir() if p.name.startswith(_aot.MODULE))).write_bytes(b"not a module")
    monkeypatch.setattr(_aot, "folder", lambda: broken)
    _jit.forget()
    assert not _aot.available()
    engine = mbplanar.Engine(mbplanar.read_model(MODELS / "fourbar.toml"), backend="numba", threads=1)
    assert mbplanar.analyse(engine, engine.phi_drawn[0] + np.linspace(0, 1, 5)).records is not None
    assert _kernel_functions() == {False}
    # a folder others can write into: not loaded
    monkeypatch.setattr(_aot, "folder", lambda: built)
    os.chmod(built, 0o777)
    try:
        _aot.reset()
        assert not _aot.available()
    finally:
        os.chmod(built, 0o700)
    _jit.forget()


def test_arguments_of_other_types_go_to_numba(built):
    """A kernel asked for types the module was not built for gets numba's kernel for them."""
    from mbplanar.backends import _numba_kinematics
    _jit.forget()
    assert _aot.function(_numba_kinematics._sweep.name, "?") is None
    assert _aot.function("mbplanar.backends.nothing", "") is None


def test_build_without_numba_pycc_is_a_clear_error(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "numba.pycc", None)
    with pytest.raises(MbplanarError, match="building the compiled kernels needs numba"):
        _aot.build()
    from mbplanar.cli import main
    assert main(["compile"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("mbplanar: building the compiled kernels needs numba") and err.count("\n") == 1


Pair = namedtuple("Pair", "a b")


def test_signature_tells_apart_what_numba_types_apart():
    """`_jit.signature` (made without numba) equal exactly where `numba.typeof` is: dtypes, dimensions,
    layouts, read-only arrays, scalars, tuples and named tuples; an unaligned array has a signature of its
    own (the built kernels are for aligned ones)."""
    base = np.zeros((3, 4))
    readonly = np.zeros(3)
    readonly.flags.writeable = False
    unaligned = np.frombuffer(bytes(25), np.float64, 3, 1)
    values = [np.zeros(3), np.zeros(3, np.int64), np.zeros(3, np.bool_), np.zeros(3, np.float32), base, base.T,
              base[:, ::2], base[0], base[:, 0], readonly, unaligned, np.zeros((0, 2)), np.zeros((2, 0, 2)),
              1.0, np.float64(2.0), 3, np.int64(4), True, np.bool_(False), (1.0, 2), (np.zeros(2), 1.0),
              Pair(np.zeros(2), np.zeros(2)), Pair(np.zeros(2), np.zeros(2, np.int64))]
    for x in values:
        for y in values:
            same_numba = numba.typeof(x) == numba.typeof(y) and (x is unaligned) == (y is unaligned)
            assert (_jit.signature([x]) == _jit.signature([y])) == same_numba, (x, y)
    assert _jit.signature([object()]) is None and _jit.signature([2 ** 70]) is None
