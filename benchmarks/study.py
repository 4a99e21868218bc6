"""Design-study benchmarks: a design batch against a single-design sweep of the same size, and Dask.

    python benchmarks/study.py [--quick] [--designs D] [--dask-designs K] [--json FILE]

1. D crank-rocker four-bars (`models/fourbar_design.toml`, random dimensions) × 360 crank positions in one
   design batch (numpy, one thread), reading every design's coupler point M: positions and analogue
   velocities (the batch also computes every link's angle, ω_q, ε_q and every point's a_q). Positions
   per second on one core.
2. The same number of positions of one design in one sweep (`mbplanar.analyse`, numpy), reading the
   same arrays of M: the cost per position against which the batch's cost per design-position is
   compared (same run, ratio).
3. K designs × 12 positions through `solve_designs` on a Dask LocalCluster of 1 and of 2 single-thread
   worker processes (chunks of 2000 designs, one task each): the ratio of the wall times. The results
   of both runs are checked equal, bit for bit.

Every time is wall clock (time.perf_counter), the best of `--repeats` runs; numpy's own threads are
held to one (OMP/OPENBLAS/MKL_NUM_THREADS=1) so that "per core" means one core.
"""

from __future__ import annotations

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from run import best_time  # noqa: E402

import mbplanar  # noqa: E402
from mbplanar.study import design_batch, solve_designs  # noqa: E402

MODEL = str(ROOT / "models" / "fourbar_design.toml")


def crank_rockers(count: int, seed: int = 1) -> dict:
    """Random dimensions of crank-rocker four-bars: drawn at random, the rocker CB closing the drawn
    pose, kept when Grashof's condition makes the crank the shortest link that turns fully."""
    rng = np.random.default_rng(seed)
    n = 4 * count
    v = {"a": rng.uniform(0.05, 0.08, n), "b": rng.uniform(0.25, 0.35, n), "d": rng.uniform(0.25, 0.35, n),
         "theta0": rng.uniform(0, 360, n), "beta": rng.uniform(0, 360, n), "m": rng.uniform(0.2, 0.8, n),
         "h": rng.uniform(-0.05, 0.05, n)}
    ax, ay = v["a"] * np.cos(np.radians(v["theta0"])), v["a"] * np.sin(np.radians(v["theta0"]))
    bx, by = ax + v["b"] * np.cos(np.radians(v["beta"])), ay + v["b"] * np.sin(np.radians(v["beta"]))
    c = np.hypot(bx - v["d"], by)
    lengths = np.stack([v["a"], v["b"], c, v["d"]])
    keep = (lengths.min(axis=0) == v["a"]) & (lengths.min(axis=0) + lengths.max(axis=0) < lengths.sum(axis=0)
                                              - lengths.min(axis=0) - lengths.max(axis=0) - 0.02)
    idx = np.flatnonzero(keep)[:count]
    assert len(idx) == count
    return {k: x[idx] for k, x in v.items()}


def batch_case(designs: int, repeats: int) -> dict:
    phi = np.radians(np.arange(360.0))
    values = crank_rockers(designs)

    def run():
        motion = design_batch(MODEL, values).solve(phi)
        k = motion.point("M")
        xy, vq = motion.xy[:, :, k].copy(), motion.vq[:, :, k].copy()
        assert motion.valid.all(), "every crank-rocker turns fully"
        return xy, vq

    seconds = best_time(run, repeats)
    n = designs * len(phi)
    return {"case": "design batch", "designs": designs, "positions": n, "seconds": seconds,
            "positions_per_s": n / seconds, "us_per_position": 1e6 * seconds / n}


def sweep_case(positions: int, repeats: int) -> dict:
    engine = mbplanar.Engine(mbplanar.read_model(MODEL))
    phi = np.linspace(0, 2 * np.pi, positions, endpoint=False)
    mbplanar.analyse(engine, phi[:1000])  # the atlas, built once per engine

    def run():
        motion = mbplanar.analyse(engine, phi)
        k = motion.point("M")
        return motion.xy[:, k].copy(), motion.vq[:, k].copy()

    seconds = best_time(run, repeats)
    return {"case": "single-design sweep", "positions": positions, "seconds": seconds,
            "positions_per_s": positions / seconds, "us_per_position": 1e6 * seconds / positions}


def dask_case(designs: int, workers: int, phi) -> tuple[dict, object]:
    from mbplanar.study.cluster import close, local_client

    client = local_client(workers)
    try:
        client.run(lambda: __import__("mbplanar.study"))  # imports paid before the clock starts
        t = time.perf_counter()
        motion = solve_designs(MODEL, crank_rockers(designs, seed=2), phi, chunk=2000, client=client)
        seconds = time.perf_counter() - t
    finally:
        close(client)
    return {"case": f"dask, {workers} worker(s)", "designs": designs, "positions": designs * len(phi),
            "seconds": seconds}, motion


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small sizes (smoke run)")
    ap.add_argument("--designs", type=int, help="designs in the batch case (default 10000; quick 500)")
    ap.add_argument("--dask-designs", type=int, help="designs in the Dask case (default 100000; quick 4000)")
    ap.add_argument("--repeats", type=int, default=None)
    ap.add_argument("--no-dask", action="store_true")
    ap.add_argument("--json", metavar="FILE")
    args = ap.parse_args(argv)
    designs = args.designs or (500 if args.quick else 10_000)
    repeats = args.repeats or (1 if args.quick else 2)
    cases = [batch_case(designs, repeats)]
    cases.append(sweep_case(cases[0]["positions"], repeats))
    ratio = cases[0]["us_per_position"] / cases[1]["us_per_position"]
    doc = {"date": time.strftime("%Y-%m-%d"), "cpus": os.cpu_count(), "cases": cases,
           "batch_vs_sweep_cost_ratio": ratio}
    for c in cases:
        print(f"{c['case']:<22} {c['positions']:>9} positions  {c['seconds']:8.2f} s  "
              f"{c['positions_per_s']:12.0f} positions/s  {c['us_per_position']:.3f} µs/position")
    print(f"cost per design-position / cost per position of one design's sweep: {ratio:.2f}")
    if not args.no_dask:
        k = args.dask_designs or (4000 if args.quick else 100_000)
        phi = np.radians(np.arange(0.0, 360.0, 30.0))
        one, m1 = dask_case(k, 1, phi)
        two, m2 = dask_case(k, 2, phi)
        equal = all(np.array_equal(getattr(m1, n), getattr(m2, n), equal_nan=True)
                    for n in ("valid", "angle", "xy", "vq", "aq"))
        doc["dask"] = {"one": one, "two": two, "speedup": one["seconds"] / two["seconds"], "equal": equal}
        print(f"dask {k} designs x {len(phi)} positions: 1 worker {one['seconds']:.2f} s, 2 workers "
              f"{two['seconds']:.2f} s, speed-up {doc['dask']['speedup']:.2f}, results equal: {equal}")
    if args.json:
        Path(args.json).write_text(json.dumps(doc, indent=1))
    return doc


if __name__ == "__main__":
    main()
