"""Path generation: a four-bar whose coupler curve passes near untimed target points, by a global
search over batches of designs (scipy's differential evolution, the whole population scored in one
call by `batch.fourbar_coupler_paths`) and a local least-squares refinement in which every target
point has its own crank angle. The chosen design is written as a model and checked by mbplanar: full
crank turn on one branch, the targets met in order, errors from mbplanar's analysis.

The error of a design is the distance of each target point from the nearest point of the coupler curve
traced by a full crank turn on one assembly branch; the objective is their RMS.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..engine import Engine
from ..errors import ModelError
from ..kinematics import analyse
from ._models import read_design
from .batch import design_toml, fourbar_coupler_paths
from .defects import Defects, check_defects

__all__ = ["PathResult", "synthesise_path"]


@dataclass(frozen=True)
class PathResult:
    """A defect-free four-bar for the target points: `design` (10,) (see `batch.DESIGN_COLUMNS`),
    `errors` (T,) the distances of the targets from the analysed coupler curve, `phi` (T,) the crank
    angles of the nearest curve points, `evaluations` the designs scored, `seed` the random seed."""

    design: np.ndarray
    toml: str
    mechanism: object
    targets: np.ndarray
    errors: np.ndarray
    phi: np.ndarray
    defects: Defects
    evaluations: int
    seconds: float
    seed: int

    @property
    def rms(self) -> float:
        return float(np.sqrt(np.mean(self.errors ** 2)))

    @property
    def max(self) -> float:
        return float(np.max(self.errors))


def _bounds(targets, reach):
    centre = 0.5 * (targets.min(axis=0) + targets.max(axis=0))
    size = float(np.ptp(targets, axis=0).max())
    r = reach * size
    lo = [centre[0] - r, centre[1] - r, centre[0] - r, centre[1] - r, 0.02 * size, 0.05 * size, 0.05 * size, -r, -r, -1]
    hi = [centre[0] + r, centre[1] + r, centre[0] + r, centre[1] + r, size, 2 * r, 2 * r, r, r, 1]
    return list(zip(lo, hi)), size


def _designs(x):
    """Population (10, S) → design rows (S, 10) with the assembly mode ±1 from the last coordinate's sign."""
    d = np.array(x, float).T.copy()
    d[:, 9] = np.where(d[:, 9] >= 0, 1.0, -1.0)
    return d


def _grashof_crank(d, margin: float = 0.01):
    """Penalty ≥ 0: zero for a crank that turns fully (Grashof, the crank the shortest link) with
    s + l ≤ p + q − margin·(p + q), clear of the change-point four-bars (s + l = p + q)."""
    ground = np.hypot(d[:, 2] - d[:, 0], d[:, 3] - d[:, 1])
    links = np.stack([d[:, 4], d[:, 5], d[:, 6], ground], axis=1)
    s, l = links.min(axis=1), links.max(axis=1)
    pq = links.sum(axis=1) - s - l
    grashof = np.maximum(s + l - (1.0 - margin) * pq, 0.0)
    shortest = np.maximum(d[:, 4] - links[:, 1:].min(axis=1), 0.0)
    return grashof + shortest


def _order_penalty(index, samples):
    """Zero when the nearest-sample indices (S, T) go round the curve once in one sense."""
    step = np.diff(np.concatenate([index, index[:, :1]], axis=1), axis=1) % samples
    forward = np.sum(step > samples // 2, axis=1)          # steps that go backwards
    backward = np.sum((step > 0) & (step <= samples // 2), axis=1)
    return np.minimum(forward, backward).astype(float)


def _score(x, targets, phi, size, closed_order=True):
    d = _designs(x)
    _, _, p, ok = fourbar_coupler_paths(d, phi)
    gap = np.hypot(p[:, :, None, 0] - targets[None, None, :, 0], p[:, :, None, 1] - targets[None, None, :, 1])
    gap = np.where(ok[..., None], gap, np.inf)
    index = np.argmin(gap, axis=1)                                     # (S, T)
    near = np.take_along_axis(gap, index[:, None, :], axis=1)[:, 0]
    rms = np.sqrt(np.mean(near ** 2, axis=1))
    penalty = _grashof_crank(d) + (~ok.all(axis=1)) * size
    if closed_order:
        penalty = penalty + 0.1 * size * _order_penalty(index, len(phi))
    return np.where(np.isfinite(rms), rms, 10 * size) + 10 * penalty


def _refine(design, targets, phi0):
    """Least squares in the design's 9 continuous numbers and one crank angle per target."""
    from scipy.optimize import least_squares
    mode = design[9]
    t_count = len(targets)

    def residual(z):
        d = np.r_[z[:9], mode][None]
        _, _, p, ok = fourbar_coupler_paths(d, z[9:])
        r = (p[0] - targets).ravel()
        return np.where(np.repeat(ok[0], 2), r, 1.0)
    z0 = np.r_[design[:9], phi0]
    method = "lm" if 2 * t_count >= 9 + t_count else "trf"          # lm needs as many residuals as unknowns
    res = least_squares(residual, z0, method=method, xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=40 * (9 + t_count))
    return np.r_[res.x[:9], mode], res.x[9:], res.nfev


def _in_order(phi_t) -> bool:
    """The targets' crank angles go round once in one sense (cyclically)."""
    for sense in (1, -1):
        u = np.mod(sense * (phi_t - phi_t[0]), 2 * math.pi)
        if np.all(np.diff(u) > 0):
            return True
    return False


def _nearest_angles(design, targets, samples=3600):
    fine = np.linspace(0.0, 2 * math.pi, samples, endpoint=False)
    _, _, p, _ = fourbar_coupler_paths(design[None], fine)
    return fine[np.argmin(np.hypot(p[0, :, None, 0] - targets[:, 0], p[0, :, None, 1] - targets[:, 1]), axis=0)]


def synthesise_path(targets, seed: int = 0, popsize: int = 20, maxiter: int = 1000, samples: int = 120,
                    reach: float = 2.0, time_limit: float = 40.0, refine: int = 8) -> PathResult:
    """A four-bar whose coupler passes near the untimed `targets` (T, 2), met in their order on one
    branch of a full crank turn.

    Parameters
    ----------
    targets : (T, 2) array
        Target points, in the order along the curve (T ≥ 5).
    seed : int
        Random seed of the global search (the same seed and budget give the same design).
    popsize, maxiter : int
        Differential evolution's population factor and largest number of generations.
    samples : int
        Crank positions per turn in the global stage.
    reach : float
        Pivots and coupler point within `reach` × the targets' span of their middle.
    time_limit : float
        Seconds after which the global stage stops (checked once per generation; the generations run
        so far are counted, so a run is reproducible only when it ends by `maxiter` or convergence).
    refine : int
        How many of the best distinct members of the final population are refined by least squares.
    """
    from scipy.optimize import differential_evolution
    t0 = time.perf_counter()
    targets = np.asarray(targets, float)
    if targets.ndim != 2 or targets.shape[1] != 2 or not np.all(np.isfinite(targets)):
        raise ModelError("target points must be rows of two finite numbers")
    if len(targets) < 5:
        raise ModelError(f"path generation needs at least 5 target points, got {len(targets)}")
    bounds, size = _bounds(targets, reach)
    phi = np.linspace(0.0, 2 * math.pi, samples, endpoint=False)
    count = [0]

    def score(x):
        count[0] += np.shape(x)[1]
        return _score(x, targets, phi, size)

    def stop(*_args, **_kw):
        return time.perf_counter() - t0 > time_limit
    res = differential_evolution(score, bounds, popsize=popsize, maxiter=maxiter, tol=1e-12, seed=seed,
                                 vectorized=True, updating="deferred", polish=False, init="sobol",
                                 mutation=(0.5, 1.0), recombination=0.9, callback=stop)
    order = np.argsort(res.population_energies)
    members = res.population[order]
    found = []
    for x in members[:refine]:
        design = _designs(x[:, None])[0]
        phi0 = _nearest_angles(design, targets)
        for cand, phi_t in ((design, phi0), _refine(design, targets, phi0)[:2]):
            if _grashof_crank(cand[None])[0] > 0 or not _in_order(phi_t):
                continue
            err = np.hypot(*(fourbar_coupler_paths(cand[None], phi_t)[2][0] - targets).T)
            found.append((float(np.sqrt(np.mean(err ** 2))), len(found), cand, phi_t))
    rejected = []
    for _, _, design, phi_t in sorted(found, key=lambda f: f[:2]):      # best first, until one has no defect
        try:
            return _verified(design, targets, phi_t, count[0], time.perf_counter() - t0, seed)
        except ModelError as exc:
            rejected.append(str(exc))
    why = f"; the best had a defect: {rejected[0]}" if rejected else ""
    raise ModelError(f"no feasible design found: no candidate turns fully through the targets in order{why}")


def _verified(design, targets, phi_t, evaluations, seconds, seed) -> PathResult:
    """The design as a model, drawn at the first target's crank angle, checked and measured by mbplanar."""
    text = design_toml(design, float(phi_t[0]))
    mech = read_design(text)
    engine = Engine(mech)
    a, b, p, ok = fourbar_coupler_paths(design[None], phi_t)
    defects = check_defects(engine, phi_t, {"A": a[0], "B": b[0], "P": p[0]}, full_turn=True,
                            tol=1e-7 * float(np.ptp(targets, axis=0).max()))
    if not defects.ok:
        raise ModelError(defects.describe())
    m = analyse(engine, np.asarray(defects.node_phi))
    errors = np.hypot(*(m.xy[:, m.point("P")] - targets).T)
    return PathResult(design, text, mech, targets, errors, np.asarray(defects.node_phi), defects, evaluations,
                      seconds, seed)
