"""Path generation on two literature targets (untimed): RMS and largest distance of the target points
from the coupler curve of a full crank turn on one branch (mbplanar's analysis of the written model),
the time and the designs scored, 5 seeds each, the median of the seeds against the published design.

Run: PYTHONPATH=. python benchmarks/synth_path.py [--seeds 5] [-o benchmarks/synth_path.json]
The machine may be shared: the load average before and after each target is recorded with the wall
times, and each run's CPU time (this process, all threads) beside them.
"""

import argparse
import json
import os
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
    ap.add_argument("-o", "--output", default="benchmarks/synth_path.json")
    args = ap.parse_args()
    out = {"date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "cpus": os.cpu_count(),
           "settings": "synthesise_path defaults (8 starts × differential evolution 200 generations of 150 "
                       "designs, 60 crank positions per curve, 3 polishes per start)", "runs": {}}
    for name, (points, ref_rms, ref_max) in TARGETS.items():
        runs, load = [], [os.getloadavg()[0]]
        for seed in range(args.seeds):
            t0, c0 = time.perf_counter(), time.process_time()
            try:
                r = synthesise_path(np.array(points, float), seed=seed)
                runs.append({"seed": seed, "rms": r.rms, "max": r.max, "seconds": time.perf_counter() - t0,
                             "cpu_seconds": time.process_time() - c0,
                             "evaluations": r.evaluations, "transmission_deg": r.transmission_deg,
                             "defects": r.defects.as_dict(), "design": r.design.tolist()})
            except Exception as exc:                     # a failed seed is a result too
                runs.append({"seed": seed, "error": str(exc), "seconds": time.perf_counter() - t0})
            print(name, {k: v for k, v in runs[-1].items() if k not in ("design", "defects")}, flush=True)
        load.append(os.getloadavg()[0])
        ok = [x for x in runs if "rms" in x]
        med = (lambda key: float(np.median([x[key] for x in ok])) if ok else None)
        out["runs"][name] = {"reference_rms": ref_rms, "reference_max": ref_max, "runs": runs,
                             "median_rms": med("rms"), "median_max": med("max"), "median_seconds": med("seconds"),
                             "median_cpu_seconds": med("cpu_seconds"), "median_evaluations": med("evaluations"),
                             "load_average": load}
        print(name, "median RMS", med("rms"), "max", med("max"), "s", med("seconds"), flush=True)
    with open(args.output, "w", encoding="utf-8") as fh:
        json.dump(out, fh, indent=1)


if __name__ == "__main__":
    main()
