"""The inputs of `mbplanar synth path`: targets from CSV or TOML, the model and its parameter bounds,
constraints, search settings, the Dask client and the progress bar, gathered into one problem.

A TOML input holds `targets = [[x, y], ...]` (or `[[x, y, input], ...]` with `timed = true`; or
`targets_csv = "file.csv"`), an optional `[model]` table {file, point, travel} with `[parameters]`
bounds {name = [lower, upper]}, `[constraints]` (`constraints.read_constraints`) and `[search]`
{seed, starts, shapes, keep, budget, popsize, generations, samples}. Options on the command line win.

Targets are in metres for the built-in four-bar, in the model's `length_unit` with a model. A CSV header
may name the unit of its columns (`x_mm`, `x [mm]`, `x (mm)`): a unit other than that one is refused,
naming the row, and so are targets 100 times larger or smaller than the model's drawing.

The four-bar's constraints default to the designer's (`path.DESIGNER`: a crank that turns fully,
transmission angle ≥ 30°, link ratio ≤ 10); each can be changed or dropped (`none`, or `false` in TOML),
and the summary says which bounds are defaults and which were given.
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._progress import shown
from ..errors import ModelError
from .constraints import PathConstraints, read_constraints

__all__ = ["PathProblem", "path_problem", "bound_option"]

SEARCH_KEYS = ("seed", "starts", "shapes", "keep", "budget", "popsize", "generations", "samples")
MODEL_SEARCH_KEYS = ("seed", "starts", "keep", "popsize", "generations", "samples")
UNIT_FACTORS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "in": 0.0254, "inch": 0.0254, "ft": 0.3048, "um": 1e-6,
                "km": 1e3}
"""Length units a CSV header may name (metres each), so that a file in another unit is recognised."""
SCALE_LIMIT = 100.0
"""Targets this many times larger or smaller than the model's drawing are refused (another unit?)."""


@dataclass
class PathProblem:
    """A path-generation run: targets (T, 2) SI, timing (T,) SI or None, constraints (and where each
    bound comes from: "default", "given" or "off"), the model (None: the built-in four-bar) with its
    point, bounds and travel, search settings and the Dask choice."""

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
    sources: dict = field(default_factory=dict)
    yes: bool = False

    def run(self):
        """Synthesise (serially or on Dask, with the progress bar when asked, and the time estimate of
        `mbplanar._progress.Progress` from the first starts)."""
        from .._progress import Progress
        from ..study.cluster import close, connect, local_client
        client = local_client(self.workers) if self.workers else connect(self.scheduler) if self.scheduler else None
        starts = self.search.get("starts", 3 if self.model is None else 2)
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


def bound_option(text: str) -> float | None:
    """A bound given on the command line: a number, or `none` (no bound)."""
    if str(text).strip().lower() in ("none", "off", "no"):
        return None
    try:
        value = float(text)
    except ValueError:
        raise ModelError(f"expected a number or 'none', got {text!r}") from None
    if not math.isfinite(value):
        raise ModelError(f"expected a finite number or 'none', got {text!r}")
    return value


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


def _seconds(value, key: str = "budget") -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (math.isfinite(value) and value > 0):
        raise ModelError(f"{key} must be a positive number of seconds, got {value!r}")
    return float(value)


# -- targets ------------------------------------------------------------------------------------------
def _header_units(path, width: int) -> tuple[int, list]:
    """The first data row's line number's header line (0: none) and the length unit each header cell
    names ([] without a header)."""
    try:
        text = Path(path).read_text(encoding="utf-8-sig")
    except OSError:
        return 0, []
    for n, row in enumerate(csv.reader(text.splitlines()), 1):
        if not row or not "".join(row).strip() or row[0].lstrip().startswith("#"):
            continue
        try:
            [float(v) for v in row]
            return 0, []
        except ValueError:
            return n, [_cell_unit(c) for c in row[:2]]
    return 0, []


def _cell_unit(cell: str) -> str | None:
    """The unit a header cell names: `x_mm`, `x [mm]`, `x (mm)`, `x/mm`, `x in mm` (None: no unit)."""
    c = cell.strip().lower()
    m = re.search(r"[\[(]\s*([a-zµ]+)\s*[\])]\s*$", c) or re.search(r"(?:_|/|\s+in\s+)([a-zµ]+)\s*$", c)
    if not m:
        return None
    unit = m.group(1).replace("µ", "u")
    return unit


def _check_header(path, expected: str) -> None:
    """Refuse a CSV whose header names a length unit other than `expected` (the targets' unit)."""
    row, units = _header_units(path, 2)
    for unit in units:
        if unit is None or unit == expected:
            continue
        if unit in UNIT_FACTORS:
            raise ModelError(f"the header names the unit '{unit}' but the targets are read in '{expected}'"
                             f"{' (the model' + chr(39) + 's length_unit)' if expected != 'm' else ''}: write "
                             f"them in {expected} (multiply by {UNIT_FACTORS[unit] / UNIT_FACTORS[expected]:g})",
                             source=str(path), where=f"row {row}")
        raise ModelError(f"the header names the unit '{unit}', not a length unit mbplanar knows; the targets "
                         f"are read in '{expected}'", source=str(path), where=f"row {row}")


def _rows(src, data: dict, width: int, unit: str):
    """Target rows (T, width) from the CSV `src`, a TOML's `targets_csv` or its `targets` list; the file
    the rows came from and each row's line (for messages)."""
    from .command import csv_rows
    if data and "targets" not in data and "targets_csv" not in data:
        raise ModelError("a TOML input needs 'targets' (or 'targets_csv')", source=str(src))
    if not data or "targets_csv" in data:
        path = Path(src).parent / str(data["targets_csv"]) if data else Path(src)
        _check_header(path, unit)
        return csv_rows(path, width), str(path), "row"
    value = data.get("targets")
    if not isinstance(value, list) or not value:
        raise ModelError(f"'targets' must be a list of [{', '.join(['number'] * width)}] rows", source=str(src))
    for k, row in enumerate(value, 1):
        ok = isinstance(row, list) and len(row) == width and all(
            isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in row)
        if not ok:
            raise ModelError(f"needs {width} finite numbers, got {row!r}", source=str(src), where=f"targets row {k}")
    return np.array(value, float), str(src), "targets row"


def _validated(rows, source: str, label: str) -> np.ndarray:
    """The targets checked (`path.validate_targets`), an error naming the file and the row."""
    from .path import validate_targets
    try:
        return validate_targets(rows[:, :2], where=label)
    except ModelError as exc:
        raise ModelError(exc.message, source=source) from None


def _against_model(targets, mech, source: str, label: str) -> None:
    """Refuse targets (SI) spread 100 times wider or narrower than the model's drawing, or lying 100
    drawing sizes from it (`mbplanar.model._scale`'s rule), naming the row farthest off."""
    from ..model import drawing_size, out_of_scale, scale_message
    size = drawing_size(mech)
    if size <= 0:
        return
    spots = np.array([j.at for j in mech.joints.values()], float)
    away = np.hypot(*(targets - spots.mean(axis=0)).T)
    spread = float(np.ptp(targets, axis=0).max())
    if out_of_scale(spread, size) or (away.max() > size and out_of_scale(away.max(), size)):
        k = int(np.argmax(away))
        unit, scale = mech.units.length, mech.units.length_scale
        what = "the target points spread over" if out_of_scale(spread, size) else "the target points lie up to"
        value = spread if out_of_scale(spread, size) else float(away.max())
        raise ModelError(f"({targets[k, 0] / scale:.6g}, {targets[k, 1] / scale:.6g}) {unit}: "
                         + scale_message(what, value, size, unit, scale, reference=f"the model {mech.source} spans"),
                         source=source, where=f"{label} {k + 1}")


# -- constraints ----------------------------------------------------------------------------------------
def _constraints(data: dict, args, src, four_bar: bool) -> tuple[PathConstraints, dict]:
    """The run's constraints: the four-bar's designer defaults (a model: a full turn only), then the
    TOML's [constraints], then the options; and where each bound comes from."""
    from .path import DESIGNER
    base = DESIGNER if four_bar else PathConstraints()
    table = data.get("constraints", {})
    table = dict(table) if isinstance(table, dict) else table
    sources = {"full_turn": "default", "min_transmission_deg": "default" if four_bar else "off",
               "max_ratio": "default" if four_bar else "off"}
    if isinstance(table, dict):
        for key in ("min_transmission_deg", "max_ratio"):
            if key not in table:
                table[key] = getattr(base, key)
                continue
            sources[key] = "given"
            if table[key] is False or (isinstance(table[key], str) and table[key].strip().lower() == "none"):
                table[key], sources[key] = None, "off"
        if "full_turn" in table:
            sources["full_turn"] = "given"
    c = read_constraints(table, f"{src}: [constraints]", full_turn=base.full_turn)
    pivots = {**c.pivots, **dict(_pivot(p) for p in args.pivot)}
    mu, ratio = c.min_transmission_deg, c.max_ratio
    if args.min_transmission is not None:
        mu = bound_option(args.min_transmission)
        sources["min_transmission_deg"] = "given" if mu is not None else "off"
    if args.max_ratio is not None:
        ratio = bound_option(args.max_ratio)
        sources["max_ratio"] = "given" if ratio is not None else "off"
    if args.open:
        sources["full_turn"] = "given"
    turn = c.full_turn and not args.open
    try:
        out = PathConstraints(turn, mu, ratio, pivots, c.transmission_joints)
    except ModelError as exc:
        raise ModelError(str(exc), source=str(src)) from None
    if not turn:
        sources["full_turn"] = "off" if sources["full_turn"] == "given" else sources["full_turn"]
    return out, sources


def path_problem(args) -> PathProblem:
    """The problem the command line (and its TOML input) describes."""
    from .command import read_toml
    src = args.input
    data = read_toml(src) if str(src).lower().endswith(".toml") else {}
    known = ("targets", "targets_csv", "timed", "model", "parameters", "constraints", "search")
    unknown = sorted(set(data) - set(known))
    if unknown:
        raise ModelError(f"unknown key(s) {', '.join(unknown)} (known: {', '.join(known)})", source=str(src))
    timed = bool(args.timed or data.get("timed", False))
    width = 3 if timed else 2
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
    rows, source, label = _rows(src, data, width, "m" if mech is None else mech.units.length)
    _validated(rows, source, label)
    sliding = mech is not None and mech.joints[mech.inputs[0].joint].kind == "P"
    if mech is not None:    # targets (and a sliding input's values) in the model's length unit
        _against_model(rows[:, :2] * mech.units.length_scale, mech, source, label)
        rows = _in_model_units(rows, mech, sliding, src)
        args.input_unit = mech.units.length
    timing = None
    if timed:
        timing = rows[:, 2] if sliding else np.radians(rows[:, 2])
    c, sources = _constraints(data, args, src, model is None)
    search = dict(data.get("search", {}))
    allowed = SEARCH_KEYS if model is None else MODEL_SEARCH_KEYS
    bad = sorted(set(search) - set(allowed))
    if bad:
        raise ModelError(f"[search]: unknown key(s) {', '.join(bad)} (known: {', '.join(allowed)})", source=str(src))
    for key in allowed:
        if getattr(args, key, None) is not None:
            search[key] = getattr(args, key)
    for key, value in search.items():
        search[key] = _seconds(value) if key == "budget" else _int(value, key, 0 if key == "seed" else 1)
    if model is not None and getattr(args, "budget", None) is not None:
        raise ModelError("--budget applies to the built-in four-bar; bound a model's search with --generations")
    if args.workers is not None and args.workers < 1:
        raise ModelError("--workers must be at least 1")
    travel = model_t.get("travel")
    if travel is not None and not sliding:
        travel = [math.radians(float(v)) for v in travel]   # degrees for a crank input
    elif travel is not None:
        travel = [float(v) * mech.inputs[0].scale for v in travel]     # the sliding input's unit
    return PathProblem(rows[:, :2], timing, c, model, point, bounds, travel, search, args.workers,
                       args.scheduler, shown(args.progress), sources=sources, yes=bool(getattr(args, "yes", False)))


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
    from ..model import drawing_size, warn_scale
    k = mech.units.length_scale
    rows = np.array(rows, float)
    rows[:, :2] *= k
    if sliding and rows.shape[1] > 2:
        rows[:, 2] *= mech.inputs[0].scale
    spread = float(np.max(np.ptp(rows[:, :2], axis=0))) if len(rows) > 1 else 0.0
    warn_scale("the target points spread over", spread, drawing_size(mech), mech.units.length, k,
               source=str(src), reference=f"the model {mech.source} spans")
    return rows
