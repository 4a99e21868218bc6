"""Path generation on any model's parameters: the named `[parameters]` of a model are searched within
bounds so that one of its points passes near target points; the four-bar of `path.synthesise_path` is
one case of this.

Every candidate design is solved by mbplanar's design batch (`mbplanar.study.batch.DesignBatch`: the
engine's own Newton and continuation over a batch of designs, each on the branch it is drawn in), so
any linkage that the table format describes can be synthesised. The search is the four-bar's:
independent starts (differential evolution over design batches, then a least-squares polish within the
bounds), constraints as penalties and weighted residuals, and the chosen design written as the model
with its new parameter values, checked and measured by mbplanar (defects, errors, transmission angle).

Untimed targets lie anywhere on the curve traced by the input over its travel (a full turn of a crank,
or `travel` about the drawn pose), met in their order; timed targets give the input's advance from the
first target (the input's value at the first target, relative to the drawn pose, is a design variable).
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..engine import Engine
from ..errors import MbplanarError, ModelError
from ..kinematics import analyse
from ..model import parse_model
from ._models import table_toml
from .constraints import PathConstraints, transmission_angles
from .defects import check_defects
from .path import PathOutcome, _task, nearest_on_model, start_seeds
from .path_search import _order_penalty, nearest_on_polyline
from .starts import run_starts

__all__ = ["ModelPathResult", "synthesise_model_path"]

TWO_PI = 2.0 * math.pi
WEIGHT = 10.0


@dataclass(frozen=True)
class ModelPathResult(PathOutcome):
    """A model's parameters found by path synthesis, with the fields of every path generator (see
    `PathResult`: `toml`, `mechanism`, `targets`, `errors`, `phi`, `defects`, `transmission_deg`,
    `success`, `message`, `warnings`, ...); its `transmission_deg` is the angle at the constraint's
    `transmission_joints` (nan when none are named).

    Attributes
    ----------
    values : dict
        {parameter: value in its unit}; the model's text `toml` holds them.
    point : str
        The shaped joint or point.
    travel : (2,) tuple of float
        The input's range about the drawn pose (SI) over which its curve was traced.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.synthesis import synthesise_model_path
    >>> targets = [[0.13, 0.21], [0.06, 0.22], [-0.01, 0.18], [-0.05, 0.12], [-0.03, 0.06], [0.02, 0.06],
    ...            [0.09, 0.1], [0.15, 0.17]]
    >>> r = synthesise_model_path("models/fourbar_design.toml", "M", {"m": (0.0, 1.0), "h": (-0.2, 0.2)},
    ...                           targets, starts=1, popsize=5, generations=1, samples=12, keep=1)
    >>> sorted(r.values), r.point, r.errors.shape
    (['h', 'm'], 'M', (8,))
    >>> mbplanar.parse_model(r.toml).name == mbplanar.read_model("models/fourbar_design.toml").name
    True
    """

    values: dict = None
    point: str = ""
    travel: tuple = ()


@dataclass(frozen=True)
class _Problem:
    """Everything a start needs (plain data, so that it travels to Dask workers)."""

    data: dict
    source: str
    point: str
    names: tuple
    lo: np.ndarray
    hi: np.ndarray
    targets: np.ndarray
    timing: np.ndarray | None
    constraints: PathConstraints
    travel: tuple            # input range about the drawn pose (SI) of the curve
    periodic: bool           # a crank input (full turns meaningful)
    popsize: int = 8
    generations: int = 40
    samples: int = 48
    keep: int = 2
    _cache: dict = field(default_factory=dict, compare=False, repr=False)

    def __getstate__(self):          # the engine cache stays behind when a start travels to a worker
        return {k: v for k, v in self.__dict__.items() if k != "_cache"}

    def __setstate__(self, state):
        self.__dict__.update(state, _cache={})

    @property
    def size(self) -> float:
        return float(np.ptp(self.targets, axis=0).max())

    def base(self):
        """The template and the reference engine (built once per process)."""
        if "base" not in self._cache:
            from ..model import Template
            template = Template(self.data, self.source)
            self._cache["base"] = template, Engine(parse_model(template.bind(), source=self.source))
        return self._cache["base"]

    def motion(self, values, phi_rel):
        """Design batch of parameter rows values (S, n) at input values phi_rel (S, N) relative to each
        design's drawn pose: positions of the point and of the named joints (S, N, k, 2), valid (S, N)
        and the drawn input φ0 (S,)."""
        from ..study.batch import DesignBatch
        from ..study.geometry import design_geometry
        from ..study.variants import variants_from
        template, engine = self.base()
        variants = variants_from(template, {n: values[:, i] for i, n in enumerate(self.names)}, check=False)
        batch = DesignBatch(engine, design_geometry(template, variants, engine.mech), template, variants)
        phi0 = np.where(np.isfinite(batch.geometry.phi0), batch.geometry.phi0, 0.0)
        with np.errstate(all="ignore"):
            m = batch.solve(phi0[:, None] + phi_rel, exact_limits=False, fallback=False)
        names = [self.point] + list(self.constraints.transmission_joints or ())
        xy = m.xy[:, :, [m.point(n) for n in names]]
        valid = m.valid & m.ok[:, None] & np.all(np.isfinite(xy), axis=(2, 3))
        return xy, valid, phi0, batch.geometry

    def grid(self) -> np.ndarray:
        lo, hi = self.travel
        return np.linspace(lo, hi, self.samples, endpoint=not self.closed)

    @property
    def closed(self) -> bool:
        return self.periodic and self.constraints.full_turn

    def violations(self, xy, valid, geometry, count) -> np.ndarray:
        """(S, 3) lengths: not closing over the travel (full turn), transmission angle, pivot regions."""
        c, size = self.constraints, self.size
        out = np.zeros((count, 3))
        if c.full_turn:
            out[:, 0] = size * np.mean(~valid, axis=1)
        if c.min_transmission_deg is not None:
            mu = np.where(valid, transmission_angles(xy[:, :, 1], xy[:, :, 2], xy[:, :, 3]), np.pi / 2)
            out[:, 1] = size * np.maximum(math.radians(c.min_transmission_deg + 0.05) - mu.min(axis=1), 0.0)
        for name in c.pivots:
            lo, hi = c.box(name)
            at = geometry.at[name].T
            out[:, 2] += np.nan_to_num(np.hypot(*np.maximum(np.maximum(lo - at, at - hi), 0.0).T), nan=size)
        return out


# -- global stage ---------------------------------------------------------------------------------------
def _split(x, problem: _Problem):
    """Population rows (S, V) → parameter values (S, n) and (timed) the first target's input (S,)."""
    n = len(problem.names)
    return x[:, :n], (x[:, n] if problem.timing is not None else None)


def _score(x, problem: _Problem) -> np.ndarray:
    x = np.asarray(x, float).T
    values, first = _split(x, problem)
    size, grid = problem.size, problem.grid()
    phi = np.broadcast_to(grid, (len(x), len(grid)))
    if first is not None:
        phi = np.column_stack([first[:, None] + problem.timing[None, :], phi])
    xy, valid, _, geometry = problem.motion(values, phi)
    penalty = problem.violations(xy[:, -len(grid):], valid[:, -len(grid):], geometry, len(x)).sum(axis=1)
    if first is None:
        near, index, _ = nearest_on_polyline(xy[:, :, 0], valid, problem.targets, closed=problem.closed)
        if problem.closed:
            penalty = penalty + 0.1 * size * _order_penalty(index, len(grid))
        else:
            step = np.diff(index, axis=1)
            penalty = penalty + 0.1 * size * np.minimum(np.sum(step < 0, axis=1), np.sum(step > 0, axis=1))
            ahead = np.where(np.sum(step < 0, axis=1) <= np.sum(step > 0, axis=1), 1, -1)
            lo, hi = np.minimum(index[:, 0], index[:, -1]), np.maximum(index[:, 0], index[:, -1])
            cols = np.arange(len(grid))[None, :]
            between = (cols >= lo[:, None]) & (cols <= hi[:, None] + (ahead[:, None] > 0))
            penalty = penalty + size * np.mean(between & ~valid, axis=1)
    else:
        t = len(problem.targets)
        miss = np.hypot(*np.moveaxis(xy[:, :t, 0] - problem.targets, -1, 0))
        near = np.where(valid[:, :t], miss, np.inf)
    rms = np.sqrt(np.mean(near ** 2, axis=1))
    return np.where(np.isfinite(rms), rms, 10 * size) + WEIGHT * penalty


# -- polish -------------------------------------------------------------------------------------------------
def _residuals(z, problem: _Problem, weight: float) -> np.ndarray:
    """(K, 2T + 3) target misses and weighted violations of unknowns z (K, n + T or n + 1)."""
    n, t, grid = len(problem.names), len(problem.targets), problem.grid()
    rel = z[:, n:] if problem.timing is None else z[:, n:n + 1] + problem.timing[None, :]
    phi = np.column_stack([rel, np.broadcast_to(grid, (len(z), len(grid)))])
    xy, valid, _, geometry = problem.motion(z[:, :n], phi)
    miss = np.where(valid[:, :t, None], xy[:, :t, 0] - problem.targets, problem.size).reshape(len(z), -1)
    v = problem.violations(xy[:, t:], valid[:, t:], geometry, len(z))
    return np.column_stack([miss, weight * v])


def _polish(values, rel, problem: _Problem):
    """Least squares within the parameters' bounds from values (n,), the targets' inputs rel (T,)."""
    from scipy.optimize import least_squares
    n = len(problem.names)
    z = np.r_[values, rel if problem.timing is None else rel[:1]]
    lo = np.r_[problem.lo, np.full(len(z) - n, -np.inf)]
    hi = np.r_[problem.hi, np.full(len(z) - n, np.inf)]
    if problem.timing is not None:
        lo[n], hi[n] = problem.travel
    span = hi - lo
    z = np.clip(z, lo + 1e-9 * np.where(np.isfinite(span), span, 1), hi - 1e-9 * np.where(np.isfinite(span), span, 1))
    count = 0
    for weight in (WEIGHT, 100 * WEIGHT):
        def jac(u, weight=weight):
            h = 1e-7 * np.maximum(1.0, np.abs(u))
            rows = [u] + [u + h[i] * np.eye(len(u))[i] for i in range(n)]
            if problem.timing is None:      # each target's residual depends on its own input only
                rows.append(u + np.r_[np.zeros(n), h[n:]])
            else:
                rows.append(u + h[n] * np.eye(len(u))[n])
            r = _residuals(np.array(rows), problem, weight)
            d = (r[1:] - r[0])
            j = np.zeros((r.shape[1], len(u)))
            j[:, :n] = (d[:n] / h[:n, None]).T
            if problem.timing is None:
                tt = len(problem.targets)
                for i in range(tt):
                    j[2 * i:2 * i + 2, n + i] = d[n, 2 * i:2 * i + 2] / h[n + i]
            else:
                j[:, n] = d[n] / h[n]
            return j
        res = least_squares(lambda u, weight=weight: _residuals(u[None], problem, weight)[0], z, jac=jac,
                            bounds=(lo, hi), method="trf", x_scale="jac", xtol=1e-12, ftol=1e-12, gtol=1e-12,
                            max_nfev=8 * len(z))
        z = res.x
        count += res.nfev * (n + 2)
        if not np.any(_residuals(z[None], problem, 1.0)[0, 2 * len(problem.targets):] > 0):
            break
    rel = z[n:] if problem.timing is None else z[n] + problem.timing
    return z[:n], rel, count


def _start(problem: _Problem, seed: int) -> tuple[list, int]:
    """One start: differential evolution over design batches, then the polish of its best members."""
    from scipy.optimize import differential_evolution
    count = [0]

    def objective(x):
        count[0] += np.shape(x)[1]
        return _score(x, problem)
    bounds = list(zip(problem.lo, problem.hi))
    if problem.timing is not None:
        bounds.append(problem.travel)
    res = differential_evolution(objective, bounds, popsize=problem.popsize, maxiter=problem.generations,
                                 tol=0.0, atol=0.0, seed=seed, vectorized=True, updating="deferred",
                                 polish=False, init="sobol", mutation=(0.5, 1.0), recombination=0.9)
    found = []
    n = len(problem.names)
    for x in res.population[np.argsort(res.population_energies, kind="stable")][:problem.keep]:
        rel = _nearest_inputs(x[:n], problem) if problem.timing is None else x[n] + problem.timing
        if rel is None:
            continue
        values, rel, used = _polish(x[:n], rel, problem)
        count[0] += used
        r = _residuals(np.r_[values, rel if problem.timing is None else rel[:1]][None], problem, 1.0)[0]
        t = len(problem.targets)
        found.append((0 if np.all(r[2 * t:] <= 0) else 1, float(np.sqrt(np.mean(r[:2 * t] ** 2) * 2)), values, rel))
    return found, count[0]


def _nearest_inputs(values, problem: _Problem, samples: int = 720):
    """The inputs (relative to the drawn pose) of the curve samples nearest to each target (T,)."""
    lo, hi = problem.travel
    fine = np.linspace(lo, hi, samples, endpoint=not problem.closed)
    xy, valid, _, _ = problem.motion(values[None], fine[None])
    if not valid.any():
        return None
    p = xy[0, :, 0]
    gap = np.where(valid[0][:, None], np.hypot(p[:, None, 0] - problem.targets[:, 0], p[:, None, 1] - problem.targets[:, 1]), np.inf)
    return fine[np.argmin(gap, axis=0)]


# -- the whole search -----------------------------------------------------------------------------------------
def synthesise_model_path(model, point: str, bounds: dict, targets, *, timing=None,
                          constraints: PathConstraints | None = None, travel=None, seed: int = 0, starts: int = 2,
                          popsize: int = 8, generations: int = 40, samples: int = 48, keep: int = 2, client=None,
                          progress=None) -> ModelPathResult:
    """Parameters of `model` within `bounds` such that its point `point` passes near `targets`.

    Parameters
    ----------
    model : str, Path, dict or Template
        A model with a `[parameters]` table.
    point : str
        The joint or point whose path is shaped.
    bounds : dict
        {parameter: (lower, upper)} in the parameter's unit: the parameters searched (others keep their
        declared values).
    targets, timing, constraints, seed, starts, popsize, generations, samples, keep, client, progress
        As in `path.synthesise_path` (timing: the input's values at the targets, SI; only the advances
        from the first target matter). `constraints.transmission_joints` names the three joints of the
        transmission angle; pivot regions name ground joints; `max_ratio` belongs to the four-bar.
    travel : (2,) sequence, optional
        The input's range about its drawn value (SI) over which the curve is traced; default a full
        turn (−π, π) of a crank input. Needed for a prismatic input.

    Returns
    -------
    ModelPathResult
        The model with the parameters found (`values`, `toml`) and its errors from mbplanar's analysis.

    Raises
    ------
    ModelError
        A model that cannot be read or has no `[parameters]`, bounds naming no parameter or not
        finite with lower < upper, a model with more than one input, an unknown `point`, constraints
        naming unknown joints or pivots off the ground, `max_ratio` (the four-bar's), a prismatic
        input without `travel`, settings below their least values (starts ≥ 1, popsize ≥ 5,
        generations ≥ 1, samples ≥ 12, keep ≥ 1), the errors of `synthesise_path` for the targets, or no
        design within the bounds that assembles through the targets without a defect.

    Examples
    --------
    The coupler point M of models/fourbar_design.toml through 8 points, its parameters b, m and h free
    (a short search; models/synthesis/path_model.toml holds the same problem for ``mbplanar synth path``):

    >>> from mbplanar.synthesis import PathConstraints, synthesise_model_path
    >>> targets = [[0.13, 0.21], [0.06, 0.22], [-0.01, 0.18], [-0.05, 0.12], [-0.03, 0.06], [0.02, 0.06],
    ...            [0.09, 0.1], [0.15, 0.17]]
    >>> bounds = {"m": (0.0, 1.0), "h": (-0.2, 0.2), "b": (0.2, 0.5)}
    >>> c = PathConstraints(min_transmission_deg=30.0, transmission_joints=("A", "B", "C"))
    >>> r = synthesise_model_path("models/fourbar_design.toml", "M", bounds, targets, constraints=c,
    ...                           starts=1, popsize=5, generations=1, samples=12, keep=1)
    >>> r.success, {k: round(v, 3) for k, v in r.values.items()}, round(r.max, 4)
    (True, {'m': 0.388, 'h': 0.06, 'b': 0.354}, 0.0049)
    """
    from ..study.run import load_template
    t0 = time.perf_counter()
    base = _task(targets, timing, constraints, PathConstraints())
    template = load_template(model)
    problem = _problem(template, point, bounds, base, travel, popsize, generations, samples, keep)
    if starts < 1 or popsize < 5 or generations < 1 or samples < 12 or keep < 1:
        raise ModelError("path generation needs starts ≥ 1, popsize ≥ 5, generations ≥ 1, samples ≥ 12, keep ≥ 1")
    results = run_starts(_start, problem, start_seeds(seed, starts), client, progress)
    evaluations = sum(r[1] for r in results)
    found = [(miss, rms, k, i, v, rel) for k, r in enumerate(results) for i, (miss, rms, v, rel) in enumerate(r[0])]
    rejected = []
    for _, _, _, _, values, rel in sorted(found, key=lambda f: f[:4]):   # within the bounds first, then best
        try:
            return _verified(problem, template, values, rel, evaluations, time.perf_counter() - t0, seed, starts)
        except MbplanarError as exc:
            rejected.append(str(exc))
    why = f"; the best had a defect: {rejected[0]}" if rejected else ""
    raise ModelError(f"{template.source}: no design found within the bounds: no candidate assembles through "
                     f"the targets on one branch{why}")


def _problem(template, point, bounds, task, travel, popsize, generations, samples, keep) -> _Problem:
    src = template.source
    c = task.constraints
    if not bounds:
        raise ModelError(f"{src}: name the parameters to search with their bounds")
    unknown = sorted(set(bounds) - set(template.parameters))
    if unknown:
        raise ModelError(f"{src}: {', '.join(unknown)} name no parameter of the model "
                         f"(parameters: {', '.join(template.names) or 'none declared'})")
    lo, hi = [], []
    for name, pair in bounds.items():
        try:
            a, b = (float(v) for v in pair)
        except (TypeError, ValueError):
            raise ModelError(f"{src}: bounds of {name} must be two numbers [lower, upper], got {pair!r}") from None
        if not (math.isfinite(a) and math.isfinite(b) and a < b):
            raise ModelError(f"{src}: bounds of {name} must be finite with lower < upper, got [{a}, {b}]")
        lo.append(a)
        hi.append(b)
    engine = Engine(parse_model(template.bind(), source=src))
    mech = engine.mech
    if len(engine.inputs) != 1:
        raise ModelError(f"{src}: path generation needs a model with one input, it has {len(engine.inputs)}")
    if point not in mech.joints and point not in mech.points:
        raise ModelError(f"{src}: no joint or point '{point}' (points: {', '.join(list(mech.points) or ['none'])})")
    periodic = mech.joints[engine.inputs[0].joint].kind == "R"
    if c.max_ratio is not None:
        raise ModelError(f"{src}: max_ratio belongs to the built-in four-bar; bound the parameters instead")
    if c.min_transmission_deg is not None and not c.transmission_joints:
        raise ModelError(f"{src}: min_transmission_deg needs transmission_joints = [J1, J2, J3] (the angle at J2)")
    for name in list(c.transmission_joints or ()) + list(c.pivots):
        if name not in mech.joints:
            raise ModelError(f"{src}: constraint names no joint '{name}' (joints: {', '.join(mech.joints)})")
    for name in c.pivots:
        if mech.ground not in mech.joints[name].links:
            raise ModelError(f"{src}: pivot region of {name}: not a fixed pivot (a joint on the ground link)")
    if travel is None:
        if not periodic:
            raise ModelError(f"{src}: a prismatic input needs its travel (the range about the drawn pose)")
        travel = (-math.pi, math.pi) if not c.full_turn or task.timing is not None else (0.0, TWO_PI)
    travel = (float(travel[0]), float(travel[1]))
    if not travel[0] < travel[1]:
        raise ModelError(f"{src}: travel must be [lower, upper] with lower < upper")
    if c.full_turn and not periodic:
        c = PathConstraints(False, c.min_transmission_deg, c.max_ratio, c.pivots, c.transmission_joints)
    template.bind({n: v for n, v in zip(bounds, lo)})
    return _Problem(template.raw, src, point, tuple(bounds), np.array(lo), np.array(hi), task.targets,
                    task.timing, c, travel, periodic, popsize, generations, samples, keep)


def _verified(problem: _Problem, template, values, rel, evaluations, seconds, seed, starts) -> ModelPathResult:
    """The model with the found values, checked and measured by mbplanar."""
    found = {n: float(v) for n, v in zip(problem.names, values)}
    raw = dict(template.raw)
    params = dict(raw.get("parameters", {}))
    for n, v in found.items():
        params[n] = {**params[n], "value": v} if isinstance(params[n], dict) else v
    raw["parameters"] = params
    text = table_toml(raw, f"{template.source} with parameters from path synthesis (seed {seed})")
    from ..model import Template
    mech = parse_model(Template(raw, template.source).bind(), source=template.source)
    engine = Engine(mech)
    phi0 = float(engine.phi_drawn[0])
    node_phi = phi0 + np.asarray(rel, float)
    c = problem.constraints
    xy, _, _, _ = problem.motion(np.asarray(values)[None], np.asarray(rel)[None])
    defects = check_defects(engine, node_phi, {problem.point: xy[0, :, 0]}, periodic=problem.periodic,
                            full_turn=c.full_turn and problem.periodic, tol=1e-6 * problem.size)
    if defects.circuit or defects.unreached or defects.branch or defects.full_turn is False:
        raise ModelError(dataclasses.replace(defects, order=False).describe())
    warnings = ["the design meets the targets out of order (no input sense reaches them in turn)"] \
        if defects.order else []
    node_phi = np.asarray(defects.node_phi)
    m = analyse(engine, node_phi)
    errors = np.hypot(*(m.xy[:, m.point(problem.point)] - problem.targets).T)
    lo, hi = problem.travel
    dense = analyse(engine, phi0 + np.linspace(lo, hi, 1441) if not problem.closed else
                    node_phi[0] + np.linspace(0.0, TWO_PI, 1441))
    if problem.timing is None:  # the nearest point of the analysed path, where nearer than the polished foot
        errors = np.minimum(errors, nearest_on_model(engine, problem.point, problem.targets, dense))
    mu = float("nan")
    if c.transmission_joints:
        j = [dense.xy[:, dense.point(n)] for n in c.transmission_joints]
        mu = float(np.degrees(transmission_angles(*j).min()))
        if c.min_transmission_deg is not None and mu < c.min_transmission_deg - 1e-9:
            warnings.append(f"the smallest transmission angle {mu:.2f}° is below the bound "
                            f"{c.min_transmission_deg:g}° (no design found meets it)")
    success = not warnings
    message = "defect-free design within the constraints" if success else "design found, but " + "; ".join(warnings)
    return ModelPathResult(text, mech, problem.targets, errors, node_phi, defects, evaluations, seconds, seed,
                           starts, problem.timing is not None, mu, c, success, message, tuple(warnings),
                           values=found, point=problem.point, travel=problem.travel)
