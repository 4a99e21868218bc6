"""Start-up benchmarks: wall time of fresh processes (import, `mbplanar solve`, numba warm start).

    python benchmarks/startup.py [--runs N] [--json FILE]

Each case is a new Python process, timed from start to exit by the parent (wall: time.perf_counter;
CPU: the child's user + system time from os.wait4); the figures are the medians of `--runs` rounds in
which the cases take turns, after one unrecorded warm-up run of each (which writes the byte-code, the
engine cache and numba's cache). `import numpy` is the floor every case is also given against. The byte-code is
allowed to be written (PYTHONDONTWRITEBYTECODE is removed from the environment) as an installed
package has it; the package measured is this checkout (PYTHONPATH).

Cases: `import numpy` (the floor), `import mbplanar`, `mbplanar solve models/fourbar.toml --at 30`
with the engine cache and without it (`--no-cache`), and the same with `--backend numba`.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

SOLVE = ["-m", "mbplanar", "solve", "models/fourbar.toml", "--at", "30"]
CASES = {
    "import numpy": ["-c", "import numpy"],
    "import mbplanar": ["-c", "import mbplanar"],
    "solve (numpy, cached engine)": SOLVE,
    "solve (numpy, --no-cache)": ["-m", "mbplanar", "--no-cache", *SOLVE[2:]],
    "solve (numba, cached engine)": ["-m", "mbplanar", "--backend", "numba", *SOLVE[2:]],
    "solve (numba, --no-cache)": ["-m", "mbplanar", "--no-cache", "--backend", "numba", *SOLVE[2:]],
}


def environment(cache_dir: str, package: Path) -> dict[str, str]:
    """The child's environment: the checkout `package` first, byte-code written, a private engine cache."""
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env["PYTHONPATH"] = str(package)
    env["MBPLANAR_CACHE_DIR"] = cache_dir
    return env


def run_once(args: list[str], env: dict[str, str]) -> tuple[float, float]:
    """Wall and CPU seconds (user + system) of one process `python args`; fails loudly on an error."""
    start = time.perf_counter()
    child = subprocess.Popen([sys.executable, *args], cwd=env["PYTHONPATH"], env=env,
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(child.pid, 0)
    wall = time.perf_counter() - start
    error = child.stderr.read().decode()
    child.stderr.close()
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(" ".join(args) + ": " + (error.strip().splitlines() or ["failed"])[-1])
    return wall, usage.ru_utime + usage.ru_stime


def measure(cases: dict[str, list[str]], env: dict[str, str], runs: int) -> dict[str, dict[str, float]]:
    """Median wall and CPU seconds of each case over `runs` rounds; the cases take turns within a round,
    so that a load from other processes falls on all of them alike."""
    for name, args in list(cases.items()):
        try:
            run_once(args, env)  # warm-up: byte-code, engine cache, numba cache
        except RuntimeError as error:
            print(f"{name:32s} left out: {error}")
            cases = {k: v for k, v in cases.items() if k != name}
    times: dict[str, list[tuple[float, float]]] = {name: [] for name in cases}
    for _ in range(runs):
        for name, args in cases.items():
            times[name].append(run_once(args, env))
    return {name: {"wall_s": statistics.median(w for w, _ in got), "cpu_s": statistics.median(c for _, c in got)}
            for name, got in times.items()}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--json", metavar="FILE")
    parser.add_argument("--package", type=Path, default=ROOT,
                        help="the checkout to time (default: this one; e.g. an export of another commit)")
    parser.add_argument("--only", nargs="*", metavar="CASE", help="substrings of the case names to run")
    args = parser.parse_args(argv)
    cases = {name: case for name, case in CASES.items()
             if not args.only or name == "import numpy" or any(part in name for part in args.only)}
    with tempfile.TemporaryDirectory() as cache_dir:
        figures = measure(cases, environment(cache_dir, args.package.resolve()), args.runs)
    floor = figures["import numpy"]
    for name, got in figures.items():
        print(f"{name:32s} wall {got['wall_s']:.3f} s  cpu {got['cpu_s']:.3f} s  "
              f"(numpy + {got['wall_s'] - floor['wall_s']:.3f} s wall, + {got['cpu_s'] - floor['cpu_s']:.3f} s cpu)")
    if args.json:
        Path(args.json).write_text(json.dumps({"runs": args.runs, "cases": figures}, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
