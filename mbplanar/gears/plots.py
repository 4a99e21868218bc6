"""Pictures of a gear design (matplotlib, optional extra `plot`): the block contour with the chosen
shifts, the meshing pair with its line of action, a whole gear, the specific sliding along the path of
contact, and a planetary train's scheme with its velocity diagram."""

from __future__ import annotations

import math

import numpy as np

from ..errors import ModelError
from .export import mesh_placement, placed
from .pair import MARGIN_TOLERANCE

__all__ = ["contour_figure", "mesh_figure", "gear_figure", "sliding_figure", "velocity_figure", "save_figure",
           "PAIR_PICTURES", "TRAIN_PICTURES"]

PAIR_PICTURES = ("contour", "mesh", "gear1", "gear2", "sliding")
TRAIN_PICTURES = ("velocity",)
_COLOURS = ("#b03a2e", "#2a6fb0", "#7d3c98", "#1e8449", "#b9770e", "#5d6d7e", "#a04000", "#117a65")


def _plt():
    """pyplot on the Agg backend; `PlotUnavailable` (exit 2) without matplotlib."""
    from ..viz import require_matplotlib
    return require_matplotlib()


def contour_figure(contour, chosen=None, title: str | None = None):
    """The block contour: the admissible region (shaded), the zero line of every check, the
    balanced-sliding curve (dotted), the line of a fixed sum (dashed) and the chosen point."""
    plt = _plt()
    c = contour
    fig, ax = plt.subplots(figsize=(7, 6))
    X1, X2 = np.meshgrid(c.x1, c.x2)
    ax.contourf(X1, X2, c.admissible.astype(float), levels=[0.5, 1.5], colors=["#e8f1e4"])
    handles = []
    from matplotlib.lines import Line2D
    for k, (name, margin) in enumerate(sorted(c.margins.items())):
        values = np.where(np.isfinite(margin), margin, -1.0)
        # a margin held at zero by construction (a ring's tip cut back to the pinion's form point) is met,
        # not an edge: its rounding noise would draw a scatter of zero lines
        values = np.where(np.abs(values) <= MARGIN_TOLERANCE, MARGIN_TOLERANCE, values)
        if values.min() < 0 < values.max():
            colour = _COLOURS[k % len(_COLOURS)]
            ax.contour(X1, X2, values, levels=[0.0], colors=[colour], linewidths=1.3)
            handles.append(Line2D([], [], color=colour, label=name))
    gap = np.where(np.isfinite(c.sliding_gap), c.sliding_gap, np.nan)
    if np.nanmin(gap) < 0 < np.nanmax(gap):
        ax.contour(X1, X2, gap, levels=[0.0], colors=["k"], linestyles=[":"], linewidths=1.0)
        handles.append(Line2D([], [], color="k", ls=":", label="ζ₁(A) = ζ₂(E)"))
    if c.shift_sum is not None:
        x = c.x1
        y = c.shift_sum + x if c.internal else c.shift_sum - x
        ax.plot(x, y, "k--", lw=0.9)
        handles.append(Line2D([], [], color="k", ls="--", label=f"x_Σ = {c.shift_sum:.4g}"))
    if chosen is not None:
        ax.plot([chosen[0]], [chosen[1]], "r*", ms=14)
        handles.append(Line2D([], [], color="r", marker="*", ls="", ms=10,
                              label=f"chosen ({chosen[0]:.4f}, {chosen[1]:.4f})"))
    ax.set_xlim(c.x1[0], c.x1[-1])
    ax.set_ylim(c.x2[0], c.x2[-1])
    ax.set_xlabel("x₁")
    ax.set_ylabel("x₂")
    ax.grid(alpha=0.25)
    ax.legend(handles=handles, fontsize=7, loc="upper right", framealpha=0.9)
    ax.set_title(title or "Block contour (shaded: every check met)")
    fig.tight_layout()
    return fig


def _active_pieces(prof, r_lo, r_hi):
    """The parts of the involute pieces between radii r_lo and r_hi."""
    out = []
    for piece in prof.pieces:
        if piece.part != "involute":
            continue
        r = np.hypot(piece.points[:, 0], piece.points[:, 1])
        keep = (r >= min(r_lo, r_hi) - 1e-12) & (r <= max(r_lo, r_hi) + 1e-12)
        if keep.sum() > 1:
            out.append(piece.points[keep])
    return out


def mesh_figure(pair, profiles, title: str | None = None):
    """The two gears in mesh near the pitch point: outlines, base, working pitch and tip circles, the line
    of action N₁N₂ with the ends A and E of the path of contact and the pitch point P, the active
    profiles drawn heavier."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7.5, 7.5))
    (c1, t1), (c2, t2) = mesh_placement(pair)
    aw, alw = pair.centre_distance, pair.working_pressure_angle
    rw1 = pair.gears[0].working_diameter / 2
    pitch_point = np.array([0.0, rw1])
    for k, (prof, (centre, turn)) in enumerate(zip(profiles, ((c1, t1), (c2, t2)))):
        g = pair.gears[k]
        out = placed(prof.outline, centre, turn)
        colour = ("#dde6ee", "#f0e2cf")[k]
        if g.internal:
            ax.plot(*np.vstack([out, out[:1]]).T, color="#1a1a1a", lw=0.8)
        else:
            ax.fill(out[:, 0], out[:, 1], color=colour, ec="#1a1a1a", lw=0.8)
        t = np.linspace(0, 2 * math.pi, 1441)
        for r, style, lw in ((g.base_diameter / 2, ":", 0.8), (g.working_diameter / 2, "--", 0.8),
                             (g.tip_diameter / 2, "-", 0.4)):
            ax.plot(centre[0] + r * np.cos(t), centre[1] + r * np.sin(t), ls=style, lw=lw, color="#2a6fb0")
        r_active = g.active_diameter / 2
        for seg in _active_pieces(prof, r_active, prof.tip_radius):
            seg = placed(seg, centre, turn)
            ax.plot(seg[:, 0], seg[:, 1], color=_COLOURS[k], lw=2.4)
        ax.plot(*centre, "k+", ms=10)
    # the line of action: through P at α_w to the common tangent; N₁, N₂ the feet of the perpendiculars
    # from the centres (on the base circles); ρ₁ is measured from N₁ towards P
    direction = np.array([math.cos(alw), -math.sin(alw)])
    n1, n2 = (pitch_point + np.dot(np.asarray(o) - pitch_point, direction) * direction for o in (c1, c2))
    towards_p = (pitch_point - n1) / np.linalg.norm(pitch_point - n1)
    rho_a, rho_e = pair.path
    a_pt, e_pt = n1 + rho_a * towards_p, n1 + rho_e * towards_p
    ax.plot([n1[0], n2[0]], [n1[1], n2[1]], color="k", lw=0.9)
    ax.plot([a_pt[0], e_pt[0]], [a_pt[1], e_pt[1]], color="#b03a2e", lw=3, solid_capstyle="butt")
    for label, p in (("N₁", n1), ("N₂", n2), ("A", a_pt), ("E", e_pt), ("P", pitch_point)):
        ax.plot(*p, "ko", ms=3.5)
        ax.annotate(label, p, textcoords="offset points", xytext=(5, 4), fontsize=9)
    span = 3.5 * pair.module + max(np.linalg.norm(e_pt - pitch_point), np.linalg.norm(a_pt - pitch_point))
    span = max(span, 6 * pair.module)
    ax.set_xlim(pitch_point[0] - 2 * span, pitch_point[0] + 2 * span)
    ax.set_ylim(pitch_point[1] - 2 * span, pitch_point[1] + 2 * span)
    ax.set_aspect("equal")
    z1, z2 = (g.teeth for g in pair.gears)
    ax.set_title(title or f"z = {z1}, {z2}: α_w = {math.degrees(alw):.4f}°, a_w = {aw * 1e3:.4f} mm, "
                          f"ε_α = {pair.contact_ratio:.4f}", fontsize=10)
    ax.grid(alpha=0.15)
    fig.tight_layout()
    return fig


def gear_figure(pair, profile, gear: int):
    """One whole gear with its pitch, base, tip and root circles."""
    plt = _plt()
    g = pair.gears[gear - 1]
    fig, ax = plt.subplots(figsize=(6.5, 6.5))
    out = profile.outline
    if g.internal:
        ax.plot(*np.vstack([out, out[:1]]).T, color="#1a1a1a", lw=0.8)
    else:
        ax.fill(out[:, 0], out[:, 1], color="#dde6ee", ec="#1a1a1a", lw=0.8)
    t = np.linspace(0, 2 * math.pi, 1441)
    for r, style, label in ((g.pitch_diameter / 2, "--", "pitch"), (g.base_diameter / 2, ":", "base"),
                            (g.tip_diameter / 2, "-", "tip"), (g.root_diameter / 2, "-.", "root")):
        ax.plot(r * np.cos(t), r * np.sin(t), ls=style, lw=0.7, color="#2a6fb0", label=f"{label} d = {2 * r * 1e3:.4g} mm")
    ax.plot([0], [0], "k+")
    ax.set_aspect("equal")
    ax.legend(fontsize=7, loc="upper right")
    ax.set_title(f"gear {gear}: z = {g.teeth}, x = {g.shift:.4f}" + (" (undercut)" if profile.undercut else "")
                 + (" (internal)" if g.internal else ""), fontsize=10)
    fig.tight_layout()
    return fig


def sliding_figure(pair):
    """Specific sliding ζ₁, ζ₂ along the path of contact (ρ₁ from N₁), ends A and E marked."""
    plt = _plt()
    rho_a, rho_e = pair.path
    L = pair.line_of_action
    u = pair.ratio
    lo = max(rho_a, 1e-6 * L) if rho_a > 0 else 1e-3 * L
    rho1 = np.linspace(lo, rho_e, 600)
    rho2 = L + rho1 if pair.internal else L - rho1
    with np.errstate(divide="ignore", invalid="ignore"):
        z1 = 1 - rho2 / (u * rho1)
        z2 = 1 - u * rho1 / rho2
    fig, ax = plt.subplots(figsize=(7.5, 4))
    ax.plot(rho1 * 1e3, z1, label="ζ₁", color=_COLOURS[0])
    ax.plot(rho1 * 1e3, z2, label="ζ₂", color=_COLOURS[1])
    for rho, name in ((rho_a, "A"), (rho_e, "E")):
        ax.axvline(rho * 1e3, color="grey", lw=0.7, ls=":")
        ax.annotate(name, (rho * 1e3, 0), textcoords="offset points", xytext=(3, 5))
    bottom = min(np.nanmin(z1[np.isfinite(z1)]), np.nanmin(z2[np.isfinite(z2)]))
    ax.set_ylim(max(bottom, -10) - 0.2, 1.1)
    ax.axhline(0, color="k", lw=0.6)
    ax.set_xlabel("ρ₁ from N₁ along the line of action, mm")
    ax.set_ylabel("specific sliding")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    return fig


def velocity_figure(train, omega_in: float = 1.0):
    """The train's half section (gears as bars at their radii, the carrier, the fixed gear hatched) beside
    its velocity diagram: the linear velocity of each link against the radius, v = ω r for the central
    links and the carrier, a straight line through the planet's two pitch points for the planet."""
    from .planetary import SCHEMES, train_speeds
    plt = _plt()
    sch = SCHEMES[train.scheme]
    m = train.module
    z1, z2, z3, z4 = (train.teeth[0], train.teeth[1], train.teeth[1], train.teeth[2]) if not sch.two_rows \
        else train.teeth
    r1, r2, r3, r4 = (m * z / 2 for z in (z1, z2, z3, z4))
    aw = train.centre_distance
    w = train_speeds(train, omega_in)
    fig, (sk, vd) = plt.subplots(1, 2, figsize=(10, 5.5), sharey=True, gridspec_kw={"width_ratios": [1, 1.4]})
    rows = (0.0, 1.0) if sch.two_rows else (0.0, 0.0)
    # half section: each gear a bar from its centre's radius ± its pitch radius
    bar = dict(lw=6, solid_capstyle="butt")
    p1 = r1                                                   # pitch point of gear 1 – planet
    p2 = aw + r3 if sch.second == "internal" else aw - r3     # pitch point of planet – gear 4
    sk.plot([rows[0]] * 2, [0, r1], color=_COLOURS[0], **bar, label=f"1 (z = {z1})")
    sk.plot([rows[0]] * 2, [aw - r2, aw + r2], color=_COLOURS[1], **bar, label=f"2 (z = {z2})")
    if sch.two_rows:
        sk.plot([rows[1]] * 2, [aw - r3, aw + r3], color=_COLOURS[1], **bar, label=f"3 (z = {z3})")
        sk.plot(rows, [aw, aw], color=_COLOURS[1], lw=2)
    fixed_lo, fixed_hi = (r4, r4 + 3 * m) if sch.second == "internal" else (0, r4)
    sk.plot([rows[1]] * 2, [fixed_lo, fixed_hi], color="#5d6d7e", **bar, label=f"{4 if sch.two_rows else 3} "
                                                                                 f"(z = {z4}, fixed)")
    sk.plot([rows[1] + 0.12] * 2, [fixed_lo, fixed_hi], color="#5d6d7e", lw=1)
    for y in np.linspace(fixed_lo, fixed_hi, 6):
        sk.plot([rows[1] + 0.12, rows[1] + 0.22], [y, y - 0.02 * aw], color="#5d6d7e", lw=0.8)
    hx = rows[0] - 0.5
    sk.plot([hx, hx, rows[0] - 0.2], [0, aw, aw], color="k", lw=2, label="carrier H")
    if sch.first == "internal":                               # gear 1 is a ring: a bar at its radius
        sk.lines[0].set_ydata([r1, r1 + 3 * m])
    sk.axhline(0, color="k", lw=0.6, ls="-.")
    sk.set_xlim(-1.2, 1.8)
    sk.set_xticks([])
    sk.set_ylabel("radius, m")
    sk.legend(fontsize=7, loc="upper left")
    sk.set_title(f"scheme {train.scheme}, {train.planets} planets", fontsize=10)
    # velocity diagram (velocities in m/s for ω_in = 1 rad/s)
    top = max(r4 + 3 * m, aw + max(r2, r3), r1 + 3 * m)
    ys = np.array([0.0, top])
    vd.plot(w["gear 1"] * ys, ys, color=_COLOURS[0], label=f"1: ω = {w['gear 1']:.5g}")
    vd.plot(w["carrier"] * ys, ys, color="k", label=f"H: ω = {w['carrier']:.5g}")
    v_p1 = w["gear 1"] * p1                                   # the planet's velocity at its pitch points
    v_p2 = 0.0
    yp = np.array([aw - max(r2, r3), aw + max(r2, r3)])
    vd.plot(v_p1 + w["planet"] * (yp - p1), yp, color=_COLOURS[1], label=f"2: ω = {w['planet']:.5g}")
    vd.plot([0, 0], [0, top], color="#5d6d7e", lw=2, label="fixed gear: v = 0")
    for y, v, name in ((p1, v_p1, "P₁₂"), (p2, v_p2, "P₃₄"), (aw, w["carrier"] * aw, "O₂")):
        vd.plot([v], [y], "ko", ms=3.5)
        vd.annotate(name, (v, y), textcoords="offset points", xytext=(4, 3), fontsize=8)
        vd.axhline(y, color="grey", lw=0.4, ls=":")
    vd.axvline(0, color="k", lw=0.6)
    vd.set_xlabel(f"linear velocity, m/s (ω_in = {omega_in:g} rad/s)")
    vd.legend(fontsize=7, loc="upper left")
    vd.grid(alpha=0.25)
    vd.set_title(f"velocity diagram: ratio {train.ratio:.6g}", fontsize=10)
    fig.tight_layout()
    return fig


def save_figure(fig, path) -> None:
    """Write a figure (PNG, SVG or PDF) and close it."""
    from ..viz import save_figure as save
    suffix = str(path).rsplit(".", 1)[-1].lower()
    if suffix not in ("png", "svg", "pdf"):
        raise ModelError(f"--plot-output must end in .png, .svg or .pdf, got {path}")
    save(fig, path)
