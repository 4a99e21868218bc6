"""The kernels compiled ahead of time (`mbplanar.backends._aot`, ``mbplanar compile``): numba's own on-disk
cache, filled with every kernel (the design batch's included), which a new process then loads without
compiling; mbplanar's index of that cache, which removes kernels compiled from other sources; and no
private attribute of numba written, no ``numba.pycc``."""

import ast
import json
import os
import re
import subprocess
import sys
from collections import namedtuple
from pathlib import Path

import numpy as np
import pytest

import mbplanar
from mbplanar.errors import MbplanarError

numba = pytest.importorskip("numba")

from mbplanar.backends import _aot, _jit  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "mbplanar"


@pytest.fixture(scope="module")
def built():
    """`mbplanar compile`'s build into numba's cache folder of this checkout (what the other numba tests use:
    the kernels it compiles are not compiled again by them)."""
    from mbplanar.study.batch import compile_sample
    return _aot.build(samples=(compile_sample,))


def test_compile_reaches_every_kernel_the_design_batch_included(built):
    import importlib
    for module in _aot.KERNEL_MODULES:
        importlib.import_module(f"mbplanar.backends.{module}")
    names = {kernel.name for kernel in _aot.entries(_jit.kernels())}
    assert {"mbplanar.backends._numba_kinetostatics._kernel", "mbplanar.backends._numba_kinematics._sweep",
            "mbplanar.backends._numba_design._designs"} <= names
    index = json.loads((built / _aot.INDEX).read_text())
    assert index["digest"] == _aot.digest() and index["kernels"] == sorted(names)
    assert _aot.status()["kernels"] == sorted(names)
    for kernel in _aot.entries(_jit.kernels()):  # compiled or loaded here (the kernels they call with them)
        assert kernel.dispatcher.signatures, kernel.name
    # every kernel module is one of the sources the index covers, and numba's cache is where `_jit` says
    backends = {p.stem for p in (PACKAGE / "backends").glob("*.py")}
    with_kernels = {m for m in backends if re.search(r"^\w+ = njit\(", (PACKAGE / "backends" / f"{m}.py").read_text(), re.M)}
    assert with_kernels == set(_aot.KERNEL_MODULES) and set(_aot.KERNEL_MODULES) <= {p.stem for p in _aot.sources()}
    assert Path(_jit.cache_path()) == built


CHILD = """import sys, json, numpy as np, mbplanar
from mbplanar.backends import _jit
from mbplanar.study import design_batch
e = mbplanar.Engine(mbplanar.read_model(sys.argv[1]), backend="numba", threads=1)
m = mbplanar.analyse(e, e.phi_drawn[0] + np.linspace(0, 6.2, 500), 2.0, 1.0)
k = mbplanar.kinetostatics(e, m)
p = mbplanar.position(e, 0.3, omega=2.0)
b = design_batch(sys.argv[2], {"a": np.linspace(0.09, 0.11, 8)}, backend="numba")
d = b.solve(np.radians(np.arange(0.0, 360.0, 30.0)))
made = [kernel for kernel in _jit.kernels() if kernel.made]
print(json.dumps(dict(misses=sum(kernel.dispatcher.stats.cache_misses.total() for kernel in made),
                      hits=sum(kernel.dispatcher.stats.cache_hits.total() for kernel in made),
                      rows=m.records is not None, total=float(m.a.sum() + k.balancing["O"].sum() + p.xy.sum()),
                      designs=float(np.nansum(d.xy)))))
"""


def test_a_new_process_after_compile_loads_every_kernel_without_compiling(built):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    out = subprocess.run([sys.executable, "-c", CHILD, str(ROOT / "models" / "fourbar_loaded.toml"),
                          str(ROOT / "models" / "fourbar_design.toml")], env=env, capture_output=True, text=True,
                         check=True, cwd=ROOT)
    got = json.loads(out.stdout)
    # the sweep (also one position), the kinetostatics and the design kernels
    assert got["misses"] == 0 and got["hits"] >= 3 and got["rows"], (got, out.stderr)
    assert "compiling" not in out.stderr  # (no compile notice)
    engine = mbplanar.Engine(mbplanar.read_model(ROOT / "models" / "fourbar_loaded.toml"))
    m = mbplanar.analyse(engine, engine.phi_drawn[0] + np.linspace(0, 6.2, 500), 2.0, 1.0)
    reference = (m.a.sum() + mbplanar.kinetostatics(engine, m).balancing["O"].sum()
                 + mbplanar.position(engine, 0.3, omega=2.0).xy.sum())
    assert got["total"] == pytest.approx(reference, rel=1e-12, abs=1e-9)


def _fake_cache(folder: Path) -> dict:
    """A cache folder with numba's files of two kernels, and files that are not the kernels'."""
    folder.mkdir(parents=True, exist_ok=True)
    files = {name: folder / name for name in (
        "_numba_kinematics._sweep-235.py311.nbi", "_numba_kinematics._sweep-235.py311.1.nbc",
        "_numba_design._designs-870.py311.nbi", "_numba.cpython-311.pyc", "other_module.f-3.py311.nbi")}
    for path in files.values():
        path.write_bytes(b"x")
    return files


def test_an_index_of_other_sources_removes_the_kernels_cache_files(tmp_path):
    files = _fake_cache(tmp_path / "cache")
    folder = tmp_path / "cache"
    (folder / _aot.INDEX).write_text(json.dumps({"format": _aot.FORMAT, "digest": "other sources", "kernels": ["k"]}))
    index = _aot._checked(folder, "these sources")
    assert index == {"format": _aot.FORMAT, "digest": "these sources", "kernels": None}
    assert json.loads((folder / _aot.INDEX).read_text()) == index
    left = {name for name, path in files.items() if path.exists()}
    assert left == {"_numba.cpython-311.pyc", "other_module.f-3.py311.nbi"}  # only the kernels' files went
    # the same sources: nothing removed, the index kept
    files = _fake_cache(folder)
    assert _aot._checked(folder, "these sources") == index and all(p.exists() for p in files.values())
    # no index, or an unreadable one: as other sources
    for text in (None, "not json", "[1, 2]"):
        _fake_cache(folder)
        if text is None:
            (folder / _aot.INDEX).unlink()
        else:
            (folder / _aot.INDEX).write_text(text)
        assert _aot._checked(folder, "these sources")["digest"] == "these sources"
        assert not (folder / "_numba_design._designs-870.py311.nbi").exists()


def test_a_new_process_checks_numbas_cache_folder_before_loading(tmp_path):
    """With NUMBA_CACHE_DIR (numba's documented setting) the kernels' cache is there; a process that
    makes a kernel finds the stale index and removes the stale kernel files before numba reads them."""
    env = dict(os.environ, PYTHONPATH=str(ROOT), NUMBA_CACHE_DIR=str(tmp_path))
    probe = "from mbplanar.backends import _jit; print(_jit.cache_path())"
    folder = Path(subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True,
                                 check=True).stdout.strip())
    assert folder.is_relative_to(tmp_path) and json.loads((folder / _aot.INDEX).read_text())["kernels"] is None
    files = _fake_cache(folder)
    index = json.loads((folder / _aot.INDEX).read_text())
    subprocess.run([sys.executable, "-c", probe], env=env, check=True, capture_output=True)
    assert all(p.exists() for p in files.values())  # these sources: kept
    (folder / _aot.INDEX).write_text(json.dumps(dict(index, digest="an older mbplanar")))
    subprocess.run([sys.executable, "-c", probe], env=env, check=True, capture_output=True)
    assert not files["_numba_kinematics._sweep-235.py311.nbi"].exists() and files["other_module.f-3.py311.nbi"].exists()
    assert json.loads((folder / _aot.INDEX).read_text())["digest"] == index["digest"]


def test_the_digest_follows_every_source(monkeypatch, tmp_path):
    before = _aot.digest()
    copies = []
    for path in _aot.sources():
        copy = tmp_path / path.parent.name / path.name
        copy.parent.mkdir(exist_ok=True)
        copy.write_bytes(path.read_bytes())
        copies.append(copy)
    monkeypatch.setattr(_aot, "sources", lambda: copies)
    monkeypatch.setattr(_aot, "_digest", [])
    assert _aot.digest() == before
    copies[-1].write_bytes(copies[-1].read_bytes() + b"\n")
    monkeypatch.setattr(_aot, "_digest", [])
    assert _aot.digest() != before


def test_kernels_read_no_global_from_outside_the_sources():
    """numba freezes the globals a kernel reads into the compiled code: each must be defined in one of
    the index's sources (not imported from another module), else an edit there would not be seen."""
    import importlib
    sources = {p.stem for p in _aot.sources()}
    for module in _aot.KERNEL_MODULES:
        importlib.import_module(f"mbplanar.backends.{module}")
    imported = {}
    for name in _aot.KERNEL_MODULES:
        tree = ast.parse((PACKAGE / "backends" / f"{name}.py").read_text())
        for node in tree.body:
            if isinstance(node, ast.ImportFrom) and not (node.level == 1 and (node.module or "") in sources | {""}):
                imported.update({(name, alias.asname or alias.name): node.module for alias in node.names})
    wrong = []
    for kernel in _jit.kernels():
        module = kernel.py_func.__module__.rpartition(".")[2]
        for name in kernel.py_func.__code__.co_names:
            value = kernel.py_func.__globals__.get(name)
            if value is None or type(value).__name__ == "module":
                continue
            if (module, name) in imported:
                wrong.append(f"{kernel.name} reads {name} from {imported[module, name]}")
    assert not wrong, wrong


def test_compile_without_numba_is_a_clear_error(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "numba", None)
    with pytest.raises(MbplanarError, match="compiling the kernels needs numba"):
        _aot.build()
    from mbplanar.cli import main
    assert main(["compile"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("mbplanar: compiling the kernels needs numba") and err.count("\n") == 1


def test_no_numba_pycc_and_no_private_attribute_of_numba_written():
    for path in PACKAGE.rglob("*.py"):
        text = path.read_text()
        assert "numba.pycc" not in text and "_source_stamp" not in text and "_cache_file" not in text, path


Pair = namedtuple("Pair", "a b")


def test_signature_tells_apart_what_numba_types_apart():
    """`_jit.signature` (made without numba, the key of a kernel's compiled functions) equal exactly where
    `numba.typeof` is: dtypes, dimensions, layouts, read-only arrays, scalars, tuples and named tuples; an
    unaligned array has a signature of its own."""
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
