"""Path generation: a four-bar whose coupler curve passes near target points.

Targets are untimed (each point anywhere on the curve, met in their order) or timed (each point with
the crank's advance from the first target). The search runs `starts` independent starts, each a global
stage (scipy's differential evolution, the whole population scored in one call over a batch of
designs, `batch.fourbar_coupler_paths`) and a least-squares polish (scipy's `least_squares`) of the
best distinct members of its final population. The starts are independent, seeded from one seed, so
they run one after the other here or one task each on a Dask cluster with equal results.

The error of an untimed target is its distance from the nearest point of the coupler curve traced on
one assembly branch (the global stage measures it on a polyline of the curve, the polish with one crank
angle per target, which converges to the foot of the perpendicular); of a timed target, its distance
from the coupler point at its crank angle. The objective is their RMS. Constraints
(`constraints.PathConstraints`) enter the global stage as penalties and the polish as weighted
residuals, and are checked exactly afterwards. The chosen design is written as a model and checked by
mbplanar: the defects (circuit, branch, order, full turn), the errors and the transmission angles are
mbplanar's analysis of that model.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..engine import Engine
from ..errors import ModelError
from ..kinematics import analyse
from ._models import read_design
from .batch import design_toml, fourbar_coupler_paths
from .constraints import PathConstraints, fourbar_violations, transmission_angles
from .defects import Defects, check_defects
from .starts import run_starts

__all__ = ["PathOutcome", "PathResult", "PathTask", "synthesise_path", "nearest_on_polyline"]

TWO_PI = 2.0 * math.pi
WEIGHT = 10.0  # penalty per unit of violation (lengths), global stage and polish


@dataclass(frozen=True)
class PathTask:
    """What to synthesise: `targets` (T, 2); `timing` None (untimed) or (T,) the crank's advance from
    the first target to each (rad, counter-clockwise positive); `constraints`."""

    targets: np.ndarray
    timing: np.ndarray | None = None
    constraints: PathConstraints = field(default_factory=PathConstraints)

    @property
    def size(self) -> float:
        return float(np.ptp(self.targets, axis=0).max())


@dataclass(frozen=True)
class PathOutcome:
    """What every path generator returns: the written model (`toml`, `mechanism`), the `targets` (T, 2)
    and their `errors` (T,) from mbplanar's analysis of that model, `phi` (T,) the input at each target
    (the nearest curve point's, or the timed one's), the `defects` check, the smallest transmission angle
    over the travel `transmission_deg` (nan when not defined), the `constraints`, and the search's
    `evaluations`, `seconds`, `seed` and `starts`."""

    toml: str
    mechanism: object
    targets: np.ndarray
    errors: np.ndarray
    phi: np.ndarray
    defects: Defects
    evaluations: int
    seconds: float
    seed: int
    starts: int
    timed: bool
    transmission_deg: float
    constraints: PathConstraints

    @property
    def rms(self) -> float:
        return float(np.sqrt(np.mean(self.errors ** 2)))

    @property
    def max(self) -> float:
        return float(np.max(self.errors))


@dataclass(frozen=True)
class PathResult(PathOutcome):
    """A defect-free four-bar: `design` (10,) (see `batch.DESIGN_COLUMNS`), `ratio` its longest over
    shortest link; the coupler point is `point` ("P") of the model."""

    design: np.ndarray = None
    ratio: float = float("nan")
    point: str = "P"


# -- geometry of the search ---------------------------------------------------------------------------
def _bounds(task: PathTask, reach: float) -> list:
    """Bounds of the global stage: pivots and coupler point within `reach` × the targets' span of their
    middle (a pivot with a region: that box), lengths up to 2 × reach × span, mode sign, (timed) phase."""
    t = task.targets
    centre = 0.5 * (t.min(axis=0) + t.max(axis=0))
    size = task.size
    r = reach * size
    lo = [centre[0] - r, centre[1] - r, centre[0] - r, centre[1] - r, 0.02 * size, 0.05 * size, 0.05 * size, -r, -r, -1]
    hi = [centre[0] + r, centre[1] + r, centre[0] + r, centre[1] + r, size, 2 * r, 2 * r, r, r, 1]
    for name, col in (("A0", 0), ("B0", 2)):
        box = task.constraints.box(name)
        if box is not None:
            lo[col:col + 2], hi[col:col + 2] = list(box[0]), list(box[1])
    if task.timing is not None:
        lo.append(0.0)
        hi.append(TWO_PI)
    return list(zip(lo, hi))


def _designs(x) -> np.ndarray:
    """Population (V, S) → design rows (S, 10), the assembly mode ±1 from the 10th coordinate's sign."""
    d = np.array(np.asarray(x, float)[:10].T)
    d[:, 9] = np.where(d[:, 9] >= 0, 1.0, -1.0)
    return d


def nearest_on_polyline(p, ok, targets, closed: bool = True, dtype=np.float64):
    """Distances (S, T) of targets (T, 2) from the polylines p (S, P, 2) through the samples where ok
    (S, P) (a segment counts when both its ends close), and the index (S, T) of the nearest segment's
    start; inf where no segment closes. `dtype` float32 halves the global stage's cost (coordinates
    are taken about the targets' mean first, so single precision keeps ~1e-7 of their span)."""
    q = np.roll(p, -1, axis=1) if closed else p[:, 1:]
    p0 = p if closed else p[:, :-1]
    good = ok & np.roll(ok, -1, axis=1) if closed else ok[:, :-1] & ok[:, 1:]
    c = targets.mean(axis=0)
    ex = (q[..., 0] - p0[..., 0]).astype(dtype)[..., None]                     # (S, P, 1)
    ey = (q[..., 1] - p0[..., 1]).astype(dtype)[..., None]
    with np.errstate(invalid="ignore", over="ignore"):
        inv = 1.0 / np.maximum(ex * ex + ey * ey, dtype(1e-30))
        wx = (targets[:, 0] - c[0]).astype(dtype) - (p0[..., 0] - c[0]).astype(dtype)[..., None]   # (S, P, T)
        wy = (targets[:, 1] - c[1]).astype(dtype) - (p0[..., 1] - c[1]).astype(dtype)[..., None]
        s = wx * ex
        s += wy * ey
        s *= inv
        np.clip(s, 0.0, 1.0, out=s)
        wx -= s * ex
        wy -= s * ey
        wx *= wx
        wy *= wy
        wx += wy
    wx[~(good & np.all(np.isfinite(p0), axis=-1))] = np.inf
    wx[np.isnan(wx)] = np.inf
    index = np.argmin(wx, axis=1)
    return np.sqrt(np.take_along_axis(wx, index[:, None, :], axis=1)[:, 0].astype(float)), index


def nearest_on_model(engine, point: str, targets, motion, iterations: int = 8) -> np.ndarray:
    """Distances (T,) of targets (T, 2) from the path of `point` analysed by mbplanar: the nearest
    position of `motion` (a dense sweep of `engine`) brackets each, and Newton's method on
    (P − target)·dP/dφ = 0 with mbplanar's analogues dP/dφ, d²P/dφ² (all targets at once, kept within
    the bracket) finds the foot of the perpendicular."""
    grid = motion.phi[:, 0]
    k = motion.point(point)
    p = motion.xy[:, k]
    i = np.argmin(np.hypot(p[:, None, 0] - targets[:, 0], p[:, None, 1] - targets[:, 1]), axis=0)
    lo, hi = grid[np.maximum(i - 1, 0)], grid[np.minimum(i + 1, len(grid) - 1)]
    x = grid[i]
    for _ in range(iterations):
        m = analyse(engine, x)
        d, v, a = m.xy[:, k] - targets, m.vq[:, k], m.aq[:, k]
        slope = np.sum(v * v, axis=1) + np.sum(d * a, axis=1)
        step = np.where(slope > 0, -np.sum(d * v, axis=1) / np.where(slope > 0, slope, 1.0), 0.0)
        x = np.clip(x + step, np.minimum(lo, hi), np.maximum(lo, hi))
    m = analyse(engine, x)
    return np.minimum(np.hypot(*(m.xy[:, k] - targets).T), np.hypot(*(p[i] - targets).T))


def _order_penalty(index, samples: int) -> np.ndarray:
    """Zero when the nearest-sample indices (S, T) go round the curve once in one sense (cyclically)."""
    step = np.diff(np.concatenate([index, index[:, :1]], axis=1), axis=1) % samples
    back = np.sum(step > samples // 2, axis=1)
    ahead = np.sum((step > 0) & (step <= samples // 2), axis=1)
    return np.minimum(back, ahead).astype(float)


def _arc_penalty(index, ok) -> np.ndarray:
    """Number of extra arcs (runs of closing samples) the targets' nearest samples (S, T) lie on."""
    start = ok & ~np.roll(ok, 1, axis=1)
    run = np.cumsum(start, axis=1)
    wraps = ok[:, 0] & ok[:, -1] & start.any(axis=1)
    run = np.where(wraps[:, None] & (run == run[:, -1:]), 0, run)
    arcs = np.take_along_axis(run, index, axis=1)
    return np.array([len(np.unique(r)) - 1 for r in arcs], float)


# -- the global stage -----------------------------------------------------------------------------------
def _travel(task: PathTask, x_phase, samples: int) -> np.ndarray:
    """Crank angles sampled over the travel: the full turn (P,), or (S, P) from a timed design's phase."""
    c = task.constraints
    if task.timing is None or c.full_turn:
        return np.linspace(0.0, TWO_PI, samples, endpoint=False)
    lo, hi = min(0.0, task.timing.min()), max(0.0, task.timing.max())
    return x_phase[:, None] + np.linspace(lo, hi, samples)[None, :]


def _closes(task: PathTask) -> bool:
    """Whether the whole sampled travel must close: a full turn, or a timed travel between targets
    (untimed targets without a full turn need only the arc that holds them)."""
    return task.constraints.full_turn or task.timing is not None


def score(x, task: PathTask, samples: int) -> np.ndarray:
    """Objective of a population x (V, S): RMS error + WEIGHT × (violations + order/arc defects)."""
    d = _designs(x)
    size = task.size
    phase = np.asarray(x, float)[10] if task.timing is not None else None
    travel = _travel(task, phase, samples)
    a, b, p, ok = fourbar_coupler_paths(d, travel)
    penalty = fourbar_violations(task.constraints, d, a, b, ok, size, closure=_closes(task)).sum(axis=1)
    if task.timing is None:
        near, index = nearest_on_polyline(p, ok, task.targets, closed=True, dtype=np.float32)
        penalty = penalty + 0.1 * size * _order_penalty(index, samples)
        if not task.constraints.full_turn:
            penalty = penalty + 0.1 * size * _arc_penalty(index, ok)
    else:
        _, _, pt, okt = fourbar_coupler_paths(d, phase[:, None] + task.timing[None, :])
        near = np.where(okt, np.hypot(*np.moveaxis(pt - task.targets, -1, 0)), np.inf)
    rms = np.sqrt(np.mean(near ** 2, axis=1))
    return np.where(np.isfinite(rms), rms, 10 * size) + WEIGHT * penalty


# -- the polish -----------------------------------------------------------------------------------------
def _unknowns(design, phi_t, task: PathTask) -> np.ndarray:
    """The polish's unknowns: the design's 9 numbers, then one crank angle per target (untimed) or the
    crank angle at the first target (timed)."""
    return np.r_[design[:9], phi_t if task.timing is None else phi_t[:1]]


def _angles(z, task: PathTask) -> np.ndarray:
    """Crank angles (K, T) at the targets of unknowns z (K, n)."""
    return z[:, 9:] if task.timing is None else z[:, 9:10] + task.timing[None, :]


def _residuals(z, mode: float, task: PathTask, samples: int, weight: float) -> np.ndarray:
    """Residuals (K, 2T + 4) of unknowns z (K, n): target misses (x, y) and weighted violations."""
    d = np.column_stack([z[:, :9], np.full(len(z), mode)])
    phi_t = _angles(z, task)
    _, _, p, ok = fourbar_coupler_paths(d, phi_t)
    miss = np.where(ok[..., None], p - task.targets, task.size).reshape(len(z), -1)
    travel = _travel(task, z[:, 9], samples) if task.timing is not None else np.linspace(0.0, TWO_PI, samples, endpoint=False)
    a, b, _, okt = fourbar_coupler_paths(d, travel)
    v = fourbar_violations(task.constraints, d, a, b, okt, task.size, closure=_closes(task))
    return np.column_stack([miss, weight * v])


def _polish_bounds(task: PathTask, n: int):
    lo, hi = np.full(n, -np.inf), np.full(n, np.inf)
    for name, col in (("A0", 0), ("B0", 2)):
        box = task.constraints.box(name)
        if box is not None:
            lo[col:col + 2], hi[col:col + 2] = box
    return lo, hi


def polish(design, phi_t, task: PathTask, samples: int) -> tuple[np.ndarray, np.ndarray, int]:
    """Least squares from `design` (10,) with crank angles phi_t (T,) at the targets: the polished design,
    its angles at the targets and the residual evaluations (the Jacobian's columns count too). The
    penalty weight grows ×100 twice while the polished design does not meet the constraints exactly."""
    from scipy.optimize import least_squares
    mode = float(design[9])
    z = _unknowns(design, phi_t, task)
    lo, hi = _polish_bounds(task, len(z))
    z = np.clip(z, lo + 1e-12 * task.size, hi - 1e-12 * task.size)
    method = "trf" if np.isfinite(np.r_[lo, hi]).any() else "lm"   # MINPACK's LM when nothing bounds
    if method == "lm":
        lo, hi = -np.inf, np.inf
    count = 0
    for weight in (WEIGHT, 100 * WEIGHT, 1e4 * WEIGHT):
        def fun(u):
            return _residuals(u[None], mode, task, samples, weight)[0]

        def jac(u):
            h = 1e-7 * np.maximum(1.0, np.abs(u))
            rows = np.vstack([u, u + np.diag(h)])
            r = _residuals(rows, mode, task, samples, weight)
            return ((r[1:] - r[0]) / h[:, None]).T
        res = least_squares(fun, z, jac=jac, bounds=(lo, hi), method=method, x_scale="jac",
                            xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=12 * len(z))
        z = res.x
        count += res.nfev * (len(z) + 1)
        if feasible(*_positive(np.r_[z[:9], mode], _angles(z[None], task)[0]), task):
            break
    design, phi_t = _positive(np.r_[z[:9], mode], _angles(z[None], task)[0])
    return design, phi_t, count


def _positive(design, phi_t):
    """The same four-bar with positive lengths: a negative crank is the crank turned by π, a negative
    coupler the coupler frame turned by π (u, v → −u, −v); the rocker enters squared."""
    d, phi_t = design.copy(), phi_t.copy()
    if d[4] < 0:
        d[4], phi_t = -d[4], phi_t + math.pi
    if d[5] < 0:
        d[5], d[7], d[8] = -d[5], -d[7], -d[8]
    d[6] = abs(d[6])
    return d, phi_t


def _in_order(phi_t) -> bool:
    """The targets' crank angles go round at most once in one sense (cyclically)."""
    for sense in (1, -1):
        u = np.mod(sense * (phi_t - phi_t[0]), TWO_PI)
        if np.all(np.diff(u) > 0):
            return True
    return False


def _nearest_angles(design, targets, samples: int = 3600) -> np.ndarray:
    fine = np.linspace(0.0, TWO_PI, samples, endpoint=False)
    _, _, p, ok = fourbar_coupler_paths(design[None], fine)
    gap = np.where(ok[0][:, None], np.hypot(p[0, :, None, 0] - targets[:, 0], p[0, :, None, 1] - targets[:, 1]), np.inf)
    return fine[np.argmin(gap, axis=0)]


def feasible(design, phi_t, task: PathTask, samples: int = 720) -> bool:
    """The design meets the constraints exactly (no margin) on `samples` crank angles of its travel and
    reaches untimed targets in order."""
    c = task.constraints
    d = design[None]
    if task.timing is None and not _in_order(phi_t):
        return False
    if c.full_turn:
        travel = np.linspace(0.0, TWO_PI, samples, endpoint=False)
    else:
        lo, hi = float(np.min(phi_t)), float(np.max(phi_t))
        if task.timing is None:  # untimed: the arc from the first to the last target in their sense
            sense = 1 if np.all(np.diff(np.mod(phi_t - phi_t[0], TWO_PI)) > 0) else -1
            lo, hi = sorted((phi_t[0], phi_t[0] + sense * np.mod(sense * (phi_t[-1] - phi_t[0]), TWO_PI)))
        travel = np.linspace(lo, hi, samples)
    a, b, _, ok = fourbar_coupler_paths(d, travel)
    v = fourbar_violations(c, d, a, b, ok, task.size, margin=0.0)
    return bool(np.all(v[0] <= 1e-12 * task.size))


# -- one start ------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class _Setup:
    task: PathTask
    popsize: int
    generations: int
    samples: int
    reach: float
    keep: int


def run_start(setup: _Setup, seed: int) -> tuple[list, int]:
    """One start: differential evolution from `seed`, then the polish of its `keep` best distinct
    members. Returns the feasible candidates [(rms, design (10,), phi_t (T,))] and the evaluations."""
    from scipy.optimize import differential_evolution
    task = setup.task
    count = [0]

    def objective(x):
        count[0] += np.shape(x)[1]
        return score(x, task, setup.samples)
    res = differential_evolution(objective, _bounds(task, setup.reach), popsize=setup.popsize,
                                 maxiter=setup.generations, tol=0.0, atol=0.0, seed=seed, vectorized=True,
                                 updating="deferred", polish=False, init="sobol", mutation=(0.5, 1.0),
                                 recombination=0.9)
    order = np.argsort(res.population_energies, kind="stable")
    found, seen = [], []
    for x in res.population[order]:
        if len(seen) >= setup.keep:
            break
        design = _designs(x[:, None])[0]
        if any(np.allclose(design, s, rtol=0, atol=1e-3 * task.size) for s in seen):
            continue
        seen.append(design)
        phi0 = _nearest_angles(design, task.targets) if task.timing is None else x[10] + task.timing
        polished = polish(design, phi0, task, setup.samples)
        count[0] += polished[2]
        for cand, phi_t in ((design, phi0), polished[:2]):
            if feasible(cand, phi_t, task):
                err = _errors(cand, phi_t, task)
                found.append((float(np.sqrt(np.mean(err ** 2))), cand, phi_t))
    return found, count[0]


def _errors(design, phi_t, task: PathTask) -> np.ndarray:
    _, _, p, _ = fourbar_coupler_paths(design[None], phi_t)
    return np.hypot(*(p[0] - task.targets).T)


def start_seeds(seed: int, starts: int) -> list[int]:
    """The seeds of `starts` independent starts drawn from one `seed` (numpy's SeedSequence.spawn)."""
    return [int(s.generate_state(1)[0]) for s in np.random.SeedSequence(seed).spawn(starts)]


# -- the whole search ---------------------------------------------------------------------------------
def _task(targets, timing, constraints) -> PathTask:
    targets = np.asarray(targets, float)
    if targets.ndim != 2 or targets.shape[1] != 2 or not np.all(np.isfinite(targets)):
        raise ModelError("target points must be rows of two finite numbers")
    if len(targets) < 5:
        raise ModelError(f"path generation needs at least 5 target points, got {len(targets)}")
    if np.ptp(targets, axis=0).max() <= 0:
        raise ModelError("the target points all coincide")
    if timing is not None:
        timing = np.asarray(timing, float)
        if timing.shape != (len(targets),) or not np.all(np.isfinite(timing)):
            raise ModelError(f"timed targets need one finite input value per target point ({len(targets)})")
        timing = timing - timing[0]
        if np.any(np.diff(timing) == 0):
            raise ModelError("timed targets: two target points share one input value")
    return PathTask(targets, timing, constraints or PathConstraints())


def synthesise_path(targets, *, timing=None, constraints: PathConstraints | None = None, seed: int = 0,
                    starts: int = 8, popsize: int = 15, generations: int = 200, samples: int = 60,
                    reach: float = 2.0, keep: int = 3, client=None, progress=None) -> PathResult:
    """A defect-free four-bar whose coupler point passes near `targets`.

    Parameters
    ----------
    targets : (T, 2) array
        Target points (T ≥ 5), in their order along the curve.
    timing : (T,) array, optional
        Timed targets: the crank's angle at each target (rad); only the advances from the first
        target matter (the crank's angle at the first target is a design variable). None: untimed.
    constraints : PathConstraints, optional
        Full turn (default), smallest transmission angle, largest link ratio, pivot regions.
    seed : int
        Random seed: the same seed and settings give the same design, serial or on Dask.
    starts : int
        Independent starts (global stage + polish each), seeded from `seed`.
    popsize, generations : int
        Differential evolution's population factor and number of generations per start.
    samples : int
        Crank positions per turn (a polyline of the coupler curve) in the global stage.
    reach : float
        Pivots and coupler point within `reach` × the targets' span of their middle.
    keep : int
        Distinct best members of each start's final population that are polished.
    client : dask.distributed.Client, optional
        Run the starts as tasks on this client (one task per start).
    progress : callable, optional
        progress(done, total) as starts finish.
    """
    t0 = time.perf_counter()
    task = _task(targets, timing, constraints)
    if starts < 1 or popsize < 5 or generations < 1 or samples < 12 or keep < 1:
        raise ModelError("path generation needs starts ≥ 1, popsize ≥ 5, generations ≥ 1, samples ≥ 12, keep ≥ 1")
    setup = _Setup(task, popsize, generations, samples, reach, keep)
    results = run_starts(run_start, setup, start_seeds(seed, starts), client, progress)
    evaluations = sum(r[1] for r in results)
    found = [(rms, k, i, d, phi) for k, r in enumerate(results) for i, (rms, d, phi) in enumerate(r[0])]
    rejected = []
    for _, _, _, design, phi_t in sorted(found, key=lambda f: f[:3]):      # best first, until one has no defect
        try:
            return _verified(design, phi_t, task, evaluations, time.perf_counter() - t0, seed, starts)
        except ModelError as exc:
            rejected.append(str(exc))
    why = f"; the best had a defect: {rejected[0]}" if rejected else ""
    raise ModelError("no feasible design found: no candidate meets the constraints and reaches the targets "
                     f"in order{why}")


def _verified(design, phi_t, task: PathTask, evaluations, seconds, seed, starts) -> PathResult:
    """The design as a model drawn at the first target's crank angle, checked and measured by mbplanar."""
    targets, c = task.targets, task.constraints
    text = design_toml(design, float(phi_t[0]))
    mech = read_design(text)
    engine = Engine(mech)
    a, b, p, ok = fourbar_coupler_paths(design[None], phi_t)
    defects = check_defects(engine, phi_t, {"A": a[0], "B": b[0], "P": p[0]}, full_turn=c.full_turn,
                            tol=1e-7 * task.size)
    if not defects.ok:
        raise ModelError(defects.describe())
    node_phi = np.asarray(defects.node_phi)
    m = analyse(engine, node_phi)
    errors = np.hypot(*(m.xy[:, m.point("P")] - targets).T)
    span = TWO_PI if c.full_turn else defects.sense * (node_phi[-1] - node_phi[0])
    dense = analyse(engine, node_phi[0] + np.linspace(0.0, span, 3601))
    xy = {k: dense.xy[:, dense.point(k)] for k in ("A", "B", "B0", "P")}
    if task.timing is None:  # the nearest point of the analysed curve, where nearer than the polished foot
        errors = np.minimum(errors, nearest_on_model(engine, "P", targets, dense))
    mu = float(np.degrees(transmission_angles(xy["A"], xy["B"], xy["B0"]).min()))
    if c.min_transmission_deg is not None and mu < c.min_transmission_deg - 1e-9:
        raise ModelError(f"transmission angle {mu:.4f}° below the bound {c.min_transmission_deg}°")
    links = [design[4], design[5], design[6], float(np.hypot(*(design[2:4] - design[0:2])))]
    return PathResult(text, mech, targets, errors, node_phi, defects, evaluations, seconds, seed, starts,
                      task.timing is not None, mu, c, design=design, ratio=max(links) / min(links))
