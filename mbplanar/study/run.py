"""Running a design study: every variant of a table summarised, in chunks of designs that run one
after the other here, or one task each on a Dask cluster (`client`). The chunks are the same either
way, and each is computed by the same function from the same data, so a study on a cluster equals the
serial run bit for bit."""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._progress import Interrupted
from ..errors import MbplanarError, ModelError, did_you_mean
from ..model import Template, Units, parse_model
from ..forces import has_force_data
from ..kinematics import analyse
from .summary import SAMPLES, DesignSummary, _forces, failed_design, summarise, summarise_design, with_forces
from .variants import Variants, read_variants

__all__ = ["Study", "run_study", "solve_designs", "load_template", "join_motions", "CHUNK"]

CHUNK = 64  # designs per task
FULL_TURN = 2 * np.pi


@dataclass(frozen=True)
class Study:
    r"""The summaries of a study's designs, in table order, and what they were computed for.

    Attributes
    ----------
    model, source : str
        The model's name and file.
    input, unit : str
        The input's name and unit.
    parameters : tuple of str
        The parameters' names.
    designs : list of DesignSummary
        One per design.
    counts : dict
        {"designs", "assembled", "full_turn", "locking"}: how many.
    units : Units
        The model's units (the summaries' lengths and angles are in them).

    Examples
    --------
    >>> import os, tempfile
    >>> from mbplanar.study import run_study
    >>> path = os.path.join(tempfile.mkdtemp(), "couplers.csv")
    >>> _ = open(path, "w").write("variant,b\nlong,0.35\nshort,0.12\n")
    >>> study = run_study("models/fourbar_design.toml", path, samples=12)
    >>> study.parameters[:3], study.counts
    (('a', 'b', 'd'), {'designs': 2, 'assembled': 2, 'full_turn': 1, 'locking': 1})
    """

    model: str
    source: str
    input: str
    unit: str
    parameters: tuple
    designs: list[DesignSummary]
    counts: dict  # how many designs: in all, assembled, turning fully, stopping at a motion limit
    units: Units = field(default_factory=Units)   # the units the model was written in


def _counts(designs: list) -> dict:
    """`Study.counts` of the summaries `designs`."""
    ok = [d for d in designs if d.assembles]
    return {"designs": len(designs), "assembled": len(ok), "full_turn": sum(bool(d.full_turn) for d in ok),
            "locking": sum(bool(d.limits) and not d.full_turn for d in ok)}


def load_template(model) -> Template:
    """The `Template` (a model with parameters) of a model file, a parsed table, or a Template as it is.

    Parameters
    ----------
    model : str, Path, dict or Template
        A model file's path, the table as `tomllib` gives it, or a `Template`.

    Returns
    -------
    Template
        The model's table with its parameters; `Template.bind(values)` gives a model's table for
        other parameter values.

    Raises
    ------
    ModelError
        A file that cannot be read or is not TOML (the message names it).

    Examples
    --------
    >>> import tomllib
    >>> from mbplanar.study import load_template
    >>> template = load_template("models/fourbar_design.toml")
    >>> list(template.parameters)
    ['a', 'b', 'd', 'theta0', 'beta', 'm', 'h']
    >>> load_template(tomllib.load(open("models/fourbar_design.toml", "rb"))).parameters["b"].value
    0.3
    """
    if isinstance(model, Template):
        return model
    if isinstance(model, dict):
        return Template(model)
    path = Path(model)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise ModelError(f"{path}: cannot read the model file ({exc})") from None
    try:
        return Template(tomllib.loads(text), str(path))
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"{path}: TOML syntax error: {exc}") from None


def _base_engine(template: Template):
    from ..engine import Engine

    return Engine(parse_model(template.bind(), source=template.source))


def run_chunk(data: dict, source: str, variants: Variants, points=(), samples: int = SAMPLES,
              forces=None, method: str = "batch") -> list[DesignSummary]:
    """Summaries of a chunk of designs (one Dask task).

    method "serial": the reference engine is re-dimensioned for each design, which then walks its own
    branch (`summarise_design`). "batch": a `DesignBatch` marches every design's branch at once, over a
    whole turn either way from the drawn pose, and locates their limits; each design's summary then reads
    the atlas its march built (`DesignBatch.seeded_engine`), so it walks no further itself.
    """
    template = Template(data, source)
    base = _base_engine(template)
    values = [{**template.defaults(), **variants.row(k)} for k in range(len(variants))]
    if method == "serial" or base.mech.joints[base.inputs[0].joint].kind != "R":
        return [summarise_design(base, template, variants.names[k], values[k], points, samples, forces)
                for k in range(len(variants))]
    from .batch import DesignBatch
    from .geometry import design_geometry

    batch = DesignBatch(base, design_geometry(template, variants, base.mech))
    phi0 = batch.geometry.phi0
    with np.errstate(invalid="ignore"):
        batch.solve(np.stack([phi0 - FULL_TURN, phi0 + FULL_TURN], axis=1))
    out = []
    for k in range(len(variants)):
        name = variants.names[k]
        if batch.reasons[k] is not None:
            out.append(failed_design(name, values[k], batch.reasons[k]))
            continue
        try:
            out.append(summarise(batch.seeded_engine(k), name, values[k], points, samples, False))
        except MbplanarError as exc:
            out.append(failed_design(name, values[k], str(exc)))
    if has_force_data(base.mech) if forces is None else forces:
        _batch_forces(batch, template, variants, out)
    return out


def _batch_forces(batch, template: Template, variants: Variants, out: list):
    """The largest reaction and the mean balancing load over each summary's samples, all designs'
    samples in one design batch and one kinetostatic solve (`design_kinetostatics`); where the model has
    loads that solve declines, each design's own `kinetostatics`."""
    from .batch import DesignBatch, _take_geometry
    from .forces import design_kinetostatics

    idx = np.array([k for k, d in enumerate(out) if d.assembles and d.samples_phi is not None
                    and len(d.samples_phi)], int)
    if not len(idx):
        return
    inp = batch.engine.inputs[0]
    rows = [inp.to_si(np.asarray(out[k].samples_phi, float)) for k in idx]  # fewer where a design locks
    width = max(len(r) for r in rows)
    phi = np.stack([np.concatenate([r, np.full(width - len(r), r[0])]) for r in rows])
    sub = DesignBatch(batch.engine, _take_geometry(batch.geometry, idx))
    with np.errstate(invalid="ignore"):
        motion = sub.solve(phi)
        motion.valid[...] &= np.arange(width) < np.array([len(r) for r in rows])[:, None]  # not the padding
        got = design_kinetostatics(sub, motion, template, variants.take(idx))
    if got is None:
        for k in idx:
            engine = batch.seeded_engine(int(k))
            out[k] = with_forces(out[k], *_forces(engine, analyse(engine, inp.to_si(np.asarray(out[k].samples_phi,
                                                                                                float)))))
        return
    largest, joints = got.largest()
    mean = got.mean_balancing()
    for i, k in enumerate(idx):
        out[k] = with_forces(out[k], None if joints[i] is None else float(largest[i]), joints[i],
                             None if not np.isfinite(mean[i]) else float(mean[i]))


def _chunks(count: int, size: int) -> list[slice]:
    return [slice(start, min(start + size, count)) for start in range(0, count, size)]


def run_study(model, variants, *, points=(), samples: int = SAMPLES, forces=None, client=None,
              chunk: int = CHUNK, progress=None, method: str = "batch") -> Study:
    """Summarise every design of a variant table: assembly, full turn or limits, extremes, transmission
    angle, and with loads the reactions.

    Parameters
    ----------
    model : str, Path, dict or Template
        The model with its `[parameters]`.
    variants : Variants or str or Path
        The designs (a `Variants`, or the path of a CSV variant table).
    points : sequence of str
        Points whose coupler curves are sampled.
    samples : int
        Samples per design over its range of motion.
    forces : bool, optional
        Reactions and balancing moment (default: when the model has loads or masses).
    client : dask.distributed.Client, optional
        Run the chunks as tasks on this client's cluster; default: here, one after the other.
    chunk : int
        Designs per chunk (per task).
    progress : callable, optional
        Called as progress(done, total) after each chunk (designs done so far).
    method : {"batch", "serial"}
        "batch" marches the designs of a chunk together (`run_chunk`); "serial" is the reference, one
        engine per design through the public API.

    Returns
    -------
    Study
        One `DesignSummary` per design, in table order, and the counts.

    Raises
    ------
    ValueError
        `chunk` below 1 or an unknown `method`.
    ModelError
        A model with more than one input, a point it does not have, or a model or table that cannot
        be read.
    Interrupted
        Ctrl-C (the message says how many designs were done).

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.study import load_template, run_study, variants_from
    >>> template = load_template("models/fourbar_design.toml")
    >>> study = run_study(template, variants_from(template, {"b": np.array([0.3, 0.12])}), samples=12)
    >>> [(d.name, d.full_turn) for d in study.designs], study.counts["locking"]
    ([('1', True), ('2', False)], 1)
    """
    template = load_template(model)
    if not isinstance(variants, Variants):
        variants = read_variants(variants, template)
    if chunk < 1:
        raise ValueError(f"chunk must be a positive number of designs, not {chunk}")
    if method not in ("batch", "serial"):
        raise ValueError(f"method must be 'batch' or 'serial', not {method!r}")
    base = _base_engine(template)
    if len(base.inputs) != 1:
        raise ModelError(f"{template.source}: a design study drives one input; this model has {len(base.inputs)}")
    for p in points:
        if p not in base.mech.joints and p not in base.mech.points:
            raise ModelError(f"{template.source}: point '{p}' is neither a joint nor a point of the model; "
                             f"{did_you_mean(p, [*base.mech.joints, *base.mech.points], 'joints and points')}")
    parts = [variants.take(s) for s in _chunks(len(variants), chunk)]
    args = (tuple(points), samples, forces, method)
    inp = base.inputs[0]
    if client is None:
        results, done = [], 0
        try:
            for part in parts:
                results.append(run_chunk(template.raw, template.source, part, *args))
                done += len(part)
                if progress is not None:
                    progress(done, len(variants))
        except KeyboardInterrupt:
            done_designs = [d for part in results for d in part]
            partial = Study(base.mech.name, template.source, inp.name, inp.unit, template.names, done_designs,
                            _counts(done_designs), base.mech.units)
            raise Interrupted(f"interrupted (Ctrl-C) after {done} of {len(variants)} designs",
                              source=template.source, partial=partial) from None
    else:
        from .cluster import run_on_client

        results = run_on_client(client, run_chunk, template.raw, template.source, parts, args, progress)
    designs = [d for part in results for d in part]
    return Study(base.mech.name, template.source, inp.name, inp.unit, template.names, designs, _counts(designs),
                 base.mech.units)


def solve_chunk(data: dict, source: str, variants: Variants, phi, exact_limits: bool = True,
                fallback: bool = True, backend: str = "numpy", points=None, accelerations: bool = True, links=None):
    """The kinematics of a chunk of designs (one Dask task): a `DesignBatch` solved at `phi`."""
    from .batch import design_batch

    return design_batch(Template(data, source), variants, backend=backend).solve(phi, exact_limits, fallback, points,
                                                                                accelerations, links)


def solve_designs(model, variants, phi, *, exact_limits: bool = True, fallback: bool = True, client=None,
                  chunk: int = 2000, progress=None, backend: str = "numpy", points=None,
                  accelerations: bool = True, links=None):
    """The kinematics of every design of a variant table at input values `phi` (SI): a design batch, here
    or, with `client`, one Dask task per chunk of designs.

    Parameters
    ----------
    model : str, Path, dict or Template
        The model with its `[parameters]`.
    variants : Variants, dict or str
        The designs (a `Variants`, parameter arrays (D,), or a CSV variant table's path).
    phi : array_like
        (N,) input values for every design, or (D, N) one row per design (SI).
    exact_limits, fallback : bool
        See `DesignBatch.solve`.
    client : dask.distributed.Client, optional
        Run the chunks on this client's cluster.
    chunk : int
        Designs per chunk (per task).
    progress : callable, optional
        progress(done, total) after each chunk.
    backend : {"numpy", "numba"}
        The design batch's loops (`design_batch`).
    points, accelerations, links
        What each design's motion holds (`DesignBatch.solve`).

    Returns
    -------
    DesignMotion
        The chunks joined in table order (limits renumbered to the table's designs).

    Raises
    ------
    ValueError
        `chunk` below 1, or `phi` the batch refuses (see `DesignBatch`).
    ModelError
        A model or variant table that cannot be read.

    Examples
    --------
    The same as one design batch, cut into chunks of one design:

    >>> import numpy as np
    >>> from mbplanar.study import design_batch, solve_designs
    >>> b = {"b": np.array([0.3, 0.35, 0.12])}
    >>> phi = np.radians([0.0, 90.0, 180.0])
    >>> chunked = solve_designs("models/fourbar_design.toml", b, phi, chunk=1)
    >>> whole = design_batch("models/fourbar_design.toml", b).solve(phi)
    >>> bool(np.array_equal(chunked.valid, whole.valid)), bool(np.allclose(chunked.xy, whole.xy, equal_nan=True))
    (True, True)
    """
    from .variants import variants_from

    template = load_template(model)
    if isinstance(variants, dict):
        variants = variants_from(template, variants)
    elif not isinstance(variants, Variants):
        variants = read_variants(variants, template)
    if chunk < 1:
        raise ValueError(f"chunk must be a positive number of designs, not {chunk}")
    phi = np.asarray(phi, float)
    slices = _chunks(len(variants), chunk)
    parts = [variants.take(s) for s in slices]
    rows = [phi if phi.ndim == 1 else phi[s] for s in slices]
    if client is None:
        results, done = [], 0
        for part, x in zip(parts, rows):
            results.append(solve_chunk(template.raw, template.source, part, x, exact_limits, fallback, backend,
                                       points, accelerations, links))
            done += len(part)
            if progress is not None:
                progress(done, len(variants))
    else:
        from .cluster import run_on_client

        tasks = [(part, x) for part, x in zip(parts, rows)]
        results = run_on_client(client, _solve_task, template.raw, template.source, tasks,
                                (exact_limits, fallback, backend, points, accelerations, links), progress)
    return join_motions(results, [s.start for s in slices])


def _solve_task(data, source, task, exact_limits, fallback, backend="numpy", points=None, accelerations=True,
                links=None):
    part, phi = task
    return solve_chunk(data, source, part, phi, exact_limits, fallback, backend, points, accelerations, links)


def join_motions(parts: list, offsets: list):
    """One `DesignMotion` of chunks of designs, in order, limits renumbered to the joined designs.

    Parameters
    ----------
    parts : list of DesignMotion
        The chunks' motions (the same positions count, points and links).
    offsets : list of int
        Each chunk's first design in the joined table.

    Returns
    -------
    DesignMotion
        The designs of every chunk, in order.

    Raises
    ------
    ValueError
        Chunks whose arrays do not stack (numpy's error).

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.study import design_batch, join_motions
    >>> phi = np.radians(np.arange(0.0, 360.0, 30.0))
    >>> one = design_batch("models/fourbar_design.toml", {"b": np.array([0.3])}).solve(phi)
    >>> two = design_batch("models/fourbar_design.toml", {"b": np.array([0.12])}).solve(phi)
    >>> joined = join_motions([one, two], [0, 1])
    >>> joined.phi.shape, [lim.design for lim in joined.limits]
    ((2, 12), [1])
    """
    from dataclasses import replace

    first = parts[0]
    arrays = {name: None if getattr(first, name) is None else np.concatenate([getattr(p, name) for p in parts])
              for name in ("phi", "valid", "ok", "angle", "wq", "eq", "xy", "vq", "aq")}
    limits = [replace(lim, design=lim.design + off) for p, off in zip(parts, offsets) for lim in p.limits]
    reasons = [r for p in parts for r in p.reasons]
    return replace(first, **arrays, limits=limits, reasons=reasons)
