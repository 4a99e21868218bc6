"""Higher-pair sweeps on the compiled backend against numpy, in the same run and on equal work.

    python benchmarks/higher.py [--positions N] [--rounds R] [--json FILE]

Cases (N positions over a turn of the input, one core: `Engine(threads=1)`, numpy's own threads held to
one):

- `shaper_geared` (a gear train driving the shaper's linkage: three gear pairs, a guide load along the
  stroke, heavy links, gravity), positions + velocities + accelerations of every point, and with the
  reactions and contact forces (`kinetostatics`);
- `cam_follower` (a roller on a spline cam profile read from `mbplanar cam`'s CSV, a translating
  follower), positions + velocities + accelerations of every point.

Equal work: each timed call solves the sweep and reads every point's position, velocity and
acceleration and every link's angle (and every reaction and balancing load), as `run.py` reads them
(`read_motion`, `read_reactions`); the two backends' results are checked equal first (positions to
1e-12 of the size). Timing as `run.py`: the cases in turn, in rounds, each round keeping the fastest of
a few calls in a row; the figure is the median over the rounds (µs per position), and the ratio numba /
numpy is the median over the rounds of the ratio within a round, so that the load of the moment
cancels. The load average is recorded.
"""

from __future__ import annotations

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import datetime  # noqa: E402
import json  # noqa: E402
import platform  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))

from run import ROOT, full_turn, in_rounds, kinematics_request, read_motion, read_reactions  # noqa: E402

import mbplanar  # noqa: E402

CASES = [("shaper_geared", "kinematics"), ("shaper_geared", "reactions"), ("cam_follower", "kinematics")]


def _call(engine, phi, work):
    """The timed call: the sweep solved and every output of the work read."""
    request = kinematics_request()
    if work == "kinematics":
        return lambda: read_motion(mbplanar.analyse(engine, phi, **request))
    return lambda: read_reactions(mbplanar.kinetostatics(engine, mbplanar.analyse(engine, phi)))


def _check(engines, phi):
    """Both backends give the same positions (1e-12 of the size), through the compiled kernel on numba."""
    ref, fast = (mbplanar.analyse(e, phi) for e in engines)
    assert fast.records is not None, "the compiled kernel declined the sweep"
    assert np.max(np.abs(fast.xy - ref.xy)) <= 1e-12 * engines[0].size


def run(n: int, rounds: int, burst: int = 3) -> dict:
    rows, calls = [], []
    for name, work in CASES:
        mech = mbplanar.read_model(ROOT / "models" / f"{name}.toml")
        engines = (mbplanar.Engine(mech), mbplanar.Engine(mech, backend="numba", threads=1))
        phi = full_turn(engines[0], n)
        _check(engines, phi)
        pair = [_call(e, phi, work) for e in engines]
        for call in pair:
            call()  # warm: compiled or loaded, the atlas built
        rows.append(dict(name=name, work=work, n=n))
        calls.append(pair)
    flat = [call for pair in calls for call in pair]
    times = in_rounds(flat, rounds, burst)
    for k, row in enumerate(rows):
        numpy_t, numba_t = times[2 * k], times[2 * k + 1]
        row["numpy_us"] = 1e6 * statistics.median(numpy_t) / n
        row["numba_us"] = 1e6 * statistics.median(numba_t) / n
        row["numpy_over_numba"] = statistics.median(a / b for a, b in zip(numpy_t, numba_t))
    return dict(date=datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
                machine=f"{platform.machine()}, {os.cpu_count()} cores", load=os.getloadavg()[0],
                rounds=rounds, cases=rows)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--positions", type=int, default=3600)
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--json", metavar="FILE")
    args = parser.parse_args(argv)
    doc = run(args.positions, args.rounds)
    print(f"{doc['date']}, load {doc['load']:.1f}, {args.positions} positions, {args.rounds} rounds, one core")
    for row in doc["cases"]:
        print(f"{row['name']:15s} {row['work']:11s} numpy {row['numpy_us']:8.2f} µs/position   "
              f"numba {row['numba_us']:6.2f} µs/position   numpy / numba {row['numpy_over_numba']:6.1f}")
    if args.json:
        Path(args.json).write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
