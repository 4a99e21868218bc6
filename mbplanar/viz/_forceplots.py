"""Pictures of the kinetostatics: reaction arrows on the kinematic diagram, and the reactions and the
balancing moment against the generalized coordinate (magnitudes, hodographs, moments).

Forces are computed by `mbplanar.forces.kinetostatics` at the model's input speed and acceleration (no
flywheel: J_I = 0). A model without masses, gravity or loads has no forces to draw: the pictures say so.
matplotlib is imported only through `mbplanar.viz._plotting.require_matplotlib`.
"""

from __future__ import annotations

import textwrap

import numpy as np

from ..kinematics import contact_geometry, describe_limit
from ..forces import has_force_data, kinetostatics
from ._plotting import (COLORS, _coordinate, _figure, _full_turn, _plot_lines, _xstep, cycle_motion, include_points,
                       input_speed, lean_ticks, require_matplotlib)

__all__ = ["reaction_label", "balancing_label", "draw_reactions", "forces_figure", "NO_LOADS"]

NO_LOADS = "the model has no masses, inertias, gravity or loads: every reaction is zero"
REACTION_COLOR = "#1e8449"


def reaction_label(reaction) -> str:
    """The label of a joint's reaction: F_ij, the force on link i from link j.

    Parameters
    ----------
    reaction : Reaction
        A reaction of a kinetostatics result (its `on` and `source` links).

    Returns
    -------
    str
        'F12' for one-character link names, 'F[crank,rod]' otherwise.

    Raises
    ------
    AttributeError
        An object without `on` and `source`.

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> from mbplanar.viz import reaction_label
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> result = mbplanar.kinetostatics(engine, mbplanar.analyse(engine, np.radians([30.0])))
    >>> {joint: reaction_label(r) for joint, r in result.reactions.items()}
    {'O': 'F10', 'A': 'F12', 'B': 'F23', 'C': 'F30'}
    """
    on, src = reaction.on, reaction.source
    return f"F{on}{src}" if len(on) == 1 and len(src) == 1 else f"F[{on},{src}]"


def balancing_label(engine, joint: str) -> tuple[str, str]:
    """('balancing moment' or 'balancing force', unit) of the input at `joint`."""
    rotary = engine.mech.joints[joint].kind == "R"
    return ("balancing moment", "N·m") if rotary else ("balancing force", "N")


def draw_reactions(ax, engine, result, b: int, size: float, share: float = 0.3) -> float:
    """Reaction arrows at position `b` of a `Kinetostatics`: one per pair, from the pair's point along the
    force on link i from link j (label F_ij), one scale for all, the longest `share`·size long. The
    scale, the moments in prismatic pairs and the balancing loads go to the legend. Returns the scale
    (m per N; 0 when nothing is drawn). Arrows carry gid 'reaction:JOINT'."""
    motion = result.motion
    forces = {n: np.array([r.fx[b], r.fy[b]]) for n, r in result.reactions.items()}
    big = max([float(np.linalg.norm(f)) for f in forces.values() if np.all(np.isfinite(f))], default=0.0)
    if not big > 0:
        msg = NO_LOADS if not has_force_data(engine.mech) else "no reaction at this position"
        ax.plot([], [], color=REACTION_COLOR, lw=2, label=f"reactions: {msg}" if result.success else
                f"reactions: {result.message}")
        return 0.0
    k = share * size / big
    contact = {n: g.point for n, g in contact_geometry(engine, motion).items()} if engine.mech.higher else {}
    tips = {}  # arrows drawn on top of each other (F12 = F23 through a massless block) share one label
    for name, f in forces.items():
        if not (np.all(np.isfinite(f)) and np.linalg.norm(f) > 1e-9 * big):
            continue
        p = contact[name][b] if name in contact else motion.xy[b, motion.point(name)]
        ax.quiver([p[0]], [p[1]], [f[0] * k], [f[1] * k], angles="xy", scale_units="xy", scale=1,
                  color=REACTION_COLOR, width=0.005, zorder=10, gid=f"reaction:{name}")
        key = tuple(np.round(np.concatenate([p, p + f * k]) / (1e-4 * size)).astype(int))
        tips.setdefault(key, (p + f * k, name, []))[2].append(reaction_label(result.reactions[name]))
    include_points(ax, [tip for tip, _, _ in tips.values()], 0.08 * size)
    for tip, name, labels in tips.values():
        ax.annotate(" = ".join(labels), tip, xytext=(3, 3), textcoords="offset points", fontsize=9,
                    color=REACTION_COLOR, fontweight="bold", zorder=10, gid=f"reactionlabel:{name}")
    ax.plot([], [], color=REACTION_COLOR, lw=2, label=f"reactions: {size * share:.3g} m ≙ {_newtons(big)} N")
    for name, r in result.reactions.items():
        if engine.mech.kind_of(name) == "P" and np.isfinite(r.moment[b]):
            m = r.moment[b] if abs(r.moment[b]) > 1e-9 * big * size else 0.0
            ax.plot([], [], ls="none", label=f"moment in {name} ({reaction_label(r)}): {m:.4g} N·m")
    for name, q in result.balancing.items():
        what, unit = balancing_label(engine, name)
        ax.plot([], [], ls="none", label=f"{what} at {name}: {q[b]:.4g} {unit}")
    return k


def _newtons(x: float) -> str:
    return f"{x:.4g}" if abs(x) < 1e4 else f"{x:.0f}"


def forces_figure(engine, at=None, *, count=181, cycle=None, figsize=(10, 8)):
    """Reactions and balancing loads over the cycle at the model's speed: |F_ij| of every pair, their
    hodographs (the tip of F_ij), the balancing moment (with its cycle mean on a full turn) and the
    moments in the prismatic pairs. `cycle`: a cycle motion to reuse."""
    plt = require_matplotlib()
    motion = cycle_motion(engine, count) if cycle is None else cycle
    inp = engine.inputs[0]
    name = engine.mech.title or engine.mech.name
    speed = input_speed(engine)
    if not has_force_data(engine.mech):
        fig = _figure(plt, (7, 3))
        ax = fig.add_subplot()
        ax.text(0.5, 0.5, NO_LOADS, ha="center", va="center", transform=ax.transAxes, gid="noloads")
        ax.set_axis_off()
        fig.suptitle(f"{name}: reactions", fontsize=10)
        return fig
    result = kinetostatics(engine, motion)
    x, xlabel = _coordinate(engine, motion.phi[:, 0])
    fig = _figure(plt, figsize)
    axes = fig.subplots(2, 2)
    names = [reaction_label(r) + f" ({j})" for j, r in result.reactions.items()]
    step = _xstep(engine, x)
    _plot_lines(axes[0, 0], x, [r.magnitude for r in result.reactions.values()], names, "|F| [N]", xlabel,
                "Reaction magnitudes", step)
    hod = axes[0, 1]
    lean_ticks(hod)
    for k, (label, r) in enumerate(zip(names, result.reactions.values())):
        hod.plot(r.fx, r.fy, color=COLORS[k % len(COLORS)], lw=1.2, label=label, gid=f"hodograph:{r.joint}")
    hod.plot([0], [0], marker="+", color="k", ms=8, ls="none")
    hod.set_aspect("equal", adjustable="datalim")
    hod.set_xlabel("Fx [N]")
    hod.set_ylabel("Fy [N]")
    hod.set_title("Hodographs of the reactions", fontsize=10)
    hod.grid(True, alpha=0.3)
    bal = axes[1, 0]
    lean_ticks(bal, step)
    for k, (joint, q) in enumerate(result.balancing.items()):
        what, unit = balancing_label(engine, joint)
        bal.plot(x, q, color=COLORS[k % len(COLORS)], lw=1.6, label=f"{what} at {joint}", gid=f"balancing:{joint}")
        if _full_cycle(engine, motion) and np.all(np.isfinite(q)):
            bal.axhline(float(np.mean(q)), color=COLORS[k % len(COLORS)], ls="--", lw=1,
                        label=f"cycle mean {np.mean(q):.4g} {unit}")
    what, unit = balancing_label(engine, inp.joint)
    bal.axhline(0, color="k", lw=0.6)
    _style(bal, f"{what.capitalize()} [{unit}]", xlabel, what.capitalize())
    prismatic = [(j, r) for j, r in result.reactions.items() if engine.mech.kind_of(j) == "P"]
    if prismatic:
        _plot_lines(axes[1, 1], x, [r.moment for _, r in prismatic],
                    [f"{reaction_label(r)} ({j})" for j, r in prismatic], "M [N·m]", xlabel,
                    "Moments in the prismatic pairs", step)
    else:
        axes[1, 1].set_axis_off()
    residual = float(np.nanmax(result.virtual_power_residual)) if len(motion.phi) else 0.0
    notes = [f"virtual-power residual ≤ {residual:.1e}"]
    notes += [] if result.success else [result.message]
    notes += [describe_limit(engine, lim) for lim in motion.limits]
    fig.suptitle(f"{name}: reactions and {what} at {speed}\n" + textwrap.fill("; ".join(notes), 120),
                 fontsize=10)
    return fig


def _full_cycle(engine, motion) -> bool:
    """True when `motion` covers exactly one turn of the input, equally spaced (its mean is the cycle's)."""
    return _full_turn(engine) and motion.success and not motion.limits and len(motion.phi) > 2


def _style(ax, ylabel, xlabel, title):
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, frameon=False)
