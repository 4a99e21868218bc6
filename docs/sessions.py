"""The command sessions shown in the README and the docs (indented ``$ mbplanar ...`` lines and the output
under them) are real: this module runs them and compares, and can refresh the shown output.

    python docs/sessions.py            # list the sessions whose shown output is not what the command prints
    python docs/sessions.py --write    # rewrite the shown output with what the commands print now

`tests/test_docs.py` runs the check. Commands run from a scratch folder holding ``models`` (files they write
land there); ``head`` looks at a file an earlier command wrote; picture commands, ``serve`` and commands on files
that are not shipped (``broken.toml``) are shown but not run.
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
PAGES = ["README.md", "docs/cli.md"]
NOT_RUN = ("report", "plot", "animate", "serve")   # pictures; a server runs until Ctrl-C


def sessions(text: str) -> list[tuple[int, str, list[str]]]:
    """(line number, command, shown output lines) of every indented ``$ ...`` line: the output is the
    indented lines after it, up to the next command or the end of the block."""
    found, lines = [], text.splitlines()
    for k, line in enumerate(lines):
        if line.startswith("    $ "):
            shown = []
            for nxt in lines[k + 1:]:
                if not nxt.startswith("    ") or nxt.startswith("    $ "):
                    break
                shown.append(nxt[4:].rstrip())
            found.append((k, line[6:], shown))
    return found


def run(command: str, workdir: Path) -> tuple[int, list[str]] | None:
    """Exit status and printed lines (standard output, then standard error) of `command` in `workdir`, or
    None for a command that is shown but not run."""
    if command.startswith("head "):
        done = subprocess.run(command, shell=True, cwd=workdir, capture_output=True, text=True, timeout=60)
        return done.returncode, done.stdout.splitlines()
    argv = shlex.split(command)
    if argv[0] != "mbplanar" or argv[1] in NOT_RUN or not (workdir / argv[2]).exists():
        return None
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
        failed = any(ln.startswith("mbplanar: ") for ln in printed)    # an error or a motion limit
        if _without_noise(printed) != _without_noise(shown) or \
                (command.startswith("mbplanar ") and (code != 0) != failed):
            wrong.append(f"{page}: {command}")
            edits.append((k, len(shown), printed))
    if write and edits:
        for k, count, printed in reversed(edits):
            lines[k + 1:k + 1 + count] = ["    " + ln if ln else "" for ln in printed]
        path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return wrong, ran


def scratch() -> Path:
    """A scratch folder with the repository's models, for the commands to run in."""
    workdir = Path(tempfile.mkdtemp(prefix="mbplanar-sessions-"))
    (workdir / "models").symlink_to(ROOT / "models")
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
