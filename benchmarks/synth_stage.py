"""Cost of one generation of the differential evolution of path generation over a limited travel (150
four-bars × 60 crank positions): the closed-form score of `synthesis.path_search.score` (trace,
distances to the targets, penalties) against the
trace alone by the study's generic design batch (`study.batch.design_batch`), compiled (numba) and
numpy, on the same random population of the 18-point target's bounds. Same-run figures; the load
average before and after is printed, since the machine may be shared.

Run: PYTHONPATH=. python benchmarks/synth_stage.py [--repeat 5]
"""

import argparse
import math
import os
import time

import numpy as np

from benchmarks.synth_path import TARGETS
from mbplanar.engine import Engine
from mbplanar.model import parse_model
from mbplanar.study.batch import design_batch
from mbplanar.study.run import load_template
from mbplanar.synthesis.batch import fourbar_coupler_paths
from mbplanar.synthesis.path import _task
from mbplanar.synthesis.path_search import _bounds, _designs, score

# the four-bar as parameters: pivots, crank drawn at 0 rad, coupler at beta (deg); rocker from the pose
FOURBAR = {
    "name": "fourbar_stage", "ground": "0",
    "links": [{"name": "1"}, {"name": "2"}, {"name": "3"}],
    "joints": [
        {"name": "A0", "type": "R", "links": ["0", "1"], "at": ["a0x", "a0y"]},
        {"name": "A", "type": "R", "links": ["1", "2"], "at": {"from": "A0", "length": "a", "angle": 0.0}},
        {"name": "B", "type": "R", "links": ["2", "3"], "at": {"from": "A", "length": "b", "angle": "beta"}},
        {"name": "B0", "type": "R", "links": ["3", "0"], "at": ["b0x", "b0y"]},
    ],
    "points": [{"name": "P", "link": "2", "along": ["A", "B"], "fraction": "m", "offset": "h"}],
    "parameters": {"a0x": 0.0, "a0y": 0.0, "b0x": 1.0, "b0y": 0.0, "a": 0.3, "b": 1.0, "beta": 60.0,
                   "m": 0.5, "h": 0.2},
    "input": {"joint": "A0"},
}


def parameter_rows(d) -> dict:
    """Design rows (S, 10) as the template's parameters (the coupler's angle of the pose at φ = 0)."""
    a, b, _, _ = fourbar_coupler_paths(d, [0.0])
    beta = np.degrees(np.arctan2(b[:, 0, 1] - a[:, 0, 1], b[:, 0, 0] - a[:, 0, 0]))
    return {"a0x": d[:, 0], "a0y": d[:, 1], "b0x": d[:, 2], "b0y": d[:, 3], "a": d[:, 4], "b": d[:, 5],
            "beta": np.where(np.isfinite(beta), beta, 0.0), "m": d[:, 7] / d[:, 5], "h": d[:, 8]}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    task = _task(np.array(TARGETS["bulatovic18"]["points"], float), None, None)
    bounds = np.array(_bounds(task, 2.0))
    size, samples = 150, 60
    x = bounds[:, :1] + np.ptp(bounds, axis=1)[:, None] * np.random.default_rng(0).random((10, size))
    print("load average", os.getloadavg()[0])
    t0 = time.perf_counter()
    for _ in range(args.repeat):
        score(x, task, samples)
    closed = (time.perf_counter() - t0) / args.repeat
    print(f"closed-form score: {closed * 1e3:.1f} ms per generation ({size} designs × {samples} positions)")
    values = parameter_rows(_designs(x))
    grid = np.linspace(0.0, 2 * math.pi, samples, endpoint=False)
    template = load_template(FOURBAR)
    for backend in ("numba", "numpy"):
        engine = Engine(parse_model(template.bind(), source=template.source), backend=backend)

        def generation():
            batch = design_batch(template, values, engine=engine)
            with np.errstate(all="ignore"):
                return batch.solve(batch.geometry.phi0[:, None] + grid, exact_limits=False, fallback=False,
                                   points=["A", "B", "P"], accelerations=False)
        generation()                                   # compile (numba) outside the timing
        t0 = time.perf_counter()
        for _ in range(args.repeat):
            m = generation()
        took = (time.perf_counter() - t0) / args.repeat
        print(f"generic design batch ({backend}): {took * 1e3:.1f} ms per generation, {took / closed:.1f}× the "
              f"closed-form score; valid positions {m.valid.mean():.2f}")
    print("load average", os.getloadavg()[0])


if __name__ == "__main__":
    main()
