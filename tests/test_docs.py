"""The documentation: the README is a short user's guide whose commands and API example run; every Python
block of every page runs as written, in page order (an excerpt of the code is checked against the code);
every file a page names is shipped, every `mbplanar.X` it names imports; the tutorial's code blocks check
their answers; and the Sphinx site builds with warnings as errors."""

from __future__ import annotations

import importlib
import os
import re
import shlex
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


@pytest.mark.parametrize("page", [p for p in sessions.PAGES if sessions.sessions((ROOT / p).read_text(encoding="utf-8"))])
def test_shown_command_output_is_what_the_command_prints(page, tmp_path):
    """Every page's shown sessions (README and docs), so that the numbers a page shows are the code's."""
    (tmp_path / "models").symlink_to(ROOT / "models")
    (tmp_path / "tests").symlink_to(ROOT / "tests")
    stale, ran = sessions.check(page, tmp_path)
    assert ran >= (4 if page == "README.md" else 0)  # (synthesis.md's searches are shown, not run)
    assert not stale, f"shown output is stale (python docs/sessions.py --write refreshes it): {stale}"


def test_tutorial_code_blocks_check_their_answers():
    """(They run with every page's blocks below.)"""
    pages = sorted(DOCS.glob("tutorial*.md")) + [DOCS / "notebooks.md"]
    for page in pages:
        blocks = python_blocks(page.read_text(encoding="utf-8"))
        assert blocks and any("assert" in b for b in blocks), page.name


#: the first line of a block that shows the code of a module rather than running: "# excerpt of PATH"
EXCERPT = re.compile(r"^# excerpt of (\S+)$", flags=re.M)
PAGES_WITH_CODE = sorted(p.name for p in DOCS.glob("*.md") if python_blocks(p.read_text(encoding="utf-8")))


@pytest.mark.parametrize("page", PAGES_WITH_CODE)
def test_every_python_block_runs_in_page_order(page, tmp_path, monkeypatch):
    """Each page's blocks run one after the other in one namespace, as a reader would paste them, in a scratch
    folder holding the models (the files they write land there); excerpts of the code are checked below."""
    blocks = [b for b in python_blocks((DOCS / page).read_text(encoding="utf-8")) if not EXCERPT.match(b)]
    if not blocks:
        pytest.skip(f"{page}: excerpts of the code only")
    if page in ("compiled.md", "position.md", "study.md"):
        pytest.importorskip("numba", reason="the page's blocks use the compiled backend: pip install -e '.[fast]'")
    (tmp_path / "models").symlink_to(ROOT / "models")
    monkeypatch.chdir(tmp_path)
    namespace: dict = {"__name__": "__docs__"}
    try:
        for k, code in enumerate(blocks):
            exec(compile(code, f"{page} block {k + 1}", "exec"), namespace)  # noqa: S102 (our own docs)
    finally:
        if "matplotlib.pyplot" in sys.modules:  # pictures a block may have drawn
            sys.modules["matplotlib.pyplot"].close("all")


def test_excerpts_are_the_code_as_it_is():
    """A block starting "# excerpt of PATH" shows lines of PATH in their order ("..." for lines left out)."""
    checked = 0
    for page in sorted(DOCS.glob("*.md")):
        for block in python_blocks(page.read_text(encoding="utf-8")):
            parts = EXCERPT.split(block)
            for path, shown in zip(parts[1::2], parts[2::2]):
                source = iter((ROOT / path).read_text(encoding="utf-8").splitlines())
                for line in shown.splitlines():
                    if line.strip() in ("", "..."):
                        continue
                    assert any(line.rstrip() == got.rstrip() for got in source), f"{page.name}: {path}: {line!r}"
                checked += 1
    assert checked >= 2


#: paths of the repository a page may name
SHIPPED = re.compile(r"(?<![\w./-])((?:models|docs|benchmarks|tests|mbplanar)/[\w./-]*\w)")
#: options whose value is a file a command writes
WRITES = ("-o", "--output", "--out", "--plot", "--csv", "--curve", "--dxf", "--svg", "--summary", "--table", ">")


def _shown_commands(text: str) -> list[list[str]]:
    """The words of every shown command line ``$ ...`` of a page (indented or in a fenced block)."""
    return [shlex.split(m) for m in re.findall(r"^\s*\$ (.*?)\s*$", text, flags=re.M)]


@pytest.mark.parametrize("page", sorted(p.name for p in DOCS.glob("*.md")) + ["../README.md"])
def test_every_file_a_page_names_is_shipped(page):
    """A path into the repository names a file or folder that exists; a model or table a shown command reads
    is shipped, or written by an earlier command of the page."""
    text = (DOCS / page).read_text(encoding="utf-8")
    missing = sorted({m for m in SHIPPED.findall(text) if not (ROOT / m).exists()
                      and not m.startswith(("docs/_build", "mbplanar/examples")) and "__pycache__" not in m})
    # (built: the docs, a wheel's copy of models/, and the bytecode folders numba's cache shares)
    written: set[str] = set()
    for argv in _shown_commands(text):
        for k, arg in enumerate(argv):
            if k and argv[k - 1] in WRITES:
                written.add(arg)
            elif argv[0] == "mbplanar" and re.fullmatch(r"[\w./-]+\.(toml|csv)", arg) and arg not in written \
                    and not (ROOT / arg).exists():
                missing.append(arg)
    assert not missing, f"{page} names files that are not shipped: {missing}"


def _resolves(dotted: str) -> bool:
    """Whether ``mbplanar.a.b.c`` names a module, or an attribute of one."""
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            value = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        try:
            for name in parts[cut:]:
                value = getattr(value, name)
        except AttributeError:
            return False
        return True
    return False


def test_every_mbplanar_name_the_docs_give_imports():
    """`mbplanar.friction` and the like must be real: each ``mbplanar.X.Y`` of the docs and the README is a
    module or one of its attributes."""
    named = set()
    for page in sorted(DOCS.glob("*.md")) + [ROOT / "README.md"]:
        for dotted in re.findall(r"\bmbplanar(?:\.[A-Za-z_]\w*)+", page.read_text(encoding="utf-8")):
            named.add((page.name, dotted))
    assert len(named) > 40
    wrong = sorted(f"{page}: {dotted}" for page, dotted in named if not _resolves(dotted))
    assert not wrong, wrong


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
