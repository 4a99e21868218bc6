"""Design-study benchmarks: design batches (numpy and numba) against a single-design sweep of the same
size on the same backend, and Dask.

    python benchmarks/study.py [--quick] [--designs D] [--numpy-designs D] [--dask-designs K]
                               [--dask-rounds R] [--no-dask] [--json FILE]

1. D crank-rocker four-bars (`models/fourbar_design.toml`, random dimensions) × 360 crank positions in one
   design batch (numba, the compiled design kernel, and numpy, the reference), reading every design's
   coupler point M: positions and velocity analogues. The batch computes what is asked for
   (`points=["M"], links=[], accelerations=False`), M's xy and v_q, and all of it is read. Positions per
   second on one core.
2. Equal work for the ratio: the same number of positions of one design in one sweep
   (`mbplanar.analyse(..., points=["M"])`, which also gives every link's angle and rates and M's
   accelerations) against a design batch asked for the same (`points=["M"]`, every link,
   `accelerations=True`), each reading M's xy and v_q, on the same backend: the batch's cost per
   design-position over the sweep's cost per position (same run).
3. K designs × 12 positions through `solve_designs` (numpy; M's xy and v_q) on a Dask LocalCluster of 1 and of 2
   single-thread worker processes (chunks of 2000 designs, one task each), R rounds interleaved
   (1, 2, 1, 2, ...): the ratio of the median wall times. The results of the runs are checked equal,
   bit for bit.

Times are wall clock (time.perf_counter), the best of `--repeats` runs, and the process's CPU time of
that run (time.process_time: on a machine shared with other jobs it is what one core spent); numpy's
own threads and the compiled kernels are held to one thread (OMP/OPENBLAS/MKL_NUM_THREADS=1,
MBPLANAR_THREADS=1) so that "per core" means one core. The load average is recorded before each case.
"""

from __future__ import annotations

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "MBPLANAR_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

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


def _timed(run, repeats: int):
    """(wall seconds, CPU seconds) of the fastest of `repeats` runs (after one warm-up run when
    repeats > 1: numba's kernels loaded, the allocator warm)."""
    if repeats > 1:
        run()
    best = (float("inf"), float("inf"))
    for _ in range(repeats):
        c, t = time.process_time(), time.perf_counter()
        run()
        wall, cpu = time.perf_counter() - t, time.process_time() - c
        best = min(best, (wall, cpu))
    return best


def _case(name, backend, n, wall, cpu, **extra) -> dict:
    return {"case": name, "backend": backend, "positions": n, "seconds": wall, "cpu_seconds": cpu,
            "positions_per_s": n / wall, "positions_per_cpu_s": n / cpu, "us_per_position": 1e6 * wall / n,
            "us_per_position_cpu": 1e6 * cpu / n, "load": os.getloadavg()[0], **extra}


def batch_case(designs: int, repeats: int, backend: str, sweeps_work: bool = False) -> dict:
    """The design batch: M's positions and velocities only, or with `sweeps_work` what a single-design
    sweep gives (every link's angle and rates, M's accelerations too)."""
    phi = np.radians(np.arange(360.0))
    values = crank_rockers(designs)
    load = os.getloadavg()[0]
    request = dict(points=["M"]) if sweeps_work else dict(points=["M"], links=[], accelerations=False)

    def run():
        batch = design_batch(MODEL, values, backend=backend)
        motion = batch.solve(phi, **request)
        k = motion.point("M")
        xy, vq = motion.xy[:, :, k].copy(), motion.vq[:, :, k].copy()
        assert motion.valid.all() and np.isfinite(xy).all() and np.isfinite(vq).all(), "every crank-rocker turns"
        return xy, vq

    wall, cpu = _timed(run, repeats)
    out = _case("design batch" + (", sweep's work" if sweeps_work else ""), backend, designs * len(phi), wall,
                cpu, designs=designs)
    out["load"] = load
    return out


def sweep_case(positions: int, repeats: int, backend: str) -> dict:
    engine = mbplanar.Engine(mbplanar.read_model(MODEL), backend=backend, threads=1)
    phi = np.linspace(0, 2 * np.pi, positions, endpoint=False)
    mbplanar.analyse(engine, phi[:1000])  # the atlas, built once per engine
    load = os.getloadavg()[0]

    def run():
        motion = mbplanar.analyse(engine, phi, points=["M"])
        k = motion.point("M")
        xy, vq = motion.xy[:, k].copy(), motion.vq[:, k].copy()
        assert len(xy) == positions and np.isfinite(vq).all()
        return xy, vq

    wall, cpu = _timed(run, repeats)
    out = _case("single-design sweep", backend, positions, wall, cpu)
    out["load"] = load
    return out


def dask_case(designs: int, workers: int, phi) -> tuple[dict, object]:
    from mbplanar.study.cluster import close, local_client

    client = local_client(workers)
    try:
        client.run(lambda: __import__("mbplanar.study"))  # imports paid before the clock starts
        load = os.getloadavg()[0]
        t = time.perf_counter()
        motion = solve_designs(MODEL, crank_rockers(designs, seed=2), phi, chunk=2000, client=client, points=["M"],
                               accelerations=False)
        seconds = time.perf_counter() - t
    finally:
        close(client)
    return {"case": f"dask, {workers} worker(s)", "designs": designs, "positions": designs * len(phi),
            "seconds": seconds, "load": load}, motion


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small sizes (smoke run)")
    ap.add_argument("--designs", type=int, help="designs in the numba batch case (default 10000; quick 500)")
    ap.add_argument("--numpy-designs", type=int, help="designs in the numpy batch case (default 2000; quick 200)")
    ap.add_argument("--dask-rounds", type=int, default=2, help="rounds of the Dask case (median; default 2)")
    ap.add_argument("--dask-designs", type=int, help="designs in the Dask case (default 100000; quick 4000)")
    ap.add_argument("--repeats", type=int, default=None)
    ap.add_argument("--no-dask", action="store_true")
    ap.add_argument("--json", metavar="FILE")
    args = ap.parse_args(argv)
    designs = args.designs or (500 if args.quick else 10_000)
    numpy_designs = args.numpy_designs or (200 if args.quick else 2_000)
    repeats = args.repeats or (1 if args.quick else 2)
    doc = {"date": time.strftime("%Y-%m-%d %H:%M"), "cpus": os.cpu_count(), "cases": [], "ratios": {}}
    for backend, count in (("numba", designs), ("numpy", numpy_designs)):
        doc["cases"].append(batch_case(count, repeats, backend))
        batch = batch_case(count, repeats, backend, sweeps_work=True)
        sweep = sweep_case(batch["positions"], repeats, backend)
        doc["cases"] += [batch, sweep]
        doc["ratios"][backend] = {"wall": batch["us_per_position"] / sweep["us_per_position"],
                                  "cpu": batch["us_per_position_cpu"] / sweep["us_per_position_cpu"]}
    for c in doc["cases"]:
        print(f"{c['case']:<34} {c['backend']:<6} {c['positions']:>9} positions  {c['seconds']:7.2f} s wall "
              f"{c['cpu_seconds']:7.2f} s CPU  {c['positions_per_s']:11.0f}/s wall  {c['positions_per_cpu_s']:11.0f}/s CPU"
              f"  load {c['load']:.1f}")
    for backend, r in doc["ratios"].items():
        print(f"{backend}: cost per design-position / cost per position of one design's sweep: "
              f"{r['wall']:.2f} (wall), {r['cpu']:.2f} (CPU)")
    if not args.no_dask:
        k = args.dask_designs or (4000 if args.quick else 100_000)
        phi = np.radians(np.arange(0.0, 360.0, 30.0))
        runs = {1: [], 2: []}
        first = None
        equal = True
        for _ in range(args.dask_rounds):
            for workers in (1, 2):
                case, motion = dask_case(k, workers, phi)
                runs[workers].append(case)
                if first is None:
                    first = motion
                else:
                    equal &= all(np.array_equal(getattr(first, n), getattr(motion, n), equal_nan=True)
                                 for n in ("valid", "angle", "wq", "xy", "vq"))
        median = {w: float(np.median([c["seconds"] for c in cases])) for w, cases in runs.items()}
        doc["dask"] = {"designs": k, "positions_per_design": len(phi), "rounds": runs, "median_seconds": median,
                       "speedup": median[1] / median[2], "equal": bool(equal)}
        print(f"dask {k} designs x {len(phi)} positions, {args.dask_rounds} round(s): 1 worker "
              f"{[round(c['seconds'], 1) for c in runs[1]]} s, 2 workers {[round(c['seconds'], 1) for c in runs[2]]} s "
              f"(loads {[round(c['load'], 1) for c in runs[1] + runs[2]]}); median speed-up "
              f"{doc['dask']['speedup']:.2f}, results equal: {equal}")
    if args.json:
        Path(args.json).write_text(json.dumps(doc, indent=1))
    return doc


if __name__ == "__main__":
    main()
