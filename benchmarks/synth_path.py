"""Path generation on two literature targets (untimed): RMS and largest distance of the target points
from the coupler curve of a full crank turn on one branch, the time and the designs scored, 5 seeds each.

Run: PYTHONPATH=. python benchmarks/synth_path.py [--seeds 5] [--time-limit 40] [-o benchmarks/synth_path.json]
"""

import argparse
import json
import time

import numpy as np

from mbplanar.synthesis.path import synthesise_path

TARGETS = {
    # Bulatović et al. 2016, 18 points; the published design reaches RMS 0.0166, max 0.0382 by this measure
    "bulatovic18": ([(0.5, 1.1), (0.4, 1.1), (0.3, 1.1), (0.2, 1.0), (0.1, 0.9), (0.05, 0.75), (0.02, 0.6),
                     (0, 0.5), (0, 0.4), (0.03, 0.3), (0.1, 0.25), (0.15, 0.2), (0.2, 0.3), (0.3, 0.4), (0.4, 0.5),
                     (0.5, 0.7), (0.6, 0.9), (0.6, 1.0)], 0.0166, 0.0382),
    # 12 points; the reference reaches RMS 0.00353, max 0.0074
    "twelve": ([(4.15, 2.21), (4.5, 2.18), (4.53, 1.83), (4.13, 1.68), (3.67, 1.58), (2.96, 1.33), (2.67, 1.06),
                (2.63, 0.82), (2.92, 0.81), (3.23, 1.07), (3.49, 1.45), (3.76, 1.87)], 0.00353, 0.0074),
}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--time-limit", type=float, default=40.0)
    ap.add_argument("-o", "--output", default="benchmarks/synth_path.json")
    args = ap.parse_args()
    out = {"date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "time_limit": args.time_limit, "runs": {}}
    for name, (points, ref_rms, ref_max) in TARGETS.items():
        runs = []
        for seed in range(args.seeds):
            t0 = time.perf_counter()
            try:
                r = synthesise_path(np.array(points, float), seed=seed, time_limit=args.time_limit)
                runs.append({"seed": seed, "rms": r.rms, "max": r.max, "seconds": time.perf_counter() - t0,
                             "evaluations": r.evaluations, "design": r.design.tolist()})
            except Exception as exc:                     # a failed seed is a result too
                runs.append({"seed": seed, "error": str(exc), "seconds": time.perf_counter() - t0})
            print(name, runs[-1], flush=True)
        ok = [x["rms"] for x in runs if "rms" in x]
        out["runs"][name] = {"reference_rms": ref_rms, "reference_max": ref_max, "runs": runs,
                             "median_rms": float(np.median(ok)) if ok else None}
    with open(args.output, "w", encoding="utf-8") as fh:
        json.dump(out, fh, indent=1)


if __name__ == "__main__":
    main()
