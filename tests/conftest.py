"""Shared fixtures: model paths and engines built once per session; hypothesis profiles; the elliptic
trammel (a slider-driven mechanism with a dead point) used by several test files."""

import math
import os
import signal
from pathlib import Path

import pytest
from hypothesis import settings

import mbplanar

# "ci" (the default): the same examples on every run, so that a red CI is a real regression and can be
# replayed; HYPOTHESIS_PROFILE=explore draws new examples on every run, for hunting bugs locally.
settings.register_profile("ci", derandomize=True, database=None)
settings.register_profile("explore", derandomize=False)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

MODELS = Path(__file__).resolve().parent.parent / "models"

# A shell starts a background job (`pytest &`, a CI runner's script) with SIGINT ignored, and an ignored signal
# stays ignored in every process started from it: the tests that interrupt `mbplanar` with SIGINT would wait
# for nothing. A handled signal goes back to its default in a child, so handle it here.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


def linkage_models() -> list[Path]:
    """The bundled linkage models (models/*.toml without the cam files, which have no joints)."""
    import tomllib
    return sorted(p for p in MODELS.glob("*.toml") if "joints" in tomllib.loads(p.read_text(encoding="utf-8")))


@pytest.fixture(scope="session", autouse=True)
def engine_cache_of_the_run(tmp_path_factory):
    """The command line's engine cache (`mbplanar.engine._cache`) in a folder of this test run, not the
    user's: the CLI tests go through it, and the processes they start inherit the setting."""
    before = os.environ.get("MBPLANAR_CACHE_DIR")
    os.environ["MBPLANAR_CACHE_DIR"] = str(tmp_path_factory.mktemp("engine-cache"))
    yield os.environ["MBPLANAR_CACHE_DIR"]
    if before is None:
        del os.environ["MBPLANAR_CACHE_DIR"]
    else:
        os.environ["MBPLANAR_CACHE_DIR"] = before


@pytest.fixture(scope="session")
def engine_of():
    cache = {}

    def get(name):
        if name not in cache:
            cache[name] = mbplanar.Engine(mbplanar.read_model(MODELS / f"{name}.toml"))
        return cache[name]

    return get


def trammel():
    """Rod AB (L = 1) with A on the x axis (the input slider) and B on the y axis, drawn at 0.6 rad."""
    length, th0 = 1.0, 0.6
    a, b = (length * math.cos(th0), 0.0), (0.0, length * math.sin(th0))
    m = mbplanar.Mechanism("trammel")
    for name in "123":
        m.add_link(name)
    m.add_joint("Ap", "P", "0", "1", at=a, guide=0.0)
    m.add_joint("A", "R", "1", "2", at=a)
    m.add_joint("B", "R", "2", "3", at=b)
    m.add_joint("Bp", "P", "0", "3", at=b, guide=90.0)
    m.add_point("M", "2", at=(a[0] / 2, b[1] / 2))
    m.add_input("Ap", unit="m")
    return mbplanar.Engine(m), length, th0
