"""Shared fixtures: model paths and engines built once per session; hypothesis profiles."""

import os
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


@pytest.fixture(scope="session")
def engine_of():
    cache = {}

    def get(name):
        if name not in cache:
            cache[name] = mbplanar.Engine(mbplanar.read_model(MODELS / f"{name}.toml"))
        return cache[name]

    return get
