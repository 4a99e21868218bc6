"""The synthesis summary a synthesised model carries, and its section in `mbplanar report`.

`mbplanar synth ... -o best.toml` appends the run's summary to the model as a `[synthesis]` table
(`summary_table`): the problem, the target points with their errors (by mbplanar's analysis), the RMS
and largest error, the defects checked, the constraints, the seed, the evaluations and the time. The
model stays an ordinary model; `mbplanar report best.toml` then shows a "Synthesis" section with these
numbers and, for path generation, the target points against the analysed path.
"""

from __future__ import annotations

import html
import math

import numpy as np

from ._models import _key, _value

__all__ = ["summary_table", "report_section", "register"]

KEPT = ("problem", "form", "point", "timed", "success", "message", "warnings", "rms_error", "max_error",
        "error_unit", "errors", "targets", "target_phi_deg", "evaluations", "seed", "starts", "seconds", "budget",
        "stopped", "delta1", "delta2", "delta", "parameters", "design", "constraints", "order", "tradeoff",
        "defects")


def _plain(v):
    """TOML-safe copy: no None (TOML has no null), no non-finite numbers, no empty tables."""
    if isinstance(v, dict):
        out = {str(k): _plain(x) for k, x in v.items() if x is not None}
        return {k: x for k, x in out.items() if x is not None and x != {}}
    if isinstance(v, (list, tuple)):
        items = [_plain(x) for x in v]
        return items if all(x is not None for x in items) else None
    if isinstance(v, (bool, str)):
        return v
    if isinstance(v, (int, float, np.integer, np.floating)):
        return v if math.isfinite(float(v)) else None
    return None


def summary_table(summary: dict) -> str:
    """The `[synthesis]` table (TOML text) of a run's summary."""
    data = _plain({k: summary[k] for k in KEPT if k in summary})
    lines = ["", "# The synthesis that produced this model (shown by `mbplanar report`)", "[synthesis]"]
    lines += [f"{_key(k)} = {_value(v)}" for k, v in data.items()]
    return "\n".join(lines) + "\n"


def report_section(engine, ctx):
    """The report's synthesis section: present when the model carries a `[synthesis]` table."""
    s = getattr(engine.mech, "extras", {}).get("synthesis")
    if not isinstance(s, dict):
        return None
    from ..viz import html_table
    unit = s.get("error_unit", "")
    rows = [(k, s[k]) for k in ("problem", "point", "success", "rms_error", "max_error", "evaluations", "seed",
                                "starts", "seconds", "delta1", "delta2", "delta") if k in s]
    parts = [html_table(("quantity", "value"), rows, f"Synthesis result (errors in {unit})")]
    defects = s.get("defects", {})
    if defects:
        found = [k for k in ("circuit", "branch", "unreached") if defects.get(k)] + (["order"] if defects.get("order") else [])
        parts.append(f"<p>Defects checked by mbplanar's analysis: {html.escape(', '.join(defects.get('checked', [])))}"
                     f" — {'none found' if not found else 'found: ' + html.escape(', '.join(found))}.</p>")
    warnings = s.get("warnings") or []
    if warnings:
        items = "".join(f"<li>{html.escape(str(w))}</li>" for w in warnings)
        parts.append(f"<p>Warnings of the synthesis:</p><ul>{items}</ul>")
    for key, title in (("design", "Design"), ("parameters", "Parameters found"), ("constraints", "Constraints")):
        if isinstance(s.get(key), dict):
            parts.append(html_table(("name", "value"), [(k, _text(v)) for k, v in s[key].items()], title))
    targets, errors = s.get("targets"), s.get("errors")
    if targets and errors and len(targets) == len(errors):
        parts.append(html_table(("target", "x", "y", f"error [{unit}]"),
                                [(i + 1, t[0], t[1], e) for i, (t, e) in enumerate(zip(targets, errors))],
                                "Target points and their distances from the analysed path"))
        point = s.get("point", "P")
        if point in engine.mech.points or point in engine.mech.joints:
            parts.append(ctx.figure(_path_figure(engine, ctx, np.array(targets, float), point),
                                    "target points against the analysed path"))
    return "\n".join(parts)


def _text(v) -> str:
    return f"{v:.6g}" if isinstance(v, float) else str(v)


def _path_figure(engine, ctx, targets, point):
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 5))
    m = ctx.cycle
    p = m.xy[:, m.point(point)]
    ax.plot(p[:, 0], p[:, 1], "C0-", label=f"path of {point} (mbplanar)")
    ax.plot(targets[:, 0], targets[:, 1], "C3o", mfc="none", label="target points")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return fig


def register() -> None:
    """Add the synthesis section to `mbplanar report` (after the model's section)."""
    from ..viz import register_section
    register_section("synthesis", "Synthesis", report_section, after="model")
