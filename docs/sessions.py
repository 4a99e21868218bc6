"""The command sessions shown in the README and the docs (indented ``$ mbplanar ...`` lines and the output
under them) are real: this module runs them and compares, and can refresh the shown output.

    python docs/sessions.py            # list the sessions whose shown output is not what the command prints
    python docs/sessions.py --write    # rewrite the shown output with what the commands print now

`tests/test_docs.py` runs the check on every page. Commands run from a scratch folder holding ``models`` and
``tests`` (files they write land there); ``head`` looks at a file an earlier command wrote; a command piped
into ``cut``, ``tail`` or ``head`` runs through the shell; picture commands (and ``--plot``), ``serve``, the ``synth``
searches and commands on files that are not shipped (``broken.toml``) are shown but not run. A line ``...``
in the shown output stands for lines left out.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGES = ["README.md"] + sorted(f"docs/{p.name}" for p in (ROOT / "docs").glob("*.md"))
NOT_RUN = ("report", "plot", "animate", "serve")  # pictures (and --plot), a server (runs until Ctrl-C): shown, not run


def sessions(text: str) -> list[tuple[int, str, list[str]]]:
    """(line number, command, shown output lines) of every ``$ ...`` line, indented by four spaces or at
    the start of a line of a fenced block (```, ```text, ```console): the output is the lines after it
    with the same indent, up to the next command or the end of the block."""
    found, lines, inside, fenced = [], text.splitlines(), False, False
    for k, line in enumerate(lines):
        if line.startswith("```"):
            inside = not inside
            fenced = inside and line.strip() in ("```", "```text", "```console")
            continue
        indent = "    " if line.startswith("    $ ") else "" if fenced and line.startswith("$ ") else None
        if indent is None:
            continue
        shown = []
        for nxt in lines[k + 1:]:
            if not nxt.startswith(indent) or nxt.startswith(indent + "$ ") or nxt.startswith("```") \
                    or (indent and not nxt.strip()):
                break
            shown.append(nxt[len(indent):].rstrip())
        found.append((k, line[len(indent) + 2:], shown))
    return found


def run(command: str, workdir: Path) -> tuple[int, list[str]] | None:
    """Exit status and printed lines (standard output, then standard error) of `command` in `workdir`, or
    None for a command that is shown but not run."""
    if command.startswith("head "):
        if not (workdir / shlex.split(command)[-1]).exists():  # written by a command that is not run
            return None
        done = subprocess.run(command, shell=True, cwd=workdir, capture_output=True, text=True, timeout=60)
        return done.returncode, done.stdout.splitlines()
    argv = shlex.split(command)
    if argv[0] != "mbplanar" or argv[1] in NOT_RUN or argv[1] == "synth" or "--plot" in argv \
            or len(argv) < 3 or not (workdir / argv[2]).exists():
        return None
    if "|" in argv:
        python = shlex.quote(sys.executable)
        env = dict(os.environ, PYTHONPATH=str(ROOT))
        done = subprocess.run(command.replace("mbplanar ", f"{python} -m mbplanar ", 1), shell=True, cwd=workdir,
                              capture_output=True, text=True, timeout=300, env=env)
        return done.returncode, [ln.rstrip() for ln in (done.stdout + done.stderr).splitlines()]
    from mbplanar.cli import main
    out, err = io.StringIO(), io.StringIO()
    here = os.getcwd()
    os.chdir(workdir)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(argv[1:])
    finally:
        os.chdir(here)
    return code, [ln.rstrip() for ln in (out.getvalue() + err.getvalue()).splitlines()]


_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)")


def _without_noise(lines: list[str]) -> list[str]:
    """The lines with rounding noise (numbers below 1e-10 written with an exponent: residuals, a zero
    work of gravity) made equal, and runs of spaces (a column's width) made one, so that the comparison does
    not depend on the last bits of a machine."""
    return [" ".join(_NUMBER.sub(lambda m: "~0" if abs(float(m.group())) < 1e-10 else m.group(), ln).split())
            for ln in lines]


def _shows(printed: list[str], shown: list[str]) -> bool:
    """Whether `shown` is `printed`, a line "..." in it standing for any lines left out."""
    if "..." not in shown:
        return printed == shown
    parts, part = [], []
    for line in shown:
        if line == "...":
            parts.append(part)
            part = []
        else:
            part.append(line)
    parts.append(part)
    first, *middle, last = parts
    if printed[:len(first)] != first or (last and printed[len(printed) - len(last):] != last):
        return False
    at, end = len(first), len(printed) - len(last)
    for part in middle:
        found = next((k for k in range(at, end - len(part) + 1) if printed[k:k + len(part)] == part), None)
        if found is None:
            return False
        at = found + len(part)
    return at <= end


def check(page: str, workdir: Path, write: bool = False) -> tuple[list[str], int]:
    """The commands of `page` whose shown output differs from what they print (or that fail without saying
    so), and how many commands ran; with `write`, the page is rewritten with the real output."""
    path = ROOT / page
    lines = path.read_text(encoding="utf-8").splitlines()
    wrong, edits, ran = [], [], 0
    for k, command, shown in sessions("\n".join(lines)):
        done = run(command, workdir)
        if done is None:
            continue
        code, printed = done
        ran += 1
        failed = any(ln.startswith("mbplanar: ") and not re.search(r"^mbplanar: (.*: )?(warning|note): ", ln)
                     for ln in printed)    # an error or a motion limit, not a warning or a note
        if not _shows(_without_noise(printed), _without_noise(shown)) or \
                (command.startswith("mbplanar ") and (code != 0) != failed):
            wrong.append(f"{page}: {command}")
            edits.append((k, len(shown), printed))
    if write and edits:
        for k, count, printed in reversed(edits):
            indent = lines[k][:len(lines[k]) - len(lines[k].lstrip())]
            lines[k + 1:k + 1 + count] = [indent + ln if ln else "" for ln in printed]
        path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return wrong, ran


def scratch() -> Path:
    """A scratch folder with the repository's models, for the commands to run in."""
    workdir = Path(tempfile.mkdtemp(prefix="mbplanar-sessions-"))
    (workdir / "models").symlink_to(ROOT / "models")
    (workdir / "tests").symlink_to(ROOT / "tests")
    return workdir


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    write = "--write" in sys.argv[1:]
    folder = scratch()
    stale = [c for page in PAGES for c in check(page, folder, write)[0]]
    print("\n".join(stale) if stale else "every shown session prints what it shows")
    if stale and write:
        print("rewritten with the commands' output")
    sys.exit(1 if stale and not write else 0)
