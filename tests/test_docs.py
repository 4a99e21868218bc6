"""The documentation: the README is a short user's guide whose commands and API example run, the tutorial's
code blocks run and check their answers, and the Sphinx site builds with warnings as errors."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
README = (ROOT / "README.md").read_text(encoding="utf-8")


def python_blocks(text: str) -> list[str]:
    """The ```python fenced blocks of a Markdown text, in order."""
    return re.findall(r"^```python\n(.*?)^```", text, flags=re.S | re.M)


def run_blocks(blocks, where):
    """Run the blocks one after the other in one namespace, from the repository's root."""
    namespace: dict = {"__name__": "__docs__"}
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        for k, code in enumerate(blocks):
            exec(compile(code, f"{where} block {k + 1}", "exec"), namespace)  # noqa: S102 (our own docs)
    finally:
        os.chdir(cwd)
        import matplotlib.pyplot as plt  # pictures a block may have drawn
        plt.close("all")
    return namespace


def test_readme_is_a_short_users_guide():
    lines = README.splitlines()
    assert len(lines) <= 250
    assert "../shared" not in README and "REFERENCE.md" not in README
    assert not re.search(r"\bissue \d+|\bsession \d+|\bseed \d+", README, flags=re.I)
    for target in re.findall(r"\]\(([^)#]+)\)", README):          # every relative link exists
        if "://" not in target:
            assert (ROOT / target).exists(), target


def test_readme_test_command_is_what_ci_runs():
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert 'pip install -e ".[test,plot]" && python -m pytest -q' in README
    assert 'install --quiet -e ".[test,plot]"' in ci
    assert ci.strip().splitlines()[-1] == "python -m pytest -q"


def test_readme_python_api_runs(capsys):
    (block,) = python_blocks(README)
    assert len([ln for ln in block.splitlines() if ln.strip()]) <= 10
    run_blocks([block], "README")
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "I(0,1) → II(2,3)"
    balancing, residual = map(float, out[2].split())
    assert abs(balancing - 2.69865) < 5e-6 and residual < 1e-12 and out[-1] == "True"


def shell_sessions(text: str):
    """(command, output lines) of every indented `$ ...` line of a page, the output being the indented lines
    that follow it up to the next command or the block's end."""
    sessions, lines = [], text.splitlines()
    for k, line in enumerate(lines):
        if line.startswith("    $ "):
            out = []
            for nxt in lines[k + 1:]:
                if not nxt.startswith("    ") or nxt.startswith("    $ "):
                    break
                out.append(nxt[4:].rstrip())
            sessions.append((line[6:], out))
    return sessions


@pytest.mark.parametrize("page", ["README.md", "docs/cli.md"])
def test_shown_command_output_is_what_the_command_prints(page, tmp_path, capsys, monkeypatch):
    from mbplanar.cli import main
    (tmp_path / "models").symlink_to(ROOT / "models")
    monkeypatch.chdir(tmp_path)                      # files the commands write land here
    checked = 0
    for command, shown in shell_sessions((ROOT / page).read_text(encoding="utf-8")):
        if command.startswith("head "):              # a look at a file a command wrote
            done = subprocess.run(command, shell=True, cwd=tmp_path, capture_output=True, text=True, timeout=60)
            assert done.stdout.splitlines() == shown, f"{page}: {command}"
            continue
        if not command.startswith("mbplanar "):
            continue
        argv = shlex.split(command)[1:]
        if argv[0] in ("report", "plot", "animate") or not Path(argv[1]).exists():
            continue                                 # pictures: tested elsewhere; example files not shipped
        code = main(argv)
        printed = capsys.readouterr()
        out = [ln.rstrip() for ln in (printed.out + printed.err).splitlines()]
        assert code == (1 if any(ln.startswith("mbplanar: ") for ln in shown) else 0), command
        assert out == shown or (not shown and not out), f"{page}: {command}"
        checked += 1
    assert checked >= 4


def test_tutorial_code_blocks_run_and_check_their_answers():
    pages = sorted(DOCS.glob("tutorial*.md")) + [DOCS / "notebooks.md"]
    assert pages
    for page in pages:
        blocks = python_blocks(page.read_text(encoding="utf-8"))
        assert blocks and any("assert" in b for b in blocks), page.name
        run_blocks(blocks, page.name)


def test_docs_build_with_warnings_as_errors(tmp_path):
    pytest.importorskip("sphinx", reason="the docs build needs sphinx: pip install -e '.[docs]'")
    pytest.importorskip("myst_parser", reason="the docs build needs myst-parser: pip install -e '.[docs]'")
    pytest.importorskip("numpydoc", reason="the docs build needs numpydoc: pip install -e '.[docs]'")
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    done = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
                           "-d", str(tmp_path / "doctrees"), str(DOCS), str(tmp_path / "html")],
                          capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 0, done.stderr[-4000:]
    html = tmp_path / "html"
    cli = (html / "cli.html").read_text(encoding="utf-8")
    for command in ("mbplanar solve", "mbplanar sweep", "--true-motion"):   # generated from the parser
        assert command in cli
    api = (html / "api.html").read_text(encoding="utf-8")
    for name in ("mbplanar.analyse", "mbplanar.Engine", "mbplanar.kinetostatics"):   # from the docstrings
        assert f'id="{name}"' in api
    for page in DOCS.glob("*.md"):                 # the index's glob takes in every page
        assert (html / f"{page.stem}.html").exists(), page.name
