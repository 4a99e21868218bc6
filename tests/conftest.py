"""Shared fixtures: model paths and engines built once per session."""

from pathlib import Path

import pytest

import mbplanar

MODELS = Path(__file__).resolve().parent.parent / "models"


@pytest.fixture(scope="session")
def engine_of():
    cache = {}

    def get(name):
        if name not in cache:
            cache[name] = mbplanar.Engine(mbplanar.read_model(MODELS / f"{name}.toml"))
        return cache[name]

    return get
