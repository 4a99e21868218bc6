"""Higher-pair sweeps on the compiled backend against numpy, in the same run and on equal work.

    python benchmarks/higher.py [--positions N] [--rounds R] [--designs D] [--json FILE]

Cases (N positions over a turn of the input, one core: `Engine(threads=1)`, numpy's own threads held to
one):

- `shaper_geared` (a gear train driving the shaper's linkage: three gear pairs, a guide load along the
  stroke, heavy links, gravity), positions + velocities + accelerations of every point, and with the
  reactions and contact forces (`kinetostatics`);
- `cam_follower` (a roller on a spline cam profile read from `mbplanar cam`'s CSV, a translating
  follower), positions + velocities + accelerations of every point.

and a design batch (`design_batch(...).solve`): D geared five-bars (default 1000; `[parameters]` the
gears' module m and the crank EB's pivot at the centre distance 24·m, random within ±5 %) × 360 input
values over a turn, the coupler point P's position and velocity analogue asked for and read
(`points=["P"], links=[], accelerations=False`), on numpy (each design by its own engine, built from its
own table) and on numba (the compiled design kernel, each design's gears from its own table): CPU time
of one batch each (after a warm batch of 20 designs), their ratio, and the answers checked equal (1e-12
of the size).

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


def geared_designs(count: int, seed: int = 2) -> tuple[dict, dict]:
    """The geared five-bar with `[parameters]` m (the gears' module) and e (the crank EB's pivot, at the
    centre distance 24·m: the gears mesh), and `count` designs with m within ±5 % of 5 mm."""
    import tomllib
    text = (ROOT / "models" / "geared_five_bar.toml").read_text(encoding="utf-8")
    text = (text.replace("module = 0.005", 'module = "m"').replace("at = [0.12, 0.0]", 'at = ["e", 0.0]')
            .replace("at = [0.12, 0.05]", 'at = ["e", 0.05]'))
    data = dict(tomllib.loads(text), parameters={"m": 0.005, "e": 0.12})
    m = 0.005 * np.random.default_rng(seed).uniform(0.95, 1.05, count)
    return data, {"m": m, "e": 24 * m}


def design_case(designs: int, positions: int = 360) -> dict:
    """A design batch of `designs` geared five-bars × `positions` on numpy and on numba (CPU s each)."""
    import time
    from mbplanar.study import design_batch
    data, values = geared_designs(designs)
    few = {k: v[:20] for k, v in values.items()}
    got, cpu = {}, {}
    for backend in ("numba", "numpy"):
        design_batch(data, few, backend=backend).solve(np.linspace(0.0, 2 * np.pi, positions), points=["P"],
                                                        links=[], accelerations=False)     # (warm)
        t = time.process_time()
        batch = design_batch(data, values, backend=backend)
        phi = batch.geometry.phi0[:, None] + np.linspace(0.0, 2 * np.pi, positions, endpoint=False)
        motion = batch.solve(phi, points=["P"], links=[], accelerations=False)
        float(motion.xy.sum() + motion.vq.sum())
        cpu[backend] = time.process_time() - t
        got[backend] = motion
    a, b = got["numpy"], got["numba"]
    assert a.ok.all() and b.ok.all() and np.array_equal(a.valid, b.valid)
    assert np.nanmax(np.abs(a.xy - b.xy)) <= 1e-12 * 0.3
    return dict(designs=designs, positions=positions, numpy_s=cpu["numpy"], numba_s=cpu["numba"],
                numpy_over_numba=cpu["numpy"] / cpu["numba"], load=os.getloadavg()[0])


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
    parser.add_argument("--designs", type=int, default=1000)
    parser.add_argument("--json", metavar="FILE")
    args = parser.parse_args(argv)
    doc = run(args.positions, args.rounds)
    doc["design_batch"] = design_case(args.designs)
    print(f"{doc['date']}, load {doc['load']:.1f}, {args.positions} positions, {args.rounds} rounds, one core")
    for row in doc["cases"]:
        print(f"{row['name']:15s} {row['work']:11s} numpy {row['numpy_us']:8.2f} µs/position   "
              f"numba {row['numba_us']:6.2f} µs/position   numpy / numba {row['numpy_over_numba']:6.1f}")
    d = doc["design_batch"]
    print(f"design batch: {d['designs']} geared five-bars × {d['positions']} positions: "
          f"numpy {d['numpy_s']:.2f} s CPU, numba {d['numba_s']:.2f} s CPU, "
          f"numpy / numba {d['numpy_over_numba']:.1f} (load {d['load']:.1f})")
    if args.json:
        Path(args.json).write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
