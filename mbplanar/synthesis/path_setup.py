"""The inputs of `mbplanar synth path`: targets from CSV or TOML, the model and its parameter bounds,
constraints, search settings, the Dask client and the progress bar, gathered into one problem.

A TOML input holds `targets = [[x, y], ...]` (or `[[x, y, input], ...]` with `timed = true`; or
`targets_csv = "file.csv"`), an optional `[model]` table {file, point, travel} with `[parameters]`
bounds {name = [lower, upper]}, `[constraints]` (`constraints.read_constraints`) and `[search]`
{seed, starts, popsize, generations, samples, keep}. Options on the command line win.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._progress import shown
from ..errors import ModelError
from .constraints import PathConstraints, read_constraints

__all__ = ["PathProblem", "path_problem"]

SEARCH_KEYS = ("seed", "starts", "popsize", "generations", "samples", "keep")


@dataclass
class PathProblem:
    """A path-generation run: targets (T, 2), timing (T,) SI or None, constraints, the model (None: the
    built-in four-bar) with its point, bounds and travel, search settings and the Dask choice."""

    targets: np.ndarray
    timing: np.ndarray | None
    constraints: PathConstraints
    model: str | None = None
    point: str | None = None
    bounds: dict = field(default_factory=dict)
    travel: tuple | None = None
    search: dict = field(default_factory=dict)
    workers: int | None = None
    scheduler: str | None = None
    progress: bool = False
    yes: bool = False

    def run(self):
        """Synthesise (serially or on Dask, with the progress bar when asked, and the time estimate of
        `mbplanar._progress.Progress` from the first starts)."""
        from .._progress import Progress
        from ..study.cluster import close, connect, local_client
        client = local_client(self.workers) if self.workers else connect(self.scheduler) if self.scheduler else None
        starts = self.search.get("starts", 8 if self.model is None else 2)
        update = Progress(starts, "starts", show=self.progress, what=f"a search of {starts} starts", yes=self.yes)
        done = update.close
        try:
            if self.model is None:
                from .path import synthesise_path
                return synthesise_path(self.targets, timing=self.timing, constraints=self.constraints,
                                       client=client, progress=update, **self.search)
            from .path_model import synthesise_model_path
            return synthesise_model_path(self.model, self.point, self.bounds, self.targets, timing=self.timing,
                                         constraints=self.constraints, travel=self.travel, client=client,
                                         progress=update, **self.search)
        finally:
            done()
            if client is not None:
                close(client)

    def design(self, r) -> dict:
        """The design's numbers for the summary: the four-bar's columns, or the parameters found."""
        if self.model is not None:
            return dict(r.values)
        from .batch import DESIGN_COLUMNS
        return {k: float(v) for k, v in zip(DESIGN_COLUMNS, r.design)}


def _pivot(text: str) -> tuple:
    name, _, box = text.partition("=")
    try:
        v = [float(x) for x in box.split(",")]
    except ValueError:
        v = []
    if not name.strip() or len(v) != 4:
        raise ModelError(f"--pivot {text!r}: expected NAME=XMIN,YMIN,XMAX,YMAX")
    return name.strip(), [v[:2], v[2:]]


def _vary(text: str) -> tuple:
    name, _, span = text.partition("=")
    lo, _, hi = span.partition(":")
    try:
        return name.strip(), (float(lo), float(hi))
    except ValueError:
        raise ModelError(f"--vary {text!r}: expected NAME=LOWER:UPPER") from None


def _int(value, key: str, least: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < least:
        raise ModelError(f"{key} must be a whole number ≥ {least}, got {value!r}")
    return value


def path_problem(args) -> PathProblem:
    """The problem the command line (and its TOML input) describes."""
    from .command import csv_rows, read_toml
    src = args.input
    data = read_toml(src) if str(src).lower().endswith(".toml") else {}
    known = ("targets", "targets_csv", "timed", "model", "parameters", "constraints", "search")
    unknown = sorted(set(data) - set(known))
    if unknown:
        raise ModelError(f"unknown key(s) {', '.join(unknown)} (known: {', '.join(known)})", source=str(src))
    timed = bool(args.timed or data.get("timed", False))
    width = 3 if timed else 2
    if data:
        if "targets_csv" in data:
            rows = csv_rows(Path(src).parent / str(data["targets_csv"]), width)
        else:
            try:
                rows = np.array(data.get("targets"), float)
            except (TypeError, ValueError):
                rows = np.zeros((0,))
            if rows.ndim != 2 or rows.shape[1] != width or not np.all(np.isfinite(rows)):
                raise ModelError(f"'targets' must be a list of [{', '.join(['number'] * width)}] rows",
                                 source=str(src))
    else:
        rows = csv_rows(src, width)
    model_t = data.get("model", {})
    if not isinstance(model_t, dict) or set(model_t) - {"file", "point", "travel"}:
        raise ModelError("[model] takes file, point and travel", source=str(src))
    model = args.model or (str(Path(src).parent / model_t["file"]) if "file" in model_t else None)
    bounds = dict(data.get("parameters", {}))
    bounds.update(dict(_vary(v) for v in args.vary))
    if model is None and (bounds or args.point or model_t):
        raise ModelError("--vary, --point and [parameters] need a model (--model or [model] file)")
    point = args.point or model_t.get("point")
    if model is not None and not point:
        raise ModelError("name the model's point whose path is shaped (--point or [model] point)")
    mech = None if model is None else _model_of(model)
    sliding = mech is not None and mech.joints[mech.inputs[0].joint].kind == "P"
    if mech is not None:    # targets (and a sliding input's values) in the model's length unit
        rows = _in_model_units(rows, mech, sliding, src)
        args.input_unit = mech.units.length
    timing = None
    if timed:
        timing = rows[:, 2] if sliding else np.radians(rows[:, 2])
    c = read_constraints(data.get("constraints", {}), f"{src}: [constraints]")
    pivots = {**c.pivots, **dict(_pivot(p) for p in args.pivot)}
    try:
        c = PathConstraints(c.full_turn and not args.open,
                            args.min_transmission if args.min_transmission is not None else c.min_transmission_deg,
                            args.max_ratio if args.max_ratio is not None else c.max_ratio, pivots,
                            c.transmission_joints)
    except ModelError as exc:
        raise ModelError(str(exc), source=str(src)) from None
    search = dict(data.get("search", {}))
    bad = sorted(set(search) - set(SEARCH_KEYS))
    if bad:
        raise ModelError(f"[search]: unknown key(s) {', '.join(bad)} (known: {', '.join(SEARCH_KEYS)})", source=str(src))
    for key in ("seed", "starts", "generations", "popsize"):
        if getattr(args, key) is not None:
            search[key] = getattr(args, key)
    for key, value in search.items():
        search[key] = _int(value, key, 0 if key == "seed" else 1)
    if args.workers is not None and args.workers < 1:
        raise ModelError("--workers must be at least 1")
    travel = model_t.get("travel")
    if travel is not None and not sliding:
        travel = [math.radians(float(v)) for v in travel]   # degrees for a crank input
    return PathProblem(rows[:, :2], timing, c, model, point, bounds, travel, search, args.workers,
                       args.scheduler, shown(args.progress), bool(getattr(args, "yes", False)))


def _model_of(model):
    """The model (its declared parameters) whose path is synthesised."""
    from ..model import parse_model
    from ..study.run import load_template
    template = load_template(model)
    return parse_model(template.bind(), source=template.source)


def _in_model_units(rows, mech, sliding: bool, src):
    """Target rows (x, y[, input]) read in the model's length unit, in SI (a sliding input's values in its
    own unit);
    targets spread 100 times wider or narrower than the model's drawing warn (`mbplanar.model._scale`)."""
    from ..model._scale import drawing_size, warn_scale
    k = mech.units.length_scale
    rows = np.array(rows, float)
    rows[:, :2] *= k
    if sliding and rows.shape[1] > 2:
        rows[:, 2] *= mech.inputs[0].scale
    spread = float(np.max(np.ptp(rows[:, :2], axis=0))) if len(rows) > 1 else 0.0
    warn_scale("the target points spread over", spread, drawing_size(mech), mech.units.length, k,
               source=str(src), reference=f"the model {mech.source} spans")
    return rows
