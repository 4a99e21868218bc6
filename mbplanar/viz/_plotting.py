"""Pictures of a mechanism with matplotlib: the kinematic diagram (optionally with velocity and
acceleration vectors, reaction arrows, instantaneous centres), trajectories, plots against the
generalized coordinate, GIF animation. The force pictures live in `mbplanar.viz._forceplots`.

matplotlib (the optional extra `mbplanar[plot]`) is imported only when a picture is asked for, with the
Agg backend; without it `require_matplotlib` raises `PlotUnavailable` (CLI exit 2) saying how to install it.

Figures are registered in `FIGURES` (WHAT → `Figure(function, help)`): every function takes
`(engine, at=None, **options)` and returns a matplotlib Figure; `at` is the generalized coordinate in the
model's unit (default: the drawn pose). Other modules add their pictures (e.g. dynamics) with
`register_figure(name, function, help)`; `mbplanar plot MODEL WHAT` picks them up.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Callable

import numpy as np

from ..errors import ModelError, MotionError, PlotUnavailable, did_you_mean
from ..kinematics import describe_limit
from ._scene import build_scene

__all__ = ["PlotUnavailable", "require_matplotlib", "FIGURES", "register_figure", "make_figure", "path_rates",
           "path_analogues", "path_note", "unknown_picture",
           "save_figure", "cycle_values", "cycle_motion", "swing_values", "position_motion", "draw_mechanism",
           "draw_trajectories", "draw_vectors", "draw_instant_centres", "diagram_figure",
           "trajectories_figure", "kinematics_figure", "analogues_figure", "transmission_figure",
           "forces_figure", "transmission_series", "pressure_series", "transmission_angles", "pressure_angles",
           "moving_points", "write_gif",
           "figure_bytes", "SHOW", "show_options", "input_speed"]

INK = "#1a1a1a"
LINK_FILL = "#cfe0f3"
BLOCK_FILL = "#f3e3c3"
COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2",
          "#7f7f7f", "#bcbd22"]


def require_matplotlib():
    """matplotlib's pyplot on the Agg backend (no display needed), imported on first use.

    Returns
    -------
    module
        `matplotlib.pyplot`.

    Raises
    ------
    PlotUnavailable
        matplotlib or Pillow is not installed (``pip install mbplanar[plot]``).

    Examples
    --------
    >>> from mbplanar.viz import require_matplotlib
    >>> plt = require_matplotlib()
    >>> plt.get_backend().lower()
    'agg'
    """
    try:
        import matplotlib
        matplotlib.use("Agg", force=True)
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise PlotUnavailable("pictures need matplotlib and Pillow: pip install mbplanar[plot]") from exc
    return plt


# -- positions to draw --------------------------------------------------------------------------------
def _full_turn(engine) -> bool:
    inp = engine.inputs[0]
    lo, hi = inp.default_sweep()
    return inp.unit in ("deg", "rad") and abs(inp.to_si(hi - lo)) >= 2 * math.pi - 1e-9


def cycle_values(engine, count: int = 72) -> np.ndarray:
    """`count` input values (SI) over the model's sweep; a full turn leaves out its repeated end."""
    if count < 1:
        raise ModelError("the number of positions must be at least 1")
    if len(engine.inputs) != 1:  # a straight path in input space: every input over its sweep at once
        return np.stack([_input_cycle(inp, count) for inp in engine.inputs], axis=1)
    return _input_cycle(engine.inputs[0], count)


def _input_cycle(inp, count: int) -> np.ndarray:
    """`count` values (SI) of one input over its sweep; a full turn leaves out its repeated end."""
    lo, hi = inp.default_sweep()
    full = inp.unit in ("deg", "rad") and abs(inp.to_si(hi - lo)) >= 2 * math.pi - 1e-9
    return inp.to_si(np.linspace(lo, hi, count, endpoint=not full or count == 1))


def cycle_motion(engine, count: int = 72):
    """Kinematics over the model's cycle at its speed, for pictures and animations.

    The positions run over the input's sweep; if the drawn branch ends before the sweep does (a
    motion limit), the `count` positions are spread over the part that is reached, so an animation
    still has `count` frames.

    Parameters
    ----------
    engine : Engine
        The model.
    count : int
        Positions.

    Returns
    -------
    Motion
        The positions, velocities and accelerations; its `limits` name the limits met.

    Raises
    ------
    MotionError
        Not even one position of the sweep can be reached.

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> from mbplanar.viz import cycle_motion
    >>> motion = cycle_motion(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), 8)
    >>> np.degrees(motion.phi[:3, 0]).round(6).tolist(), motion.success
    ([0.0, 45.0, 90.0], True)
    """
    from ..kinematics import analyse
    values = cycle_values(engine, count)
    motion = analyse(engine, values)
    if motion.success:
        return motion
    if len(motion.phi) == 0:
        raise MotionError(f"no position of the sweep can be reached: {motion.message}", source=engine.mech.source)
    several = len(engine.inputs) != 1
    swing = swing_values(engine, count) if not several and engine.inputs[0].sweep is None else None
    if swing is not None:
        fine = analyse(engine, swing)
        return replace(fine, limits=[lim for lim in engine.atlas().limits.values() if lim is not None])
    lo, hi = motion.phi[0], motion.phi[-1]
    fine = analyse(engine, np.linspace(lo, hi, count) if several else np.linspace(lo[0], hi[0], count))
    return replace(fine, limits=motion.limits)


def path_rates(engine) -> np.ndarray:
    """How fast each input moves along the model's input path (`cycle_values`: every input over its
    sweep at once) per unit of the first input: dφ_k/dφ_1 in SI (n_in,); [1.0] with one input."""
    widths = np.array([inp.to_si(hi) - inp.to_si(lo) for inp in engine.inputs for lo, hi in [inp.default_sweep()]])
    return widths / widths[0]


def path_analogues(engine, motion):
    """The analogues along the model's input path at the positions of `motion`: (w, e, v, a), the first
    and second derivatives by the first input (SI) of every link's angle (B, L) and point (B, P, 2),
    the other inputs moving with it as `path_rates` says (a straight path: no second derivative of the
    inputs). With one input the motion's own analogues (wq, eq, vq, aq)."""
    if len(engine.inputs) == 1:
        return motion.wq, motion.eq, motion.vq, motion.aq
    from ..kinematics import analyse
    along = analyse(engine, motion.phi, omega=path_rates(engine), epsilon=0.0, points=motion.point_names)
    return along.w, along.e, along.v, along.a


def path_note(engine) -> str:
    """'' with one input; else how the path analogues are taken: 'along the input path, d/dphi1 with
    phi2 moving 1× as fast'."""
    if len(engine.inputs) == 1:
        return ""
    first = engine.inputs[0].name
    moving = ", ".join(f"{inp.name} moving {r:.4g}× as fast" for inp, r in zip(engine.inputs[1:], path_rates(engine)[1:]))
    return f"along the input path: d/d{first} with {moving}"


def swing_values(engine, count: int = 72) -> np.ndarray | None:
    """`count` input values (SI) of a rocking input's whole cycle: from the dead point below the drawn
    pose to the one above and back (a triangle wave, so an animation loops without a jump and a
    trajectory retraces itself instead of closing with a chord), ending at the walk's last solvable
    positions next to the limits; None unless the input is stopped by a motion limit both ways."""
    engine.reach()
    atlas = engine.atlas()
    if atlas.limits[-1] is None or atlas.limits[+1] is None:
        return None
    grid = atlas.arrays()[0]
    t = np.arange(count) / max(count, 1)
    return grid[0] + (grid[-1] - grid[0]) * (1.0 - np.abs(1.0 - 2.0 * t))


def position_motion(engine, at=None):
    """Kinematics at one position, given in the model's units (default: the drawn pose).

    Parameters
    ----------
    engine : Engine
        The model.
    at : float or sequence of float, optional
        The input value(s), in the inputs' units (degrees for a crank declared in degrees); one per
        input. None: the drawn pose.

    Returns
    -------
    Motion
        One position with its rates.

    Raises
    ------
    ModelError
        Not one value per input.
    MotionError
        A position the model cannot reach from its drawn pose (the message names it).

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> from mbplanar.viz import position_motion
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> [round(float(np.degrees(position_motion(engine, at).phi[0, 0])), 9) for at in (None, 30)]
    [60.0, 30.0]
    """
    from ..kinematics import analyse
    values = [inp.from_si(p) for inp, p in zip(engine.inputs, engine.phi_drawn)] if at is None else \
        list(np.atleast_1d(np.asarray(at, float)))
    if len(values) != len(engine.inputs):
        raise ModelError(f"a position needs {len(engine.inputs)} input value(s)", source=engine.mech.source)
    phi = np.array([[inp.to_si(v) for inp, v in zip(engine.inputs, values)]])
    motion = analyse(engine, phi if len(values) > 1 else phi[:, 0])
    if not motion.success:
        where = ", ".join(f"{inp.name} = {v:g} {inp.unit}" for inp, v in zip(engine.inputs, values))
        raise MotionError(f"cannot reach {where}: {motion.message}", source=engine.mech.source)
    return motion


def _coordinate(engine, phi_si):
    """Input values in the model's unit for plot axes, and the axis label."""
    inp = engine.inputs[0]
    return inp.from_si(np.asarray(phi_si)), f"{inp.name} [{inp.unit}]"


def moving_points(engine, scene) -> list:
    """The names of a scene's points worth plotting a path for: the moving ones, one per place.

    Parameters
    ----------
    engine : Engine
        The model.
    scene : Scene
        Its drawing (`build_scene`).

    Returns
    -------
    list of str
        Joints that move (coincident pairs once, the ground pivots left out), then the points of
        interest.

    Raises
    ------
    ValueError
        A `scene` whose joints are not the ones it lists (not from `build_scene`).

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.viz import build_scene, cycle_motion, moving_points
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> moving_points(engine, build_scene(engine, cycle_motion(engine, 8)))
    ['A', 'B', 'M']
    """
    names = [n for n in scene.joint_names if scene.labels.get(n) and n not in scene.pivots]
    names = [n for n in names if np.ptp(scene.joint_xy[:, scene.joint_names.index(n)], axis=0).max()
             > 1e-9 * scene.size or scene.batch == 1]
    return names + list(scene.point_names)


def _point_xy(scene, name):
    if name in scene.joint_names:
        return scene.joint_xy[:, scene.joint_names.index(name)]
    return scene.point_xy[:, scene.point_names.index(name)]


# -- drawing the mechanism --------------------------------------------------------------------------
def _hatch_line(ax, a, b, normal, step, depth, gid, lw=1.0):
    """A base line a–b with short slanted strokes on the side of `normal` (the ground symbol)."""
    a, b, normal = np.asarray(a, float), np.asarray(b, float), np.asarray(normal, float)
    ax.plot([a[0], b[0]], [a[1], b[1]], color=INK, lw=lw * 1.4, solid_capstyle="butt", gid=gid, zorder=2)
    length = np.linalg.norm(b - a)
    u = (b - a) / max(length, 1e-12)
    n = max(int(length / step), 2)
    starts = a + np.outer(np.linspace(0, 1, n + 1)[1:], b - a)
    ends = starts + depth * normal - depth * u
    segs = np.stack((starts, ends), axis=1)
    from matplotlib.collections import LineCollection
    ax.add_collection(LineCollection(segs, colors=INK, linewidths=lw * 0.8, zorder=2, gid=gid))


def _ground_pivot(ax, p, size, name):
    """Ground revolute pair: a triangle under the pin with a hatched base."""
    h, w = 0.055 * size, 0.032 * size
    x, y = p
    from matplotlib.patches import Polygon
    ax.add_patch(Polygon([[x, y], [x - w, y - h], [x + w, y - h]], closed=True, fc="white", ec=INK, lw=1.2,
                         zorder=3, gid=f"pivot:{name}"))
    _hatch_line(ax, (x - 1.6 * w, y - h), (x + 1.6 * w, y - h), (0, -1), 0.35 * w, 0.45 * w, f"pivot:{name}")


def draw_mechanism(ax, scene, b: int = 0, *, labels: bool = True, alpha: float = 1.0, ghost: bool = False):
    """Draw one position of a scene on matplotlib axes, in the conventions of mechanism drawings.

    Links as bars or plates, revolute pairs as circles, ground pivots hatched, slider blocks on their
    guides, points of interest marked. Artists carry gids: 'joint:NAME' (revolute pair markers),
    'slider:NAME' (blocks), 'guide:NAME', 'link:NAME', 'pivot:NAME', 'point:NAME', and
    their labels 'jointlabel:NAME', 'linklabel:NAME'.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw.
    scene : Scene
        The drawing (`build_scene`).
    b : int
        The position (batch index).
    labels : bool
        Write the pairs' and points' names.
    alpha : float
        Opacity.
    ghost : bool
        Thin grey lines only (other positions drawn behind the main one).

    Returns
    -------
    None

    Raises
    ------
    IndexError
        `b` outside the scene's batch.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.viz import build_scene, draw_mechanism, position_motion, require_matplotlib
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> fig, ax = require_matplotlib().subplots()
    >>> draw_mechanism(ax, build_scene(engine, position_motion(engine)))
    >>> sorted({a.get_gid().split(":")[0] for a in ax.get_children() if a.get_gid()})
    ['joint', 'jointlabel', 'link', 'linklabel', 'pivot', 'point']
    >>> require_matplotlib().close(fig)
    """
    from matplotlib.patches import Polygon
    size = scene.size
    ink = "#9a9a9a" if ghost else INK
    lw_bar = 1.0 if ghost else 2.6
    r_pin = 0.016 * size
    for s in scene.sliders:  # guides first: the carrier holds them
        g = s.guide[b]
        if s.grounded and not ghost:
            u = (g[1] - g[0]) / np.linalg.norm(g[1] - g[0])
            n = np.array([-u[1], u[0]])
            if n[1] > 1e-9 or (abs(n[1]) <= 1e-9 and n[0] > 0):
                n = -n
            off = 0.032 * size * n
            ax.plot(g[:, 0], g[:, 1], color=ink, lw=0.8, ls=(0, (8, 3, 1, 3)), zorder=1, gid=f"guide:{s.joint}")
            _hatch_line(ax, g[0] + off, g[1] + off, n, 0.022 * size, 0.025 * size, f"guide:{s.joint}")
        elif not s.grounded:
            ax.plot(g[:, 0], g[:, 1], color=ink, lw=lw_bar * 0.8, alpha=alpha, zorder=3, gid=f"guide:{s.joint}",
                    solid_capstyle="round")
    for pair in scene.pairs:
        draw_pair(ax, pair, b, size, ink, ghost)
    for k, link in enumerate(scene.links):
        out = link.outline[b]
        color = COLORS[k % len(COLORS)]
        if link.kind == "bar":
            ax.plot(out[:, 0], out[:, 1], color=ink, lw=lw_bar, alpha=alpha, solid_capstyle="round", zorder=3,
                    gid=f"link:{link.name}")
            for st in link.stubs[b]:
                ax.plot(st[:, 0], st[:, 1], color=ink, lw=lw_bar * 0.8, alpha=alpha, solid_capstyle="round",
                        zorder=3, gid=f"link:{link.name}")
        elif link.kind == "polygon":
            ax.add_patch(Polygon(out, closed=True, fc="none" if ghost else LINK_FILL, ec=ink, lw=lw_bar * 0.75,
                                 alpha=alpha, zorder=3, joinstyle="round", gid=f"link:{link.name}"))
        if labels and not ghost and np.all(np.isfinite(link.label[b])):
            ax.text(*link.label[b], link.name, color=color, fontsize=11, fontweight="bold", ha="center",
                    va="center", zorder=8, gid=f"linklabel:{link.name}")
    for s in scene.sliders:
        ax.add_patch(Polygon(s.corners[b], closed=True, fc="none" if ghost else BLOCK_FILL, ec=ink,
                             lw=1.0 if ghost else 1.6, alpha=alpha, zorder=5, gid=f"slider:{s.joint}"))
    if not ghost:
        for name in scene.pivots:
            _ground_pivot(ax, scene.joint_xy[b, scene.joint_names.index(name)], size, name)
    for name in scene.revolute:
        p = scene.joint_xy[b, scene.joint_names.index(name)]
        ax.plot([p[0]], [p[1]], marker="o", ms=4 if ghost else 7.5, mfc="white", mec=ink, mew=1.4,
                alpha=alpha, ls="none", zorder=7, gid=f"joint:{name}")
    for k, name in enumerate(scene.point_names):
        p = scene.point_xy[b, k]
        if ghost:
            continue
        centre = name in scene.centres
        ax.plot([p[0]], [p[1]], marker="o", ms=6.5 if centre else 4.5, mfc=INK, mec=INK,
                mfcalt="white", fillstyle="left" if centre else "full", ls="none", zorder=7, gid=f"point:{name}")
        if labels:
            ax.annotate(name, p, xytext=(5, -11), textcoords="offset points", fontsize=8.5, color="#444",
                        zorder=8)
    if labels and not ghost:
        for name in scene.joint_names:
            text = scene.labels.get(name)
            if text:
                p = scene.joint_xy[b, scene.joint_names.index(name)]
                ax.annotate(text, p, xytext=(6, 5), textcoords="offset points", fontsize=10, style="italic",
                            zorder=8, gid=f"jointlabel:{name}")
    del r_pin


#: how each line of a higher pair is drawn: (width × the bar's, dash pattern or None, fill)
PAIR_STYLES = {"pitch": (0.35, (0, (7, 2, 1, 2)), None), "rack": (0.35, (0, (7, 2, 1, 2)), None),
               "profile": (0.55, None, "#e8eef5"), "roller": (0.45, None, "white"), "knife": (0.6, None, None),
               "face": (0.7, None, None), "slot": (0.35, None, None), "slot-centre": (0.2, (0, (3, 3)), None)}
CONTACT_COLOR = "#c0392b"


def draw_pair(ax, pair, b: int, size: float, ink=INK, ghost: bool = False):
    """A higher pair at position `b`: its pitch circles and lines with tooth marks, a cam's profile and
    its follower's element, a slot's walls; the mesh point or contact as a dot (gids 'pair:NAME',
    'contact:NAME')."""
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Polygon
    for kind, _, xy, closed in pair.lines:
        width, dash, fill = PAIR_STYLES[kind]
        pts = xy[b]
        if fill is not None and closed and not ghost:
            ax.add_patch(Polygon(pts, closed=True, fc=fill, ec="none", zorder=2.2, gid=f"pair:{pair.name}"))
        ax.plot(pts[:, 0], pts[:, 1], color=ink, lw=(1.0 if ghost else 2.6) * width * 2, ls=dash or "-",
                zorder=2.4 if kind != "roller" else 6, gid=f"pair:{pair.name}")
    if pair.marks.shape[1] and not ghost:
        ax.add_collection(LineCollection(pair.marks[b], colors=ink, linewidths=0.6, zorder=2.4, gid=f"pair:{pair.name}"))
    if not ghost and np.all(np.isfinite(pair.contact[b])):
        ax.plot(*pair.contact[b], marker="o", ms=4, color=CONTACT_COLOR, ls="none", zorder=9, gid=f"contact:{pair.name}")


def _frame_axes(ax, scene, title=None):
    x0, x1, y0, y1 = scene.extent()
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])
    for spine in ax.spines.values():
        spine.set_visible(False)
    _scale_bar(ax, scene.size, (x0, x1, y0, y1))
    if title:
        ax.set_title(title, fontsize=11)


def _scale_bar(ax, size, box):
    """A scale bar of a round length in the lower-left corner."""
    x0, x1, y0, y1 = box
    target = 0.25 * size
    length = 10 ** math.floor(math.log10(target))
    length *= next(m for m in (5, 2, 1) if m * length <= target)
    x, y = x0 + 0.03 * (x1 - x0), y0 + 0.03 * (y1 - y0)
    ax.plot([x, x + length], [y, y], color=INK, lw=2, solid_capstyle="butt", gid="scalebar")
    ax.text(x + length / 2, y + 0.012 * (y1 - y0), f"{length:g} m", ha="center", va="bottom", fontsize=8)


def draw_trajectories(ax, scene, names=None, lw=1.1):
    """Paths of points over the scene's positions (coupler curves), each named at its start."""
    names = moving_points(None, scene) if names is None else names
    for k, name in enumerate(names):
        xy = _point_xy(scene, name)
        closed = np.vstack([xy, xy[:1]]) if scene.batch > 2 else xy
        ax.plot(closed[:, 0], closed[:, 1], color=COLORS[k % len(COLORS)], lw=lw, alpha=0.9, zorder=1.5,
                gid=f"trajectory:{name}", label=name)


def draw_vectors(ax, scene, motion, b, which="v", share=0.3):
    """Velocity ('v') or acceleration ('a') vectors of the moving points at position `b`, one scale for
    all, the longest `share`·size long; the scale is written in the corner."""
    names = moving_points(None, scene)
    vec = motion.v if which == "v" else motion.a
    idx = [motion.point(n) for n in names]
    p, q = motion.xy[b, idx], vec[b, idx]
    big = float(np.max(np.linalg.norm(q, axis=-1))) if len(q) else 0.0
    if not big > 0:
        return 0.0
    k = share * scene.size / big
    color = "#c0392b" if which == "v" else "#2e86c1"
    ax.quiver(p[:, 0], p[:, 1], q[:, 0] * k, q[:, 1] * k, angles="xy", scale_units="xy", scale=1, color=color,
              width=0.004, zorder=9, gid=f"vectors:{which}")
    include_points(ax, p + q * k, 0.05 * scene.size)
    unit = "m/s" if which == "v" else "m/s²"
    ax.plot([], [], color=color, lw=2, label=f"{'velocity' if which == 'v' else 'acceleration'}: "
                                              f"{scene.size * share:.3g} m ≙ {big:.3g} {unit}")
    return k


def include_points(ax, xy, pad):
    """Widen the axes' limits so that the points (n, 2) (e.g. arrow tips) are inside, `pad` beyond."""
    xy = np.asarray(xy, float).reshape(-1, 2)
    xy = xy[np.all(np.isfinite(xy), axis=1)]
    if len(xy):
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        ax.set_xlim(min(x0, xy[:, 0].min() - pad), max(x1, xy[:, 0].max() + pad))
        ax.set_ylim(min(y0, xy[:, 1].min() - pad), max(y1, xy[:, 1].max() + pad))


def draw_instant_centres(ax, scene, motion, b, reach=1.5):
    """Instantaneous centres P_k0 of the moving links (those within `reach` of the drawing's extent)."""
    x0, x1, y0, y1 = scene.extent()
    w, h = x1 - x0, y1 - y0
    shown = []
    for k, link in enumerate(motion.link_names[1:], start=1):
        c = motion.ic[b, k]
        if not np.all(np.isfinite(c)):
            continue
        if not (x0 - reach * w <= c[0] <= x1 + reach * w and y0 - reach * h <= c[1] <= y1 + reach * h):
            continue
        ax.plot([c[0]], [c[1]], marker="x", ms=8, mew=2, color="#8e44ad", ls="none", zorder=9,
                gid=f"ic:{link}")
        ax.annotate(f"P{link}0", c, xytext=(5, 5), textcoords="offset points", fontsize=9, color="#8e44ad")
        shown.append(c)
    if shown:
        pts = np.array(shown)
        ax.set_xlim(min(ax.get_xlim()[0], pts[:, 0].min() - 0.1 * w), max(ax.get_xlim()[1], pts[:, 0].max() + 0.1 * w))
        ax.set_ylim(min(ax.get_ylim()[0], pts[:, 1].min() - 0.1 * h), max(ax.get_ylim()[1], pts[:, 1].max() + 0.1 * h))
    return len(shown)


def input_speed(engine) -> str:
    """'ω = 7.645 rad/s, ε = 0 rad/s²' (a prismatic input: 'v = ... m/s, a = ... m/s²'): the model's; with
    several inputs each named ('phi1: ω = 1 rad/s, ε = 0 rad/s²; phi2: ...')."""
    def one(inp):
        if engine.mech.joints[inp.joint].kind == "R":
            return f"ω = {inp.omega:g} rad/s, ε = {inp.epsilon:g} rad/s²"
        return f"v = {inp.omega:g} m/s, a = {inp.epsilon:g} m/s²"
    if len(engine.inputs) == 1:
        return one(engine.inputs[0])
    return "; ".join(f"{inp.name}: {one(inp)}" for inp in engine.inputs)


def input_label(engine, phi_row, fmt=".4g") -> str:
    """'phi = 30 deg' of a position's input values (SI, (n_in,)), every input, comma-separated."""
    return ", ".join(f"{inp.name} = {inp.from_si(float(p)):{fmt}} {inp.unit}" for inp, p in zip(engine.inputs, phi_row))


def _title(engine, motion, b=0):
    return f"{engine.mech.title or engine.mech.name}\n{input_label(engine, motion.phi[b])}"


def _figure(plt, figsize):
    return plt.figure(figsize=figsize, layout="constrained")


SHOW = {"velocities": "v", "accelerations": "a", "reactions": "reactions", "centres": "centres", "loads": "loads"}


def diagram_figure(engine, at=None, *, vectors=(), centres=False, reactions=False, loads=False, cycle=None,
                   count=72, figsize=(7.5, 6.5)):
    """Kinematic diagram at one position, at the model's input speed, with its springs, dampers and
    torques between links; `vectors` ⊂ {'v', 'a'} adds velocity/acceleration vectors, `centres` the
    instantaneous centres, `reactions` the reaction arrows (kinetostatics), `loads` the applied loads.
    `count` positions of the cycle size the guides and the frame."""
    plt = require_matplotlib()
    motion = position_motion(engine, at)
    cycle = cycle_motion(engine, count) if cycle is None else cycle
    scene = build_scene(engine, motion, cycle)
    fig = _figure(plt, figsize)
    ax = fig.add_subplot()
    draw_mechanism(ax, scene, 0)
    title = _title(engine, motion) + (f", {input_speed(engine)}" if vectors or reactions else "")
    _frame_axes(ax, build_scene(engine, cycle, cycle) if cycle is not None else scene, title)
    from ._elementplots import draw_elements, draw_loads
    draw_elements(ax, engine, motion, 0, scene.size)
    if loads:
        draw_loads(ax, engine, motion, 0, scene.size)
    for which in vectors:
        draw_vectors(ax, scene, motion, 0, which)
    if centres:
        draw_instant_centres(ax, scene, motion, 0)
    if reactions:
        from ._forceplots import draw_reactions
        from ..forces import kinetostatics
        draw_reactions(ax, engine, kinetostatics(engine, motion), 0, scene.size)
    if (vectors or reactions or loads) and ax.get_legend_handles_labels()[1]:
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, 0.0), ncols=2, fontsize=8, frameon=False)
    return fig


def show_options(text: str | None) -> dict:
    """`diagram_figure` options from a comma list of SHOW names ('velocities,reactions'; 'all')."""
    names = [n.strip() for n in (text or "").split(",") if n.strip()]
    names = list(SHOW) if names == ["all"] else names
    bad = [n for n in names if n not in SHOW]
    if bad:
        raise ModelError(f"unknown --show item '{bad[0]}'; {did_you_mean(bad[0], SHOW, 'items')} (or all)")
    return {"vectors": tuple(SHOW[n] for n in names if SHOW[n] in ("v", "a")),
            "centres": "centres" in names, "reactions": "reactions" in names, "loads": "loads" in names}


def vectors_figure(engine, at=None, **kw):
    """Diagram with the velocity and acceleration vectors and the instantaneous centres."""
    return diagram_figure(engine, at, vectors=("v", "a"), centres=True, **kw)


def trajectories_figure(engine, at=None, *, points=None, count=120, figsize=(7.5, 6.5)):
    """Trajectories of the moving points (or of `points`: names of pairs and points) over the cycle,
    drawn with the mechanism at `at` and, faint, at eight other positions."""
    plt = require_matplotlib()
    cycle = cycle_motion(engine, count)
    whole = build_scene(engine, cycle, cycle)
    known = whole.joint_names + whole.point_names
    for name in points or ():
        if name not in known:
            raise ModelError(f"no point or pair '{name}' to trace; {did_you_mean(name, known, 'points and pairs')}",
                             source=engine.mech.source)
    motion = position_motion(engine, at)
    scene = build_scene(engine, motion, cycle)
    fig = _figure(plt, figsize)
    ax = fig.add_subplot()
    for b in np.linspace(0, whole.batch - 1, 8, endpoint=False).astype(int):
        draw_mechanism(ax, whole, b, labels=False, ghost=True, alpha=0.6)
    draw_trajectories(ax, whole, points)
    draw_mechanism(ax, scene, 0)
    _frame_axes(ax, whole, "Trajectories over the cycle: " + _title(engine, motion))
    ax.legend(loc="upper left", fontsize=8, frameon=False, ncols=2)
    return fig


def _link_series(motion):
    return motion.link_names[1:], slice(1, None)


def _xstep(engine, x) -> float | None:
    """Tick spacing of a coordinate axis in degrees spanning half a turn or more: 90°."""
    return 90.0 if engine.inputs[0].unit == "deg" and len(x) and np.ptp(x) >= 180 else None


def lean_ticks(ax, xstep=None):
    """Few ticks on an axes' two axes: about 5 each (x every `xstep` when given).

    Cleaner small panels, and ticks are most of what a multi-panel figure costs to draw.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes.
    xstep : float, optional
        The x ticks' spacing (e.g. 90 for degrees).

    Returns
    -------
    None

    Raises
    ------
    ValueError
        A non-positive `xstep` (matplotlib's error when the ticks are drawn).

    Examples
    --------
    >>> from mbplanar.viz import lean_ticks, require_matplotlib
    >>> fig, ax = require_matplotlib().subplots()
    >>> _ = ax.plot([0, 360], [0, 1])
    >>> lean_ticks(ax, xstep=90)
    >>> ax.set_xlim(0, 360)
    (0.0, 360.0)
    >>> [x for x in ax.get_xticks().tolist() if 0 <= x <= 360]
    [0.0, 90.0, 180.0, 270.0, 360.0]
    >>> require_matplotlib().close(fig)
    """
    from matplotlib.ticker import MaxNLocator, MultipleLocator
    steps = [1, 2, 2.5, 5, 10]
    ax.xaxis.set_major_locator(MultipleLocator(xstep) if xstep else MaxNLocator(5, steps=steps))
    ax.yaxis.set_major_locator(MaxNLocator(5, steps=steps))


def _plot_lines(ax, x, ys, names, ylabel, xlabel, title, xstep=None):
    lean_ticks(ax, xstep)
    for k, (y, name) in enumerate(zip(ys, names)):
        ax.plot(x, y, color=COLORS[k % len(COLORS)], lw=1.4, label=name)
    if xlabel:
        ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    if names:
        ax.legend(fontsize=7, ncols=2, frameon=False)


def _series_panels(engine, motion, real: bool):
    """(title, ylabel, names, values (n, B)) of the kinematic panels."""
    scene = build_scene(engine, motion, motion)
    links = motion.link_names[1:]
    pts = moving_points(engine, scene)
    idx = [motion.point(n) for n in pts]
    sliders = [n for n in motion.joint_names if engine.mech.joints[n].kind == "P"]
    jdx = [motion.joint(n) for n in sliders]
    angles = np.degrees(np.unwrap(motion.angle[:, 1:], axis=0)).T
    if real:
        w, e, v, a = motion.w[:, 1:], motion.e[:, 1:], motion.v[:, idx], motion.a[:, idx]
        sfx, wu, eu, vu, au = "", "rad/s", "rad/s²", "m/s", "m/s²"
    else:
        wq, eq, vq, aq = path_analogues(engine, motion)
        w, e, v, a = wq[:, 1:], eq[:, 1:], vq[:, idx], aq[:, idx]
        sfx, wu, eu, vu, au = " analogue", "rad/rad", "rad/rad²", "m/rad", "m/rad²"
    panels = [("Link angles", "angle [°]", links, angles)]
    if sliders:
        panels.append(("Slider displacements (from the drawn pose)", "s [m]", sliders,
                       (motion.value[:, jdx] - np.array([engine.joint_value_drawn[n] for n in sliders])).T))
    else:
        panels.append(("Point coordinates", "x, y [m]", [f"{n}.{c}" for n in pts for c in "xy"],
                       motion.xy[:, idx].reshape(len(motion.phi), -1).T))
    panels += [(f"Angular velocity{sfx}", f"ω [{wu}]", links, w.T),
               (f"Point speed{sfx}", f"|v| [{vu}]", pts, np.linalg.norm(v, axis=-1).T),
               (f"Angular acceleration{sfx}", f"ε [{eu}]", links, e.T),
               (f"Point acceleration{sfx}", f"|a| [{au}]", pts, np.linalg.norm(a, axis=-1).T)]
    return panels


def _panels_figure(engine, real, count, figsize):
    plt = require_matplotlib()
    motion = cycle_motion(engine, count)
    x, xlabel = _coordinate(engine, motion.phi[:, 0])
    fig = _figure(plt, figsize)
    axes = fig.subplots(3, 2, sharex=True)
    for k, (ax, (title, ylabel, names, values)) in enumerate(zip(axes.flat, _series_panels(engine, motion, real))):
        _plot_lines(ax, x, values, names, ylabel, xlabel if k >= 4 else None, title, _xstep(engine, x))
    what = f"real, at {input_speed(engine)}" if real else \
        ("analogues (d/dφ, d²/dφ²)" if len(engine.inputs) == 1 else f"analogues {path_note(engine)}")
    limit = "".join("\n" + describe_limit(engine, lim) for lim in motion.limits)
    fig.suptitle(f"{engine.mech.title or engine.mech.name}: kinematics, {what}{limit}", fontsize=10)
    return fig


def kinematics_figure(engine, at=None, *, count=181, figsize=(10, 10)):
    """Positions, real velocities and accelerations (at the model's input speed) over the cycle."""
    return _panels_figure(engine, True, count, figsize)


def analogues_figure(engine, at=None, *, count=181, figsize=(10, 10)):
    """Positions and the analogues of velocities and accelerations (d/dφ, d²/dφ²) over the cycle."""
    return _panels_figure(engine, False, count, figsize)


def transmission_series(engine, motion) -> dict:
    """Transmission angle μ (°, 0…180, not folded) at every revolute pair P–J–Q inside an Assur group
    (the pairs `mbplanar check` judges): the angle at J between the lines to P and Q.
    {'μ at B (A–B–C)': (B,) array}."""
    from ..analysis import transmission_triples
    out = {}
    for p, j, q in transmission_triples(engine):
        mid = motion.xy[:, motion.point(j)]
        a = motion.xy[:, motion.point(p)] - mid
        c = motion.xy[:, motion.point(q)] - mid
        cos = np.einsum("bi,bi->b", a, c) / (np.linalg.norm(a, axis=-1) * np.linalg.norm(c, axis=-1))
        out[f"μ at {j} ({p}–{j}–{q})"] = np.degrees(np.arccos(np.clip(cos, -1, 1)))
    return out


def pressure_series(engine, motion) -> dict:
    """Pressure angle (°, 0…90, 0 ideal) of every slider driven by a rod and of every cam's or slot's
    contact, as `mbplanar check` computes them: {'ϑ at Bp (A–B)': (B,) array, 'ϑ at K (contact)': ...}."""
    from ..analysis import contact_angles
    from ..analysis import pressure_angles as angles
    pairs, values = angles(engine, motion)
    out = {f"ϑ at {s} ({a}–{b})" if a != b else f"ϑ at {s} (normal of {b})": np.degrees(values[:, k])
           for k, (a, b, s) in enumerate(pairs)}
    names, values = contact_angles(engine, motion)
    out.update({f"ϑ at {n} (contact)": np.degrees(np.abs(values[:, k])) for k, n in enumerate(names)})
    return out


# the names these had (`mbplanar.analysis` has functions of those names returning labels and radians)
transmission_angles, pressure_angles = transmission_series, pressure_series


def transmission_figure(engine, at=None, *, count=181, figsize=(7.5, 6.5)):
    """Transmission angles μ of the revolute pairs inside Assur groups (with the usual 40°…140° band)
    and pressure angles of the sliders driven by rods, over the cycle."""
    plt = require_matplotlib()
    motion = cycle_motion(engine, count)
    x, xlabel = _coordinate(engine, motion.phi[:, 0])
    fig = _figure(plt, figsize)
    top, bottom = fig.subplots(2, 1, sharex=True)
    angles, pressure = transmission_series(engine, motion), pressure_series(engine, motion)
    _plot_lines(top, x, list(angles.values()), list(angles), "μ [°]", None, "Transmission angles (90° ideal)",
                _xstep(engine, x))
    top.axhspan(40, 140, color="#2ca02c", alpha=0.07)
    top.set_ylim(0, 180)
    if not angles:
        top.text(0.5, 0.5, "no revolute pair between two rods in an Assur group", transform=top.transAxes,
                 ha="center")
    _plot_lines(bottom, x, list(pressure.values()), list(pressure), "ϑ [°]", xlabel,
                "Pressure angles of the sliders and contacts (0° ideal)", _xstep(engine, x))
    bottom.set_ylim(0, 90)
    if not pressure:
        bottom.text(0.5, 0.5, "no slider driven by a rod, no cam or slot", transform=bottom.transAxes, ha="center")
    limit = "".join("\n" + describe_limit(engine, lim) for lim in motion.limits)
    fig.suptitle(f"{engine.mech.title or engine.mech.name}: transmission and pressure angles{limit}", fontsize=10)
    return fig


def forces_figure(engine, at=None, **options):
    """Reactions (magnitudes, hodographs), balancing moment and prismatic-pair moments over the cycle."""
    from ._forceplots import forces_figure as draw
    return draw(engine, at, **options)


def dynamics_figure(engine, at=None, *, dynamics=None, count=3600, figsize=(10, 10)):
    """Machine dynamics over the cycle: J_II and dJ_II/dφ, the reduced moments, work and ΔT_I, and the
    true ω(φ), ε(φ) of the crank (energy–mass method and the simulated steady state). `dynamics`: a
    computed `Dynamics` (default: `machine_dynamics(engine)` on `count` steps, at least 36); `at`
    marks one position. ModelError for a model without a [dynamics] section."""
    from ..forces import machine_dynamics
    plt = require_matplotlib()
    d = machine_dynamics(engine, steps=max(int(count), 36)) if dynamics is None else dynamics
    inp = engine.inputs[0]
    x, xlabel = _coordinate(engine, d.phi)
    fig = _figure(plt, figsize)
    axes = fig.subplots(3, 2, sharex=True).flat
    _plot_lines(axes[0], x, [d.J_II, d.dJ_II], ["J_II", "dJ_II/dφ"], "[kg·m²]", None,
                "Reduced inertia of the second group")
    moments = list(d.reduced.moments.items())
    _plot_lines(axes[1], x, [m for _, m in moments] + [d.M_red], [n for n, _ in moments] + ["M_red (total)"],
                "M [N·m]", None, f"Reduced moments (dashed: −M_dr = {-d.driving_moment:.6g} N·m)")
    axes[1].axhline(-d.driving_moment, color=INK, lw=0.8, ls="--")
    _plot_lines(axes[2], x, [d.A_c, d.driving_moment * d.phi, d.A_total], ["A_c (loads)", "A_dr (drive)", "A_Σ"],
                "A [J]", None, "Work from φ = 0")
    _plot_lines(axes[3], x, [d.T_II, d.dT_I], ["T_II = J_II·ω_m²/2", "ΔT_I = A_Σ − T_II"], "T [J]", None,
                f"Kinetic energy; J_I = {d.inertia_first_group:.6g} kg·m² (δ = {d.spec.delta:g})")
    for value in (d.dT_I_max, d.dT_I_min):
        axes[3].axhline(value, color=INK, lw=0.6, ls=":")
    sim = d.simulation
    omegas, names = [d.omega], ["energy–mass method"]
    eps, enames = [d.epsilon], ["energy–mass method"]
    if sim is not None:
        omegas.append(sim.omega)
        names.append(f"simulated (δ = {sim.delta:.4g})")
        eps.append(sim.epsilon)
        enames.append("simulated")
    _plot_lines(axes[4], x, omegas, names, "ω [rad/s]", xlabel, f"Crank speed; ω_m = {d.omega_mean:.6g} rad/s")
    axes[4].axhline(d.omega_mean, color=INK, lw=0.6, ls="--")
    _plot_lines(axes[5], x, eps, enames, "ε [rad/s²]", xlabel, "Crank acceleration")
    if at is not None:
        mark = _coordinate(engine, np.array([inp.to_si(float(at))]))[0][0]
        for ax in axes:
            ax.axvline(mark, color="#d62728", lw=0.8, alpha=0.6)
    fig.suptitle(f"{engine.mech.title or engine.mech.name}: machine dynamics", fontsize=10)
    return fig


# -- registry ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Figure:
    function: Callable
    help: str


FIGURES: dict[str, Figure] = {
    "diagram": Figure(diagram_figure, "kinematic diagram at one position"),
    "vectors": Figure(vectors_figure, "diagram with velocity and acceleration vectors and instantaneous centres"),
    "trajectories": Figure(trajectories_figure, "trajectories (coupler curves) of the points over the cycle"),
    "kinematics": Figure(kinematics_figure, "positions, real velocities and accelerations against the coordinate"),
    "analogues": Figure(analogues_figure, "positions and analogues of velocities and accelerations"),
    "transmission": Figure(transmission_figure, "transmission angles and pressure angles against the coordinate"),
    "forces": Figure(forces_figure, "reactions, their hodographs and the balancing moment against the coordinate"),
    "dynamics": Figure(dynamics_figure, "J_II, reduced moments, work, ΔT_I, true ω(φ) and ε(φ) (models with [dynamics])"),
    "shaking": Figure(lambda engine, at=None, **kw: _elementplots().shaking_figure(engine, at, **kw),
                      "shaking force on the frame (hodograph) and shaking moment over the cycle"),
    "efficiency": Figure(lambda engine, at=None, **kw: _elementplots().efficiency_figure(engine, at, **kw),
                         "instantaneous efficiency with friction in the pairs (models with [friction])"),
    "simulation": Figure(lambda engine, at=None, **kw: _elementplots().simulation_figure(engine, at, **kw),
                         "motion under the given forces against time and its energy balance ([simulate])"),
}


def _elementplots():
    from . import _elementplots as module
    return module


def register_figure(name: str, function: Callable, help: str) -> None:
    """Add a picture to `make_figure` and ``mbplanar plot``, or replace one of the same name.

    Parameters
    ----------
    name : str
        The picture's name (``mbplanar plot MODEL NAME``).
    function : callable
        ``function(engine, at=None, **options)`` returning a matplotlib Figure.
    help : str
        One line for ``mbplanar plot --help``.

    Returns
    -------
    None

    Raises
    ------
    Exception
        Nothing is raised here; what `function` raises comes out of `make_figure`.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.viz import FIGURES, make_figure, register_figure, require_matplotlib
    >>> def crank_only(engine, at=None, **options):
    ...     fig, ax = require_matplotlib().subplots()
    ...     ax.set_title(engine.mech.title)
    ...     return fig
    >>> register_figure("title", crank_only, "the model's title only")
    >>> make_figure(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), "title").axes[0].get_title()
    'Crank-rocker four-bar'
    >>> del FIGURES["title"]
    """
    FIGURES[name] = Figure(function, help)


#: words people write for a picture of another name
PICTURE_SYNONYMS = {"friction": "efficiency", "reactions": "forces", "coupler": "trajectories",
                    "paths": "trajectories", "flywheel": "dynamics", "velocities": "vectors"}


def unknown_picture(what: str) -> str:
    """The message for a picture `what` that `FIGURES` lacks: the closest names, or the synonym's picture."""
    hint = (f"did you mean '{PICTURE_SYNONYMS[what.lower()]}'?" if what.lower() in PICTURE_SYNONYMS
            else did_you_mean(what, FIGURES, "pictures"))
    return f"unknown picture '{what}'; {hint} (pictures: {', '.join(FIGURES)})"


def make_figure(engine, what: str, at=None, **options):
    r"""One of the pictures of ``mbplanar plot`` as a matplotlib figure.

    Parameters
    ----------
    engine : Engine
        The model.
    what : str
        A name of `FIGURES`: "diagram", "vectors", "trajectories", "kinematics", "analogues",
        "transmission", "forces", "dynamics", "shaking", "efficiency", "simulation", or one added by
        `register_figure`.
    at : float, optional
        The position for a one-position picture, in the input's unit (default: the drawn pose).
    **options
        Passed to the picture's function (e.g. ``count``, ``figsize``).

    Returns
    -------
    matplotlib.figure.Figure
        The figure (`save_figure` or `figure_bytes` write and close it).

    Raises
    ------
    PlotUnavailable
        matplotlib is not installed.
    ModelError
        An unknown picture (the message names the closest), or one the model has no data for.
    MotionError
        A position the model cannot reach.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.viz import figure_bytes, make_figure
    >>> fig = make_figure(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), "diagram", at=30)
    >>> figure_bytes(fig, "png", dpi=30)[:4]
    b'\x89PNG'
    """
    require_matplotlib()
    if what not in FIGURES:
        raise ModelError(unknown_picture(what))
    return FIGURES[what].function(engine, at, **options)


def save_figure(fig, path, dpi=120):
    """Write a figure to a file, the format from the suffix, and close it.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    path : str or Path
        A .png, .svg or .pdf file.
    dpi : int
        Resolution of a PNG, dots per inch.

    Returns
    -------
    None

    Raises
    ------
    ModelError
        Another suffix (the figure is closed all the same).
    OSError
        The file cannot be written.

    Examples
    --------
    >>> import os, tempfile, mbplanar
    >>> from mbplanar.viz import make_figure, save_figure
    >>> path = os.path.join(tempfile.mkdtemp(), "fourbar.svg")
    >>> save_figure(make_figure(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), "diagram"), path)
    >>> open(path).read(5)
    '<?xml'
    """
    plt = require_matplotlib()
    suffix = str(path).rsplit(".", 1)[-1].lower() if "." in str(path) else ""
    if suffix not in ("png", "svg", "pdf"):
        plt.close(fig)
        raise ModelError(f"{path}: a picture is written as .png, .svg or .pdf")
    try:
        fig.savefig(path, dpi=dpi)
    finally:
        plt.close(fig)


def figure_bytes(fig, fmt="png", dpi=100) -> bytes:
    """A figure as PNG or SVG bytes, closed afterwards (for a web page or a report).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    fmt : {"png", "svg", "pdf"}
        The format.
    dpi : int
        Resolution of a PNG, dots per inch.

    Returns
    -------
    bytes
        The file's content.

    Raises
    ------
    ValueError
        A format matplotlib does not write (matplotlib's error).

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.viz import figure_bytes, make_figure
    >>> data = figure_bytes(make_figure(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), "diagram"), "svg")
    >>> data[:5]
    b'<?xml'
    """
    import io
    plt = require_matplotlib()
    buf = io.BytesIO()
    try:
        fig.savefig(buf, format=fmt, dpi=dpi)
    finally:
        plt.close(fig)
    return buf.getvalue()


# -- GIF animation ----------------------------------------------------------------------------------
def write_gif(engine, path, frames=36, *, dpi=80, fps=12, figsize=(6.4, 5.6), trajectories=True):
    """An animated GIF of the cycle, what ``mbplanar animate MODEL -o FILE.gif`` writes.

    Parameters
    ----------
    engine : Engine
        The model.
    path : str or Path
        The GIF file.
    frames : int
        Positions over the cycle (fewer only if the mechanism cannot move at all).
    dpi : int
        Resolution, dots per inch.
    fps : float
        Frames per second.
    figsize : (2,) tuple of float
        The frame's size, inches.
    trajectories : bool
        Draw the points' paths behind the mechanism.

    Returns
    -------
    Motion
        The positions drawn.

    Raises
    ------
    PlotUnavailable
        matplotlib or Pillow is not installed.
    MotionError
        No position of the cycle can be reached.
    OSError
        The file cannot be written.

    Examples
    --------
    >>> import os, tempfile, mbplanar
    >>> from mbplanar.viz import write_gif
    >>> path = os.path.join(tempfile.mkdtemp(), "fourbar.gif")
    >>> motion = write_gif(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), path, frames=3, dpi=20)
    >>> len(motion.phi), open(path, "rb").read(6)
    (3, b'GIF89a')
    """
    plt = require_matplotlib()
    from PIL import Image
    motion = cycle_motion(engine, frames)
    scene = build_scene(engine, motion, motion)
    fig = plt.figure(figsize=figsize, dpi=dpi)
    ax = fig.add_axes((0.02, 0.02, 0.96, 0.88))
    images = []
    for b in range(scene.batch):
        ax.clear()
        if trajectories:
            draw_trajectories(ax, scene, lw=0.7)
        draw_mechanism(ax, scene, b)
        _frame_axes(ax, scene)
        fig.suptitle(f"{engine.mech.title or engine.mech.name}\n{input_label(engine, motion.phi[b], '7.2f')}"
                     f"   frame {b + 1}/{scene.batch}", fontsize=10)
        fig.canvas.draw()
        rgba = np.asarray(fig.canvas.buffer_rgba())
        images.append(Image.fromarray(rgba[..., :3].copy()).convert("P", palette=Image.ADAPTIVE, colors=64))
    plt.close(fig)
    images[0].save(path, save_all=True, append_images=images[1:], duration=int(1000 / fps), loop=0,
                   optimize=False, disposal=1)
    return motion
