"""Fuzzing the table reader and the engine: every mutant of a valid model gives a correct result or a
clean `MbplanarError`, never another exception, never NaN.

Mutants are built on the parsed TOML document (drop, duplicate, rename, bad numbers, swapped types) and
on the text (deleted, duplicated or truncated lines and characters). Each surviving mutant is compiled and
solved at its drawn pose and two nearby positions.
"""

import copy
import json
import math
import os
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


def _files_found(doc: dict, folder: Path) -> dict:
    """The document with its curves' files named by their place (the mutants are parsed from nowhere)."""
    rows = doc.get("joints", [])
    for row in rows.values() if isinstance(rows, dict) else rows:
        for key in ("profile", "path"):
            if isinstance(row, dict) and "file" in row.get(key, {}):
                row[key]["file"] = str(folder / row[key]["file"])
    return doc


DOCS = {p.name: _files_found(tomllib.loads(TEXTS[p.name]), p.parent) for p in MODELS}

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


# -- careless command lines: a table of cases, each with the exit status and what the message names ----
from mbplanar.cli import main  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data"
FOURBAR, SHAPER, FIVE = (str(ROOT / "models" / n) for n in ("fourbar.toml", "shaper.toml", "five_bar.toml"))
ROCKER = str(DATA / "double_rocker.toml")

CLI_CASES = [
    # (argv, exit status, text the one-line message contains)
    (["solve", FOURBAR, "--at", "30", "--omega", "nan"], 2, "omega must be finite"),
    (["solve", FOURBAR, "--at", "30", "--omega", "inf"], 2, "omega must be finite"),
    (["solve", FOURBAR, "--at", "30", "--omega=-inf"], 2, "omega must be finite"),
    (["solve", FOURBAR, "--at", "30", "--epsilon", "nan"], 2, "epsilon must be finite"),
    (["solve", FOURBAR, "--at", "30", "--omega", "1e300"], 2, "omega must be finite and at most"),
    (["solve", FOURBAR, "--at", "30", "--epsilon", "1e308"], 2, "epsilon must be finite and at most"),
    (["solve", FOURBAR, "--at", "nan"], 2, "finite"),
    (["solve", FOURBAR, "--at", "30,40"], 2, "needs 1 finite value"),
    (["solve", ROCKER, "--at", "1e20"], 1, "moves within -91.79078447 … 91.79078447 deg"),
    (["solve", ROCKER, "--at", "120"], 1, "motion limit"),
    (["forces", FOURBAR, "--at", "180"], 2, "no loads"),
    (["forces", SHAPER, "--at", "30", "--input-inertia", "-1"], 2, "input_inertia must be a finite number >= 0"),
    (["sweep", FOURBAR, "--steps", "0"], 2, "positive integer"),
    (["sweep", FOURBAR, "--steps", "-5"], 2, "positive integer"),
    (["sweep", FOURBAR, "--step", "0"], 2, "--step must be positive"),
    (["sweep", FOURBAR, "--step", "nan"], 2, "finite number"),
    (["sweep", FOURBAR, "--from", "inf"], 2, "finite number"),
    (["sweep", SHAPER, "--true-motion", "--omega", "3"], 2, "--true-motion"),
    (["sweep", FIVE], 2, "needs --from and --to"),
    (["sweep", FIVE, "--from", "60,100", "--to", "90"], 2, "--to needs 2 value"),
    (["sweep", FOURBAR, "--grid"], 2, "--grid applies to several inputs"),
    (["solve", FIVE, "--at", "70"], 2, "phi1, phi2"),
    (["plot", FOURBAR, "diagram", "--dpi", "20000"], 2, "from 10 to 1200"),
    (["plot", FOURBAR, "diagram", "--dpi", "0"], 2, "from 10 to 1200"),
    (["plot", FIVE, "diagram", "--at", "70"], 2, "phi1, phi2"),
    (["plot", FOURBAR, "diagram", "--at", "inf"], 2, "finite"),
    (["animate", FOURBAR, "--frames", "1"], 2, "from 2 to 3600"),
    (["animate", FOURBAR, "--frames", "100000000"], 2, "from 2 to 3600"),
    (["report", FOURBAR, "--frames", "0"], 2, "from 2 to 3600"),
    (["dynamics", SHAPER, "--steps", "10"], 2, "from 36 to"),
    (["dynamics", SHAPER, "--steps", "1000000000"], 2, "from 36 to"),
    (["dynamics", SHAPER, "--delta", "nan"], 2, "--delta must be a number between 0 and 1"),
    (["sweep", SHAPER, "--omega", "nan"], 2, "omega must be finite"),
]


@pytest.mark.parametrize("argv, status, says", CLI_CASES, ids=lambda v: " ".join(v) if isinstance(v, list) else None)
def test_careless_command_lines(argv, status, says, tmp_path, capsys):
    """Exit 2 for bad input, 1 for a motion that cannot be made, with one line that says what is wrong;
    never a traceback, never a 0-byte output file."""
    out = tmp_path / ("out.png" if argv[0] == "plot" else "out.html" if argv[0] in ("animate", "report")
                      else "out.csv")
    extra = ["-o", str(out)] if argv[0] in ("plot", "animate", "report", "sweep") else []
    assert main(argv + extra) == status
    err = capsys.readouterr().err
    assert says in err and "Traceback" not in err
    lines = [line for line in err.strip().splitlines() if not line.startswith(("usage:", " "))]
    assert len(lines) == 1, err
    assert not out.exists()


@pytest.mark.parametrize("argv, rows", [
    (["sweep", FOURBAR, "--from", "10", "--to", "10"], 1),            # one position, not 73 equal rows
    (["sweep", FOURBAR, "--steps", "4", "--from", "350", "--to", "10"], 5),
    (["sweep", FIVE, "--from", "70,110", "--to", "70,110"], 1),
])
def test_sweep_row_counts(argv, rows, capsys):
    assert main(argv) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert len(lines) == rows + 1
    assert all(cell for line in lines[1:] for cell in line.split(",")[:40])  # no empty number


def test_far_input_values_answer_like_near_ones(capsys):
    """Periodic: --at 36000 and --at 1e20 (10²⁰ mod 360 = 280) answer as --at 0 and --at 280."""
    for far, near in (("36000", "0"), ("1e20", "280"), ("-7200", "0")):
        assert main(["solve", FOURBAR, "--at", far, "--json"]) == 0
        a = json.loads(capsys.readouterr().out)
        assert main(["solve", FOURBAR, "--at", near, "--json"]) == 0
        b = json.loads(capsys.readouterr().out)
        for name, p in b["points"].items():
            assert all(abs(a["points"][name][k] - v) <= 1e-13 for k, v in p.items()), (far, name)


def test_forces_on_a_model_without_loads_writes_no_zeros(capsys):
    assert main(["forces", FOURBAR, "--at", "180", "--json"]) == 2
    assert capsys.readouterr().out == ""


def test_streamed_sweep_equals_one_batch(tmp_path, monkeypatch):
    """A sweep written in chunks (here of 7 positions) is the sweep of one batch, row for row."""
    import mbplanar.io.sweep as io_sweep
    from mbplanar.kinematics.plan import sweep_plan
    whole, parts = tmp_path / "whole.csv", tmp_path / "parts.csv"
    assert main(["sweep", SHAPER, "--steps", "40", "-o", str(whole)]) == 0
    monkeypatch.setattr(io_sweep, "SWEEP_CHUNK", 7)
    assert main(["sweep", SHAPER, "--steps", "40", "-o", str(parts)]) == 0
    a, b = (np.genfromtxt(p, delimiter=",", skip_header=1) for p in (whole, parts))
    assert parts.read_text().splitlines()[0] == whole.read_text().splitlines()[0]
    assert a.shape == b.shape == (41, a.shape[1])
    assert np.all(np.abs(a - b) <= 1e-12 * (1 + np.abs(a).max(axis=0)))  # (round-off of Newton, forces in N)
    count, values, _ = sweep_plan(mbplanar.Engine(mbplanar.read_model(FOURBAR)), [10 ** 8])
    assert count == 10 ** 8 + 1 and values(count - 2, count)[:, 0].tolist() == [360 - 3.6e-6, 360.0]


def test_sweep_into_a_closed_pipe_exits_quietly():
    import subprocess
    import sys
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.run(f"'{sys.executable}' -m mbplanar sweep '{FOURBAR}' --steps 3000 | head -n 2",
                          shell=True, capture_output=True, text=True, env=env, timeout=120)
    assert proc.stdout.count("\n") == 2 and proc.stderr == ""
