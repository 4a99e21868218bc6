"""One start of four-bar path generation: candidate designs, each polished and assessed.

A crank that turns fully (the default) is searched by the shape screen (`path_screen`): Sobol samples
of crank-rocker shapes, each placed on the targets by its best similarity, the best of them measured
by their true nearest-point distances, and the best distinct ones polished by least squares
(`path_polish`). A limited travel (no full turn) is searched by differential evolution over design
batches (scipy's, the whole population scored in one call) before the same polish.

Every candidate comes back assessed: its RMS error, whether it meets the constraints exactly, and how
it meets the targets' order (`path_order`, with the tolerance for targets met a hair out of order).
A start is a function of its seed alone (and of the budget, when one is given), so that starts give
the same candidates serially or on a Dask cluster.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from .batch import fourbar_coupler_paths
from .constraints import PathConstraints, fourbar_violations
from .path_order import OrderReport, order_report
from .path_polish import (constraint_bounds, least_squares_fit, meets, polish_timed, polish_untimed,
                          positive_lengths)
from .path_screen import (arc_resample, placed_designs, procrustes_screen, sample_shapes, target_offsets,
                          traced)

__all__ = ["PathTask", "Candidate", "Setup", "run_start", "nearest_on_polyline", "positive_lengths"]

TWO_PI = 2.0 * math.pi
WEIGHT = 10.0           # penalty per unit of violation (lengths) in the differential evolution's score
CURVE = 64              # points of a curve in the screen (crank positions, then arc-length points)
RESCORED = 256          # screened designs measured by their true nearest-point distances
RESCORE_SAMPLES = 96    # crank positions of the polyline they are measured on
CHUNK = 2048            # shapes screened at once (a budget is looked at between chunks)
POLISH_EVALUATIONS = 60     # residual evaluations of a start's polish, per penalty weight
DEEP_EVALUATIONS = 400      # ... and of the final polish of the best few
DEEPENED = 3                # distinct best candidates polished again at the end


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

    def relaxed(self) -> "PathTask":
        """The same task without the transmission-angle and link-ratio bounds."""
        c = self.constraints
        return PathTask(self.targets, self.timing, PathConstraints(c.full_turn, None, None, c.pivots,
                                                                   c.transmission_joints))


@dataclass(frozen=True)
class Candidate:
    """A polished design: `rms`, `design` (10,), `phi` (T,) the crank angle at each target, `meets`
    the constraints exactly, `order` how it meets the targets' order (None for timed targets), `pool`
    "main" (under the task's constraints) or "relaxed" (without the transmission and ratio bounds)."""

    rms: float
    design: np.ndarray
    phi: np.ndarray
    meets: bool
    order: OrderReport | None
    pool: str = "main"

    @property
    def rank(self) -> tuple:
        """Sort key: in order and within the constraints first, then the error plus the length of the
        steps back beyond the order tolerance."""
        excess = 0.0 if self.order is None else self.order.excess
        return (0 if self.meets and excess == 0.0 else 1 if self.meets else 2, self.rms + excess)


@dataclass(frozen=True)
class Setup:
    """Everything a start needs (plain data, so that it travels to Dask workers): the task, the shape
    screen's `shapes` and `keep` (designs polished per start), whether to search the `relaxed` pool
    too, the differential evolution's `popsize`, `generations`, `samples`, `reach` (limited travel), and
    the seconds `budget` of the start (None: no time limit)."""

    task: PathTask
    shapes: int = 8192
    keep: int = 6
    relaxed: bool = False
    popsize: int = 15
    generations: int = 200
    samples: int = 60
    reach: float = 2.0
    budget: float | None = None


# -- helpers -------------------------------------------------------------------------------------------
def nearest_on_polyline(p, ok, targets, closed: bool = True, dtype=np.float64):
    """Distances (S, T) of targets (T, 2) from the polylines p (S, P, 2) through the samples where ok
    (S, P) (a segment counts when both its ends close), the index (S, T) of the nearest segment's start
    and the fraction (S, T) along it; inf where no segment closes. `dtype` float32 halves the cost
    (coordinates are taken about the targets' mean first, so single precision keeps ~1e-7 of their span)."""
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
    near = np.sqrt(np.take_along_axis(wx, index[:, None, :], axis=1)[:, 0].astype(float))
    return near, index, np.take_along_axis(s, index[:, None, :], axis=1)[:, 0].astype(float)


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


def _in_order(phi_t) -> bool:
    """The targets' crank angles go round at most once in one sense (cyclically)."""
    for sense in (1, -1):
        u = np.mod(sense * (phi_t - phi_t[0]), TWO_PI)
        if np.all(np.diff(u) > 0):
            return True
    return False


class _Clock:
    """The start's budget: `over()` once its seconds are spent (never without a budget)."""

    def __init__(self, budget):
        self.end = None if budget is None else time.perf_counter() + budget

    def over(self) -> bool:
        return self.end is not None and time.perf_counter() > self.end


# -- assessing a candidate ------------------------------------------------------------------------------
def assess(design, phi, errors, task: PathTask, pool: str = "main", samples: int = 720) -> Candidate:
    """A polished design's `Candidate`: constraints met exactly, order along the curve (a full turn:
    arc-length positions with the tolerance; a limited travel: the crank angles, strictly)."""
    c = task.constraints
    size = task.size
    rms = float(np.sqrt(np.mean(np.asarray(errors) ** 2)))
    if task.timing is not None:
        travel = _timed_travel(task, np.array([phi[0]]))
        return Candidate(rms, design, phi, meets(c, design, size, travel), None, pool)
    if c.full_turn:
        ring = np.linspace(0.0, TWO_PI, samples, endpoint=False)
        _, _, p, _ = fourbar_coupler_paths(design[None], ring)
        seg = np.hypot(*(np.roll(p[0], -1, axis=0) - p[0]).T)
        run = np.r_[0.0, np.cumsum(seg)]
        where = np.mod(phi, TWO_PI) / TWO_PI * samples
        k = np.minimum(where.astype(int), samples - 1)
        positions = run[k] + (where - k) * seg[k]
        order = order_report(positions, run[-1], task.targets)
        return Candidate(rms, design, phi, meets(c, design, size), order, pool)
    ok = _in_order(phi)
    order = OrderReport(1, np.zeros(len(phi) - 1) if ok else np.full(len(phi) - 1, math.inf), 0.0, TWO_PI)
    return Candidate(rms, design, phi, meets(c, design, size, _arc(phi, samples)), order, pool)


def _arc(phi, samples: int) -> np.ndarray:
    """Crank angles (samples,) from the first target's to the last's, in the sense the targets go."""
    sense = 1 if np.all(np.diff(np.mod(phi - phi[0], TWO_PI)) > 0) else -1
    end = phi[0] + sense * np.mod(sense * (phi[-1] - phi[0]), TWO_PI)
    lo, hi = sorted((float(phi[0]), float(end)))
    return np.linspace(lo, hi, samples)


def _timed_travel(task: PathTask, phase):
    """Crank angles (K, P) of a timed, limited travel from each phase (K,) (None for a full turn)."""
    if task.constraints.full_turn:
        return None
    lo, hi = min(0.0, task.timing.min()), max(0.0, task.timing.max())
    return np.asarray(phase, float)[:, None] + np.linspace(lo, hi, 60)[None, :]


def _polished(design, phase, task: PathTask, pool: str, evaluations: int = POLISH_EVALUATIONS):
    """Polish one design (untimed: orthogonal distances; timed: from the crank angle `phase` at the
    first target) under the pool's constraints, with at most `evaluations` residual evaluations per
    penalty weight; (Candidate, designs traced)."""
    t = task if pool == "main" else task.relaxed()
    if task.timing is None and t.constraints.full_turn:
        p = polish_untimed(design, t.targets, t.constraints, t.size, evaluations)
    elif task.timing is None:
        return _polish_limited(design, phase, t, evaluations)
    else:
        p = polish_timed(design, phase, t.targets, t.timing, t.constraints, t.size,
                         travel=None if t.constraints.full_turn else (lambda ph: _timed_travel(t, ph)),
                         max_nfev=evaluations)
    return assess(p.design, p.phi, p.errors, t, pool), p.evaluations


def deepened(candidates: list, task: PathTask, count: int = DEEPENED,
             deadline: float | None = None) -> tuple[list, int]:
    """The `count` best distinct candidates (each pool's, best first) polished again with
    `DEEP_EVALUATIONS` residual evaluations (the search's polish stops early, for breadth), until the
    `deadline` (time.perf_counter) if one is given: the candidates with the deepened ones added, and the
    designs traced."""
    out, traced_count = list(candidates), 0
    for pool in ("main", "relaxed"):
        ranked = sorted((c for c in candidates if c.pool == pool), key=lambda c: c.rank)
        seen = []
        for cand in ranked:
            if len(seen) >= count or (deadline is not None and time.perf_counter() > deadline):
                break
            if any(np.allclose(cand.design, s, rtol=0.0, atol=1e-3 * task.size) for s in seen):
                continue
            seen.append(cand.design)
            phase = cand.phi if task.timing is None and not task.constraints.full_turn else cand.phi[0]
            better, n = _polished(cand.design, phase, task, pool, DEEP_EVALUATIONS)
            out.append(better)
            traced_count += n
    return out, traced_count


# -- the shape screen (a crank that turns fully) --------------------------------------------------------
def _screen(task: PathTask, count: int, rng, clock: _Clock):
    """Screen `count` shapes in chunks: the shapes (S, 10), their curves (S, CURVE) complex, screen RMS
    (S,), correspondence, start and scale, in the targets' normalised frame; and the shapes traced."""
    t = task.targets
    centre = 0.5 * (t.min(axis=0) + t.max(axis=0))
    size = task.size
    tz = ((t[:, 0] - centre[0]) + 1j * (t[:, 1] - centre[1])) / size
    offsets = target_offsets(np.column_stack([tz.real, tz.imag]), CURVE, task.timing)
    parts = []
    traced_count = 0
    sample = sample_shapes(count, rng)
    for lo in range(0, count, CHUNK):
        d = sample.designs[lo:lo + CHUNK]
        if task.timing is None:
            curves, _ = arc_resample(traced(d, CURVE), CURVE)
        else:
            curves = traced(d, CURVE)
        rms, which, start, scale = procrustes_screen(curves, tz, offsets)
        parts.append((d, sample.transmission_deg[lo:lo + CHUNK], sample.ratio[lo:lo + CHUNK], curves, rms,
                      which, start, scale))
        traced_count += len(d)
        if clock.over():
            break
    joined = [np.concatenate([p[i] for p in parts]) for i in range(8)]
    return joined, offsets, tz, centre, traced_count


def _rescored(task: PathTask, designs) -> tuple[np.ndarray, np.ndarray]:
    """True score of placed designs (K, 10): RMS nearest-point distance on a polyline of the turn plus
    the length of the steps back beyond the order tolerance (untimed); RMS miss at the timed angles."""
    t = task.targets
    _, _, p, ok = fourbar_coupler_paths(designs, np.linspace(0.0, TWO_PI, RESCORE_SAMPLES, endpoint=False))
    rows = max(1, 4_000_000 // (RESCORE_SAMPLES * len(t)))         # bounded memory for long target lists
    parts = [nearest_on_polyline(p[k:k + rows], ok[k:k + rows], t) for k in range(0, len(p), rows)]
    near, index, frac = (np.concatenate([q[i] for q in parts]) for i in range(3))
    rms = np.sqrt(np.mean(near ** 2, axis=1))
    seg = np.hypot(*np.moveaxis(np.roll(p, -1, axis=1) - p, -1, 0))
    run = np.concatenate([np.zeros((len(p), 1)), np.cumsum(seg, axis=1)], axis=1)
    positions = np.take_along_axis(run, index, axis=1) + frac * np.take_along_axis(seg, index, axis=1)
    excess = np.array([order_report(positions[k], run[k, -1], t).excess if np.isfinite(rms[k]) else np.inf
                       for k in range(len(designs))])
    return rms + excess, rms


def _pool_picks(task: PathTask, screened, offsets, tz, centre, mask, keep: int) -> list:
    """The `keep` best distinct designs of the shapes where `mask`: the screen's best `RESCORED` placed
    on the targets, then ranked by their true score; [(design (10,), phase at the first target)]."""
    d, _, _, curves, rms, which, start, scale = screened
    pool = np.flatnonzero(mask & np.isfinite(rms))
    if not len(pool):
        return []
    pool = pool[np.argsort(rms[pool], kind="stable")[:RESCORED]]
    size = task.size
    placed = placed_designs(d[pool], curves[pool], tz, offsets, which[pool], start[pool], scale[pool])
    placed[:, 0:4] = placed[:, 0:4] * size + np.tile(centre, 2)
    placed[:, 4:9] *= size
    phase = TWO_PI * start[pool] / CURVE + np.angle(scale[pool])
    if task.timing is None:
        key, _ = _rescored(task, placed)
    else:
        _, _, p, ok = fourbar_coupler_paths(placed, phase[:, None] + task.timing[None, :])
        key = np.sqrt(np.mean(np.where(ok, np.hypot(*np.moveaxis(p - task.targets, -1, 0)), np.inf) ** 2, axis=1))
    picks, seen = [], []
    for i in np.argsort(key, kind="stable"):
        if len(picks) >= keep or not np.isfinite(key[i]):
            break
        if any(np.allclose(placed[i], s, rtol=0.0, atol=0.02 * size) for s in seen):
            continue
        seen.append(placed[i])
        picks.append((placed[i], float(phase[i])))
    return picks


def screened_start(setup: Setup, seed: int) -> tuple[list, int]:
    """One start of the shape screen from `seed`: its polished candidates [Candidate] and evaluations
    (shapes traced, designs rescored, and the polish's designs)."""
    task = setup.task
    c = task.constraints
    clock = _Clock(setup.budget)
    rng = np.random.default_rng(seed)
    screened, offsets, tz, centre, count = _screen(task, setup.shapes, rng, clock)
    mu, ratio = screened[1], screened[2]
    inside = np.ones(len(mu), bool)
    if c.min_transmission_deg is not None:
        inside &= mu >= c.min_transmission_deg
    if c.max_ratio is not None:
        inside &= ratio <= c.max_ratio
    picks = _pool_picks(task, screened, offsets, tz, centre, inside, setup.keep)
    if len(picks) < setup.keep:     # too few shapes within the bounds: the best others, polished towards them
        picks += _pool_picks(task, screened, offsets, tz, centre, ~inside, setup.keep - len(picks))
    pools = [("main", picks)]
    if setup.relaxed:
        pools.append(("relaxed", _pool_picks(task, screened, offsets, tz, centre, ~inside,
                                             max(2, setup.keep // 3))))
    count += RESCORED * len(pools)
    found = []
    for pool, picks in pools:
        for design, phase in picks:
            if clock.over() and found:
                break
            cand, n = _polished(design, phase, task, pool)
            found.append(cand)
            count += n
    return found, count


# -- differential evolution (a limited travel) ------------------------------------------------------------
def _designs(x) -> np.ndarray:
    """Population (V, S) → design rows (S, 10), the assembly mode ±1 from the 10th coordinate's sign."""
    d = np.array(np.asarray(x, float)[:10].T)
    d[:, 9] = np.where(d[:, 9] >= 0, 1.0, -1.0)
    return d


def _bounds(task: PathTask, reach: float) -> list:
    """Bounds of the differential evolution: pivots and coupler point within `reach` × the targets' span
    of their middle (a pivot with a region: that box), lengths up to 2 × reach × span, mode sign,
    (timed) phase."""
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


def score(x, task: PathTask, samples: int) -> np.ndarray:
    """Objective of a population x (V, S) over a limited travel: RMS error + WEIGHT × (violations +
    order/arc defects)."""
    d = _designs(x)
    size = task.size
    c = task.constraints
    if task.timing is None:
        travel = np.linspace(0.0, TWO_PI, samples, endpoint=False)
    else:
        travel = _timed_travel(task, np.asarray(x, float)[10])
    a, b, p, ok = fourbar_coupler_paths(d, travel)
    penalty = fourbar_violations(c, d, a, b, ok, size, closure=task.timing is not None).sum(axis=1)
    if task.timing is None:
        near, index, _ = nearest_on_polyline(p, ok, task.targets, closed=True, dtype=np.float32)
        penalty = penalty + 0.1 * size * (_order_penalty(index, samples) + _arc_penalty(index, ok))
    else:
        phase = np.asarray(x, float)[10]
        _, _, pt, okt = fourbar_coupler_paths(d, phase[:, None] + task.timing[None, :])
        near = np.where(okt, np.hypot(*np.moveaxis(pt - task.targets, -1, 0)), np.inf)
    rms = np.sqrt(np.mean(near ** 2, axis=1))
    return np.where(np.isfinite(rms), rms, 10 * size) + WEIGHT * penalty


def _residuals(z, mode: float, task: PathTask, weight: float) -> np.ndarray:
    """Residuals (K, 2T + 4) of unknowns z (K, 9 + T): design, one crank angle per untimed target; the
    constraints measured over a turn where the loop closes (the targets' arc need not close beyond)."""
    d = np.column_stack([z[:, :9], np.full(len(z), mode)])
    _, _, p, ok = fourbar_coupler_paths(d, z[:, 9:])
    miss = np.where(ok[..., None], p - task.targets, task.size).reshape(len(z), -1)
    a, b, _, okt = fourbar_coupler_paths(d, np.linspace(0.0, TWO_PI, 60, endpoint=False))
    v = fourbar_violations(task.constraints, d, a, b, okt, task.size, closure=False)
    return np.column_stack([miss, weight * v])


def _polish_limited(design, phi_t, task: PathTask, evaluations: int | None = None) -> tuple[Candidate, int]:
    """Least squares of untimed targets on a limited travel, in the design's 9 numbers and one crank
    angle per target (the angles converge to the feet of the perpendiculars)."""
    mode = float(design[9])
    z = np.r_[design[:9], phi_t]
    lo, hi = constraint_bounds(task.constraints, len(z))
    count = 0
    for weight in (WEIGHT, 100 * WEIGHT, 1e4 * WEIGHT):
        def fun(u, weight=weight):
            return _residuals(u[None], mode, task, weight)[0]

        def jac(u, weight=weight):
            h = np.r_[np.full(9, 1e-7 * task.size), np.full(len(u) - 9, 1e-7)]
            r = _residuals(np.vstack([u, u + np.diag(h)]), mode, task, weight)
            return ((r[1:] - r[0]) / h[:, None]).T
        res = least_squares_fit(fun, jac, z, lo, hi, evaluations or 12 * len(z))
        z = res.x
        count += res.nfev * (len(z) + 1)
        d, phi = positive_lengths(np.r_[z[:9], mode], z[9:])
        if _in_order(phi) and meets(task.constraints, d, task.size, _arc(phi, 720)):
            break
    d, phi = positive_lengths(np.r_[z[:9], mode], z[9:])
    _, _, p, _ = fourbar_coupler_paths(d[None], phi)
    return assess(d, phi, np.hypot(*(p[0] - task.targets).T), task), count


def _nearest_angles(design, targets, samples: int = 3600) -> np.ndarray:
    fine = np.linspace(0.0, TWO_PI, samples, endpoint=False)
    _, _, p, ok = fourbar_coupler_paths(design[None], fine)
    gap = np.where(ok[0][:, None], np.hypot(p[0, :, None, 0] - targets[:, 0], p[0, :, None, 1] - targets[:, 1]), np.inf)
    return fine[np.argmin(gap, axis=0)]


def de_start(setup: Setup, seed: int) -> tuple[list, int]:
    """One start of differential evolution from `seed` (a limited travel), then the polish of the
    `keep` best distinct members of its final population: [Candidate] and the evaluations."""
    from scipy.optimize import differential_evolution
    task = setup.task
    count = [0]
    clock = _Clock(setup.budget)

    def objective(x):
        count[0] += np.shape(x)[1]
        return score(x, task, setup.samples)

    def stop(*_):
        return clock.over()
    res = differential_evolution(objective, _bounds(task, setup.reach), popsize=setup.popsize,
                                 maxiter=setup.generations, tol=0.0, atol=0.0, seed=seed, vectorized=True,
                                 updating="deferred", polish=False, init="sobol", mutation=(0.5, 1.0),
                                 recombination=0.9, callback=stop if setup.budget is not None else None)
    order = np.argsort(res.population_energies, kind="stable")
    found, seen = [], []
    for x in res.population[order]:
        if len(seen) >= setup.keep or (clock.over() and found):
            break
        design = _designs(x[:, None])[0]
        if any(np.allclose(design, s, rtol=0, atol=1e-3 * task.size) for s in seen):
            continue
        seen.append(design)
        phi0 = _nearest_angles(design, task.targets) if task.timing is None else x[10] + task.timing
        _, _, p, _ = fourbar_coupler_paths(design[None], phi0)
        found.append(assess(design, phi0, np.hypot(*(p[0] - task.targets).T), task))   # as found, and polished
        if task.timing is None:
            cand, n = _polish_limited(design, phi0, task)
        else:
            cand, n = _polished(design, float(x[10]), task, "main")
        found.append(cand)
        count[0] += n
    return found, count[0]


def run_start(setup: Setup, seed: int) -> tuple[list, int]:
    """One start: the shape screen for a crank that turns fully, differential evolution otherwise."""
    return (screened_start if setup.task.constraints.full_turn else de_start)(setup, seed)
