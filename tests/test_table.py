"""Table validation: every bad table gives a ModelError (exit 2) naming the row; a mechanism that cannot
move gives a MotionError (exit 1); the CLI prints one line on stderr and no traceback unless --debug."""

import copy
import math
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

import mbplanar
from mbplanar.cli import main
from mbplanar.errors import ModelError, MotionError

ROOT = Path(__file__).resolve().parent.parent
FOURBAR = tomllib.loads((ROOT / "models/fourbar.toml").read_text())


def _strip_lengths(d):
    for link in d["links"]:
        link.pop("length", None)
    d["input"].pop("drawn_at")


def _redundant(d):
    """A rigid triangle (links 1, 4 on the ground) plus a dangling link: DOF formula 1, wrong inside."""
    _strip_lengths(d)
    d["links"] += [{"name": "4"}, {"name": "5"}]
    d["joints"] += [{"name": "E", "type": "R", "links": ["0", "4"], "at": [0.0, 0.1]},
                    {"name": "G", "type": "R", "links": ["4", "1"], "at": [0.05, 0.1]},
                    {"name": "H", "type": "R", "links": ["0", "5"], "at": [0.5, 0.5]}]


CASES = [  # (label, mutation, error type, words the message must contain)
    ("self joint", lambda d: d["joints"][1].update(links=["1", "1"]), ModelError, ["joints[1] 'A'", "itself"]),
    ("unknown link", lambda d: d["joints"][1].update(links=["1", "9"]), ModelError, ["joints[1] 'A'", "'9'"]),
    ("duplicate joint", lambda d: d["joints"].append(dict(d["joints"][1])), ModelError, ["joints[4]", "twice"]),
    ("duplicate link", lambda d: d["links"].append(dict(d["links"][1])), ModelError, ["links[3]", "twice"]),
    ("missing at", lambda d: d["joints"][1].pop("at"), ModelError, ["joints[1] 'A'", "'at'"]),
    ("P without guide", lambda d: d["joints"][1].update(type="P"), ModelError, ["joints[1] 'A'", "guide"]),
    ("NaN length", lambda d: d["links"][0].update(length=math.nan), ModelError, ["links[0] '1'", "finite"]),
    ("inf coordinate", lambda d: d["joints"][2].update(at=[math.inf, 0]), ModelError, ["joints[2] 'B'", "finite"]),
    ("zero length", lambda d: d["links"][0].update(length=0.0), ModelError, ["links[0] '1'", "positive"]),
    ("negative length", lambda d: d["links"][2].update(length=-0.25), ModelError, ["links[2] '3'", "positive"]),
    ("negative mass", lambda d: d["links"][1].update(mass=-1.0), ModelError, ["links[1] '2'", "negative"]),
    ("lengths not a list", lambda d: d["links"][0].update(lengths=5), ModelError, ["links[0] '1'", "lengths"]),
    ("input not a joint", lambda d: d["input"].update(joint="M"), ModelError, ["inputs[0]", "'M'", "not a joint"]),
    ("input is a link", lambda d: d["input"].update(joint="2"), ModelError, ["inputs[0]", "not a joint"]),
    ("bad sense", lambda d: d["input"].update(sense=[1]), ModelError, ["inputs[0]", "sense"]),
    ("two inputs", lambda d: d.update(inputs=[d.pop("input"), {"joint": "C"}]), ModelError,
     ["DOF = 1 (structural count 3·n − 2·p = 3·3 − 2·4", "2 input(s)"]),
    ("rigid", lambda d: (_strip_lengths(d), d["links"].append({"name": "4"}),
                         d["joints"].extend([{"name": "E", "type": "R", "links": ["0", "4"], "at": [0.1, 0]},
                                             {"name": "G", "type": "R", "links": ["4", "2"], "at": [0.15, 0.08]}])),
     ModelError, ["DOF", "= 0", "rigid"]),
    ("disconnected", lambda d: (d["links"].extend([{"name": "8"}, {"name": "9"}]),
                                d["joints"].append({"name": "X", "type": "R", "links": ["8", "9"], "at": [1, 1]})),
     ModelError, ["8, 9", "not connected"]),
    ("redundant loop", _redundant, ModelError, ["over-constrained", "link 4"]),
    ("unknown key", lambda d: d["links"][1].update(lenght=1), ModelError, ["links[1] '2'", "lenght"]),
    ("cannot assemble", lambda d: d["links"][2].update(length=0.01), MotionError,
     ["cannot be assembled", "link '3'"]),
]


@pytest.mark.parametrize("label, mutate, error, words", CASES, ids=[c[0] for c in CASES])
def test_bad_table_names_the_row(label, mutate, error, words):
    doc = copy.deepcopy(FOURBAR)
    mutate(doc)
    with pytest.raises(error) as info:
        mbplanar.Engine(mbplanar.parse_model(doc, source="bad.toml"))
    msg = str(info.value)
    assert "\n" not in msg
    for word in words:
        assert word in msg, (word, msg)


def test_toml_syntax_error_gives_the_line(tmp_path):
    path = tmp_path / "broken.toml"
    text = (ROOT / "models/fourbar.toml").read_text().replace('{ name = "2", length = 0.30 },',
                                                              '{ name = "2", length = 0.30 ,')
    line = 1 + text[:text.index('{ name = "2"')].count("\n")
    path.write_text(text)
    with pytest.raises(ModelError, match=rf"broken.toml: TOML syntax error: .*line {line}"):
        mbplanar.read_model(path)


# -- CLI exit codes and messages ---------------------------------------------------------------------
def _write(tmp_path, mutate):
    text = (ROOT / "models/fourbar.toml").read_text()
    path = tmp_path / "model.toml"
    path.write_text(mutate(text))
    return str(path)


def test_cli_bad_row_exit_2_one_line(tmp_path, capsys):
    path = _write(tmp_path, lambda t: t.replace('links = ["2", "3"]', 'links = ["2", "7"]'))
    assert main(["info", path]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "joints[2] 'B'" in err and "'7'" in err and "Traceback" not in err


def test_cli_ok_exit_0(capsys):
    assert main(["info", str(ROOT / "models/fourbar.toml")]) == 0


def test_cli_cannot_assemble_exit_1(tmp_path, capsys):
    path = _write(tmp_path, lambda t: t.replace('length = 0.25', 'length = 0.01'))
    assert main(["solve", path, "--at", "60"]) == 1
    assert "cannot be assembled" in capsys.readouterr().err


def test_cli_engine_message_names_the_file(tmp_path, capsys):
    doc = copy.deepcopy(FOURBAR)
    _redundant(doc)
    path = tmp_path / "red.toml"
    path.write_text(_to_toml(doc))
    assert main(["info", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"mbplanar: {path}") and err.count("\n") == 1


def _to_toml(doc):
    """Minimal TOML writer for the test documents (lists of flat tables)."""
    def val(v):
        if isinstance(v, str):
            return f'"{v}"'
        if isinstance(v, list):
            return "[" + ", ".join(val(x) for x in v) + "]"
        return repr(v)
    out = [f"{k} = {val(v)}" for k, v in doc.items() if not isinstance(v, (list, dict))]
    for k, v in doc.items():
        if isinstance(v, list):
            out.append(f"{k} = [")
            out += ["  { " + ", ".join(f"{a} = {val(b)}" for a, b in row.items()) + " }," for row in v]
            out.append("]")
    for k, v in doc.items():
        if isinstance(v, dict):
            out.append(f"[{k}]")
            out += [f"{a} = {val(b)}" for a, b in v.items()]
    return "\n".join(out) + "\n"


def test_cli_debug_shows_the_exception(tmp_path):
    path = _write(tmp_path, lambda t: t.replace('links = ["2", "3"]', 'links = ["2", "7"]'))
    with pytest.raises(ModelError):
        main(["--debug", "info", path])


def test_cli_subprocess_no_traceback(tmp_path):
    path = _write(tmp_path, lambda t: t.replace("length = 0.10", "length = nan"))
    run = subprocess.run([sys.executable, "-m", "mbplanar", "info", path], capture_output=True, text=True,
                         cwd=ROOT)
    assert run.returncode == 2
    assert "Traceback" not in run.stderr and run.stderr.count("\n") == 1
    assert "links[0] '1'" in run.stderr and "finite" in run.stderr


def test_locking_sweep_reports_the_lock_and_writes_the_rows_before_it(tmp_path, capsys):
    out = tmp_path / "lock.csv"
    code = main(["sweep", str(ROOT / "models/crank_slider_rocker_locking.toml"), "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 1
    assert "t = 1.7999" in err and "stretched at B" in err and "C, B, D" in err
    t_lock = 1.799912  # REFERENCE.md: the seed's first data lock at t = 1.799912
    rows = out.read_text().splitlines()[1:]
    t = [float(r.split(",")[0]) for r in rows]
    assert len(t) == math.floor(t_lock / (math.pi / 50)) + 1  # rows t = k·π/50 before the lock
    assert max(t) < t_lock
