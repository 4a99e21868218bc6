"""Benchmark suite of mbplanar: sweeps, single-position latency, scaling with N and with mechanism size,
against a vectorised numpy closed form and scipy.optimize.fsolve per position on the same work.

    python benchmarks/run.py [--quick] [--json out.json]

Every time is the minimum over several repeats (wall clock, time.perf_counter) with a warm engine;
µs per position. The sweeps and the single positions are timed in rounds (each round times every case
a few times in a row), so that each minimum is taken over the whole run, not over one spell of the
shared machine.
The engine build (assembly + structure + branch atlas) is timed separately. Both backends are timed
when numba is installed: `mbplanar_us` is the compiled one (`backend`), `numpy_us` the reference; the
targets of issue 7 are checked at the end (`targets`).
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
try:
    import numba  # noqa: F401
    BACKENDS = ["numpy", "numba"]
except ImportError:
    BACKENDS = ["numpy"]
BEST = BACKENDS[-1]
CLOSED = {"fourbar": (cf.fourbar, cf.fourbar_fsolve), "slider_crank": (cf.slider_crank, cf.slider_crank_fsolve)}


def best_time(fn, repeats):
    """Minimum wall time of `repeats` calls (s)."""
    best = math.inf
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def in_rounds(cases, rounds, burst):
    """Minimum wall times (s) of the calls of every case (a list of lists of callables): each round
    times every call `burst` times in a row (a warm cache, as a user's repeated calls have), and the
    rounds spread each call's repeats over the whole run."""
    best = [[math.inf] * len(calls) for calls in cases]
    for _ in range(rounds):
        for calls, times in zip(cases, best):
            for k, call in enumerate(calls):
                times[k] = min(times[k], best_time(call, burst))
    return best


def full_turn(engine, n):
    """n input values over one turn from the drawn pose (SI)."""
    return engine.phi_drawn[0] + np.linspace(0.0, 2 * np.pi, n, endpoint=False)


def build(path, backend="numpy"):
    """Engine of a model file, and the times of the build and of the atlas (first solve)."""
    t0 = time.perf_counter()
    engine = mbplanar.Engine(mbplanar.read_model(path), backend=backend)
    t1 = time.perf_counter()
    engine.atlas().cover(engine.phi_drawn[0], engine.phi_drawn[0] + 2 * np.pi)
    return engine, t1 - t0, time.perf_counter() - t1


def reactions_fn():
    try:
        from mbplanar.forces import kinetostatics
    except ImportError:
        return None
    return kinetostatics


def sweep_cases(n, repeats, fsolve_n, out):
    """Every model's sweeps on both backends (and the closed forms where they apply), timed in rounds:
    each round times every case once, so that each case's minimum is taken over the whole run and a
    slow spell of the shared machine does not decide one case."""
    kinetostatics = reactions_fn()
    builds, jobs = [], []
    for name in MODELS:
        path = ROOT / "models" / f"{name}.toml"
        if not path.exists():
            continue
        engine, t_build, t_atlas = build(path)
        fast = build(path, BEST)[0]
        builds.append((name, t_build, t_atlas))
        phi = full_turn(engine, n)
        works = [("positions", lambda e, phi=phi: e.solve(phi)),
                 ("kinematics", lambda e, phi=phi: mbplanar.analyse(e, phi))]
        if kinetostatics is not None:
            try:
                kinetostatics(engine, mbplanar.analyse(engine, phi))
                works.append(("reactions", lambda e, phi=phi: kinetostatics(e, mbplanar.analyse(e, phi))))
            except Exception as exc:  # a model without mass data
                print(f"  {name}: reactions skipped ({type(exc).__name__}: {exc})")
        closed, fsolve = CLOSED.get(name, (None, None))
        for work, fn in works:
            engines = [engine] if work == "positions" else [engine, fast]  # Engine.solve is numpy's
            for e in engines:
                fn(e)
            row = dict(name=name, work=work, n=n, mbplanar_us=None, closed_form_us=None, fsolve_us=None,
                       numpy_us=None, backend=engines[-1].backend)
            calls = [lambda e=e, fn=fn: fn(e) for e in engines]
            if closed is not None and work != "reactions":
                only = work == "positions"
                calls.append(lambda closed=closed, phi=phi, only=only: closed(phi, positions_only=only))
                few = phi[:fsolve_n]
                row["fsolve_us"] = 1e6 * best_time(lambda: fsolve(few, rates=not only), 2) / fsolve_n
            jobs.append((row, calls, len(engines)))
    best = in_rounds([calls for _, calls, _ in jobs], repeats, 3)
    for (row, calls, n_engines), times in zip(jobs, best):
        row["numpy_us"], row["mbplanar_us"] = 1e6 * times[0] / n, 1e6 * times[n_engines - 1] / n
        if len(calls) > n_engines:  # the closed form's time follows the engines'
            row["closed_form_us"] = 1e6 * times[n_engines] / n
        out.append(row)
        ratio = f"  ({row['mbplanar_us'] / row['closed_form_us']:.1f}× closed form)" if row["closed_form_us"] else ""
        print(f"  {row['name']:14s} {row['work']:11s} {row['mbplanar_us']:8.2f} µs/position ({row['backend']}; numpy "
              f"{row['numpy_us']:.2f}){ratio}"
              + (f"  closed {row['closed_form_us']:.3f}  fsolve {row['fsolve_us']:.1f}" if row["closed_form_us"] else ""))
    return builds


def latency_cases(repeats, out):
    """One position on each backend (timed in rounds, as the sweeps), then `mbplanar solve` end to end."""
    names = ("fourbar", "shaper", "six_bar_press")
    calls = []
    for name in names:
        for backend in BACKENDS:
            engine, _, _ = build(ROOT / "models" / f"{name}.toml", backend)
            phi = engine.phi_drawn[:1] + 0.3
            mbplanar.analyse(engine, phi)
            calls.append(lambda engine=engine, phi=phi: mbplanar.analyse(engine, phi))
    best = in_rounds([calls], repeats, 20)[0]
    for i, name in enumerate(names):
        times = best[i * len(BACKENDS):(i + 1) * len(BACKENDS)]
        out.append(dict(name=name, work="one position", n=1, mbplanar_us=1e6 * times[-1], closed_form_us=None,
                        fsolve_us=None, numpy_us=1e6 * times[0], backend=BEST))
        print(f"  {name:14s} one position (analyse, warm engine) {1e6 * times[-1]:8.0f} µs ({BEST}; numpy "
              f"{1e6 * times[0]:.0f})")
    cmd = [sys.executable, "-m", "mbplanar", "solve", str(ROOT / "models" / "shaper.toml"), "--at", "140.769"]
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    # bytecode compiled once, as an installed package has it (PYTHONDONTWRITEBYTECODE would otherwise
    # make every run compile the sources again)
    subprocess.run([sys.executable, "-m", "compileall", "-q", str(ROOT / "mbplanar")], check=True,
                   capture_output=True)
    t = best_time(lambda: subprocess.run(cmd, check=True, capture_output=True, env=env), max(3, repeats))
    out.append(dict(name="shaper", work="mbplanar solve (CLI, end to end)", n=1, mbplanar_us=1e6 * t,
                    closed_form_us=None, fsolve_us=None, numpy_us=1e6 * t, backend="numpy"))
    print(f"  mbplanar solve models/shaper.toml end to end (subprocess, import included) {t:.3f} s")


def scaling_n(sizes, repeats, out):
    engines = [build(ROOT / "models" / "shaper.toml", backend)[0] for backend in BACKENDS]
    for n in sizes:
        phi = full_turn(engines[0], n)
        rep = repeats if n <= 10 ** 5 else 1
        times = [best_time(lambda: mbplanar.analyse(e, phi), rep) for e in engines]
        row = dict(name="shaper", work="kinematics, scaling in N", n=n, mbplanar_us=1e6 * times[-1] / n,
                   closed_form_us=None, fsolve_us=None, numpy_us=1e6 * times[0] / n, backend=BEST)
        if n == sizes[-1]:
            peaks = []
            for e in engines:
                tracemalloc.start()
                mbplanar.analyse(e, phi)
                peaks.append(tracemalloc.get_traced_memory()[1] / 2 ** 20)
                tracemalloc.stop()
            row["numpy_peak_MB"], row["peak_MB"] = peaks[0], peaks[-1]
        out.append(row)
        print(f"  N = {n:8d}: {row['mbplanar_us']:8.2f} µs/position ({BEST}; numpy {row['numpy_us']:.2f})"
              + (f", peak traced memory {row['peak_MB']:.0f} MB (numpy {row['numpy_peak_MB']:.0f} MB)"
                 if "peak_MB" in row else ""))


def scaling_groups(builder, label, ks, n, repeats, out):
    """Time per position (positions + velocities + accelerations, N = n over a turn) of the mechanisms
    builder(k) for k in ks, and the fitted exponents of time vs k (best backend, numpy)."""
    times = {b: [] for b in BACKENDS}
    for k in ks:
        t0 = time.perf_counter()
        mech = builder(k)
        engines = {b: mbplanar.Engine(mech, backend=b) for b in BACKENDS}
        t_engine = (time.perf_counter() - t0) / len(BACKENDS)
        phi = full_turn(engines["numpy"], n)
        for e in engines.values():
            motion = mbplanar.analyse(e, phi)
            assert motion.success, motion.message
        t_build = time.perf_counter() - t0
        for b, e in engines.items():
            times[b].append(best_time(lambda: mbplanar.analyse(e, phi), repeats))
        t, t_np = times[BEST][-1], times["numpy"][-1]
        out.append(dict(name=f"chain of {k} {label}", work="kinematics", n=n, mbplanar_us=1e6 * t / n,
                        closed_form_us=None, fsolve_us=None, numpy_us=1e6 * t_np / n, backend=BEST,
                        build_s=t_build, engine_s=t_engine))
        print(f"  k = {k:3d}: {1e6 * t / n:8.2f} µs/position ({1e6 * t / n / k:.2f} per group; numpy "
              f"{1e6 * t_np / n:.2f}), engine {t_engine:.2f} s, + atlas and first sweeps {t_build - t_engine:.2f} s")
    if len(ks) > 1:
        slopes = {b: float(np.polyfit(np.log(ks), np.log(times[b]), 1)[0]) for b in BACKENDS}
        print(f"  time per position ∝ k^{slopes[BEST]:.2f} over k = {ks[0]}…{ks[-1]} (numpy k^{slopes['numpy']:.2f})")
        return slopes


def check_targets(cases, slopes, slopes4):
    """Issue 7's targets against this run: (target, value, limit, met)."""
    def us(name, work):
        return next((c["mbplanar_us"] for c in cases if c["name"] == name and c["work"] == work), None)

    fourbar = next((c for c in cases if c["name"] == "fourbar" and c["work"] == "kinematics"), None)
    big = max((c for c in cases if c["work"] == "kinematics, scaling in N"), key=lambda c: c["n"], default={})
    found = [("four-bar kinematics / closed form", fourbar and fourbar["mbplanar_us"] / fourbar["closed_form_us"], 8.0),
             ("shaper with reactions, µs/position", us("shaper", "reactions"), 1.5),
             ("six-bar press with reactions, µs/position", us("six_bar_press", "reactions"), 1.5),
             ("class IV model with reactions, µs/position", us("class4_group", "reactions"), 3.0),
             ("one position, worst of three models, µs",
              max((c["mbplanar_us"] for c in cases if c["work"] == "one position"), default=None), 50.0),
             ("mbplanar solve end to end, s", (us("shaper", "mbplanar solve (CLI, end to end)") or 0) / 1e6 or None, 0.5),
             (f"shaper sweep of {big.get('n')} positions, peak MB", big.get("peak_MB"), 2048.0),
             ("time per position vs chained dyads, exponent", slopes and slopes[BEST], 1.1),
             ("time per position vs chained class IV groups, exponent", slopes4 and slopes4[BEST], 1.1)]
    return [dict(target=t, value=v, limit=lim, met=v is not None and v <= lim) for t, v, lim in found]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small sizes, few repeats (smoke run)")
    ap.add_argument("--json", metavar="FILE", nargs="?", const="-", help="write the cases as JSON ('-': stdout)")
    ap.add_argument("--study", action="store_true", help="only the design-study cases (benchmarks/study.py)")
    args = ap.parse_args(argv)
    if args.study:  # design batches and Dask: their own script, sizes and JSON
        import study
        study.main(["--quick"] if args.quick else [])
        return 0
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
    slope = scaling_groups(dyad_chain, "dyads", [1, 2, 4] if quick else [1, 2, 4, 8, 16, 32], n, repeats, cases)
    print("scaling with mechanism size (a crank and k class IV groups):")
    slope4 = scaling_groups(class4_chain, "class IV groups", [1, 2, 4] if quick else [1, 2, 4, 8, 16, 32], n,
                            repeats, cases)
    targets = check_targets(cases, slope, slope4)
    print(f"targets of issue 7 (backend {BEST}):")
    for t in targets:
        value = "—" if t["value"] is None else f"{t['value']:.3g}"
        print(f"  {'met ' if t['met'] else 'MISS'}  {t['target']}: {value} (≤ {t['limit']:g})")
    if args.json:
        doc = dict(machine=dict(cpu=platform.processor() or platform.machine(), cpus=os.cpu_count(),
                                python=platform.python_version(), numpy=np.__version__,
                                numba=sys.modules["numba"].__version__ if "numba" in BACKENDS else None),
                   backends=BACKENDS, builds=[dict(name=b[0], build_s=b[1], atlas_s=b[2]) for b in builds],
                   chain_exponent=slope and slope[BEST], class4_chain_exponent=slope4 and slope4[BEST],
                   chain_exponents=slope, class4_chain_exponents=slope4, targets=targets, cases=cases)
        text = json.dumps(doc, indent=1)
        if args.json == "-":
            print(text)
        else:
            Path(args.json).write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
