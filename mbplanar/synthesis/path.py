"""Path generation: a four-bar whose coupler curve passes near target points.

Targets are untimed (each point anywhere on the curve, met in their order) or timed (each point with
the crank's advance from the first target). By default the design is one a designer would build: the
crank turns fully, the smallest transmission angle is at least 30° and the longest link is at most ten
times the shortest (`DESIGNER`); each bound can be changed or dropped, and the result says which held.

The search runs `starts` independent starts (`path_search`): for a crank that turns fully, a screen of
crank-rocker shapes fitted to the targets by a similarity in closed form (`path_screen`), then a
least-squares polish of the best distinct ones (`path_polish`); for a limited travel, differential
evolution over design batches and the same polish. The starts are seeded from one seed, so they run one
after the other here or one task each on a Dask cluster with equal results; nothing depends on the
clock unless a `budget` of seconds is given, which stops the search in time with the best so far.

Every candidate is judged by the constraints and by the order it meets the targets in, with a tolerance
for targets met a hair out of order (`path_order`). The best is written as a model and checked by
mbplanar: its defects (circuit, branch, full turn), errors, transmission angle and order are mbplanar's
analysis of that model. The search answers with a design whenever one assembles: a design that meets
the targets out of order beyond the tolerance, or misses a constraint, comes back with `success` False
and warnings that say what and by how much; no design only when none assembles, with the reason.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

from ..engine import Engine
from ..errors import ModelError
from ..kinematics import analyse
from ._models import read_design
from .batch import design_toml, fourbar_coupler_paths
from .constraints import PathConstraints, transmission_angles
from .defects import Defects, check_defects
from .path_order import order_report
from .path_search import Candidate, PathTask, Setup, deepened, nearest_on_polyline, run_start
from .starts import run_starts

__all__ = ["PathOutcome", "PathResult", "PathTask", "DESIGNER", "synthesise_path", "nearest_on_polyline",
           "validate_targets"]

TWO_PI = 2.0 * math.pi
DESIGNER = PathConstraints(full_turn=True, min_transmission_deg=30.0, max_ratio=10.0)
"""The default constraints: a crank that turns fully, transmission angle ≥ 30°, link ratio ≤ 10."""
VERIFY_SECONDS = 1.0
"""Of a budget, the seconds kept for writing and checking the chosen design."""

@dataclass(frozen=True)
class PathOutcome:
    """What every path generator returns: the written model (`toml`, `mechanism`), the `targets` (T, 2)
    and their `errors` (T,) from mbplanar's analysis of that model, `phi` (T,) the input at each target
    (the nearest curve point's, or the timed one's), the `defects` check, the smallest transmission angle
    over the travel `transmission_deg` (nan when not defined), the `constraints`, and the search's
    `evaluations`, `seconds`, `seed` and `starts`; `success` (the constraints met and the targets met in
    order within the tolerance), `message`, `warnings` (what the design misses, and by how much),
    `order` (how it meets the targets' order: sense, tolerance, the steps back), `tradeoff` (the best
    design found without the transmission and ratio bounds, where the search found one), and whether
    the `budget` stopped the search."""

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
    success: bool = True
    message: str = ""
    warnings: tuple = ()
    order: dict | None = None
    tradeoff: dict | None = None
    stopped: bool = False

    @property
    def rms(self) -> float:
        return float(np.sqrt(np.mean(self.errors ** 2)))

    @property
    def max(self) -> float:
        return float(np.max(self.errors))


@dataclass(frozen=True)
class PathResult(PathOutcome):
    """A four-bar path generator: the fields every path generator returns (`PathOutcome`) and the design.

    Attributes
    ----------
    toml, mechanism : str, Mechanism
        The written model (coupler point "P") and the `Mechanism` read back from it.
    targets : (T, 2) ndarray
        The target points, m.
    errors : (T,) ndarray
        Each target's distance from the analysed coupler curve, m (`rms` and `max` summarise them).
    phi : (T,) ndarray
        The crank angle at each target (the nearest curve point's, or the timed one's), rad.
    defects : Defects
        mbplanar's check of the design.
    evaluations, seconds, seed, starts : int, float, int, int
        Designs scored, wall time, the seed and the starts.
    timed : bool
        Whether the targets were timed.
    transmission_deg : float
        Smallest transmission angle over the travel, degrees.
    constraints : PathConstraints
        The bounds asked for.
    success, message, warnings : bool, str, tuple of str
        Whether the constraints are met and the targets met in order, why not, what the design misses
        and by how much.
    order : dict or None
        How the design meets the targets' order (sense, tolerance, the steps back).
    tradeoff : dict or None
        The best design found without the transmission and ratio bounds, where clearly better.
    stopped : bool
        Whether the `budget` stopped the search.
    design : (10,) ndarray
        The design row (`batch.DESIGN_COLUMNS`: pivots A0, B0, crank, coupler, rocker, coupler point
        u, v, assembly mode), m.
    ratio : float
        Longest over shortest link (the ground included).
    point : str
        The model's coupler point, "P".

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.synthesis import synthesise_path
    >>> from mbplanar.synthesis.batch import DESIGN_COLUMNS
    >>> t = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    >>> r = synthesise_path(np.column_stack([np.cos(t), 0.5 * np.sin(t)]), starts=1, shapes=64, keep=1, samples=30)
    >>> r.errors.shape, r.point, len(r.design) == len(DESIGN_COLUMNS), r.defects.ok
    ((8,), 'P', True, True)
    """

    design: np.ndarray = None
    ratio: float = float("nan")
    point: str = "P"


# -- the targets ------------------------------------------------------------------------------------------
def validate_targets(targets, where: str = "target") -> np.ndarray:
    """Target points as a (T, 2) float array, or a `ModelError` naming the row (1-based, called
    `where` + " row") at fault: fewer than 3 points, a value that is not a finite number, or all points
    at one place."""
    try:
        t = np.array(targets, dtype=float)
    except (TypeError, ValueError):
        raise ModelError("target points must be rows of two numbers x, y") from None
    if t.ndim != 2 or t.shape[1] != 2:
        raise ModelError(f"target points must be rows of two numbers x, y, got an array of shape {t.shape}")
    bad = np.flatnonzero(~np.all(np.isfinite(t), axis=1))
    if len(bad):
        k = int(bad[0])
        raise ModelError(f"{where} row {k + 1}: ({t[k, 0]}, {t[k, 1]}) is not a pair of finite numbers")
    if len(t) < 3:
        raise ModelError(f"path generation needs at least 3 target points, got {len(t)}")
    if np.ptp(t, axis=0).max() <= 0:
        raise ModelError(f"{where} rows 1-{len(t)} are all the one point ({t[0, 0]}, {t[0, 1]}): a path "
                         f"needs points at different places")
    return t


def _task(targets, timing, constraints, default: PathConstraints = DESIGNER) -> PathTask:
    """The task, the targets checked; `default` the constraints when none are given."""
    targets = validate_targets(targets)
    if timing is not None:
        timing = np.asarray(timing, float)
        if timing.shape != (len(targets),) or not np.all(np.isfinite(timing)):
            raise ModelError(f"timed targets need one finite input value per target point ({len(targets)})")
        timing = timing - timing[0]
        same = np.flatnonzero(np.diff(timing) == 0)
        if len(same):
            raise ModelError(f"timed targets: rows {same[0] + 1} and {same[0] + 2} share one input value")
    return PathTask(targets, timing, default if constraints is None else constraints)


def start_seeds(seed: int, starts: int) -> list[int]:
    """The seeds of `starts` independent starts drawn from one `seed` (numpy's SeedSequence.spawn)."""
    return [int(s.generate_state(1)[0]) for s in np.random.SeedSequence(seed).spawn(starts)]


# -- the whole search ---------------------------------------------------------------------------------
def synthesise_path(targets, *, timing=None, constraints: PathConstraints | None = None, seed: int = 0,
                    starts: int = 3, shapes: int = 8192, keep: int = 6, budget: float | None = None,
                    popsize: int = 15, generations: int = 200, samples: int = 60, reach: float = 2.0,
                    client=None, progress=None) -> PathResult:
    """A four-bar whose coupler point passes near `targets`, checked by mbplanar.

    Parameters
    ----------
    targets : (T, 2) array
        Target points (T ≥ 3), in their order along the curve.
    timing : (T,) array, optional
        Timed targets: the crank's angle at each target (rad); only the advances from the first
        target matter (the crank's angle at the first target is a design variable). None: untimed.
    constraints : PathConstraints, optional
        Default `DESIGNER`: a full turn, transmission angle ≥ 30°, link ratio ≤ 10; pivot regions.
    seed : int
        Random seed: the same seed and settings give the same design and evaluation count, serially
        or on Dask (without a `budget`).
    starts : int
        Independent starts, seeded from `seed`.
    shapes : int
        Crank-rocker shapes screened per start (a crank that turns fully).
    keep : int
        Designs polished per start.
    budget : float, optional
        Seconds (wall time) for the whole run: the search stops in time and answers with the best
        design so far (`stopped` True).
    popsize, generations, samples, reach
        The differential evolution of a limited travel: population factor, generations, crank
        positions per curve, pivots within `reach` × the targets' span of their middle.
    client : dask.distributed.Client, optional
        Run the starts as tasks on this client (one task per start).
    progress : callable, optional
        progress(done, total) as starts finish.

    Returns
    -------
    PathResult
        The design with the model's own errors, `success`, `message`, `warnings`, `order`, `tradeoff`.

    Raises
    ------
    ModelError
        Fewer than 3 targets, targets that are not finite (x, y) rows or all one point, timing of
        another length or with repeated values, settings below their least values (starts ≥ 1,
        shapes ≥ 16, keep ≥ 1, popsize ≥ 5, generations ≥ 1, samples ≥ 12), a budget that is not a
        positive number, invalid constraints, or no candidate that assembles through the targets
        without a defect.

    Examples
    --------
    Eight points of an ellipse: a crank-rocker's coupler curve meets them, within the designer's bounds:

    >>> import numpy as np
    >>> from mbplanar.synthesis import synthesise_path
    >>> t = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    >>> r = synthesise_path(np.column_stack([np.cos(t), 0.5 * np.sin(t)]), starts=1, shapes=64, keep=1, samples=30)
    >>> r.success, r.transmission_deg >= 30.0, r.ratio <= 10.0, r.max < 1e-9
    (True, True, True, True)
    """
    t0 = time.perf_counter()
    task = _task(targets, timing, constraints)
    if starts < 1 or shapes < 16 or keep < 1 or popsize < 5 or generations < 1 or samples < 12:
        raise ModelError("path generation needs starts ≥ 1, shapes ≥ 16, keep ≥ 1, popsize ≥ 5, "
                         "generations ≥ 1, samples ≥ 12")
    if budget is not None and not (isinstance(budget, (int, float)) and budget > 0 and math.isfinite(budget)):
        raise ModelError(f"the budget must be a positive number of seconds, got {budget!r}")
    c = task.constraints
    relax = c.min_transmission_deg is not None or c.max_ratio is not None
    per_start = None if budget is None else max(budget - VERIFY_SECONDS, 0.1 * budget) / starts
    setup = Setup(task, shapes, keep, relax and c.full_turn, popsize, generations, samples, reach, per_start)
    seeds = start_seeds(seed, starts)
    if budget is None or client is not None:
        results = run_starts(run_start, setup, seeds, client, progress)
    else:
        results = _within_budget(setup, seeds, t0 + budget - VERIFY_SECONDS, progress)
    evaluations = sum(r[1] for r in results)
    found = [cand for r in results for cand in r[0]]
    stopped = budget is not None and time.perf_counter() - t0 > budget - VERIFY_SECONDS
    if not stopped:
        found, more = deepened(found, task, deadline=None if budget is None else t0 + budget - VERIFY_SECONDS)
        evaluations += more
        stopped = budget is not None and time.perf_counter() - t0 > budget - VERIFY_SECONDS
    found = [(cand.rank, k, cand) for k, cand in enumerate(found)]
    main = [f[2] for f in sorted((f for f in found if f[2].pool == "main"), key=lambda f: f[:2])]
    relaxed = [f[2] for f in sorted((f for f in found if f[2].pool == "relaxed"), key=lambda f: f[:2])]
    chosen, rejected = _first_verified(main + relaxed, task, evaluations, seed, starts)
    if chosen is None:
        why = f": {rejected[0]}" if rejected else ": no candidate assembles through the targets"
        raise ModelError(f"no design found ({len(main) + len(relaxed)} candidates){why}")
    tradeoff = None
    if relaxed and not stopped:   # the best design without the angle and ratio bounds, where clearly better
        margin = max(1e-6 * chosen.rms, 1e-9 * task.size)
        better = [r for r in relaxed if r.rms < chosen.rms - margin and r.meets]
        other, _ = _first_verified(better, task.relaxed(), evaluations, seed, starts) if better else (None, [])
        tradeoff = _tradeoff(chosen, other if other is not None and other.rms < chosen.rms - margin else None, c)
    warnings = list(chosen.warnings)
    if stopped:
        warnings.append(f"the budget of {budget:g} s ran out: the best design found so far "
                        f"({len(found)} designs polished)")
    return dataclasses.replace(chosen, seconds=time.perf_counter() - t0, warnings=tuple(warnings),
                               tradeoff=tradeoff, stopped=stopped)


def _within_budget(setup: Setup, seeds, deadline: float, progress) -> list:
    """The starts one after the other, each with its share of the time left; a start that has no time
    left is skipped, except the first."""
    out = []
    for k, s in enumerate(seeds):
        left = deadline - time.perf_counter()
        if out and left <= 0:
            break
        share = max(left / (len(seeds) - k), 0.0)
        out.append(run_start(dataclasses.replace(setup, budget=share), s))
        if progress is not None:
            progress(len(out), len(seeds))
    return out


def _first_verified(candidates: list[Candidate], task: PathTask, evaluations, seed, starts):
    """The first of `candidates` (best first) that mbplanar's analysis confirms, and why the ones before
    it failed."""
    rejected = []
    for cand in candidates:
        try:
            return _verified(cand, task, evaluations, seed, starts), rejected
        except ModelError as exc:
            rejected.append(str(exc))
    return None, rejected


def _tradeoff(chosen: PathResult, other: PathResult | None, c: PathConstraints) -> dict:
    """What the transmission and ratio bounds cost: the chosen design's errors against the best design
    found without them (None where the search found none better)."""
    bounds = [k for k in ("min_transmission_deg", "max_ratio") if getattr(c, k) is not None]
    out = {"relaxed": bounds, "with": {"rms": chosen.rms, "max": chosen.max,
                                       "transmission_deg": chosen.transmission_deg, "ratio": chosen.ratio}}
    out["without"] = None if other is None else {"rms": other.rms, "max": other.max,
                                                 "transmission_deg": other.transmission_deg, "ratio": other.ratio}
    return out


# -- the chosen design, checked by mbplanar ---------------------------------------------------------------
def _verified(cand: Candidate, task: PathTask, evaluations, seed, starts) -> PathResult:
    """The design as a model drawn at the first target's crank angle, checked and measured by mbplanar:
    a circuit or branch defect, or a crank that does not turn fully when asked, rejects it; a step back
    beyond the order tolerance or a missed constraint is a warning."""
    design, phi_t = cand.design, cand.phi
    targets, c = task.targets, task.constraints
    text = design_toml(design, float(phi_t[0]))
    mech = read_design(text)
    engine = Engine(mech)
    a, b, p, ok = fourbar_coupler_paths(design[None], phi_t)
    if not ok.all():
        raise ModelError("the loop does not close at every target")
    defects = check_defects(engine, phi_t, {"A": a[0], "B": b[0], "P": p[0]}, full_turn=c.full_turn,
                            tol=1e-7 * task.size)
    if defects.circuit or defects.unreached or defects.branch or defects.full_turn is False:
        raise ModelError(dataclasses.replace(defects, order=False).describe())
    node_phi = np.asarray(defects.node_phi)
    warnings = []
    order = None
    if task.timing is None and c.full_turn:   # the order along the analysed curve, with the tolerance
        node_phi, defects, order, said = _analysed_order(engine, node_phi, defects, targets)
        warnings += said
    elif defects.order:
        warnings.append("the design meets the targets out of order (no input sense reaches them in turn)")
    m = analyse(engine, node_phi)
    errors = np.hypot(*(m.xy[:, m.point("P")] - targets).T)
    span = TWO_PI if c.full_turn else defects.sense * (node_phi[-1] - node_phi[0])
    dense = analyse(engine, node_phi[0] + np.linspace(0.0, span, 3601))
    xy = {k: dense.xy[:, dense.point(k)] for k in ("A", "B", "B0", "P")}
    if task.timing is None:  # the nearest point of the analysed curve, where nearer than the polished foot
        errors = np.minimum(errors, nearest_on_model(engine, "P", targets, dense))
    mu = float(np.degrees(transmission_angles(xy["A"], xy["B"], xy["B0"]).min()))
    links = [design[4], design[5], design[6], float(np.hypot(*(design[2:4] - design[0:2])))]
    ratio = float(max(links) / min(links))
    missed = []
    if c.min_transmission_deg is not None and mu < c.min_transmission_deg - 1e-9:
        missed.append(f"the smallest transmission angle {mu:.2f}° is below the bound {c.min_transmission_deg:g}°")
    if c.max_ratio is not None and ratio > c.max_ratio * (1 + 1e-12):
        missed.append(f"the link ratio {ratio:.3g} exceeds the bound {c.max_ratio:g}")
    for name, col in (("A0", 0), ("B0", 2)):
        box = c.box(name)
        if box is not None and (np.any(design[col:col + 2] < box[0] - 1e-9 * task.size)
                                or np.any(design[col:col + 2] > box[1] + 1e-9 * task.size)):
            missed.append(f"the pivot {name} {design[col:col + 2].tolist()} lies outside its region")
    warnings += [m_ + " (no design found meets it)" for m_ in missed]
    in_order = not defects.order
    success = in_order and not missed
    message = ("defect-free design within the constraints" if success else
               "design found, but " + "; ".join(missed + ([] if in_order else ["out of order"])))
    return PathResult(text, mech, targets, errors, node_phi, defects, evaluations, 0.0, seed, starts,
                      task.timing is not None, mu, c, success, message, tuple(warnings), order,
                      design=design, ratio=ratio)


def _analysed_order(engine, node_phi, defects: Defects, targets):
    """How the analysed coupler curve of a full turn meets the targets: positions by arc length along
    mbplanar's sweep, judged with the order tolerance; the nodes' inputs in the sense found, the defects
    with that verdict, the order as a dict, and a warning per step back."""
    dense = analyse(engine, node_phi[0] + np.linspace(0.0, TWO_PI, 3601))
    p = dense.xy[:, dense.point("P")]
    run = np.r_[0.0, np.cumsum(np.hypot(*np.diff(p, axis=0).T))]
    offset = np.mod(node_phi - node_phi[0], TWO_PI)
    positions = np.interp(offset, dense.phi[:, 0] - dense.phi[0, 0], run)
    report = order_report(positions, run[-1], targets)
    node_phi = node_phi[0] + report.sense * np.mod(report.sense * (node_phi - node_phi[0]), TWO_PI)
    said = []
    for k, j, back in report.steps_back():
        turn = math.degrees(np.mod(report.sense * (node_phi[k - 1] - node_phi[j - 1]), TWO_PI))
        verdict = "within" if back <= report.tolerance else "beyond"
        said.append(f"targets {k} and {j} are met out of order: {j} lies {back:.4g} back along the curve from "
                    f"{k} ({turn:.3g}° of crank), {verdict} the tolerance {report.tolerance:.4g}")
    defects = dataclasses.replace(defects, order=not report.ok, sense=report.sense,
                                  node_phi=tuple(float(x) for x in node_phi))
    order = {"sense": report.sense, "tolerance": report.tolerance, "curve_length": report.length,
             "steps_back": [{"from": k, "to": j, "length": back} for k, j, back in report.steps_back()],
             "ok": report.ok}
    return node_phi, defects, order, said


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

