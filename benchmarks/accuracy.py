"""Accuracy benchmarks (mbplanar.accuracy): exact sensitivities against the sweep they share a solve with,
the Monte Carlo through the compiled design batch, and both on Dask workers.

    python benchmarks/accuracy.py [--quick] [--samples N] [--rounds R] [--no-dask] [--json FILE]

1. Sensitivities of the six-bar press (models/six_bar_press.toml and its [tolerances]: 11 toleranced
   dimensions) of every output — every joint's and point's x and y, every link's angle, every joint's
   value (32 outputs) — at 360 positions over a turn, against its pos+vel+acc sweep
   (`mbplanar.analyse` of the same 360 positions: every point's position, velocity and acceleration and
   every link's angle and rates), numpy both, each reading everything it made. R rounds; in each the
   fastest CPU time of 5 calls of each, the sweep timed right after the sensitivities; the figure is
   the median over the rounds of the ratio within a round. Target: ≤ 3.
2. The Monte Carlo of models/fourbar.toml's tolerances (7 dimensions), N samples (default 10⁵) × 360
   positions of the coupler point M, through the compiled design batch on one core (`Engine(threads=1)`,
   MBPLANAR_THREADS=1), after a warm-up of 200 samples that loads the kernels: wall and CPU time. Target:
   ≤ 30 s. The numpy design batch on N/10 samples for comparison.
3. Dask, on LocalClusters of 1 and of 2 single-thread worker processes, R rounds interleaved (1, 2, 1, 2):
   the Monte Carlo of 20,000 samples × 72 positions (numpy, chunks of 2500 samples) and the sensitivities
   of the six-bar press's slider H (x) to its 11 dimensions at 400,000 positions (chunks of 50,000; the
   answer is what a task sends back, 8 bytes per position, output and dimension); the median speed-up,
   and the answers checked equal to the serial run's, bit for bit.

4. Models with higher pairs: the Monte Carlo of the geared five-bar (its gears' pitch radii, a crank's
   length, a frame pivot: 4 dimensions, the coupler point P) and of the eccentric cam with its roller
   (the roller's and the disc's radius, the eccentricity, the arm's pivot: 4 dimensions, the arm's angle),
   N/10 samples × 360 positions each, through the compiled design batch and on numpy: CPU µs per
   design-position, numpy's ratio to the compiled one's, and numpy's to the four-bar's on numpy in the
   same run (case 2).

The load average is recorded beside each figure (the development machine is shared).
"""

from __future__ import annotations

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "MBPLANAR_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import mbplanar  # noqa: E402
from mbplanar.accuracy import DesignSpace, monte_carlo, resolve_outputs, sensitivities  # noqa: E402
from mbplanar.accuracy.run import cycle, load  # noqa: E402
from mbplanar.accuracy.spec import read_tolerances  # noqa: E402

PRESS = ROOT / "models" / "six_bar_press.toml"
FOURBAR = ROOT / "models" / "fourbar.toml"


def _space(path, backend="numpy"):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        template, raw, engine = load(path, backend)
    from mbplanar.accuracy.geometry import catalogue
    spec = read_tolerances(template.data["tolerances"], str(path), catalogue(engine, raw, template),
                           engine.mech.joints, engine.mech.units.length_scale)
    engine.threads = 1
    return DesignSpace(engine, raw, template, [t.name for t in spec.dimensions]), spec


def _every_output(mech):
    return resolve_outputs(mech, list(mech.joints) + list(mech.points) + mech.moving_links
                           + [f"{j}.value" for j in mech.joints])


def _cpu(run, calls=5) -> float:
    best = float("inf")
    for _ in range(calls):
        c = time.process_time()
        run()
        best = min(best, time.process_time() - c)
    return best


def sensitivity_case(rounds: int) -> dict:
    space, _ = _space(PRESS)
    engine = space.engine
    phi, _ = cycle(engine, 360)
    outputs = _every_output(engine.mech)

    def sens():
        s = sensitivities(space, phi, outputs)
        return float(np.sum(s.d) + np.sum(s.value))

    def sweep():
        m = mbplanar.analyse(engine, phi)
        return float(m.xy.sum() + m.v.sum() + m.a.sum() + m.angle.sum() + m.w.sum() + m.e.sum() + m.value.sum())

    sens(), sweep()
    rows = []
    for _ in range(rounds):
        load = os.getloadavg()[0]
        a, b = _cpu(sens), _cpu(sweep)
        rows.append({"sensitivities_ms": 1e3 * a, "sweep_ms": 1e3 * b, "ratio": a / b, "load": load})
    return {"case": "six-bar press sensitivities / pos+vel+acc sweep", "positions": len(phi),
            "outputs": len(outputs), "dimensions": len(space.dimensions), "rounds": rows,
            "ratio": statistics.median(r["ratio"] for r in rows), "target": 3.0}


def monte_carlo_case(samples: int, backend: str) -> dict:
    space, spec = _space(FOURBAR, backend)
    phi, _ = cycle(space.engine, 360)
    outputs = resolve_outputs(space.engine.mech, ["M"])
    monte_carlo(space, spec.dimensions, phi, outputs, samples=200, seed=1)      # the kernels loaded
    load = os.getloadavg()[0]
    c, t = time.process_time(), time.perf_counter()
    mc = monte_carlo(space, spec.dimensions, phi, outputs, samples=samples, seed=1)
    wall, cpu = time.perf_counter() - t, time.process_time() - c
    assert mc.count == samples
    return {"case": f"four-bar Monte Carlo, {backend}", "samples": samples, "positions": len(phi),
            "seconds": wall, "cpu_seconds": cpu, "us_per_design_position_cpu": 1e6 * cpu / (samples * len(phi)),
            "load": load, "target_seconds": 30.0 if backend == "numba" else None}


HIGHER = {"geared_five_bar": (("links.1.length", 2e-5), ("joints.E.x", 2e-5), ("joints.G.radius_a", 1e-5),
                              ("joints.G.radius_b", 1e-5), ("P",)),
          "cam_eccentric": (("joints.K.radius", 0.02), ("joints.K.profile.x", 0.02),
                            ("joints.K.profile.radius", 0.02), ("joints.C.y", 0.02), ("arm",))}


def higher_cases(samples: int, baseline: float) -> list:
    """The Monte Carlo of the higher-pair models of `HIGHER` through the compiled design batch and on
    numpy, against the four-bar's µs per design-position `baseline` on numpy of the same run."""
    from mbplanar.accuracy import Tolerance
    out = []
    for name, rows in HIGHER.items():
        got = {}
        for backend in ("numba", "numpy"):
            template, raw, engine = load(ROOT / "models" / f"{name}.toml", backend)
            bands = [Tolerance(n, -b, b) for n, b in rows[:-1]]
            space = DesignSpace(engine, raw, template, [t.name for t in bands])
            phi, _ = cycle(engine, 360)
            outputs = resolve_outputs(engine.mech, list(rows[-1]))
            monte_carlo(space, bands, phi, outputs, samples=50, seed=1)      # (the kernels loaded)
            load_avg = os.getloadavg()[0]
            c, t = time.process_time(), time.perf_counter()
            mc = monte_carlo(space, bands, phi, outputs, samples=samples, seed=1)
            wall, cpu = time.perf_counter() - t, time.process_time() - c
            assert mc.count == samples
            got[backend] = mc
            us = 1e6 * cpu / (samples * len(phi))
            out.append({"case": f"{name} Monte Carlo, {backend}", "samples": samples, "positions": len(phi),
                        "seconds": wall, "cpu_seconds": cpu, "us_per_design_position_cpu": us,
                        "over_fourbar_numpy": us / baseline, "load": load_avg})
        out[-1]["numpy_over_numba"] = out[-1]["cpu_seconds"] / out[-2]["cpu_seconds"]
        assert np.allclose(got["numba"].std, got["numpy"].std, rtol=0, atol=1e-12 * np.abs(got["numpy"].mean).max())
    return out


def dask_cases(rounds: int, samples: int, positions: int) -> dict:
    from mbplanar.study.cluster import close, local_client

    space, spec = _space(FOURBAR)
    phi_mc = cycle(space.engine, 72)[0]
    out_mc = resolve_outputs(space.engine.mech, ["M"])
    press, _ = _space(PRESS)
    phi_s = np.linspace(0.0, 2 * np.pi, positions, endpoint=False) + float(press.engine.phi_drawn[0])
    out_s = resolve_outputs(press.engine.mech, ["H.x"])
    t = time.perf_counter()
    serial_mc = monte_carlo(space, spec.dimensions, phi_mc, out_mc, samples=samples, seed=3, chunk=2500)
    serial = {"monte_carlo": time.perf_counter() - t}
    t = time.perf_counter()
    serial_s = sensitivities(press, phi_s, out_s)
    serial["sensitivities"] = time.perf_counter() - t
    runs = {"monte_carlo": {1: [], 2: []}, "sensitivities": {1: [], 2: []}}
    equal = True
    for _ in range(rounds):
        for workers in (1, 2):
            client = local_client(workers)
            try:
                client.run(lambda: __import__("mbplanar.accuracy"))
                load = os.getloadavg()[0]
                t = time.perf_counter()
                mc = monte_carlo(space, spec.dimensions, phi_mc, out_mc, samples=samples, seed=3, chunk=2500,
                                 client=client)
                runs["monte_carlo"][workers].append({"seconds": time.perf_counter() - t, "load": load})
                t = time.perf_counter()
                s = sensitivities(press, phi_s, out_s, client=client, chunk=50_000)
                runs["sensitivities"][workers].append({"seconds": time.perf_counter() - t, "load": load})
            finally:
                close(client)
            equal &= all(np.array_equal(getattr(mc, n), getattr(serial_mc, n)) for n in ("mean", "std", "low", "high"))
            equal &= np.array_equal(s.d, serial_s.d)
    out = {"samples": samples, "mc_positions": len(phi_mc), "sensitivity_positions": positions, "rounds": runs,
           "serial_seconds": serial, "equal": bool(equal)}
    for name, r in runs.items():
        med = {w: float(np.median([c["seconds"] for c in cases])) for w, cases in r.items()}
        out[name] = {"median_seconds": med, "speedup": med[1] / med[2]}
    return out


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small sizes (smoke run)")
    ap.add_argument("--samples", type=int, help="Monte Carlo samples on numba (default 100000; quick 2000)")
    ap.add_argument("--rounds", type=int, help="rounds of the ratio and the Dask cases (default 5 and 2)")
    ap.add_argument("--no-dask", action="store_true")
    ap.add_argument("--json", metavar="FILE")
    args = ap.parse_args(argv)
    samples = args.samples or (2000 if args.quick else 100_000)
    doc = {"date": time.strftime("%Y-%m-%d %H:%M"), "cpus": os.cpu_count()}
    doc["sensitivities"] = sensitivity_case(args.rounds or (2 if args.quick else 5))
    s = doc["sensitivities"]
    print(f"{s['case']}: {s['positions']} positions, {s['outputs']} outputs × {s['dimensions']} dimensions: "
          + ", ".join(f"{r['sensitivities_ms']:.2f} / {r['sweep_ms']:.2f} ms = {r['ratio']:.2f} (load {r['load']:.1f})"
                      for r in s["rounds"]) + f"; median {s['ratio']:.2f} (target ≤ 3)")
    doc["monte_carlo"] = [monte_carlo_case(samples, "numba"), monte_carlo_case(max(samples // 10, 200), "numpy")]
    for c in doc["monte_carlo"]:
        print(f"{c['case']}: {c['samples']} samples × {c['positions']} positions: {c['seconds']:.2f} s wall, "
              f"{c['cpu_seconds']:.2f} s CPU ({c['us_per_design_position_cpu']:.3f} µs CPU per design-position), "
              f"load {c['load']:.1f}")
    doc["higher"] = higher_cases(max(samples // 10, 200), doc["monte_carlo"][1]["us_per_design_position_cpu"])
    for c in doc["higher"]:
        print(f"{c['case']}: {c['samples']} samples × {c['positions']} positions: {c['seconds']:.2f} s wall, "
              f"{c['cpu_seconds']:.2f} s CPU ({c['us_per_design_position_cpu']:.3f} µs CPU per design-position, "
              f"{c['over_fourbar_numpy']:.2f} × the four-bar's on numpy), load {c['load']:.1f}"
              + (f"; numpy / numba {c['numpy_over_numba']:.1f}" if "numpy_over_numba" in c else ""))
    if not args.no_dask:
        doc["dask"] = dask_cases(args.rounds or 2, 4000 if args.quick else 20_000, 100_000 if args.quick else 400_000)
        d = doc["dask"]
        for name in ("monte_carlo", "sensitivities"):
            r = d["rounds"][name]
            print(f"dask {name}: serial {d['serial_seconds'][name]:.2f} s; 1 worker {[round(c['seconds'], 2) for c in r[1]]} s, "
                  f"2 workers {[round(c['seconds'], 2) for c in r[2]]} s (loads {[round(c['load'], 1) for c in r[1] + r[2]]}); "
                  f"median speed-up {d[name]['speedup']:.2f}")
        print(f"dask answers equal to the serial run's: {d['equal']}")
    if args.json:
        Path(args.json).write_text(json.dumps(doc, indent=1))
    return doc


if __name__ == "__main__":
    main()
