"""A study as a JSON document, a CSV table (one row per design) and a plain-text table."""

from __future__ import annotations

import math

import numpy as np

from ..model import ANGLE_UNITS, DisplayUnits
from .run import Study

__all__ = ["study_document", "study_table", "format_study"]


def _balancing_kind(study: Study) -> str:
    return "moment" if study.unit in ANGLE_UNITS else "force"


def _shown(design: dict, study: Study, display: DisplayUnits) -> dict:
    """A design's document in `display` units: slider extremes and strokes, coupler samples (lengths),
    the mean balancing moment (a revolute input's)."""
    length = display.scale("length")
    for e in design["extremes"]:
        if e["kind"] == "slider":
            for key in ("minimum", "maximum", "stroke"):
                if e.get(key) is not None:
                    e[key] = e[key] / length
    design["samples"] = {k: (np.asarray(v) / length).tolist() for k, v in design["samples"].items()}
    if design.get("mean_balancing") is not None:
        design["mean_balancing"] = design["mean_balancing"] / display.scale(_balancing_kind(study))
    return design


def study_document(study: Study, display: DisplayUnits | None = None) -> dict:
    """JSON-ready document: model, input, parameters, counts and one summary per design, in `display`
    units (default SI), with the "units" object of the other commands."""
    display = display or DisplayUnits()
    return {"model": study.model, "source": study.source, "input": study.input, "unit": study.unit,
            "parameters": list(study.parameters), "counts": study.counts,
            "designs": [_shown(d.as_dict(), study, display) for d in study.designs], "units": display.document()}


def _limit(design, direction):
    return next((lim for lim in design.limits if lim.direction == direction), None)


def _cell(value):
    if value is None:
        return ""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return repr(value) if math.isfinite(value) else ""
    return str(value)


def study_table(study: Study, display: DisplayUnits | None = None) -> tuple[list[str], list[list[str]]]:
    """Header and rows of the summary CSV (angles of limits in degrees, the range in the input's unit,
    lengths and the balancing load in `display` units, default SI)."""
    display = display or DisplayUnits()
    designs = [_shown(d.as_dict(), study, display) for d in study.designs]
    outputs = []
    for d in study.designs:
        for e in d.extremes:
            if (e.name, e.kind) not in outputs:
                outputs.append((e.name, e.kind))
    unit = study.unit
    header = (["variant"] + list(study.parameters) + ["assembles", "full_turn", f"range_lo[{unit}]", f"range_hi[{unit}]",
              "limit_lo[deg]", "limit_lo_kind", "limit_hi[deg]", "limit_hi_kind", "min_transmission[deg]",
              f"min_transmission_at[{unit}]"])
    for name, kind in outputs:
        u = "rad" if kind == "link" else display.name("length")
        header += [f"{name}.min[{u}]", f"{name}.max[{u}]", f"{name}.stroke[{u}]", f"{name}.quick_return"]
    header += ["max_reaction[N]", "max_reaction_joint", f"mean_balancing[{display.name(_balancing_kind(study))}]",
               "reason"]
    rows = []
    for d, doc in zip(study.designs, designs):
        lo, hi = _limit(d, -1), _limit(d, +1)
        row = [d.name] + [_cell(d.parameters.get(p)) for p in study.parameters]
        row += [_cell(d.assembles), _cell(d.full_turn), _cell(d.range[0] if d.range else None),
                _cell(d.range[1] if d.range else None),
                _cell(lo and lo.phi_deg), lo.kind if lo else "", _cell(hi and hi.phi_deg),
                hi.kind if hi else "", _cell(d.transmission_min_deg), _cell(d.transmission_at)]
        by_name = {(e["name"], e["kind"]): e for e in doc["extremes"]}
        for key in outputs:
            e = by_name.get(key, {})
            row += [_cell(e.get("minimum")), _cell(e.get("maximum")), _cell(e.get("stroke")),
                    _cell(e.get("quick_return"))]
        row += [_cell(d.max_reaction), d.max_reaction_joint or "", _cell(doc["mean_balancing"]), d.reason or ""]
        rows.append(row)
    return header, rows


def format_study(study: Study) -> str:
    """Plain text: one line per design with its full turn or its limits (degrees, 7 decimals) and kinds."""
    c = study.counts
    lines = [f"{study.model}: {c['designs']} designs, input {study.input} [{study.unit}]; "
             f"{c['assembled']} assemble, {c['full_turn']} turn fully, {c['locking']} stop at motion limits"]
    width = max([len("variant")] + [len(d.name) for d in study.designs])
    lines.append(f"{'variant':<{width}}  turns  motion limits (input angle in degrees: kind)  "
                 "min transmission [deg]")
    for d in study.designs:
        if not d.assembles:
            lines.append(f"{d.name:<{width}}  —      not assembled: {d.reason}")
            continue
        if d.full_turn:
            what = "full turn"
        else:
            what = "; ".join(f"{lim.phi_deg:.7f}°: {lim.kind}" for lim in d.limits) or "—"
        tmin = "" if d.transmission_min_deg is None else f"  {d.transmission_min_deg:.4f}"
        lines.append(f"{d.name:<{width}}  {'yes' if d.full_turn else 'no':<5}  {what}{tmin}")
    return "\n".join(lines)
