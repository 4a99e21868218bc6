"""The command line's engine cache (`mbplanar.engine._cache`): a cached engine answers bit for bit as a
new one, an edited model or a damaged entry is built again, the build's warnings are given again, and
the cache can be turned off."""

import os
import pickle
import warnings
from pathlib import Path

import numpy as np
import pytest

import mbplanar
from mbplanar.cli import main
from mbplanar.engine import _cache
from mbplanar.engine._solver import Engine
from mbplanar.errors import ModelError, ModelWarning

MODELS = Path(__file__).resolve().parent.parent / "models"


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """An empty cache folder of this test, the cache turned on, and a copy of the four-bar beside it."""
    folder = tmp_path / "cache"
    monkeypatch.setenv("MBPLANAR_CACHE_DIR", str(folder))
    monkeypatch.delenv("MBPLANAR_NO_CACHE", raising=False)
    model = tmp_path / "fourbar.toml"
    model.write_text((MODELS / "fourbar.toml").read_text(encoding="utf-8"), encoding="utf-8")
    return folder, model


@pytest.fixture
def no_build(monkeypatch):
    """Make building an engine fail: what is then loaded came from the cache."""
    def refuse(*args, **kwargs):
        raise AssertionError("the engine was built, not read from the cache")
    return lambda: monkeypatch.setattr(Engine, "__init__", refuse)


def _entries(folder: Path) -> list[Path]:
    return sorted(folder.glob("*.pickle")) if folder.exists() else []


def test_a_cached_engine_answers_bit_for_bit_as_a_new_one(cache, no_build):
    folder, model = cache
    phi = np.radians([-170.0, 30.0, 61.5, 250.0])
    fresh = mbplanar.analyse(Engine(mbplanar.read_model(model)), phi)
    _cache.load_engine(model)
    assert len(_entries(folder)) == 1
    no_build()
    engine = _cache.load_engine(model, threads=3)
    assert engine.threads == 3 and engine.mech.source == str(model)
    again = mbplanar.analyse(engine, phi)
    for name in ("angle", "w", "e", "xy", "v", "a", "value"):
        np.testing.assert_array_equal(getattr(again, name), getattr(fresh, name), err_msg=name)


def test_an_edited_model_is_built_again(cache):
    folder, model = cache
    before = _cache.load_engine(model)
    model.write_text(model.read_text(encoding="utf-8").replace("length = 0.10", "length = 0.12")
                     .replace("at = [0.05, 0.0866]", "at = [0.06, 0.103923]"), encoding="utf-8")
    after = _cache.load_engine(model)
    crank = [j for j in after.mech.joints.values() if j.name == "A"][0].at
    assert before.mech.joints["A"].at != crank and abs(np.hypot(*crank) - 0.12) < 1e-12
    assert len(_entries(folder)) == 1  # one entry per model path, rewritten


@pytest.mark.parametrize("damage", [b"", b"not a pickle", pickle.dumps({"key": "another", "engine": None})])
def test_a_damaged_entry_is_built_again_silently(cache, damage):
    folder, model = cache
    _cache.load_engine(model)
    entry, = _entries(folder)
    entry.write_bytes(damage)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        engine = _cache.load_engine(model)
    assert engine.topology.structure.formula == "I(0,1) → II(2,3)"
    assert pickle.loads(entry.read_bytes())["key"] != "another"  # rewritten whole


def test_the_builds_warnings_are_given_again_from_the_cache(cache, no_build):
    folder, model = cache
    model.write_text(model.read_text(encoding="utf-8").replace("length = 0.25", "length = 0.30"), encoding="utf-8")
    for _ in range(2):
        with pytest.warns(ModelWarning, match=r"links '3': length B-C = 0\.3 m, but the sketch draws"):
            _cache.load_engine(model)
        no_build()


def test_the_builds_warnings_are_given_without_the_cache_too(cache, capsys):
    folder, model = cache
    model.write_text(model.read_text(encoding="utf-8").replace("length = 0.25", "length = 0.30"), encoding="utf-8")
    with pytest.warns(ModelWarning, match=r"links '3': length B-C = 0\.3 m, but the sketch draws"):
        _cache.load_engine(model, use_cache=False)
    assert main(["--no-cache", "solve", str(model), "--at", "30"]) == 0
    assert "warning: " in capsys.readouterr().err and _entries(folder) == []


def test_a_folder_others_can_write_is_not_read(cache, no_build):
    if not hasattr(os, "getuid"):
        pytest.skip("POSIX permissions")
    folder, model = cache
    _cache.load_engine(model)
    folder.chmod(0o777)
    no_build()
    with pytest.raises(AssertionError, match="was built"):
        _cache.load_engine(model)


def test_the_cache_can_be_turned_off(cache, monkeypatch, capsys):
    folder, model = cache
    _cache.load_engine(model, use_cache=False)
    assert main(["--no-cache", "solve", str(model), "--at", "30"]) == 0
    monkeypatch.setenv("MBPLANAR_NO_CACHE", "1")
    assert main(["solve", str(model), "--at", "30"]) == 0
    assert _entries(folder) == []
    monkeypatch.setenv("MBPLANAR_NO_CACHE", "0")
    assert main(["solve", str(model), "--at", "30"]) == 0
    assert len(_entries(folder)) == 1
    capsys.readouterr()


def test_the_cache_folder_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.delenv("MBPLANAR_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert _cache.cache_dir() == tmp_path / "mbplanar"
    monkeypatch.delenv("XDG_CACHE_HOME")
    assert _cache.cache_dir() == Path(os.path.expanduser("~")) / ".cache" / "mbplanar"


def test_errors_name_the_file_as_without_the_cache(cache, tmp_path):
    _, model = cache
    with pytest.raises(ModelError, match="missing.toml: cannot read the model file"):
        _cache.load_engine(tmp_path / "missing.toml")
    model.write_bytes(b"name = \"\xff\"\n")
    with pytest.raises(ModelError, match="fourbar.toml: the model file is not UTF-8 text"):
        _cache.load_engine(model)


def test_two_models_whose_entry_names_clash_each_get_their_own_engine(cache, monkeypatch):
    """The entry's file name is a checksum; its whole key decides: a clash costs a build, never the other
    model's engine."""
    folder, model = cache
    other = model.with_name("slider_crank.toml")
    other.write_text((MODELS / "slider_crank.toml").read_text(encoding="utf-8"), encoding="utf-8")
    monkeypatch.setattr(_cache, "_entry_name", lambda *parts: "clash")
    for path in (model, other, model, other):
        engine = _cache.load_engine(path)
        assert engine.mech.source == str(path) and engine.mech.name == mbplanar.read_model(path).name
    assert [p.name for p in _entries(folder)] == ["clash.pickle"]


def test_an_entry_name_is_a_checksum_of_the_model_path():
    names = {_cache._entry_name("pkg", "/a/fourbar.toml", "fourbar.toml", "numpy"),
             _cache._entry_name("pkg", "/b/fourbar.toml", "fourbar.toml", "numpy"),
             _cache._entry_name("pkg", "/a/fourbar.toml", "fourbar.toml", "numba"),
             _cache._entry_name("pkg", "/a/\udcff.toml", "\udcff.toml", "numpy")}  # (an undecodable file name)
    assert len(names) == 4 and all(len(n) == 16 and int(n, 16) >= 0 for n in names)
