"""An `Accuracy` for people and files: the JSON document (``mbplanar accuracy --json``, `mbplanar.io.document`),
the CSV table (``-o FILE.csv``, one row per position) and the text summary.

Documents and tables are in SI (m, rad), or with ``units="model"`` every length in the model's length
unit; the text gives lengths in the model's length unit and angles in degrees.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["document", "table", "format_text", "KEYS"]

#: the keys of an output's entry in the document
KEYS = ("name", "unit", "nominal", "shift", "worst", "sigma", "worst_max", "sigma_max", "contributions",
        "sensitivities", "monte_carlo", "clearance")


def _scale(result, units: str | None):
    """(metres per reported length unit, its name)."""
    if units in (None, "si"):
        return 1.0, "m"
    if units != "model":
        raise ValueError(f"units must be si or model, got {units!r}")
    from ..model import Units
    name = _length_unit(result)
    return Units(length=name).length_scale, name


def _length_unit(result) -> str:
    return result.length_unit


def _plain(x):
    from ..io import plain
    return plain(x)


def _unit(o, length_name):
    return length_name if o.unit == "m" else "rad"


def document(result, units: str | None = None) -> dict:
    """The JSON-ready document of an `Accuracy` (see docs/accuracy.md for its keys)."""
    factor, length_name = _scale(result, units)
    sens, st, mc, cl = result.sensitivities, result.stack, result.monte_carlo, result.clearances

    def conv(o, arr):
        return np.asarray(arr) / factor if o.unit == "m" else np.asarray(arr)

    outputs = []
    for y, o in enumerate(result.outputs):
        ranked = st.ranked(y)
        entry = {
            "name": o.name, "unit": _unit(o, length_name),
            "nominal": conv(o, sens.value[:, y]), "shift": conv(o, st.shift[:, y]), "worst": conv(o, st.worst[:, y]),
            "sigma": conv(o, st.sigma[:, y]),
            "worst_max": float(conv(o, np.nanmax(np.abs(st.shift[:, y]) + st.worst[:, y]))) if len(sens.phi) else None,
            "sigma_max": float(conv(o, np.nanmax(st.sigma[:, y]))) if len(sens.phi) else None,
            "contributions": [{"dimension": result.dimensions[k].name, "share": float(st.share[y, k]),
                               "peak": float(conv(o, st.peak[y, k]))} for k in ranked],
            "sensitivities": {d.name: sens.d[:, y, k] * (d.scale / (factor if o.unit == "m" else 1.0))
                              for k, d in enumerate(result.dimensions)},
            "monte_carlo": None if mc is None else {
                "mean": conv(o, mc.mean[:, y]), "std": conv(o, mc.std[:, y]), "low": conv(o, mc.low[:, y]),
                "high": conv(o, mc.high[:, y]), "std_over_rss": _ratio(mc.std[:, y], st.sigma[:, y])},
            "clearance": None if cl is None else {
                "error": conv(o, cl.error[:, y]), "worst": conv(o, cl.worst[:, y]),
                "error_max": float(conv(o, np.nanmax(np.abs(cl.error[:, y])))) if len(sens.phi) else None,
                "worst_max": float(conv(o, np.nanmax(cl.worst[:, y]))) if len(sens.phi) else None},
        }
        outputs.append(entry)
    dims = []
    for d, t in zip(result.dimensions, result.spec.dimensions):
        dims.append({"name": d.name, "unit": d.unit, "nominal": d.nominal, "distribution": t.distribution,
                     "lower": None if t.sigma is not None else t.lower, "upper": None if t.sigma is not None else t.upper,
                     "sigma": t.sigma, "mean": t.mean, "std": t.std, "row": t.row})
    inp_scale = _input_scale(result)
    doc = {
        "model": result.model, "source": result.source, "input": result.input, "unit": result.unit,
        "positions": len(result.phi), "full_turn": result.full_turn, "phi": result.phi,
        "phi_input": result.phi / inp_scale,
        "dimensions": dims, "outputs": outputs,
        "monte_carlo": None if mc is None else {
            "samples": mc.samples, "seed": mc.seed, "count": mc.count, "not_assembled": mc.not_assembled,
            "locking": mc.locking,
            "causes": {kind: [{"dimension": c.dimension, "correlation": c.correlation,
                               "mean_deviation": c.mean_deviation} for c in causes]
                       for kind, causes in mc.causes.items()}},
        "clearances": None if cl is None else {
            "loaded": cl.loaded,
            "pairs": [{"joint": j, "clearance": float(c) / factor, "knocks": list(cl.knocks.get(j, ())),
                       "knocks_input": [k / inp_scale for k in cl.knocks.get(j, ())]}
                      for j, c in zip(cl.joints, cl.clearances)]},
        "success": result.success, "message": result.message,
    }
    if units == "model":
        doc["units"] = {"length": length_name, "angle": "rad"}
    return _plain(doc)


def _ratio(a, b) -> float | None:
    with np.errstate(invalid="ignore", divide="ignore"):
        r = a / b
    r = r[np.isfinite(r) & (b > 0)]
    if not len(r):
        return None
    return float(r[np.argmax(np.abs(r - 1.0))])


def _input_scale(result) -> float:
    return {"deg": math.pi / 180.0, "mm": 1e-3, "cm": 1e-2}.get(result.unit, 1.0)


def table(result, units: str | None = None):
    """(header, columns (N, k)): per position the input (its unit), then per output its nominal value,
    mean shift, worst case, σ, the Monte Carlo's mean, σ, lowest and highest, the clearances' error,
    and its sensitivity to every dimension (per SI unit of the dimension)."""
    factor, length_name = _scale(result, units)
    sens, st, mc, cl = result.sensitivities, result.stack, result.monte_carlo, result.clearances
    header = [f"{result.input}[{result.unit}]"]
    cols = [result.phi / _input_scale(result)]
    for y, o in enumerate(result.outputs):
        u = _unit(o, length_name)
        f = factor if o.unit == "m" else 1.0
        parts = [("nominal", sens.value[:, y]), ("shift", st.shift[:, y]), ("worst", st.worst[:, y]),
                 ("sigma", st.sigma[:, y])]
        if mc is not None:
            parts += [("mc_mean", mc.mean[:, y]), ("mc_sigma", mc.std[:, y]), ("mc_low", mc.low[:, y]),
                      ("mc_high", mc.high[:, y])]
        if cl is not None:
            parts += [("clearance", cl.error[:, y]), ("clearance_worst", cl.worst[:, y])]
        for what, arr in parts:
            header.append(f"{o.name}.{what}[{u}]")
            cols.append(arr / f)
        for k, d in enumerate(result.dimensions):
            header.append(f"d({o.name})/d({d.name})[{u}/{_si_unit(d)}]")
            cols.append(sens.d[:, y, k] / f)
    return header, np.stack(cols, axis=1)


def _si_unit(d) -> str:
    if d.unit in ("length", "m", "mm", "cm"):
        return "m"
    if d.unit in ("deg", "rad"):
        return "rad"
    return "1"


def _shown(o, value, length_name, length_scale) -> str:
    """A length in the model's unit or an angle in degrees, with its unit."""
    if value is None or not math.isfinite(value):
        return "—"
    if o.unit == "m":
        return f"{value / length_scale:.4g} {length_name}"
    return f"{math.degrees(value):.4g}°"


def format_text(result, length_name: str = "m", length_scale: float = 1.0, top: int = 3) -> str:
    """The summary `mbplanar accuracy` prints: per output, over the cycle, its largest worst-case error
    (about the mean shift), its largest standard deviation from the RSS of the exact sensitivities and from
    the Monte Carlo, the Monte Carlo's largest deviation from nominal, the clearances' largest error, and the
    dimensions contributing most (share of the variance); then the Monte Carlo's failures and the knocks."""
    sens, st, mc, cl = result.sensitivities, result.stack, result.monte_carlo, result.clearances
    inp_scale = _input_scale(result)
    where = "one turn" if result.full_turn else (
        f"{result.phi[0] / inp_scale:.6g} to {result.phi[-1] / inp_scale:.6g} {result.unit}")
    lines = [f"{result.model}: {len(result.dimensions)} toleranced dimension(s), "
             f"{len(result.spec.clearances)} clearance(s); {len(result.phi)} positions of {result.input} "
             f"[{result.unit}] over {where}"]
    if mc is not None:
        lines.append(f"Monte Carlo: {mc.samples} samples (seed {mc.seed}), {mc.count} assembled and reached every "
                     "position")
    head = ["output", "worst case", "σ (RSS)"] + (["σ (MC)", "MC range"] if mc is not None else []) + \
        (["clearances" if cl.loaded else "clearances (worst)"] if cl is not None else []) + \
        ["largest contributions (share of variance)"]
    rows = []
    for y, o in enumerate(result.outputs):
        def shown(v):
            return _shown(o, v, length_name, length_scale)
        worst = float(np.nanmax(np.abs(st.shift[:, y]) + st.worst[:, y])) if len(result.phi) else math.nan
        row = [o.name, "±" + shown(worst), shown(float(np.nanmax(st.sigma[:, y])))]
        if mc is not None:
            good = mc.count > 1
            row.append(shown(float(np.nanmax(mc.std[:, y])) if good else math.nan))
            spread = np.fmax(np.abs(mc.low[:, y] - sens.value[:, y]), np.abs(mc.high[:, y] - sens.value[:, y]))
            row.append("±" + shown(float(np.nanmax(spread)) if mc.count else math.nan))
        if cl is not None:
            err = cl.error[:, y] if cl.loaded else cl.worst[:, y]
            row.append(("" if cl.loaded else "±") + shown(float(np.nanmax(np.abs(err)))))
        ranked = [k for k in st.ranked(y) if st.share[y, k] > 0][:top]
        row.append(", ".join(f"{result.dimensions[k].name} {100 * st.share[y, k]:.1f} %" for k in ranked) or "—")
        rows.append(row)
    widths = [max(len(str(r[i])) for r in rows + [head]) for i in range(len(head) - 1)]
    for r in [head] + rows:
        lines.append("  ".join(str(x).ljust(w) for x, w in zip(r[:-1], widths)) + "  " + str(r[-1]))
    if mc is not None and (mc.not_assembled or mc.locking):
        for kind, words in (("not_assembled", "do not assemble"), ("locking", "lock inside the cycle")):
            frac = getattr(mc, kind)
            if frac:
                causes = ", ".join(f"{c.dimension} ({'high' if c.correlation > 0 else 'low'}, r = "
                                   f"{c.correlation:+.2f})" for c in mc.causes.get(kind, ())[:3])
                lines.append(f"{100 * frac:.3g} % of the samples {words}" + (f": {causes}" if causes else ""))
    if cl is not None:
        if not cl.loaded:
            lines.append("clearances: the model has no loads or masses, so no pair carries a force: each "
                         "clearance counts in its worst direction")
        for j in cl.joints:
            knocks = cl.knocks.get(j, ())
            if knocks:
                lines.append(f"pair {j} knocks (its reaction turns through zero) at {result.input} = "
                             + ", ".join(f"{k / inp_scale:.6g}" for k in knocks) + f" {result.unit}")
    return "\n".join(lines)
