"""`mbplanar synth seed001|function|motion`: inputs from TOML or CSV, the model file, the JSON summary,
the picture. The CLI only registers the command and calls `add_arguments` and `run`."""

from __future__ import annotations

import csv
import json
import math
import tomllib
from pathlib import Path

import numpy as np

from .._progress import add_long_run_options
from ..errors import ModelError, ModelWarning, PlotUnavailable
from ..model import ANGLE_UNITS, LENGTH_UNITS, add_units_option, unit_spelling

__all__ = ["add_arguments", "run", "summary_seed001", "summary_function", "summary_motion", "csv_rows", "read_toml",
           "shown", "input_units"]


def add_arguments(parser) -> None:
    """The `synth` sub-commands and their options."""
    sub = parser.add_subparsers(dest="problem", required=True)
    s = sub.add_parser("seed001", help="seed 001's guiding crank-slider for a D-shaped foot path")
    s.add_argument("input", nargs="?", help="TOML with [chain], [target], [method] (default: the documented "
                                            "target on the seed's chain)")
    s.add_argument("--form", choices=("a", "b", "c"), help="(b) scan k, (a) scan γ, (c) four nodes (default b)")
    s.add_argument("--support-nodes", type=int, help="nodes on the support segment (default 2; 3 for form c)")
    s.add_argument("--spacing", choices=("chebyshev", "uniform"))
    s.add_argument("--fit", choices=("exact", "lsq", "minimax"), help="form (b) over more than 3 nodes")
    s.add_argument("--k-step", type=float, help="step of the scan over the guide's angle atan k (degrees)")
    s.add_argument("--gamma-step", type=float, help="step of the scan over γ for form (a) (degrees)")
    _common(s)
    s = sub.add_parser("function", help="four-bar function generator (Freudenstein)")
    s.add_argument("input", help="TOML with [function], or CSV of angle pairs phi_deg, psi_deg")
    s.add_argument("--points", type=int, help="precision points (3 exact, more: least squares)")
    s.add_argument("--spacing", choices=("chebyshev", "uniform"))
    _common(s)
    s = sub.add_parser("motion", help="four-bar motion generator through 2-5 poses (Burmester)")
    s.add_argument("input", help="TOML with poses = [[x, y, angle_deg], ...] (and dyad choices), or CSV of "
                                 "x, y, angle_deg")
    s.add_argument("--full-turn", action="store_true", help="require a crank that turns fully")
    s.add_argument("--curve", help="4 poses: write the centre- and circle-point curves to this CSV")
    _common(s)
    s = sub.add_parser("path", help="a coupler curve through target points: a four-bar, or any model's "
                                    "parameters (global search + least squares)")
    s.add_argument("input", help="CSV of target points x, y (timed: x, y, input in degrees, or metres for a "
                                 "sliding input) in their order along the curve, or TOML with targets, [model], "
                                 "[parameters], [constraints], [search]")
    s.add_argument("--model", help="synthesise this model's parameters (default: a four-bar)")
    s.add_argument("--point", help="the model's point whose path is shaped")
    s.add_argument("--vary", action="append", default=[], metavar="NAME=LO:HI",
                   help="a parameter searched within [LO, HI] (its unit); repeat for each")
    s.add_argument("--timed", action="store_true", help="the CSV's third column is the input at each target")
    s.add_argument("--open", action="store_true", help="no full turn: the targets on one branch between limits")
    s.add_argument("--min-transmission", metavar="DEG|none",
                   help="smallest transmission angle in degrees (four-bar default 30; none: no bound)")
    s.add_argument("--max-ratio", metavar="R|none",
                   help="largest ratio longest/shortest link (four-bar default 10; none: no bound)")
    s.add_argument("--pivot", action="append", default=[], metavar="NAME=XMIN,YMIN,XMAX,YMAX",
                   help="a box for a fixed pivot (four-bar: A0 crank, B0 rocker); repeat for each")
    s.add_argument("--budget", type=float, metavar="SECONDS",
                   help="stop the search in time and answer with the best design so far (four-bar)")
    s.add_argument("--seed", type=int, help="random seed (default 0): the same seed gives the same design")
    s.add_argument("--starts", type=int, help="independent starts (default 2; 2 for a model)")
    s.add_argument("--shapes", type=int, help="crank-rocker shapes screened per start (four-bar, default 8192)")
    s.add_argument("--keep", type=int, help="designs polished per start (four-bar default 6, a model 2)")
    s.add_argument("--generations", type=int, help="differential evolution's generations per start (a limited "
                                                   "travel or a model)")
    s.add_argument("--popsize", type=int, help="differential evolution's population factor")
    g = s.add_mutually_exclusive_group()
    g.add_argument("--workers", type=int, help="run the starts on a Dask LocalCluster of N worker processes")
    g.add_argument("--scheduler", help="run the starts on the Dask cluster of this scheduler")
    add_long_run_options(s, "the first starts")
    _common(s)


def _common(s):
    s.add_argument("-o", "--output", help="the synthesised model (TOML)")
    s.add_argument("--json", action="store_true", help="print the JSON summary")
    s.add_argument("--plot", help="picture of the target against the achieved motion (PNG, SVG, PDF)")
    add_units_option(s, "the summary's lengths (model: the input's length_unit, or the --model's)")


def run(args) -> int:
    problem = {"seed001": _seed001, "function": _function, "motion": _motion, "path": _path}[args.problem]
    summary, result, picture = problem(args)
    summary = shown(summary, getattr(args, "input_unit", "m") if args.units == "model" else "m")
    if args.output:
        from .report import summary_table
        summary["model"] = str(args.output)
        Path(args.output).write_text(result.toml + summary_table(summary), encoding="utf-8")
    if args.plot:
        picture(result, args.plot)
        summary["plot"] = str(args.plot)
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        _print_text(summary)
    return 0


def _print_text(summary: dict) -> None:
    verdict = "defect-free design found" if summary.get("success", True) else "design found with warnings"
    print(f"synth {summary['problem']}: {verdict} in {summary['seconds']:.2f} s "
          f"({summary['evaluations']} candidate designs scored)")
    for key, value in summary["design"].items():
        print(f"  {key} = {value}")
    unit = summary["error_unit"]
    print(f"  error over the {len(summary['errors'])} target points: max {summary['max_error']:.3e} {unit}, "
          f"RMS {summary['rms_error']:.3e} {unit}")
    for key in ("delta1", "delta2", "delta"):
        if key in summary:
            print(f"  {key} = {summary[key]:.6g}")
    for k, b in enumerate(summary.get("burmester_points", [])):
        print(f"  Burmester point {k + 1}: centre {b['centre']}, circle point {b['circle']}")
    if "structural_error" in summary:
        se = summary["structural_error"]
        print(f"  structural error over the range: max {se['max_deg']:.4g}°, RMS {se['rms_deg']:.4g}°")
    if summary["problem"] == "path":
        _print_path_constraints(summary)
    print(f"  defects checked: {', '.join(summary['defects']['checked'])}: "
          f"{'none' if summary['defects'].get('ok', True) else 'see the warnings'}")
    if summary.get("model"):
        print(f"  model written to {summary['model']}")


def _print_path_constraints(summary: dict) -> None:
    """The path generator's bounds (default, given or off) with what the design achieved, and what the
    transmission and ratio bounds cost."""
    c = summary["constraints"]
    src = c.get("sources", {})
    mu, ratio = c.get("transmission_deg"), c.get("ratio")
    parts = ["crank turns fully" if c["full_turn"] else "no full turn"]
    if c.get("min_transmission_deg") is not None:
        parts.append(f"transmission angle ≥ {c['min_transmission_deg']:g}°")
    if c.get("max_ratio") is not None:
        parts.append(f"link ratio ≤ {c['max_ratio']:g}")
    names = {"full_turn": "full turn", "min_transmission_deg": "transmission angle", "max_ratio": "link ratio"}
    groups = [f"{kind}: {', '.join(names[k] for k, v in src.items() if v == kind)}"
              for kind in ("default", "given", "off") if kind in src.values()]
    print(f"  constraints: {', '.join(parts)} ({'; '.join(groups)})")
    got = []
    if mu is not None:
        got.append(f"smallest transmission angle {mu:.4g}°")
    if ratio is not None:
        got.append(f"link ratio {ratio:.4g}")
    print(f"  achieved: {', '.join(got)} (seed {summary['seed']}, {summary['starts']} "
          f"start{'s' if summary['starts'] != 1 else ''})")
    t = summary.get("tradeoff")
    if t and t.get("without"):
        w = t["without"]
        bounds = {"min_transmission_deg": "transmission-angle", "max_ratio": "link-ratio"}
        print(f"  without the {' and '.join(bounds[b] for b in t['relaxed'])} bounds the best found: "
              f"RMS {w['rms']:.3e} {summary['error_unit']} (transmission angle {w['transmission_deg']:.3g}°, "
              f"link ratio {w['ratio']:.3g}) against RMS {summary['rms_error']:.3e} with them")
    elif t:
        print("  the transmission and ratio bounds cost nothing here (no better design found without them)")


# -- units ---------------------------------------------------------------------------------------------
#: the summaries' keys whose numbers are lengths (in "design", "target"), besides targets, poses, errors in m
_LENGTHS = {"a", "b", "c", "d", "l", "rho", "crank", "coupler", "rocker", "ground", "a0x", "a0y", "b0x", "b0y", "u",
            "v", "crank_pivot", "crank_joint", "slider_joint", "rocker_joint", "rocker_pivot", "x_start", "y0",
            "length", "height", "top_x", "nodes"}


def input_units(data: dict, src, angles: bool = False) -> tuple[str, float, float]:
    """The input's `length_unit` (any case; default m) and, with `angles`, its `angle_unit` (deg or rad):
    the unit's name, metres per unit, radians per angle unit."""
    where = f"{src}"
    unit = unit_spelling(data.get("length_unit", "m"), LENGTH_UNITS)
    if unit is None:
        raise ModelError(f"length_unit must be one of {', '.join(LENGTH_UNITS)} (in any case), got "
                         f"{data.get('length_unit')!r}", source=where)
    angle = unit_spelling(data.get("angle_unit", "deg"), ANGLE_UNITS) if angles else "deg"
    if angle is None:
        raise ModelError(f"angle_unit must be deg or rad, got {data.get('angle_unit')!r}", source=where)
    return unit, LENGTH_UNITS[unit], ANGLE_UNITS[angle]


def shown(summary: dict, unit: str) -> dict:
    """The summary with its lengths in `unit` (a length unit's name) and a ``"units"`` object."""
    k = LENGTH_UNITS[unit]

    def scale(v):
        if isinstance(v, (list, tuple)):
            return [scale(x) for x in v]
        return v / k if isinstance(v, (int, float)) and not isinstance(v, bool) else v
    if not summary.get("source_model"):
        summary["design"] = {key: scale(v) if key in _LENGTHS else v for key, v in summary["design"].items()}
    if isinstance(summary.get("target"), dict):
        summary["target"] = {key: scale(v) if key in _LENGTHS else v for key, v in summary["target"].items()}
    if "targets" in summary:
        summary["targets"] = scale(summary["targets"])
    if "poses" in summary:
        summary["poses"] = [[*scale(p[:2]), p[2]] for p in summary["poses"]]
    if "burmester_points" in summary:
        summary["burmester_points"] = [{key: scale(v) for key, v in b.items()} for b in summary["burmester_points"]]
    if summary.get("error_unit") == "m":
        summary.update(errors=scale(summary["errors"]), max_error=scale(summary["max_error"]),
                       rms_error=scale(summary["rms_error"]), error_unit=unit)
        order = summary.get("order")
        if isinstance(order, dict):       # path generation: the order's lengths, the trade-off's errors
            order.update(tolerance=scale(order["tolerance"]), curve_length=scale(order["curve_length"]),
                         steps_back=[{**b, "length": scale(b["length"])} for b in order["steps_back"]])
        for side in ("with", "without"):
            errors = (summary.get("tradeoff") or {}).get(side)
            if errors:
                errors.update(rms=scale(errors["rms"]), max=scale(errors["max"]))
    summary["units"] = {"system": "si" if unit == "m" else "model", "length": unit, "angle": "deg"}
    return summary


def _check_pose_angles(angles, src, unit: str):
    """Warn when pose angles read in degrees all lie within ±2π and turn through less than 2π: radians?"""
    angles = np.asarray(angles, float)
    if unit == "deg" and len(angles) > 1 and np.all(np.abs(angles) <= 2 * math.pi) and np.ptp(angles) > 0:
        import warnings
        warnings.warn(ModelWarning(str(ModelError(
            f"the poses turn through {np.ptp(angles):.4g}° in all (angles {angles.min():.4g} … {angles.max():.4g}, "
            "read in degrees): are they in radians? give angle_unit = \"rad\" in a TOML input, or the angles in "
            "degrees", source=str(src)))), stacklevel=3)


# -- inputs -------------------------------------------------------------------------------------------
def read_toml(path) -> dict:
    try:
        return tomllib.loads(Path(path).read_text(encoding="utf-8-sig"))
    except OSError as exc:
        raise ModelError(f"cannot read ({exc.strerror or exc})", source=str(path)) from None
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"TOML syntax error: {exc}", source=str(path)) from None


def csv_rows(path, columns: int) -> np.ndarray:
    """Numeric rows of a CSV file (a header line of names is skipped), `columns` values each."""
    try:
        text = Path(path).read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise ModelError(f"cannot read ({exc.strerror or exc})", source=str(path)) from None
    rows = []
    for n, row in enumerate(csv.reader(text.splitlines()), 1):
        if not row or not "".join(row).strip() or row[0].lstrip().startswith("#"):
            continue
        try:
            values = [float(v) for v in row]
        except ValueError:
            if not rows:
                continue                      # a header line before the data
            raise ModelError(f"not numbers: {row}", source=str(path), where=f"row {n}") from None
        if len(values) != columns or not all(math.isfinite(v) for v in values):
            raise ModelError(f"needs {columns} finite numbers, got {row}", source=str(path), where=f"row {n}")
        rows.append(values)
    if not rows:
        raise ModelError("no data rows", source=str(path))
    return np.array(rows)


def _known(table, keys, where: str) -> dict:
    """`table` itself after checking it is a table whose keys are all in `keys` (a typo is an error)."""
    if not isinstance(table, dict):
        raise ModelError(f"{where} must be a table")
    unknown = sorted(set(table) - set(keys))
    if unknown:
        raise ModelError(f"{where}: unknown key(s) {', '.join(unknown)} (known: {', '.join(sorted(keys))})")
    return table


def _number(table: dict, key: str, where: str, default=None):
    value = table.get(key, default)
    if value is None:
        raise ModelError(f"{where}: '{key}' is required")
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ModelError(f"{where}: '{key}' must be a finite number, got {value!r}")
    return float(value)


def _pairs(table: dict, key: str, where: str, width: int, required: bool = True):
    value = table.get(key)
    if value is None:
        if required:
            raise ModelError(f"{where}: '{key}' is required")
        return None
    try:
        arr = np.array(value, float)
    except (TypeError, ValueError):
        arr = np.zeros((0,))
    if arr.ndim != 2 or arr.shape[1] != width or not np.all(np.isfinite(arr)):
        raise ModelError(f"{where}: '{key}' must be a list of [{', '.join(['number'] * width)}] rows")
    return arr


def _errors(values) -> tuple[list, float, float]:
    v = np.abs(np.asarray(values, float))
    return [float(x) for x in v], float(v.max()), float(np.sqrt(np.mean(v * v)))


# -- seed 001 -------------------------------------------------------------------------------------------
def _seed001(args):
    from .guiding import SEED001_CHAIN, Chain, WalkingTarget
    from .seed001 import synthesise_seed001
    data = read_toml(args.input) if args.input else {}
    src = args.input or "<default target>"
    _known(data, ("chain", "target", "method", "length_unit"), src)
    args.input_unit, k, _ = input_units(data, src)
    chain_t = _known(data.get("chain", {}), ("a", "b", "pivot"), f"{src}: [chain]")
    pivot = _pairs({"p": [chain_t.get("pivot", list(SEED001_CHAIN.pivot))]}, "p", f"{src}: [chain] pivot", 2)[0]
    pivot = pivot * (k if "pivot" in chain_t else 1.0)
    chain = Chain(_number(chain_t, "a", f"{src}: [chain]", SEED001_CHAIN.a / k) * k,
                  _number(chain_t, "b", f"{src}: [chain]", SEED001_CHAIN.b / k) * k, (float(pivot[0]), float(pivot[1])))
    if chain.a <= 0 or chain.b <= 0:
        raise ModelError(f"{src}: [chain] a and b must be positive")
    where = f"{src}: [target]"
    t = _known(data.get("target", {}), ("x_start", "y0", "length", "height", "direction", "top_x"), where)
    direction = int(_number(t, "direction", where, -1))
    if direction not in (1, -1):
        raise ModelError(f"{where}: 'direction' must be 1 or -1")
    target = WalkingTarget(*(_number(t, key, where, DEFAULT_TARGET[key] / k) * k
                             for key in ("x_start", "y0", "length", "height")), direction,
                           None if "top_x" not in t else _number(t, "top_x", where) * k)
    method = _known(data.get("method", {}), ("form", "support_nodes", "spacing", "fit", "k_step_deg",
                                             "gamma_step_deg"), f"{src}: [method]")
    form = args.form or method.get("form", "b")
    step_k = args.k_step or method.get("k_step_deg", 1.0)
    step_g = args.gamma_step or method.get("gamma_step_deg", 1.0)
    if not (step_k > 0 and step_g > 0):
        raise ModelError("the scan steps must be positive")
    result = synthesise_seed001(target, chain, form, args.support_nodes or method.get("support_nodes"),
                                args.spacing or method.get("spacing", "chebyshev"),
                                args.fit or method.get("fit", "exact"), (0.0, 180.0, step_k), (0.0, 360.0, step_g))
    return summary_seed001(result, form), result, _plot_seed001


DEFAULT_TARGET = {"x_start": 0.0, "y0": -2.6, "length": 1.0, "height": 0.2}
"""The documented D-shaped walking-foot target (docs/synthesis.md) on the seed's chain."""


def summary_seed001(r, form: str) -> dict:
    per, mx, rms = _errors(r.node_errors)
    t = r.target
    return {"problem": "seed001", "form": form, "model": None,
            "target": {"x_start": t.x_start, "y0": t.y0, "length": t.length, "height": t.height,
                       "direction": t.direction, "nodes": r.nodes.tolist()},
            "design": r.design, "error_unit": "m",
            "errors": per, "max_error": mx, "rms_error": rms,
            "delta1": r.delta1, "delta2": r.delta2, "delta": r.delta,
            "node_phi_deg": [math.degrees(p) for p in r.node_phi],
            "defects": {"checked": ["circuit", "branch", "order", "full_turn"], **r.defects.as_dict(),
                        "rejected": r.rejected},
            "evaluations": r.candidates, "checked_by_mbplanar": r.checked, "seconds": r.seconds}


def _plot_seed001(r, path):
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.5))
    t = r.target
    ax.plot([t.x_start, t.x_start + t.length], [t.y0, t.y0], "k-", lw=3, alpha=0.3, label="target support")
    ax.plot(*t.top, "k^", ms=8, alpha=0.5, label="target height")
    p = np.vstack([r.path, r.path[:1]])
    ax.plot(p[:, 0], p[:, 1], "C0-", label="achieved foot path (mbplanar)")
    ax.plot(r.nodes[:, 0], r.nodes[:, 1], "C3o", mfc="none", label="interpolation nodes")
    ax.set_title(f"seed 001 synthesis: Δ1 = {r.delta1:.4g}, Δ2 = {r.delta2:.4g}")
    _finish(fig, ax, path)


# -- function generation ----------------------------------------------------------------------------------
def _function(args):
    from .freudenstein import FunctionTask, synthesise_angle_pairs, synthesise_function
    src = args.input
    if str(src).lower().endswith(".csv"):
        rows = csv_rows(src, 2)
        result = synthesise_angle_pairs(np.radians(rows[:, 0]), np.radians(rows[:, 1]))
        return summary_function(result, None), result, _plot_function
    data = _known(read_toml(src), ("function", "length_unit"), src)
    args.input_unit, k, _ = input_units(data, src)
    where = f"{src}: [function]"
    if "function" not in data:
        raise ModelError(f"{src}: a [function] table is required")
    f = _known(data["function"], ("expression", "x", "phi_deg", "psi_deg", "points", "spacing", "ground",
                                  "pairs_deg"), where)
    ground = _number(f, "ground", where, 1.0 / k) * k
    if ground <= 0:
        raise ModelError(f"{where}: 'ground' must be positive")
    if "pairs_deg" in f:
        rows = _pairs(f, "pairs_deg", where, 2)
        result = synthesise_angle_pairs(np.radians(rows[:, 0]), np.radians(rows[:, 1]), ground)
        return summary_function(result, None), result, _plot_function
    ranges = {key: _pairs({key: [f.get(key)]}, key, where, 2)[0] for key in ("x", "phi_deg", "psi_deg")}
    if not isinstance(f.get("expression"), str):
        raise ModelError(f"{where}: 'expression' (a formula in x, e.g. \"log10(x)\") is required")
    points = args.points or int(_number(f, "points", where, 3))
    task = FunctionTask(f["expression"], tuple(ranges["x"]), tuple(ranges["phi_deg"]), tuple(ranges["psi_deg"]),
                        points, args.spacing or f.get("spacing", "chebyshev"))
    result = synthesise_function(task, ground)
    return summary_function(result, task), result, _plot_function


def summary_function(r, task) -> dict:
    per, mx, rms = _errors(r.point_errors_deg)
    e = np.abs(r.range_error_deg)
    se = {"max_deg": float(e.max()), "rms_deg": float(np.sqrt(np.mean(e * e)))}
    if r.range_error_y is not None:
        ey = np.abs(r.range_error_y)
        se |= {"max_y": float(ey.max()), "rms_y": float(np.sqrt(np.mean(ey * ey)))}
    out = {"problem": "function", "model": None, "design": r.design, "error_unit": "deg",
           "precision_points_deg": [[math.degrees(a), math.degrees(b)] for a, b in zip(r.phi, r.psi_target)],
           "errors": per, "max_error": mx, "rms_error": rms, "structural_error": se,
           "defects": {"checked": ["circuit", "branch", "order"], **r.defects.as_dict()},
           "evaluations": 1, "seconds": r.seconds}
    if task is not None:
        out["function"] = {"expression": task.expression, "x": list(task.x_range), "phi_deg": list(task.phi_deg),
                           "psi_deg": list(task.psi_deg), "points": task.points, "spacing": task.spacing}
    return out


def _plot_function(r, path):
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(np.degrees(r.range_phi), r.range_error_deg, "C0-", label="structural error ψ achieved − wanted (mbplanar)")
    ax.plot(np.degrees(r.phi), r.point_errors_deg, "C3o", label="precision points")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_xlabel("crank angle φ [deg]")
    ax.set_ylabel("error [deg]")
    ax.set_title("Function generator (Freudenstein)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


# -- motion generation ----------------------------------------------------------------------------------
def _motion(args):
    from .burmester import centre_point_curve, synthesise_motion
    src = args.input
    circle = centre = slider = None
    full_turn = args.full_turn
    data = {} if str(src).lower().endswith(".csv") else _known(
        read_toml(src), ("poses", "circle_points", "centre_points", "slider_points", "full_turn", "length_unit",
                         "angle_unit"), src)
    args.input_unit, k, rad = input_units(data, src, angles=True)
    if not data:
        rows = csv_rows(src, 3)
    else:
        rows = _pairs(data, "poses", src, 3)
        circle, centre, slider = (None if v is None else v * k for v in
                                  (_pairs(data, key, src, 2, required=False)
                                   for key in ("circle_points", "centre_points", "slider_points")))
        full_turn = full_turn or bool(data.get("full_turn", False))
    _check_pose_angles(rows[:, 2], src, "deg" if rad != 1.0 else "rad")
    poses = np.column_stack([rows[:, :2] * k, rows[:, 2] * rad])
    result = synthesise_motion(poses, circle, centre, slider, full_turn)
    summary = summary_motion(result)
    if args.curve:
        if len(poses) != 4:
            raise ModelError("--curve needs exactly 4 poses")
        curve = centre_point_curve(poses)
        with open(args.curve, "w", newline="", encoding="utf-8") as fh:
            w = csv.writer(fh)
            w.writerow(["branch", "alpha_deg", "centre_x", "centre_y", "circle_x", "circle_y"])
            for b in range(2):
                for k, a in enumerate(curve["alpha"]):
                    c, z = curve["centre"][b, k], curve["circle"][b, k]
                    if np.isfinite(c).all() and np.isfinite(z).all():
                        w.writerow([b] + [repr(float(v)) for v in (math.degrees(a), c[0], c[1], z[0], z[1])])
        summary["curve"] = str(args.curve)
    return summary, result, _plot_motion


def summary_motion(r) -> dict:
    from .burmester import SliderDyad
    per, mx, rms = _errors(r.pose_errors)
    d1, d2 = r.dyads
    design = {"crank_pivot": d1.centre.tolist(), "crank_joint": d1.circle.tolist(),
              "crank": float(np.hypot(*(d1.circle - d1.centre)))}
    if isinstance(d2, SliderDyad):
        design |= {"slider_joint": d2.point.tolist(), "guide_deg": math.degrees(math.atan2(*d2.direction[::-1])),
                   "coupler": float(np.hypot(*(d2.point - d1.circle)))}
    else:
        design |= {"rocker_joint": d2.circle.tolist(), "rocker_pivot": d2.centre.tolist(),
                   "coupler": float(np.hypot(*(d2.circle - d1.circle))),
                   "rocker": float(np.hypot(*(d2.circle - d2.centre))),
                   "ground": float(np.hypot(*(d2.centre - d1.centre)))}
    return {"problem": "motion", "model": None, "design": design,
            "poses": [[float(x), float(y), math.degrees(t)] for x, y, t in r.poses],
            "crank_phi_deg": [math.degrees(p) for p in r.crank_phi],
            "error_unit": "m", "errors": per, "max_error": mx, "rms_error": rms,
            "angle_errors_deg": [float(v) for v in r.angle_errors_deg],
            "max_angle_error_deg": float(np.max(r.angle_errors_deg)),
            "defects": {"checked": ["circuit", "branch", "order"], **r.defects.as_dict(),
                        "rejected": r.alternatives[:20]},
            "burmester_points": [{"centre": m.tolist(), "circle": z.tolist()} for m, z in r.burmester],
            "evaluations": len(r.alternatives) + 1, "seconds": r.seconds}


def _plot_motion(r, path):
    from ..kinematics import analyse
    from ..engine import Engine
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 5.5))
    engine = Engine(r.mechanism)
    lo, hi = float(min(r.crank_phi)), float(max(r.crank_phi))
    m = analyse(engine, np.linspace(lo - 0.1 * (hi - lo), hi + 0.1 * (hi - lo), 400))
    p = m.xy[:, m.point("P")]
    ax.plot(p[:, 0], p[:, 1], "C0-", label="coupler point path (mbplanar)")
    size = np.ptp(r.poses[:, :2], axis=0).max() * 0.15 or 0.1
    for k, (x, y, t) in enumerate(r.poses):
        ax.annotate("", (x + size * math.cos(t), y + size * math.sin(t)), (x, y),
                    arrowprops={"arrowstyle": "->", "color": "C3"})
        ax.text(x, y, f" {k + 1}", color="C3")
    d1, d2 = r.dyads
    if hasattr(d2, "direction"):
        ax.plot(*np.array([d1.centre, d1.circle, d2.point]).T, "k-o", ms=4, label="crank and slider at pose 1")
        ends = d2.point + np.outer([-1.0, 1.0], d2.direction) * 2 * size
        ax.plot(*ends.T, "k--", lw=0.8)
    else:
        ax.plot(*np.array([d1.centre, d1.circle, d2.circle, d2.centre]).T, "k-o", ms=4, label="four-bar at pose 1")
    frame = np.vstack([p, r.poses[:, :2], *(np.atleast_2d(v) for d in r.dyads for v in vars(d).values()
                                            if np.shape(v) == (2,))])
    lo, hi = frame.min(axis=0), frame.max(axis=0)
    pad = 0.5 * (hi - lo).max()
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    if len(r.poses) == 4:
        from .burmester import centre_point_curve
        curve = centre_point_curve(r.poses, 7200)
        for b in range(2):
            for key, colour in (("centre", "C2."), ("circle", "C1.")):
                pts = curve[key][b]
                inside = np.all((pts >= lo - pad) & (pts <= hi + pad), axis=1)
                ax.plot(*pts[inside].T, colour, ms=1)
        ax.plot([], [], "C2.", label="centre-point curve")
        ax.plot([], [], "C1.", label="circle-point curve")
    ax.set_title("Motion generator (Burmester)")
    _finish(fig, ax, path)


def _path(args):
    import warnings
    from ..errors import ModelWarning
    from .path_setup import path_problem
    problem = path_problem(args)
    r = problem.run()
    summary = summary_path(r, problem)
    for w in r.warnings:
        warnings.warn(w, ModelWarning)
    return summary, r, _plot_path


def summary_path(r, problem) -> dict:
    """The JSON summary of a path-generation result (`problem`: its `path_setup.PathProblem`)."""
    per, mx, rms = _errors(r.errors)
    c = r.constraints
    bounds = {**c.as_dict(), "transmission_deg": r.transmission_deg if math.isfinite(r.transmission_deg) else None,
              "ratio": _finite(getattr(r, "ratio", None)), "sources": dict(problem.sources)}
    out = {"problem": "path", "model": None, "design": problem.design(r), "targets": r.targets.tolist(),
           "target_phi_deg": [math.degrees(p) for p in r.phi], "timed": r.timed, "error_unit": "m",
           "errors": per, "max_error": mx, "rms_error": rms, "success": r.success, "message": r.message,
           "warnings": list(r.warnings), "constraints": bounds, "order": r.order, "tradeoff": _plain(r.tradeoff),
           "defects": {"checked": ["circuit", "branch", "order"] + (["full_turn"] if c.full_turn else []),
                       **r.defects.as_dict()},
           "evaluations": r.evaluations, "seed": r.seed, "starts": r.starts, "seconds": r.seconds,
           "budget": problem.search.get("budget"), "stopped": r.stopped, "point": r.point}
    if problem.model:
        out["source_model"] = problem.model
    return out


def _finite(v):
    return float(v) if v is not None and math.isfinite(float(v)) else None


def _plain(v):
    """JSON-ready copy (numpy numbers as floats, non-finite as None)."""
    if isinstance(v, dict):
        return {k: _plain(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_plain(x) for x in v]
    if isinstance(v, (float, np.floating, np.integer)) and not isinstance(v, bool):
        return _finite(v)
    return v


def _plot_path(r, path):
    from ..engine import Engine
    from ..kinematics import analyse
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 5.5))
    engine = Engine(r.mechanism)
    point = getattr(r, "point", "P")
    if r.defects.full_turn:
        grid, label = r.phi[0] + np.linspace(0.0, 2 * math.pi, 721), "full turn"
    else:
        grid, label = np.linspace(r.phi.min(), r.phi.max(), 721), "from the first to the last target"
    m = analyse(engine, grid)
    p = m.xy[:, m.point(point)]
    ax.plot(p[:, 0], p[:, 1], "C0-", label=f"path of {point}, {label} (mbplanar)")
    ax.plot(r.targets[:, 0], r.targets[:, 1], "C3o", mfc="none", label="target points")
    ax.set_title(f"Path generation: RMS {r.rms:.4g}, max {r.max:.4g}")
    _finish(fig, ax, path)


def _pyplot():
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise PlotUnavailable("--plot needs matplotlib (pip install 'mbplanar[plot]')") from None
    return plt


def _finish(fig, ax, path):
    ax.set_aspect("equal", adjustable="box" if ax.get_autoscale_on() is False else "datalim")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    fig.clf()
    import matplotlib.pyplot as plt
    plt.close(fig)
