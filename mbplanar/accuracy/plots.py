"""Pictures of an `Accuracy`: the error bands of the outputs over the cycle and the tolerance zone around
a point's path (`plot MODEL accuracy`), and the report's Accuracy section (`mbplanar report`, for a model
with `[tolerances]`). matplotlib is imported when a picture is drawn.

The tolerance zone is drawn across the path, magnified (the factor is in the legend): at each position
the worst case of the error along the path's normal n, Σ_k |n·S_k| h_k about the mean shift n·Σ_k S_k m_k,
and the statistical ±3σ, 3·√(Σ_k (n·S_k σ_k)²).
"""

from __future__ import annotations

import html
import math

import numpy as np

__all__ = ["accuracy_figure", "figure_of_engine", "report_section", "register", "PICTURE_SAMPLES"]

PICTURE_SAMPLES = 5_000    # the Monte Carlo of a picture or a report: the section's samples, at most this many
BANDS = 3                  # outputs with a panel of bands


def _nice(x: float) -> float:
    """1, 2 or 5 times a power of ten, at most x (≥ 1)."""
    if not math.isfinite(x) or x <= 1:
        return 1.0
    p = 10 ** math.floor(math.log10(x))
    return max(m * p for m in (1, 2, 5) if m * p <= x)


def _display(o, length_name, length_scale):
    """(factor from SI, unit) of an output as drawn: lengths in the model's unit, angles in degrees."""
    return (1.0 / length_scale, length_name) if o.unit == "m" else (180.0 / math.pi, "°")


def _zone(result, ix: int, iy: int):
    """The path (N, 2), its unit normals (N, 2) and, along them, the mean shift, the worst case and 3σ."""
    sens = result.sensitivities
    path = sens.value[:, [ix, iy]]
    tangent = np.gradient(path, axis=0) if len(path) > 2 else np.tile([1.0, 0.0], (len(path), 1))
    if result.full_turn and len(path) > 2:
        tangent = np.roll(path, -1, axis=0) - np.roll(path, 1, axis=0)
    size = np.hypot(tangent[:, 0], tangent[:, 1])
    normal = np.stack([-tangent[:, 1], tangent[:, 0]], axis=1) / np.where(size > 0, size, 1.0)[:, None]
    sn = normal[:, 0, None] * sens.d[:, ix] + normal[:, 1, None] * sens.d[:, iy]           # (N, K)
    tols, dims = result.spec.dimensions, result.dimensions
    scale = np.array([d.scale for d in dims])
    mean = np.array([t.mean for t in tols]) * scale
    std = np.array([t.std for t in tols]) * scale
    half = np.array([t.half_width for t in tols]) * scale
    return path, normal, sn @ mean, np.abs(sn) @ half, 3 * np.sqrt((sn * std) ** 2 @ np.ones(len(std)))


def accuracy_figure(result, length_name: str = "m", length_scale: float = 1.0, engine=None, figsize=(11, 7.5)):
    """The figure of an `Accuracy`: the tolerance zone around its first point's path (with the mechanism
    drawn when `engine` is given) and the error bands of its first outputs over the cycle."""
    from ..viz import COLORS, INK, lean_ticks, require_matplotlib

    plt = require_matplotlib()
    fig = plt.figure(figsize=figsize, layout="constrained")
    outputs = result.outputs
    points = [o.target for o in outputs if o.kind == "x" and any(p.kind == "y" and p.target == o.target
                                                                 for p in outputs)]
    chosen = list(range(len(outputs)))[:BANDS]
    grid = fig.add_gridspec(max(len(chosen), 1), 2 if points else 1, width_ratios=[1.2, 1] if points else [1])
    inp_scale = {"deg": math.pi / 180.0, "mm": 1e-3, "cm": 1e-2}.get(result.unit, 1.0)
    x = result.phi / inp_scale
    if points:
        ax = fig.add_subplot(grid[:, 0])
        name = points[0]
        ix = next(k for k, o in enumerate(outputs) if o.target == name and o.kind == "x")
        iy = next(k for k, o in enumerate(outputs) if o.target == name and o.kind == "y")
        path, normal, shift, worst, sigma3 = _zone(result, ix, iy)
        extent = float(np.max(np.ptp(path, axis=0))) or 1.0
        big = float(np.nanmax(np.abs(shift) + worst)) if len(path) else 0.0
        gain = _nice(0.06 * extent / big) if big > 0 else 1.0
        if engine is not None:
            _draw_mechanism(ax, engine)
        for lo, hi, colour, label in ((shift - worst, shift + worst, "#f4c7a1", "worst case"),
                                      (shift - sigma3, shift + sigma3, "#9ecae1", "±3σ (RSS)")):
            a = path / length_scale + gain * lo[:, None] * normal / length_scale
            b = path / length_scale + gain * hi[:, None] * normal / length_scale
            ax.fill(np.concatenate([a[:, 0], b[::-1, 0]]), np.concatenate([a[:, 1], b[::-1, 1]]), color=colour,
                    alpha=0.9, lw=0, label=f"{label}, errors ×{gain:g}")
        ax.plot(path[:, 0] / length_scale, path[:, 1] / length_scale, color=INK, lw=1.0, label=f"{name}'s path")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel(f"x [{length_name}]")
        ax.set_ylabel(f"y [{length_name}]")
        ax.set_title(f"Tolerance zone of {name} (magnified ×{gain:g})", fontsize=10)
        ax.legend(fontsize=8, frameon=False, loc="best")
        ax.grid(True, alpha=0.3)
    st, mc, cl = result.stack, result.monte_carlo, result.clearances
    for row, y in enumerate(chosen):
        o = outputs[y]
        ax = fig.add_subplot(grid[row, -1])
        lean_ticks(ax, 90.0 if result.unit == "deg" and np.ptp(x) >= 180 else None)
        f, unit = _display(o, length_name, length_scale)
        shift, worst, sigma = st.shift[:, y] * f, st.worst[:, y] * f, st.sigma[:, y] * f
        ax.fill_between(x, shift - worst, shift + worst, color="#f4c7a1", lw=0, label="worst case")
        ax.fill_between(x, shift - 3 * sigma, shift + 3 * sigma, color="#9ecae1", lw=0, label="±3σ (RSS)")
        if mc is not None and mc.count > 1:
            centre = (mc.mean[:, y] - result.sensitivities.value[:, y]) * f
            ax.plot(x, centre - 3 * mc.std[:, y] * f, color=COLORS[0], lw=0.9, ls="--", label="±3σ (Monte Carlo)")
            ax.plot(x, centre + 3 * mc.std[:, y] * f, color=COLORS[0], lw=0.9, ls="--")
        if cl is not None:
            err = (cl.error[:, y] if cl.loaded else cl.worst[:, y]) * f
            ax.plot(x, err, color=COLORS[1], lw=1.1, label="clearances" + ("" if cl.loaded else " (worst)"))
            for joint, knocks in cl.knocks.items():
                for k in knocks:
                    ax.axvline(k / inp_scale, color=COLORS[1], lw=0.6, ls=":")
        ax.axhline(0.0, color=INK, lw=0.6)
        ax.set_ylabel(f"error of {o.name} [{unit}]")
        ax.grid(True, alpha=0.3)
        if row == len(chosen) - 1:
            ax.set_xlabel(f"{result.input} [{result.unit}]")
        if row == 0:
            ax.legend(fontsize=7, frameon=False, ncols=2)
    fig.suptitle(f"{result.model}: accuracy over the cycle", fontsize=11)
    return fig


def _draw_mechanism(ax, engine):
    """The mechanism in its drawn pose, faint, behind the zone."""
    from ..viz import build_scene, cycle_motion, draw_mechanism, position_motion

    motion = position_motion(engine, None)
    scene = build_scene(engine, motion, cycle_motion(engine, 36))
    draw_mechanism(ax, scene, 0, labels=True, alpha=0.35)


def _result_of(engine, samples=None, positions=None):
    """The `Accuracy` of the engine's model file (None without `[tolerances]`), its Monte Carlo with the
    section's samples, at most `PICTURE_SAMPLES` (or `samples`), at the section's positions (or
    `positions`)."""
    from ..model import TOLERANCES
    from .run import accuracy

    section = engine.mech.extras.get("tolerances")
    if section is None:
        return None
    if samples is None:
        given = section.get("samples", TOLERANCES["samples"].default) if isinstance(section, dict) else None
        samples = min(given, PICTURE_SAMPLES) if isinstance(given, int) and given >= 1 else PICTURE_SAMPLES
    return accuracy(engine.mech.source, samples=samples, positions=positions, backend=engine.backend)


def figure_of_engine(engine, at=None, *, samples=None, count=None, **options):
    """`plot MODEL accuracy`: the figure of the model's `[tolerances]` (its Monte Carlo with at most
    `PICTURE_SAMPLES` samples, unless `samples`; `count` positions, default the section's)."""
    from ..errors import ModelError
    from ..model import Units

    result = _result_of(engine, samples, count)
    if result is None:
        raise ModelError("no [tolerances] section: the accuracy picture needs one (docs/format.md)",
                         source=engine.mech.source)
    unit = result.length_unit
    return accuracy_figure(result, unit, Units(length=unit).length_scale, engine=engine, **options)


def report_section(engine, ctx):
    """The report's Accuracy section: None for a model without `[tolerances]`; the reason, for a model the
    analysis refuses (a bad row: the rest of the report stands)."""
    from ..errors import ModelError
    from ..model import Units
    from ..viz import html_table
    from .report import format_text

    if engine.mech.extras.get("tolerances") is None:
        return None
    try:
        result = _result_of(engine)
    except ModelError as exc:
        return f'<p class="warn">{html.escape(str(exc))}</p>'
    unit = result.length_unit
    scale = Units(length=unit).length_scale
    lines = format_text(result, unit, scale).splitlines()
    head, body = lines[:2], lines[2:]
    header = [c.strip() for c in _columns(body[0])]
    names = tuple(o.name + " " for o in result.outputs)
    table_rows = [_columns(line) for line in body[1:] if line.startswith(names)]
    notes = [line for line in body[1:] if not line.startswith(names)]
    text = "".join(f"<p>{html.escape(line)}</p>" for line in head + notes)
    fig = accuracy_figure(result, unit, scale, engine=engine)
    return (text + html_table(header, table_rows, "Errors over the cycle (largest over the positions)")
            + ctx.figure(fig, "tolerance zone and error bands"))


def _columns(line: str) -> list[str]:
    """The cells of a line of the text summary (two or more spaces apart)."""
    import re
    return [c for c in re.split(r"\s{2,}", line.strip()) if c]


def register() -> None:
    """Add the accuracy picture to `mbplanar plot` and the Accuracy section to `mbplanar report`."""
    from ..viz import register_figure, register_section

    register_figure("accuracy", figure_of_engine, "error bands over the cycle and the tolerance zone around a "
                                                  "point's path (models with [tolerances])")
    register_section("accuracy", "Accuracy", report_section, after="friction")
