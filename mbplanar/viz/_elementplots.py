"""Pictures of the force elements and of what the forces do: springs drawn as springs (a zigzag),
dampers as dashpots, rotational dampers and torques between links as arcs, applied loads as arrows on
the kinematic diagram; the shaking force's hodograph and the shaking moment over the cycle; the
efficiency with friction against the input; the simulated motion against time.

matplotlib is imported only through `mbplanar.viz._plotting.require_matplotlib`.
"""

from __future__ import annotations

import textwrap

import numpy as np

from ..errors import ModelError
from ..forces import ELEMENT_TYPES, drawn_end, evaluate_loads, read_loads, world_points
from ._plotting import (COLORS, _coordinate, _figure, _plot_lines, _xstep, cycle_motion, include_points,
                       input_speed, lean_ticks, require_matplotlib)

__all__ = ["spring_path", "draw_elements", "draw_loads", "shaking_figure", "efficiency_figure",
           "simulation_figure"]

SPRING_COLOR = "#7d3c98"
LOAD_COLOR = "#d35400"


def spring_path(a, b, turns: int = 6, width: float = 0.05) -> np.ndarray:
    """Points (K, 2) of a zigzag spring from a to b: straight ends of a sixth of the length each, and
    `turns` zigzags `width` times the length wide (at least a tenth of the free length's...)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = b - a
    length = float(np.hypot(*d))
    if length == 0:
        return np.array([a, b])
    u, n = d / length, np.array([-d[1], d[0]]) / length
    s = np.linspace(1 / 6, 5 / 6, 2 * turns + 1)
    side = np.zeros_like(s)
    side[1:-1:2], side[2:-1:2] = 1.0, -1.0
    mid = a + np.outer(s * length, u) + np.outer(side * width * length, n)
    return np.vstack([a, mid, b])


def _dashpot(ax, a, b, color, gid):
    """A dashpot from a to b: a rod from a into an open cylinder on b's side."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = b - a
    length = float(np.hypot(*d))
    if length == 0:
        return
    u, n = d / length, np.array([-d[1], d[0]]) / length
    w = 0.08 * length
    c0, c1 = a + 0.45 * length * u, a + 0.75 * length * u  # the cylinder
    piston = a + 0.55 * length * u
    ax.plot(*np.array([a, piston]).T, color=color, lw=1.4, zorder=6, gid=gid)
    ax.plot(*np.array([piston - w * 0.8 * n, piston + w * 0.8 * n]).T, color=color, lw=2.0, zorder=6, gid=gid)
    cup = np.array([c0 + w * n, c1 + w * n, c1 - w * n, c0 - w * n])
    ax.plot(*cup.T, color=color, lw=1.4, zorder=6, gid=gid)
    ax.plot(*np.array([c1, b]).T, color=color, lw=1.4, zorder=6, gid=gid)


def _arc(ax, centre, radius, color, gid, sign=1.0):
    """A circular arc arrow around `centre` (counter-clockwise for sign > 0)."""
    from matplotlib.patches import FancyArrowPatch
    t = np.linspace(0.2, 1.6 * np.pi, 40)
    xy = np.asarray(centre) + radius * np.column_stack([np.cos(t), np.sin(t)])
    if sign < 0:
        xy = xy[::-1]
    ax.plot(*xy[:-2].T, color=color, lw=1.2, zorder=6, gid=gid)
    ax.add_patch(FancyArrowPatch(tuple(xy[-3]), tuple(xy[-1]), arrowstyle="-|>", mutation_scale=10, color=color,
                                 zorder=6, gid=gid))


def draw_elements(ax, engine, motion, b: int, size: float) -> int:
    """Springs, dampers and torques between links at position `b` of `motion`; gids 'spring:NAME',
    'damper:NAME', 'torque:NAME'. Returns how many were drawn."""
    count = 0
    for load in read_loads(engine.mech):
        if load.kind not in ELEMENT_TYPES:
            continue
        gid = f"{load.kind}:{load.name}"
        if load.kind == "torque" or load.joint:
            link = engine.link_index[load.link]
            centre = (world_points(motion, link, np.asarray(engine.mech.joints[load.joint].at, float))[b]
                      if load.joint else motion.frames.r[b, link])
            _arc(ax, centre, 0.06 * size, SPRING_COLOR if load.joint else LOAD_COLOR, gid,
                 np.sign(load.moment) or 1.0)
            count += 1
            continue
        pa = world_points(motion, engine.link_index[load.other], np.asarray(drawn_end(engine.mech, load, 0)))[b]
        pb = world_points(motion, engine.link_index[load.link], np.asarray(drawn_end(engine.mech, load, 1)))[b]
        if load.kind == "spring":
            ax.plot(*spring_path(pa, pb).T, color=SPRING_COLOR, lw=1.3, zorder=6, gid=gid)
        else:
            _dashpot(ax, pa, pb, SPRING_COLOR, gid)
        ax.plot(*np.array([pa, pb]).T, ls="none", marker="o", ms=3.5, color=SPRING_COLOR, zorder=7)
        include_points(ax, [pa, pb], 0.05 * size)
        count += 1
    return count


def draw_loads(ax, engine, motion, b: int, size: float, share: float = 0.25) -> float:
    """The applied loads at position `b` (forces as arrows from their points, one scale, the longest
    `share`·size; pure moments as arcs): rows `force`, `weight`, `moment`, `resistance`, `friction`
    and gravity, not the elements (drawn as themselves). gid 'load:NAME'. Returns the scale (m per N)."""
    loads = [ld for ld in evaluate_loads(engine, motion) if not _is_element(engine, ld.name)]
    big = max([float(np.hypot(*ld.force[b])) for ld in loads], default=0.0)
    k = share * size / big if big > 0 else 0.0
    tips = []
    for i, ld in enumerate(loads):
        f, p = ld.force[b], ld.point[b]
        if k and np.hypot(*f) > 1e-9 * big:
            ax.quiver([p[0]], [p[1]], [f[0] * k], [f[1] * k], angles="xy", scale_units="xy", scale=1,
                      color=LOAD_COLOR, width=0.004, zorder=9, gid=f"load:{ld.name}")
            ax.annotate(ld.name, p + f * k, xytext=(3, -10), textcoords="offset points", fontsize=8,
                        color=LOAD_COLOR, zorder=9)
            tips.append(p + f * k)
        if abs(ld.moment[b]) > 0:
            _arc(ax, p, 0.045 * size, LOAD_COLOR, f"load:{ld.name}", np.sign(ld.moment[b]))
    include_points(ax, tips, 0.06 * size)
    if k:
        ax.plot([], [], color=LOAD_COLOR, lw=2, label=f"loads: {share * size:.3g} m ≙ {big:.4g} N")
    return k


def _is_element(engine, name: str) -> bool:
    return any(ld.name == name and ld.kind in ELEMENT_TYPES for ld in read_loads(engine.mech))


def shaking_figure(engine, at=None, *, count=181, figsize=(10, 4.5)):
    """The shaking force's hodograph (its tip over the cycle) and the shaking moment about the origin
    against the input, at the model's speed."""
    from ..forces import kinetostatics, shaking
    plt = require_matplotlib()
    motion = cycle_motion(engine, count)
    sh = shaking(engine, kinetostatics(engine, motion))
    fig = _figure(plt, figsize)
    hod, mom = fig.subplots(1, 2)
    lean_ticks(hod)
    hod.plot(sh.force[:, 0], sh.force[:, 1], color=COLORS[0], lw=1.4, gid="hodograph:shaking")
    hod.plot([0], [0], marker="+", color="k", ms=8, ls="none")
    hod.set_aspect("equal", adjustable="datalim")
    hod.set(xlabel="Fx [N]", ylabel="Fy [N]")
    hod.set_title(f"Shaking force on the frame (max {np.max(sh.magnitude):.4g} N)", fontsize=10)
    hod.grid(True, alpha=0.3)
    x, xlabel = _coordinate(engine, motion.phi[:, 0])
    _plot_lines(mom, x, [sh.moment], ["about (0, 0)"], "M [N·m]", xlabel, "Shaking moment", _xstep(engine, x))
    fig.suptitle(f"{engine.mech.title or engine.mech.name}: shaking at {input_speed(engine)}", fontsize=10)
    return fig


def efficiency_figure(engine, at=None, *, count=181, mu=None, figsize=(7.5, 5)):
    """Instantaneous efficiency with the model's friction (or `mu` in every pair) against the input, with
    the cycle efficiency. Where the friction iteration does not converge (a mechanism that self-locks, or
    friction out of scale) η is left out, the title says why, and a `ModelWarning` too; `MotionError`
    when it converges nowhere."""
    import warnings

    from ..errors import ModelWarning, MotionError
    from ..forces import friction_kinetostatics, not_converged, read_friction
    plt = require_matplotlib()
    spec = read_friction(engine.mech, mu)
    if spec is None:
        raise ModelError("the model has no [friction] section: nothing to draw for 'efficiency' (add [friction] "
                         "with mu and pin_radius, docs/forces.md)", source=engine.mech.source)
    motion = cycle_motion(engine, count)
    fr = friction_kinetostatics(engine, motion, spec)
    failed = ~(fr.residual <= spec.tolerance)
    if failed.all():
        raise MotionError(not_converged(engine, spec, fr, "at every position of the cycle"), source=engine.mech.source)
    note = ""
    if failed.any():
        note = (not_converged(engine, spec, fr, f"at {int(failed.sum())} of {len(failed)} positions")
                + "; the efficiency is left out there")
        warnings.warn(ModelWarning(f"{engine.mech.source}: {note}"), stacklevel=2)
    fig = _figure(plt, figsize)
    ax = fig.add_subplot()
    x, xlabel = _coordinate(engine, motion.phi[:, 0])
    cycle = "" if fr.cycle_efficiency is None or failed.any() else f"; over the sweep η = {fr.cycle_efficiency:.4g}"
    residual = float(np.max(fr.residual[~failed]))
    _plot_lines(ax, x, [np.where(failed, np.nan, fr.efficiency)], ["η = drive power without / with friction"], "η",
                xlabel, f"Instantaneous efficiency ({fr.iterations} iterations, residual ≤ {residual:.1e}{cycle})",
                _xstep(engine, x))
    ax.lines[-1].set_gid("efficiency")
    title = f"{engine.mech.title or engine.mech.name}: friction in the pairs"
    fig.suptitle(title + ("\n" + textwrap.fill(note, 110) if note else ""), fontsize=10)
    return fig


def simulation_figure(engine, at=None, *, trajectory=None, figsize=(10, 7), **_):
    """The simulated motion (`mbplanar.simulation`, the model's `[simulate]` section, integrated for the
    picture at rtol ≥ 1e-6 unless a `trajectory` is given): the inputs' coordinate and speed against
    time, and the energies (kinetic + potential − work of the drive should stay constant)."""
    from dataclasses import replace

    from ..forces import read_simulate, simulate_motion
    plt = require_matplotlib()
    if trajectory is None and "simulate" not in engine.mech.extras:
        raise ModelError("the model has no [simulate] section: nothing to draw for 'simulation' (add [simulate] "
                         "with t and the drive, docs/forces.md, or run `mbplanar simulate`)", source=engine.mech.source)
    fig = _figure(plt, figsize)
    if trajectory is None:
        spec = read_simulate(engine.mech)
        trajectory = simulate_motion(engine, replace(spec, rtol=max(spec.rtol, 1e-6), atol=max(spec.atol, 1e-9)))
    tr = trajectory
    axes = fig.subplots(2, 2)
    names = [f"{inp.name} [{'rad' if engine.mech.joints[inp.joint].kind == 'R' else 'm'}]" for inp in engine.inputs]
    _plot_lines(axes[0, 0], tr.t, list(tr.phi.T), names, "φ", "t [s]", "Inputs")
    _plot_lines(axes[0, 1], tr.t, list(tr.omega.T), names, "dφ/dt", "t [s]", "Input speeds")
    e = tr.energy
    total = e["kinetic"] + e["potential"] - e["drive_work"]
    _plot_lines(axes[1, 0], tr.t, [e["kinetic"], e["potential"], e["drive_work"]],
                ["kinetic", "potential", "work of the drive"], "[J]", "t [s]", "Energy")
    _plot_lines(axes[1, 1], tr.t, [total - total[0]], ["T + V − W − its start"], "[J]", "t [s]",
                "Energy balance")
    fig.suptitle(f"{engine.mech.title or engine.mech.name}: motion under the given forces ({tr.spec.method}, "
                 f"rtol {tr.spec.rtol:g})", fontsize=10)
    return fig
