"""The Monte Carlo of tolerances: N made designs drawn from the bands (seeded, numpy's Generator), each
closed in its drawn pose (`made.made_geometry`) and solved over the cycle by a study's design batch
(`mbplanar.study.DesignBatch`, numpy or the compiled backend), in chunks of designs that run here one
after the other or one task each on a Dask cluster (`mbplanar.study.cluster`).

The samples are drawn once, before any chunk is cut, dimension by dimension (uniform between a band's
limits, normal for a `sigma` row), so that the answer does not depend on the chunks nor on the workers.
Each chunk gives the count, mean, sum of squared deviations, minimum and maximum of every output at every
position over its designs that assemble and reach every position of the cycle; chunks are merged in
order (Chan's pairwise update). Designs that do not assemble at the drawn input, and designs that lock
inside the cycle (a motion limit before some position), are counted, and the dimensions that cause them
are those most correlated with failing (the point-biserial correlation of each dimension's deviation
with the failure, reported where it is beyond four standard errors, 4/√N).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import Interrupted
from .made import made_geometry

__all__ = ["MonteCarlo", "Cause", "draw", "monte_carlo", "CHUNK_VALUES"]

CHUNK_VALUES = 4_000_000   # designs × positions × outputs per chunk: bounds the chunk's memory (~32 MB)


@dataclass(frozen=True)
class Cause:
    """A dimension that goes with failing designs in a Monte Carlo.

    Attributes
    ----------
    dimension : str
        The dimension's name.
    correlation : float
        Its correlation with the failure, −1 … 1 (positive: the failures lie towards its upper limit).
    mean_deviation : float
        The failing samples' mean deviation, in the dimension's unit.

    Examples
    --------
    See `monte_carlo` for causes found; one made by hand:

    >>> from mbplanar.accuracy import Cause
    >>> Cause("links.2.length", -0.58, -0.215).correlation < 0       # failures towards a short rod
    True
    """

    dimension: str
    correlation: float
    mean_deviation: float


@dataclass(frozen=True)
class MonteCarlo:
    """The Monte Carlo's answer over N positions for Y outputs (SI: m, rad).

    Attributes
    ----------
    samples, seed : int
        What was drawn.
    count : int
        Designs that assemble and reach every position.
    mean, std, low, high : (N, Y) ndarray
        The outputs' mean, standard deviation, least and largest values over those designs.
    not_assembled : float
        Fraction of all samples that do not assemble at the drawn input.
    locking : float
        Fraction that assemble but lock inside the cycle.
    causes : dict
        {"not_assembled": (Cause, ...), "locking": (Cause, ...)}: the dimensions going with each.

    Examples
    --------
    The slider-crank's rod ±0.1 mm: at 90° the slider's standard deviation tends to
    1.06066·0.1 mm/√3 = 0.061237 mm:

    >>> import numpy as np
    >>> from mbplanar.accuracy import DesignSpace, Tolerance, monte_carlo, resolve_outputs
    >>> from mbplanar.accuracy.run import load
    >>> template, raw, engine = load("models/slider_crank.toml")
    >>> space = DesignSpace(engine, raw, template, ["links.2.length"])
    >>> mc = monte_carlo(space, [Tolerance("links.2.length", -1e-4, 1e-4)], np.radians([90.0]),
    ...                  resolve_outputs(engine.mech, ["Bp.x"]), samples=4000, seed=0)
    >>> mc.count, bool(abs(mc.std[0, 0] / 6.1237e-5 - 1) < 0.05)
    (4000, True)
    """

    samples: int
    seed: int
    count: int
    mean: np.ndarray
    std: np.ndarray
    low: np.ndarray
    high: np.ndarray
    not_assembled: float
    locking: float
    causes: dict

    @property
    def success(self) -> bool:
        return self.count == self.samples

    @property
    def message(self) -> str:
        if self.success:
            return f"{self.samples} samples, every one assembled and reached every position"
        return (f"{self.samples} samples: {100 * self.not_assembled:.3g} % do not assemble, "
                f"{100 * self.locking:.3g} % lock inside the cycle")


def draw(tolerances, samples: int, seed: int) -> np.ndarray:
    """The Monte Carlo's deviations of every sample, dimension by dimension.

    Uniform between a band's limits, or normal with a row's sigma, from numpy's `Generator` seeded
    `seed`: the same seed gives the same designs.

    Parameters
    ----------
    tolerances : sequence of Tolerance
        One row per dimension.
    samples : int
        How many samples.
    seed : int
        The generator's seed.

    Returns
    -------
    (samples, K) ndarray
        Deviations in the dimensions' units.

    Raises
    ------
    ValueError
        A negative `samples` (numpy's error).

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.accuracy import Tolerance, draw
    >>> x = draw([Tolerance("links.2.length", -1e-4, 1e-4), Tolerance("links.1.length", sigma=1e-5)],
    ...          100000, seed=0)
    >>> x.shape, bool(np.abs(x[:, 0]).max() <= 1e-4), np.round(x.std(axis=0) / [1e-4 / np.sqrt(3), 1e-5], 2).tolist()
    ((100000, 2), True, [1.0, 1.0])
    """
    rng = np.random.default_rng(seed)
    out = np.empty((samples, len(tolerances)))
    for k, t in enumerate(tolerances):
        out[:, k] = rng.normal(0.0, t.sigma, samples) if t.sigma is not None else rng.uniform(t.lower, t.upper,
                                                                                               samples)
    return out


def _needed(engine, outputs):
    """The points and links a design batch must give for `outputs`, and for each prismatic joint's value a
    revolute joint of its moving carrier (its frame)."""
    mech = engine.mech
    points, links, frames = [], [], {}

    def need(lst, x):
        if x not in lst:
            lst.append(x)

    for o in outputs:
        if o.kind in ("x", "y"):
            need(points, o.target)
        elif o.kind == "angle":
            need(links, o.target)
        else:
            j = mech.joints[o.target]
            if j.kind == "R":
                need(links, j.links[0])
                need(links, j.links[1])
                continue
            need(points, j.name)
            if j.carrier != mech.ground:
                ref = next((r.name for r in mech.joints_of(j.carrier) if r.kind == "R"), None)
                if ref is None:
                    raise ValueError(f"{o.name}: the carrier '{j.carrier}' of a prismatic value has no revolute "
                                     "joint to follow its frame")
                frames[j.name] = ref
                need(points, ref)
                need(links, j.carrier)
    return points, links, frames


def _values(engine, geometry, motion, outputs, frames, designs) -> np.ndarray:
    """The outputs (D, N, Y) of a solved chunk."""
    mech = engine.mech
    D, N = motion.valid.shape
    out = np.empty((D, N, len(outputs)))
    for y, o in enumerate(outputs):
        if o.kind in ("x", "y"):
            out[:, :, y] = motion.xy[:, :, motion.point(o.target), "xy".index(o.kind)]
        elif o.kind == "angle":
            out[:, :, y] = motion.angle[:, :, motion.link(o.target)]
        else:
            j = mech.joints[o.target]
            if j.kind == "R":
                out[:, :, y] = motion.angle[:, :, motion.link(j.links[1])] - motion.angle[:, :, motion.link(j.links[0])]
                continue
            xs = motion.xy[:, :, motion.point(j.name)]                       # (D, N, 2)
            at = geometry.at[j.name].T[:, None, :]                           # (D, 1, 2)
            u = geometry.guide[j.name].T[:, None, :]
            if j.name in frames:
                ref = frames[j.name]
                turn = motion.angle[:, :, motion.link(j.carrier)] - geometry.reference[j.carrier][:, None]
                c, s = np.cos(turn), np.sin(turn)
                arm = at - geometry.at[ref].T[:, None, :]
                xr = motion.xy[:, :, motion.point(ref)]
                at = xr + np.stack([c * arm[..., 0] - s * arm[..., 1], s * arm[..., 0] + c * arm[..., 1]], axis=-1)
                u = np.stack([c * u[..., 0] - s * u[..., 1], s * u[..., 0] + c * u[..., 1]], axis=-1)
            out[:, :, y] = np.sum(u * (xs - at), axis=-1)
    return out


@dataclass
class _Moments:
    """Running statistics of a chunk (merged in order): count, mean, M2, min, max (N, Y), and per sample
    whether it assembled and whether it reached every position."""

    count: int
    mean: np.ndarray
    m2: np.ndarray
    low: np.ndarray
    high: np.ndarray
    assembled: np.ndarray
    reached: np.ndarray

    def merge(self, other: "_Moments") -> "_Moments":
        n = self.count + other.count
        if other.count == 0:
            mean, m2 = self.mean, self.m2
        elif self.count == 0:
            mean, m2 = other.mean, other.m2
        else:
            delta = other.mean - self.mean
            mean = self.mean + delta * (other.count / n)
            m2 = self.m2 + other.m2 + delta * delta * (self.count * other.count / n)
        return _Moments(n, mean, m2, np.fmin(self.low, other.low), np.fmax(self.high, other.high),
                        np.concatenate([self.assembled, other.assembled]), np.concatenate([self.reached, other.reached]))


def solve_chunk(space, source, part, phi, outputs) -> _Moments:
    """The statistics of one chunk (a Dask task): `part` the deviations (D, K) in SI. The design batch runs
    on the space's engine's backend."""
    from ..study.batch import DesignBatch

    engine = space.engine
    geometry = made_geometry(engine, space.sided(part))
    points, links, frames = _needed(engine, outputs)
    batch = DesignBatch(engine, geometry)
    with np.errstate(all="ignore"):
        motion = batch.solve(phi, exact_limits=False, fallback=True, points=points, links=links,
                             accelerations=False)
    assembled = np.array([r is None for r in geometry.reasons]) & motion.ok
    reached = assembled & np.all(motion.valid, axis=1)
    good = np.flatnonzero(reached)
    shape = (len(phi), len(outputs))
    if not len(good):
        return _Moments(0, np.zeros(shape), np.zeros(shape), np.full(shape, np.inf), np.full(shape, -np.inf),
                        assembled, reached)
    values = _values(engine, geometry, motion, outputs, frames, good)[good]
    mean = values.mean(axis=0)
    return _Moments(len(good), mean, ((values - mean) ** 2).sum(axis=0), values.min(axis=0), values.max(axis=0),
                    assembled, reached)


def _causes(deviations, failed, names) -> tuple:
    """The dimensions correlated with `failed` (samples,) beyond four standard errors, strongest first."""
    n = len(failed)
    if not failed.any() or failed.all():
        return ()
    f = failed.astype(float) - failed.mean()
    out = []
    for k, name in enumerate(names):
        x = deviations[:, k] - deviations[:, k].mean()
        norm = np.sqrt((x * x).sum() * (f * f).sum())
        if norm == 0:
            continue
        r = float((x * f).sum() / norm)
        if abs(r) > 4.0 / np.sqrt(n):
            out.append(Cause(name, r, float(deviations[failed, k].mean())))
    return tuple(sorted(out, key=lambda c: -abs(c.correlation)))


def monte_carlo(space, tolerances, phi, outputs, samples: int = 100_000, seed: int = 0,
                chunk: int | None = None, client=None, progress=None) -> MonteCarlo:
    """The Monte Carlo of `tolerances` over the positions `phi` (SI, (N,)).

    Parameters
    ----------
    space : DesignSpace
        The model and its toleranced dimensions (the order of `tolerances`).
    tolerances : sequence of Tolerance
        The bands, in the dimensions' units.
    phi : array_like
        The positions (input values, SI).
    outputs : sequence of Output
        What is measured.
    samples, seed : int
        How many designs, and the Generator's seed.
    chunk : int, optional
        Designs per chunk (default: about `CHUNK_VALUES` values each).
    client : dask.distributed.Client, optional
        Run the chunks as Dask tasks (`mbplanar.study.cluster`).
    progress : callable, optional
        progress(done, total) after each chunk (samples done so far).

    Returns
    -------
    MonteCarlo
        The outputs' statistics over the designs that assemble and turn, and the causes of the others.

    Raises
    ------
    ValueError
        `samples` below 1.
    Interrupted
        Ctrl-C during the run (the message says how many samples were done).

    Examples
    --------
    A slider-crank's rod made up to 0.25 m short of its 0.3 m: some designs do not assemble at the
    drawn 45°, some lock (rod shorter than the crank) inside the turn, and the rod's length is the cause:

    >>> import numpy as np
    >>> from mbplanar.accuracy import DesignSpace, Tolerance, monte_carlo, resolve_outputs
    >>> from mbplanar.accuracy.run import load
    >>> template, raw, engine = load("models/slider_crank.toml")
    >>> space = DesignSpace(engine, raw, template, ["links.1.length", "links.2.length"])
    >>> tolerances = [Tolerance("links.1.length", -0.01, 0.01), Tolerance("links.2.length", -0.25, 0.0)]
    >>> phi = np.linspace(0.0, 2 * np.pi, 8, endpoint=False)
    >>> mc = monte_carlo(space, tolerances, phi, resolve_outputs(engine.mech, ["Bp.x"]), samples=400, seed=0)
    >>> 0 < mc.not_assembled < 0.2, 0 < mc.locking < 0.2, mc.count < 400
    (True, True, True)
    >>> [c.dimension for c in mc.causes["locking"]]
    ['links.2.length']
    """
    phi = np.asarray(phi, float).reshape(-1)
    outputs = tuple(outputs)
    if samples < 1:
        raise ValueError(f"samples must be at least 1, got {samples}")
    units = draw(tolerances, samples, seed)
    scale = np.array([d.scale for d in space.dimensions])
    deviations = units * scale
    size = chunk or max(1, CHUNK_VALUES // max(1, len(phi) * (len(outputs) + 2)))
    parts = [deviations[k:k + size] for k in range(0, samples, size)]
    if client is not None:
        from ..study.cluster import run_on_client

        results = run_on_client(client, _task, space, space.source, parts, (phi, outputs),
                                progress=progress)
    else:
        results, done = [], 0
        try:
            for part in parts:
                results.append(solve_chunk(space, space.source, part, phi, outputs))
                done += len(part)
                if progress is not None:
                    progress(done, samples)
        except KeyboardInterrupt:
            raise Interrupted(f"interrupted (Ctrl-C) after {done} of {samples} samples", source=space.source) from None
    total = results[0]
    for r in results[1:]:
        total = total.merge(r)
    std = np.sqrt(total.m2 / max(total.count - 1, 1)) if total.count else np.full_like(total.mean, np.nan)
    empty = np.full_like(total.mean, np.nan)
    not_assembled = ~total.assembled
    locking = total.assembled & ~total.reached
    names = [d.name for d in space.dimensions]
    causes = {"not_assembled": _causes(units, not_assembled, names),
              "locking": _causes(units[total.assembled], locking[total.assembled], names)}
    return MonteCarlo(samples, seed, total.count, total.mean if total.count else empty, std,
                      total.low if total.count else empty, total.high if total.count else empty,
                      float(not_assembled.mean()), float(locking.mean()), causes)


def _task(space, source, part, phi, outputs):
    return solve_chunk(space, source, part, phi, outputs)
