"""Start-up benchmarks: wall time of fresh processes (import, `mbplanar solve`, numba warm start).

    python benchmarks/startup.py [--runs N] [--baseline DIR] [--only CASE ...] [--json FILE]

Each case is a new Python process, timed from start to exit by the parent (wall: time.perf_counter;
CPU: the child's user + system time from os.wait4); the figures are the medians of `--runs` rounds in
which the cases take turns, after one unrecorded warm-up run of each (which writes the byte-code, the
engine cache and numba's cache). `import numpy` is the floor every case is also given against. The
byte-code is written (PYTHONDONTWRITEBYTECODE is dropped from the children's environment), as an
installed package has it. `--baseline DIR` times the same cases on another checkout (e.g. `git archive
main | tar -x -C DIR`) in the same rounds, so that a load from other processes falls on both alike; a
case the baseline cannot run (an option it lacks) is left out for it.

Cases: `import numpy` (the floor), `import mbplanar`, `mbplanar solve models/fourbar.toml --at 30` with
the engine cache and without it (`--no-cache`), the same with `--backend numba`, numba's own floor: a
process that calls a cached one-line kernel once (what any use of numba costs, mbplanar or not), and the
first use of the compiled backend after `mbplanar compile` (run once before the rounds): a new process
that sweeps 3600 positions of `models/fourbar_loaded.toml` with its kinetostatics and one position, on
numpy and on numba; its line "numba over numpy" is the difference of the two. The parts of numba's floor:
`import numba`, `import scipy.linalg` (which numba's target context imports to look for a BLAS), and the
floor and the first uses again with the heap frozen (`gc.freeze()`) at their end, which leaves out the
interpreter's last garbage collections over every object of the process.
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

SOLVE = ["solve", "models/fourbar.toml", "--at", "30"]
CASES = {
    "import numpy": ["-c", "import numpy"],
    "import mbplanar": ["-c", "import mbplanar"],
    "solve (numpy, cached engine)": ["-m", "mbplanar", *SOLVE],
    "solve (numpy, --no-cache)": ["-m", "mbplanar", "--no-cache", *SOLVE],
    "solve (numba, cached engine)": ["-m", "mbplanar", "--backend", "numba", *SOLVE],
    "solve (numba, --no-cache)": ["-m", "mbplanar", "--no-cache", "--backend", "numba", *SOLVE],
    "numba's floor (a one-line kernel)": ["-c", "import numpy, startup_floor; startup_floor.total(numpy.ones(3))"],
    "first use (numpy)": ["-c", "import sys; sys.argv.append('numpy'); import startup_use"],
    "first use (numba, after mbplanar compile)": ["-c", "import sys; sys.argv.append('numba'); import startup_use"],
    # the parts of numba's floor: its import, the scipy.linalg its target context imports, and the exit
    # (the interpreter's last collections walk every object numba made; a frozen heap skips them)
    "numba's part: import numba": ["-c", "import numpy, numba"],
    "numba's part: import scipy.linalg": ["-c", "import numpy, scipy.linalg"],
    "numba's floor, heap frozen at exit": ["-c", "import gc, numpy, startup_floor; startup_floor.total(numpy.ones(3)); "
                                                 "gc.freeze()"],
    "first use (numpy, heap frozen at exit)": ["-c", "import gc, sys; sys.argv.append('numpy'); import startup_use; "
                                                     "gc.freeze()"],
    "first use (numba, after mbplanar compile, heap frozen at exit)": [
        "-c", "import gc, sys; sys.argv.append('numba'); import startup_use; gc.freeze()"],
}
#: the first use: a new process that sweeps a loaded four-bar with its kinetostatics and one position
USE = """import sys, numpy as np, mbplanar
e = mbplanar.Engine(mbplanar.read_model('models/fourbar_loaded.toml'), backend=sys.argv[-1])
m = mbplanar.analyse(e, e.phi_drawn[0] + np.linspace(0, 2 * np.pi, 3600, endpoint=False))
k = mbplanar.kinetostatics(e, m)
p = mbplanar.position(e, 0.3, omega=2.0)
"""
#: numba's own start in a new process, whatever the package: a cached one-line kernel called once
FLOOR_KERNEL = """import numba


@numba.njit(cache=True)
def total(x):
    s = 0.0
    for v in x:
        s += v
    return s
"""


def environment(cache_dir: str, package: Path) -> dict[str, str]:
    """A child's environment: the checkout `package` first, byte-code written, a private engine cache."""
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env["PYTHONPATH"] = os.pathsep.join([str(package), cache_dir])  # (startup_floor.py is in cache_dir)
    env["MBPLANAR_CACHE_DIR"] = cache_dir
    return env


def run_once(args: list[str], env: dict[str, str]) -> tuple[float, float]:
    """Wall and CPU seconds (user + system) of one process `python args`; RuntimeError on a failure."""
    start = time.perf_counter()
    child = subprocess.Popen([sys.executable, *args], cwd=env["PYTHONPATH"].split(os.pathsep)[0], env=env,
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(child.pid, 0)
    wall = time.perf_counter() - start
    error = child.stderr.read().decode()
    child.stderr.close()
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(" ".join(args) + ": " + (error.strip().splitlines() or ["failed"])[-1])
    return wall, usage.ru_utime + usage.ru_stime


def measure(runs: dict[tuple[str, str], tuple[list[str], dict]], rounds: int) -> dict:
    """Median wall and CPU seconds of each (checkout, case) over `rounds` rounds in which they take turns."""
    for label, (args, env) in list(runs.items()):
        try:
            run_once(args, env)  # warm-up: byte-code, engine cache, numba cache
        except RuntimeError as error:
            print(f"{label[0]}: {label[1]} left out: {error}")
            del runs[label]
    times: dict = {label: [] for label in runs}
    for _ in range(rounds):
        for label, (args, env) in runs.items():
            times[label].append(run_once(args, env))
    return {label: {"wall_s": statistics.median(w for w, _ in got), "cpu_s": statistics.median(c for _, c in got)}
            for label, got in times.items()}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7, help="rounds (default 7)")
    parser.add_argument("--baseline", type=Path, help="another checkout timed in the same rounds")
    parser.add_argument("--only", nargs="*", metavar="CASE", help="substrings of the case names to run")
    parser.add_argument("--json", metavar="FILE")
    args = parser.parse_args(argv)
    cases = {name: case for name, case in CASES.items()
             if not args.only or name == "import numpy" or any(part in name for part in args.only)}
    checkouts = {"this": ROOT, **({"baseline": args.baseline.resolve()} if args.baseline else {})}
    with tempfile.TemporaryDirectory() as cache_dir:
        for which in checkouts:
            os.makedirs(os.path.join(cache_dir, which))
            Path(cache_dir, which, "startup_floor.py").write_text(FLOOR_KERNEL)
            Path(cache_dir, which, "startup_use.py").write_text(USE)
        if any("after mbplanar compile" in name for name in cases):
            for which, package in checkouts.items():  # the install step, into numba's cache of the checkout
                subprocess.run([sys.executable, "-m", "mbplanar", "compile"], check=True, capture_output=True,
                               cwd=package, env=environment(os.path.join(cache_dir, which), package))
        runs = {(which, name): (case, environment(os.path.join(cache_dir, which), package))
                for which, package in checkouts.items() for name, case in cases.items()
                if which == "this" or "floor" not in name}
        figures = measure(runs, args.runs)
    for which in checkouts:
        floor = figures[(which, "import numpy")]
        for (where, name), got in figures.items():
            if where == which:
                print(f"{which:8s} {name:42s} wall {got['wall_s']:.3f} s "
                      f"(numpy + {got['wall_s'] - floor['wall_s']:.3f})   cpu {got['cpu_s']:.3f} s "
                      f"(numpy + {got['cpu_s'] - floor['cpu_s']:.3f})")
        for frozen in ("", ", heap frozen at exit"):
            numpy_use = figures.get((which, f"first use (numpy{frozen})"))
            numba_use = figures.get((which, f"first use (numba, after mbplanar compile{frozen})"))
            if numpy_use and numba_use:
                print(f"{which:8s} {'first use: numba over numpy' + frozen:42s} "
                      f"wall {numba_use['wall_s'] - numpy_use['wall_s']:.3f} s"
                      f"   cpu {numba_use['cpu_s'] - numpy_use['cpu_s']:.3f} s")
    if args.json:
        document = {"runs": args.runs, "checkouts": {k: str(v) for k, v in checkouts.items()},
                    "cases": [{"checkout": which, "case": name, **got} for (which, name), got in figures.items()]}
        Path(args.json).write_text(json.dumps(document, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
