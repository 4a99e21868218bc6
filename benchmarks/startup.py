"""Start-up benchmarks: wall time of fresh processes (import, `mbplanar solve`, numba warm start).

    python benchmarks/startup.py [--runs N] [--json FILE]

Each case is a new Python process started with `subprocess.run`, timed from start to exit by the
parent (time.perf_counter); the figure is the median of `--runs` processes after one unrecorded
warm-up run (which writes the byte-code, the engine cache and numba's cache). The byte-code is
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
    "solve (numpy, --no-cache)": SOLVE + ["--no-cache"],
    "solve (numba, cached engine)": ["-m", "mbplanar", "--backend", "numba", *SOLVE[2:]],
    "solve (numba, --no-cache)": ["-m", "mbplanar", "--backend", "numba", *SOLVE[2:], "--no-cache"],
}


def environment(cache_dir: str) -> dict[str, str]:
    """The child's environment: this checkout first, byte-code written, a private engine cache."""
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env["PYTHONPATH"] = str(ROOT)
    env["MBPLANAR_CACHE_DIR"] = cache_dir
    return env


def wall_time(args: list[str], env: dict[str, str]) -> float:
    """Seconds from starting `python args` to its exit; fails loudly on a non-zero exit."""
    start = time.perf_counter()
    subprocess.run([sys.executable, *args], cwd=ROOT, env=env, check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    return time.perf_counter() - start


def median_time(args: list[str], env: dict[str, str], runs: int) -> float:
    wall_time(args, env)  # warm-up: byte-code, engine cache, numba cache
    return statistics.median(wall_time(args, env) for _ in range(runs))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--json", metavar="FILE")
    parser.add_argument("--only", nargs="*", metavar="CASE", help="substrings of the case names to run")
    args = parser.parse_args(argv)
    figures = {}
    with tempfile.TemporaryDirectory() as cache_dir:
        env = environment(cache_dir)
        for name, case in CASES.items():
            if args.only and not any(part in name for part in args.only):
                continue
            try:
                figures[name] = median_time(case, env, args.runs)
            except subprocess.CalledProcessError as error:
                print(f"{name:32s} failed: {error.stderr.decode().strip().splitlines()[-1]}")
                continue
            print(f"{name:32s} {figures[name]:.3f} s")
    if args.json:
        Path(args.json).write_text(json.dumps({"runs": args.runs, "seconds": figures}, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
