"""µs per call of one position with velocities and accelerations, the answer read by the caller:
`mbplanar.position(engine, phi)` against `mbplanar.analyse(engine, [phi])`, on both backends, one core.

Equal work: each timed call reads every point's x, y, vx, vy, ax, ay and the link angles (the arrays a
closed form returns). Each case is timed in rounds (`timeit`): the median of the rounds in CPU time of
this process (a busy shared machine inflates it less than the wall clock) and the minimum in wall-clock
time are printed.

    python benchmarks/position.py [--json FILE] [--models fourbar,slider_crank,...] [--rounds 9]
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import time
import timeit
from pathlib import Path

import numpy as np

import mbplanar

MODELS = Path(__file__).resolve().parent.parent / "models"
DEFAULT = ("fourbar", "slider_crank", "six_bar_press", "class4_group")


def _read(result):
    """What the caller reads: the points' positions, velocities, accelerations and the link angles."""
    return result.xy, result.v, result.a, result.angle


def _lean(engine, x):
    return lambda: _read(mbplanar.position(engine, x))


def _batch_of_one(engine, x):
    return lambda: _read(mbplanar.analyse(engine, [x]))


def _time(call, rounds: int) -> tuple[float, float]:
    """µs per call over `rounds` rounds of a number of calls that takes ~0.1 s: the median in CPU time of
    this process, and the minimum in wall-clock time (rounds alternate between the two clocks)."""
    call()
    number = max(1, int(0.1 / max(timeit.timeit(call, number=3, timer=time.process_time) / 3, 1e-7)))
    cpu, wall = [], []
    for _ in range(rounds):
        cpu.append(timeit.timeit(call, number=number, timer=time.process_time) / number * 1e6)
        wall.append(timeit.timeit(call, number=number, timer=time.perf_counter) / number * 1e6)
    return float(np.median(cpu)), float(np.min(wall))


def run(models, rounds: int) -> list[dict]:
    backends = ["numpy"] + (["numba"] if _has_numba() else [])
    cases = []
    for name in models:
        for backend in backends:
            engine = mbplanar.Engine(mbplanar.read_model(MODELS / f"{name}.toml"), backend=backend, threads=1)
            x = float(engine.phi_drawn[0]) + 0.3
            far = x + 2 * math.pi * 100 if engine.period() is not None else None
            row = {"model": name, "backend": backend}
            row["position_us"], row["position_wall_min_us"] = _time(_lean(engine, x), rounds)
            if far is not None:
                row["position_far_us"], _ = _time(_lean(engine, far), rounds)
            row["analyse_us"], row["analyse_wall_min_us"] = _time(_batch_of_one(engine, x), rounds)
            cases.append(row)
            print(f"{name:14s} {backend:6s} position {row['position_us']:8.2f} µs "
                  f"(wall min {row['position_wall_min_us']:.2f})"
                  + (f", 100 turns away {row['position_far_us']:8.2f} µs" if far is not None else "")
                  + f"; analyse([phi]) {row['analyse_us']:8.1f} µs", flush=True)
    return cases


def _has_numba() -> bool:
    try:
        import numba  # noqa: F401
    except ImportError:
        return False
    return True


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", help="write the cases to this file")
    parser.add_argument("--models", default=",".join(DEFAULT))
    parser.add_argument("--rounds", type=int, default=9)
    args = parser.parse_args(argv)
    cases = run(args.models.split(","), args.rounds)
    if args.json:
        Path(args.json).write_text(json.dumps({"cases": cases, "machine": platform.platform(),
                                               "python": platform.python_version(), "numpy": np.__version__,
                                               "date": time.strftime("%Y-%m-%d")}, indent=2) + "\n")


if __name__ == "__main__":
    main()
