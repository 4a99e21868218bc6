"""Benchmark suite of mbplanar: sweeps, single-position latency, scaling with N and with mechanism size,
against a vectorised numpy closed form and scipy.optimize.fsolve per position on the same work.

    python benchmarks/run.py [--quick] [--json out.json]

Every time is the minimum over several repeats (wall clock, time.perf_counter) with a warm engine;
µs per position. The engine build (assembly + structure + branch atlas) is timed separately.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import subprocess
import sys
import time
import tracemalloc
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import closed_forms as cf  # noqa: E402
from chains import class4_chain, dyad_chain  # noqa: E402
import mbplanar  # noqa: E402
from mbplanar.model import Mechanism  # noqa: E402

MODELS = ["fourbar", "slider_crank", "shaper", "six_bar_press", "class4_group"]
CLOSED = {"fourbar": (cf.fourbar, cf.fourbar_fsolve), "slider_crank": (cf.slider_crank, cf.slider_crank_fsolve)}


def best_time(fn, repeats):
    """Minimum wall time of `repeats` calls (s)."""
    best = math.inf
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def best_times(fns, repeats):
    """Minimum wall times (s) of several functions called in turn, so that a ratio between them is not
    skewed by another job that ran during one of them only."""
    best = [math.inf] * len(fns)
    for _ in range(repeats):
        for k, fn in enumerate(fns):
            t = time.perf_counter()
            fn()
            best[k] = min(best[k], time.perf_counter() - t)
    return best


def full_turn(engine, n):
    """n input values over one turn from the drawn pose (SI)."""
    return engine.phi_drawn[0] + np.linspace(0.0, 2 * np.pi, n, endpoint=False)


def build(path):
    """Engine of a model file, and the times of the build and of the atlas (first solve)."""
    t0 = time.perf_counter()
    engine = mbplanar.Engine(mbplanar.read_model(path))
    t1 = time.perf_counter()
    engine.atlas().cover(engine.phi_drawn[0], engine.phi_drawn[0] + 2 * np.pi)
    return engine, t1 - t0, time.perf_counter() - t1


def reactions_fn():
    try:
        from mbplanar.kinetostatics import kinetostatics
    except ImportError:
        return None
    return kinetostatics


def sweep_cases(n, repeats, fsolve_n, out):
    kinetostatics = reactions_fn()
    builds = []
    for name in MODELS:
        path = ROOT / "models" / f"{name}.toml"
        if not path.exists():
            continue
        engine, t_build, t_atlas = build(path)
        builds.append((name, t_build, t_atlas))
        phi = full_turn(engine, n)
        works = [("positions", lambda: engine.solve(phi)), ("kinematics", lambda: mbplanar.analyse(engine, phi))]
        if kinetostatics is not None:
            motion = mbplanar.analyse(engine, phi)
            try:
                kinetostatics(engine, motion)
                works.append(("reactions", lambda: kinetostatics(engine, mbplanar.analyse(engine, phi))))
            except Exception as exc:  # a model without mass data, or the module not finished
                print(f"  {name}: reactions skipped ({type(exc).__name__}: {exc})")
        closed, fsolve = CLOSED.get(name, (None, None))
        for work, fn in works:
            fn()
            row = dict(name=name, work=work, n=n, mbplanar_us=None, closed_form_us=None, fsolve_us=None)
            if closed is not None and work != "reactions":
                only = work == "positions"
                t, tc = best_times([fn, lambda: closed(phi, positions_only=only)], 3 * repeats)
                row["closed_form_us"] = 1e6 * tc / n
                few = phi[:fsolve_n]
                row["fsolve_us"] = 1e6 * best_time(lambda: fsolve(few, rates=not only), 2) / fsolve_n
            else:
                t = best_time(fn, repeats)
            row["mbplanar_us"] = 1e6 * t / n
            out.append(row)
            ratio = f"  ({row['mbplanar_us'] / row['closed_form_us']:.1f}× closed form)" if row["closed_form_us"] else ""
            print(f"  {name:14s} {work:11s} {row['mbplanar_us']:8.2f} µs/position{ratio}"
                  + (f"  closed {row['closed_form_us']:.3f}  fsolve {row['fsolve_us']:.1f}" if row["closed_form_us"] else ""))
    return builds


def latency_cases(repeats, out):
    for name in ("fourbar", "shaper", "six_bar_press"):
        engine, _, _ = build(ROOT / "models" / f"{name}.toml")
        phi = engine.phi_drawn[:1] + 0.3
        mbplanar.analyse(engine, phi)
        t = best_time(lambda: mbplanar.analyse(engine, phi), repeats * 5)
        out.append(dict(name=name, work="one position", n=1, mbplanar_us=1e6 * t, closed_form_us=None, fsolve_us=None))
        print(f"  {name:14s} one position (analyse, warm engine) {1e6 * t:8.0f} µs")
    cmd = [sys.executable, "-m", "mbplanar", "solve", str(ROOT / "models" / "shaper.toml"), "--at", "140.769"]
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    # bytecode compiled once, as an installed package has it (PYTHONDONTWRITEBYTECODE would otherwise
    # make every run compile the sources again)
    subprocess.run([sys.executable, "-m", "compileall", "-q", str(ROOT / "mbplanar")], check=True,
                   capture_output=True)
    t = best_time(lambda: subprocess.run(cmd, check=True, capture_output=True, env=env), max(3, repeats))
    out.append(dict(name="shaper", work="mbplanar solve (CLI, end to end)", n=1, mbplanar_us=1e6 * t,
                    closed_form_us=None, fsolve_us=None))
    print(f"  mbplanar solve models/shaper.toml end to end (subprocess, import included) {t:.3f} s")


def scaling_n(sizes, repeats, out):
    engine, _, _ = build(ROOT / "models" / "shaper.toml")
    for n in sizes:
        phi = full_turn(engine, n)
        rep = repeats if n <= 10 ** 5 else 1
        t = best_time(lambda: mbplanar.analyse(engine, phi), rep)
        row = dict(name="shaper", work="kinematics, scaling in N", n=n, mbplanar_us=1e6 * t / n,
                   closed_form_us=None, fsolve_us=None)
        if n == sizes[-1]:
            tracemalloc.start()
            mbplanar.analyse(engine, phi)
            row["peak_MB"] = tracemalloc.get_traced_memory()[1] / 2 ** 20
            tracemalloc.stop()
        out.append(row)
        print(f"  N = {n:8d}: {row['mbplanar_us']:8.2f} µs/position, {t:.4f} s"
              + (f", peak traced memory {row['peak_MB']:.0f} MB" if "peak_MB" in row else ""))


def scaling_k(ks, n, repeats, out):
    times = []
    for k in ks:
        t0 = time.perf_counter()
        engine = mbplanar.Engine(dyad_chain(k))
        phi = full_turn(engine, n)
        mbplanar.analyse(engine, phi)
        t_build = time.perf_counter() - t0
        motion = mbplanar.analyse(engine, phi)
        assert motion.success, motion.message
        t = best_time(lambda: mbplanar.analyse(engine, phi), repeats)
        times.append(t)
        out.append(dict(name=f"chain of {k} dyads", work="kinematics", n=n, mbplanar_us=1e6 * t / n,
                        closed_form_us=None, fsolve_us=None, build_s=t_build))
        print(f"  k = {k:3d}: {1e6 * t / n:8.2f} µs/position ({1e6 * t / n / k:.2f} per group), build + atlas {t_build:.2f} s")
    if len(ks) > 1:
        slope = np.polyfit(np.log(ks), np.log(times), 1)[0]
        tail = np.polyfit(np.log(ks[-3:]), np.log(times[-3:]), 1)[0] if len(ks) >= 3 else slope
        print(f"  time ∝ k^{slope:.2f} over k = {ks[0]}…{ks[-1]} (k^{tail:.2f} over the last three)")
        return slope


def scaling_groups(builder, label, ks, n, repeats, out):
    """Time per position (positions + velocities + accelerations, N = n over a turn) of the mechanisms
    builder(k) for k in ks, and the fitted exponent of time vs k."""
    times = []
    for k in ks:
        t0 = time.perf_counter()
        engine = mbplanar.Engine(builder(k))
        t_engine = time.perf_counter() - t0
        phi = full_turn(engine, n)
        motion = mbplanar.analyse(engine, phi)
        t_build = time.perf_counter() - t0
        assert motion.success, motion.message
        t = best_time(lambda: mbplanar.analyse(engine, phi), repeats)
        times.append(t)
        out.append(dict(name=f"chain of {k} {label}", work="kinematics", n=n, mbplanar_us=1e6 * t / n,
                        closed_form_us=None, fsolve_us=None, build_s=t_build, engine_s=t_engine))
        print(f"  k = {k:3d}: {1e6 * t / n:8.2f} µs/position ({1e6 * t / n / k:.2f} per group), "
              f"engine {t_engine:.2f} s, + atlas and first sweep {t_build - t_engine:.2f} s")
    if len(ks) > 1:
        slope = np.polyfit(np.log(ks), np.log(times), 1)[0]
        tail = np.polyfit(np.log(ks[-3:]), np.log(times[-3:]), 1)[0] if len(ks) >= 3 else slope
        print(f"  time per position ∝ k^{slope:.2f} over k = {ks[0]}…{ks[-1]} (k^{tail:.2f} over the last three)")
        return slope


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small sizes, few repeats (smoke run)")
    ap.add_argument("--json", metavar="FILE", nargs="?", const="-", help="write the cases as JSON ('-': stdout)")
    args = ap.parse_args(argv)
    quick = args.quick
    repeats = 2 if quick else 7
    n = 360 if quick else 3600
    cases = []
    print(f"mbplanar benchmark — {platform.processor() or platform.machine()}, {os.cpu_count()} CPU(s), "
          f"Python {platform.python_version()}, numpy {np.__version__}")
    print(f"sweeps of N = {n} positions (µs per position, minimum of {repeats} repeats):")
    builds = sweep_cases(n, repeats, 20 if quick else 300, cases)
    print("engine build (assembly + structure) and branch atlas, once per model:")
    for name, t_build, t_atlas in builds:
        print(f"  {name:14s} build {1e3 * t_build:7.1f} ms   atlas {1e3 * t_atlas:7.1f} ms")
    print("latency:")
    latency_cases(repeats, cases)
    print("scaling with N (shaper, positions + velocities + accelerations):")
    scaling_n([10, 100, 1000] if quick else [10, 100, 1000, 10 ** 4, 10 ** 5, 10 ** 6], repeats, cases)
    print("scaling with mechanism size (a crank and k dyads):")
    slope = scaling_k([1, 2, 4] if quick else [1, 2, 4, 8, 16, 32], n, repeats, cases)
    print("scaling with mechanism size (a crank and k class IV groups):")
    slope4 = scaling_groups(class4_chain, "class IV groups", [1, 2, 4] if quick else [1, 2, 4, 8, 16, 32], n,
                            repeats, cases)
    if args.json:
        doc = dict(machine=dict(cpu=platform.processor() or platform.machine(), cpus=os.cpu_count(),
                                python=platform.python_version(), numpy=np.__version__),
                   builds=[dict(name=b[0], build_s=b[1], atlas_s=b[2]) for b in builds],
                   chain_exponent=slope, class4_chain_exponent=slope4, cases=cases)
        text = json.dumps(doc, indent=1)
        if args.json == "-":
            print(text)
        else:
            Path(args.json).write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
