"""Fuzzing the table reader and the engine: every mutant of a valid model gives a correct result or a
clean `MbplanarError`, never another exception, never NaN.

Mutants are built on the parsed TOML document (drop, duplicate, rename, bad numbers, swapped types) and
on the text (deleted, duplicated or truncated lines and characters). Each surviving mutant is compiled and
solved at its drawn pose and two nearby positions.
"""

import copy
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import mbplanar
from conftest import linkage_models
from mbplanar.forces._dynamics import read_dynamics
from mbplanar.errors import MbplanarError
from mbplanar.forces import kinetostatics

MODELS = linkage_models()
TEXTS = {p.name: p.read_text(encoding="utf-8") for p in MODELS}
DOCS = {name: tomllib.loads(text) for name, text in TEXTS.items()}

BAD_VALUES = [math.nan, math.inf, -math.inf, -1.0, 0.0, -0.25, 1e300, 1e-300, 0, -3, 7, True, "",
              "x", "R", "P", "0", "1", [], [0.0], [1.0, 2.0], [math.nan, 0.0], ["A", "B"], {}]


def _paths(doc, prefix=()):
    """Every (path, value) in a nested dict/list document, containers included."""
    out = []
    items = doc.items() if isinstance(doc, dict) else enumerate(doc) if isinstance(doc, list) else ()
    for key, value in items:
        out.append((prefix + (key,), value))
        out += _paths(value, prefix + (key,))
    return out


def _names(doc):
    return sorted({str(v) for path, v in _paths(doc) if path[-1] in ("name", "joint", "link")
                   and isinstance(v, str)} | {"0", "ZZ"})


def _parent(doc, path):
    for key in path[:-1]:
        doc = doc[key]
    return doc


@st.composite
def doc_mutants(draw):
    """A model document with 1–3 structural mutations."""
    doc = copy.deepcopy(DOCS[draw(st.sampled_from(sorted(DOCS)))])
    for _ in range(draw(st.integers(1, 3))):
        paths = _paths(doc)
        if not paths:
            break
        path, value = draw(st.sampled_from(paths))
        parent, key = _parent(doc, path), path[-1]
        op = draw(st.sampled_from(["drop", "duplicate", "rename", "bad", "swap", "scale", "nudge"]))
        if op == "drop":
            del parent[key]
        elif op == "duplicate":
            if isinstance(parent, list):
                parent.insert(key, copy.deepcopy(value))
            else:
                parent[key + "_copy" if isinstance(key, str) else key] = copy.deepcopy(value)
        elif op == "rename":
            parent[key] = draw(st.sampled_from(_names(doc)))
        elif op == "bad":
            parent[key] = copy.deepcopy(draw(st.sampled_from(BAD_VALUES)))
        elif op == "swap":
            swap = {"R": "P", "P": "R", "deg": "rad", "rad": "m", "m": "mm", "mm": "deg", "cw": "ccw"}
            parent[key] = swap.get(value, value) if isinstance(value, str) else \
                [value] if not isinstance(value, list) else value[::-1]
        elif op in ("scale", "nudge") and isinstance(value, (int, float)) and not isinstance(value, bool):
            parent[key] = value * draw(st.sampled_from([-1.0, 0.5, 2.0, 10.0])) if op == "scale" \
                else value + draw(st.floats(-0.05, 0.05, allow_nan=False))
    return doc


@st.composite
def text_mutants(draw):
    """The TOML text with lines or characters deleted, duplicated or cut."""
    text = TEXTS[draw(st.sampled_from(sorted(TEXTS)))]
    lines = text.splitlines(keepends=True)
    op = draw(st.sampled_from(["drop_line", "dup_line", "cut", "char"]))
    k = draw(st.integers(0, len(lines) - 1))
    if op == "drop_line":
        del lines[k]
    elif op == "dup_line":
        lines.insert(k, lines[k])
    elif op == "cut":
        return text[:draw(st.integers(0, len(text)))]
    else:
        line = lines[k]
        i = draw(st.integers(0, max(len(line) - 1, 0)))
        lines[k] = line[:i] + draw(st.sampled_from(["", "[", "]", "=", '"', ",", "{", "x"])) + line[i + 1:]
    return "".join(lines)


def _exercise(mech):
    """Compile and solve near the drawn pose; results must be finite where reached."""
    engine = mbplanar.Engine(mech)
    phi0 = engine.phi_drawn
    step = np.array([0.05 if mech.joints[i.joint].kind == "R" else 0.05 * engine.size
                     for i in engine.inputs])
    phi = np.stack([phi0, phi0 + step, phi0 - step])
    motion = mbplanar.analyse(engine, phi[:, 0] if len(engine.inputs) == 1 else phi)
    assert len(motion.phi) <= 3
    for name in ("angle", "w", "e", "xy", "v", "a", "value", "rate", "accel"):
        assert np.all(np.isfinite(getattr(motion, name))), name
    if not motion.success:
        assert motion.message
        return
    result = kinetostatics(engine, motion)   # loads and masses of the mutant
    ok = ~result.singular
    for r in result.reactions.values():
        assert np.all(np.isfinite(r.fx[ok])) and np.all(np.isfinite(r.fy[ok]))
    read_dynamics(mech)                      # the [dynamics] section is checked


def _run(make):
    try:
        mech = make()
    except MbplanarError as exc:
        assert str(exc) and "\n" not in str(exc).strip()
        return
    try:
        _exercise(mech)
    except MbplanarError as exc:
        assert str(exc)


FUZZ = settings(max_examples=1500, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])


@FUZZ
@given(doc_mutants())
def test_document_mutants_fail_cleanly(doc):
    _run(lambda: mbplanar.parse_model(doc, source="mutant.toml"))


@settings(max_examples=500, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(text_mutants())
def test_text_mutants_fail_cleanly(text):
    _run(lambda: mbplanar.model.read_model_text(text, source="mutant.toml"))


@pytest.mark.parametrize("name", sorted(DOCS))
def test_unmutated_models_solve(name):
    _exercise(mbplanar.parse_model(copy.deepcopy(DOCS[name]), source=name))
