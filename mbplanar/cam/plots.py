"""Pictures of a cam design (matplotlib, optional extra `plot`): S/V/A/J diagrams, the pressure angle,
the cam with its follower at a chosen angle, the seed's sizing construction, and an animation (GIF)."""

from __future__ import annotations

import math

import numpy as np

from ..errors import ModelError
from .followers import face_line, pitch_point
from .geometry import rotate

__all__ = ["motion_figure", "pressure_figure", "cam_figure", "construction_figure", "save_animation",
           "save_figure"]


def _plt():
    """pyplot on the Agg backend; `PlotUnavailable` (exit 2) without matplotlib."""
    from ..viz import PlotUnavailable
    try:
        import matplotlib
    except ImportError:
        raise PlotUnavailable("pictures need matplotlib: pip install 'mbplanar[plot]'") from None
    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt
    return plt


def motion_figure(d):
    """s, v = ds/dφ, a, j against the cam angle (four panels)."""
    plt = _plt()
    phi = np.linspace(0, 2 * np.pi, 2881)
    vals = d.program.evaluate(phi)
    fig, axes = plt.subplots(4, 1, figsize=(8, 8), sharex=True)
    labels = ("s, m", "v = ds/dφ, m/rad", "a = d²s/dφ², m/rad²", "j = d³s/dφ³, m/rad³")
    for ax, y, label in zip(axes, vals, labels):
        ax.plot(np.degrees(phi), y, lw=1.2)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    for jump in d.program.continuity():
        if jump.order == 2:
            axes[3].axvline(math.degrees(jump.angle), color="#b03a2e", lw=0.6, ls=":")
    axes[-1].set_xlabel("cam angle φ, deg")
    fig.suptitle("Motion program" + (" (dotted: infinite jerk)" if d.program.continuity() else ""))
    fig.tight_layout()
    return fig


def pressure_figure(d):
    """The pressure angle against the cam angle, with the limits of the rise and the return."""
    plt = _plt()
    g = d.geometry
    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.plot(np.degrees(g.phi), np.degrees(g.pressure), lw=1.2, label="θ")
    for ext, colour in ((d.rise, "#2a6fb0"), (d.ret, "#b03a2e")):
        if ext is not None:
            lim = math.degrees(ext.limit)
            ax.axhline(lim, color=colour, ls="--", lw=0.8)
            ax.axhline(-lim, color=colour, ls="--", lw=0.8)
            ax.plot([math.degrees(ext.at)], [math.degrees(ext.value)], "o", color=colour)
    ax.set_xlabel("cam angle φ, deg")
    ax.set_ylabel("pressure angle θ, deg")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def _follower_shapes(d, phi_deg):
    """Lines and circles of the follower at cam angle `phi_deg`, in the fixed frame."""
    f = d.follower
    phi = np.array([math.radians(phi_deg)])
    s = d.program.evaluate(phi)[0]
    zero = np.zeros(1)
    lines, circles = [], []
    if f.contact == "flat":
        line = face_line(f, s, zero, zero)
        nu = np.array([math.cos(line.alpha[0]), math.sin(line.alpha[0])])
        along = np.array([-nu[1], nu[0]])
        centre = line.p[0] * nu
        half = 0.6 * f.prime_radius
        lines.append(np.array([centre - half * along, centre + half * along]))
        if f.motion == "translating":
            lines.append(np.array([centre, centre + 0.8 * f.prime_radius * nu]))
    else:
        b = pitch_point(f, s, zero, zero).b[0]
        if f.contact == "roller":
            circles.append((b, f.roller))
        if f.motion == "translating":
            lines.append(np.array([b, b + np.array([0.0, 0.8 * f.prime_radius])]))
    if f.motion == "oscillating":
        p = f.pivot
        tip = pitch_point(f, s, zero, zero).b[0]
        lines.append(np.array([p, tip]))
        circles.append((p, 0.01 * f.arm))
    return lines, circles


def cam_figure(d, at: float = 0.0):
    """The cam turned to cam angle `at` (deg) with its follower in place (fixed frame)."""
    plt = _plt()
    from matplotlib.patches import Circle
    g, f = d.geometry, d.follower
    turn = f.rotation * math.radians(at)
    fig, ax = plt.subplots(figsize=(6, 6))
    prof = rotate(g.profile, turn)
    ax.fill(prof[:, 0], prof[:, 1], color="#dde6ee", ec="#1a1a1a", lw=1.2)
    if g.pitch is not None:
        pitch = rotate(g.pitch, turn)
        ax.plot(pitch[:, 0], pitch[:, 1], ls="--", lw=0.8, color="#2a6fb0")
    lines, circles = _follower_shapes(d, at)
    for ln in lines:
        ax.plot(ln[:, 0], ln[:, 1], color="#b03a2e", lw=2)
    for c, r in circles:
        ax.add_patch(Circle(c, r, fill=False, color="#b03a2e", lw=1.5))
    ax.plot([0], [0], "k+")
    ax.set_aspect("equal")
    ax.set_title(f"cam at φ = {at:g}°")
    ax.grid(alpha=0.2)
    return fig


def construction_figure(d):
    """The seed's construction: the curve E(φ), the limit lines' region and the chosen cam centre."""
    plt = _plt()
    if d.sizing is None or d.sizing.construction is None:
        raise ModelError("the construction picture needs a sized oscillating follower (size = true)")
    c = d.sizing.construction
    fig, ax = plt.subplots(figsize=(6, 6))
    ax.fill(c.region[:, 0], c.region[:, 1], color="#e8f1e4", label="admissible cam centres")
    ax.plot(c.curve[:, 0], c.curve[:, 1], lw=1.2, label="x = −(l − v)cos ψ, y = (l − v)sin ψ")
    ax.plot(c.arm[:, 0], c.arm[:, 1], lw=0.8, color="grey", label="roller centre")
    ax.plot([0], [0], "ko", label="pivot")
    ax.plot([c.centre[0]], [c.centre[1]], "r*", ms=12, label="cam centre")
    span = 1.5 * max(np.max(np.abs(c.curve)), np.hypot(*c.centre))
    ax.set_xlim(-span, span)
    ax.set_ylim(-span, span)
    ax.set_aspect("equal")
    ax.legend(fontsize=7, loc="best")
    ax.grid(alpha=0.2)
    return fig


def save_animation(d, path, frames: int = 36, dpi: int = 80) -> None:
    """A GIF of one turn of the cam with its follower."""
    plt = _plt()
    from matplotlib.animation import FuncAnimation, PillowWriter
    from matplotlib.patches import Circle
    g, f = d.geometry, d.follower
    fig, ax = plt.subplots(figsize=(5, 5))
    reach = 1.3 * max(np.max(np.linalg.norm(g.profile, axis=1)) + f.roller,
                      f.centre_distance + f.arm if f.motion == "oscillating" else 0)
    def draw(k):
        ax.clear()
        at = 360.0 * k / frames
        prof = rotate(g.profile, f.rotation * math.radians(at))
        ax.fill(prof[:, 0], prof[:, 1], color="#dde6ee", ec="#1a1a1a")
        lines, circles = _follower_shapes(d, at)
        for ln in lines:
            ax.plot(ln[:, 0], ln[:, 1], color="#b03a2e", lw=2)
        for c, r in circles:
            ax.add_patch(Circle(c, r, fill=False, color="#b03a2e"))
        ax.set_xlim(-reach, reach)
        ax.set_ylim(-reach, reach)
        ax.set_aspect("equal")
        ax.set_title(f"φ = {at:.0f}°")
    anim = FuncAnimation(fig, draw, frames=frames)
    anim.save(path, writer=PillowWriter(fps=12), dpi=dpi)
    plt.close(fig)


def save_figure(d, what: str, path, at: float = 0.0, frames: int = 36) -> None:
    """Write picture `what` ("motion", "pressure", "cam", "construction", "animation") to `path`."""
    if what == "animation":
        if not str(path).lower().endswith(".gif"):
            raise ModelError(f"the animation is written as a GIF, not {path}")
        save_animation(d, path, frames=frames)
        return
    makers = {"motion": motion_figure, "pressure": pressure_figure,
              "cam": lambda d: cam_figure(d, at), "construction": construction_figure}
    fig = makers[what](d)
    from ..viz import save_figure as save
    save(fig, path)
