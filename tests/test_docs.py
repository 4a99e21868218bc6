"""The documentation: the README is a short user's guide whose commands and API example run, the tutorial's
code blocks run and check their answers, and the Sphinx site builds with warnings as errors."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
sys.path.insert(0, str(DOCS))
import sessions  # noqa: E402  (docs/sessions.py: the shown command sessions, run and compared)
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
    assert not re.search(r"\bissue \d+|\bsession \d+|\bruns? of\b", README, flags=re.I)
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


@pytest.mark.parametrize("page", sessions.PAGES)
def test_shown_command_output_is_what_the_command_prints(page, tmp_path):
    (tmp_path / "models").symlink_to(ROOT / "models")
    stale, ran = sessions.check(page, tmp_path)
    assert ran >= 4
    assert not stale, f"shown output is stale (python docs/sessions.py --write refreshes it): {stale}"


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
