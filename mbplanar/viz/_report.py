"""A model's whole analysis in ONE self-contained HTML file: figures inline (base64 PNG), tables of the
structure, positions and analogues, reactions and the balancing moment, the animation (inline SVG +
JS). No external URL: it reads offline.

The report is a list of sections, `SECTIONS` (key → `Section(title, function)`, in order). A section
function takes `(engine, ctx)` (ctx: a `ReportContext` with the cycle motion and helpers for figures and
tables) and returns an HTML fragment, or None to leave the section out. Other code adds sections, or
replaces one in place, with `register_section`:

    register_section("cam", "Cam", my_function, after="flywheel")
"""

from __future__ import annotations

import base64
import html
import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

__all__ = ["Section", "SECTIONS", "register_section", "ReportContext", "report_html", "write_report",
           "REPORT_POSITIONS"]

REPORT_POSITIONS = 12  # positions in the tables (equally spaced over the cycle)


@dataclass(frozen=True)
class Section:
    """One section of the HTML report (``mbplanar report``).

    Attributes
    ----------
    title : str
        The heading.
    function : callable
        function(engine, ctx) -> str or None: the section's HTML, or None to leave it out for this
        model (`ctx` holds the cycle's motion, the tables' positions and the picture settings).

    Examples
    --------
    >>> from mbplanar.viz import SECTIONS, Section
    >>> [key for key in SECTIONS if key in ("model", "diagram", "structure", "motion")]   # (and those registered)
    ['model', 'diagram', 'structure', 'motion']
    >>> isinstance(SECTIONS["model"], Section), SECTIONS["model"].title
    (True, 'Model')
    """
    title: str
    function: Callable


@dataclass
class ReportContext:
    """What sections share: the engine, the cycle motion (`cycle`), the table positions (`table`)."""

    engine: object
    cycle: object
    table: object
    dpi: int = 90
    frames: int = 36
    notes: list = field(default_factory=list)

    def figure(self, fig, alt: str) -> str:
        """An inline <img> (base64 PNG) of a matplotlib figure (closed afterwards)."""
        from ._plotting import figure_bytes
        data = base64.b64encode(figure_bytes(fig, "png", self.dpi)).decode("ascii")
        return f'<figure><img alt="{html.escape(alt)}" src="data:image/png;base64,{data}"></figure>'


def html_table(header, rows, caption=None) -> str:
    """An HTML table: floats with 6 significant digits, non-finite numbers as '—', text escaped.

    Parameters
    ----------
    header : sequence
        The column headings.
    rows : iterable of sequence
        The rows' cells.
    caption : str, optional
        The table's caption.

    Returns
    -------
    str
        The <table> element.

    Raises
    ------
    TypeError
        A row that is not iterable.

    Examples
    --------
    >>> from mbplanar.viz import html_table
    >>> print(html_table(["joint", "x (m)"], [("A", 0.1234567891), ("B<", float("nan"))]))
    <table><thead><tr><th>joint</th><th>x (m)</th></tr></thead><tbody><tr><td>A</td><td>0.123457</td></tr><tr><td>B&lt;</td><td>—</td></tr></tbody></table>
    """
    def cell(x):
        if isinstance(x, (float, np.floating)):
            return f"{x:.6g}" if math.isfinite(x) else "—"
        return html.escape(str(x))
    cap = f"<caption>{html.escape(caption)}</caption>" if caption else ""
    head = "".join(f"<th>{html.escape(str(h))}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{cell(x)}</td>" for x in row) + "</tr>" for row in rows)
    return f"<table>{cap}<thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


# -- the sections -----------------------------------------------------------------------------------
def _model_section(engine, ctx):
    from ._plotting import input_speed
    mech = engine.mech
    rows = []
    for j in mech.joints.values():
        guide = f"{j.guide_deg:.4f}°" if j.kind == "P" else ""
        rows.append((j.name, j.kind, " – ".join(j.links), j.at[0], j.at[1], guide))
    coords = "; ".join(f"<b>{html.escape(inp.name)}</b> [{html.escape(inp.unit)}] drives joint "
                       f"{html.escape(inp.joint)}" for inp in engine.inputs)
    text = (f"<p>Model file <code>{html.escape(str(mech.source))}</code>. Generalized coordinate"
            f"{'s' if len(engine.inputs) > 1 else ''}: {coords}; input speed {html.escape(input_speed(engine))}. "
            f"Ground link {html.escape(mech.ground)}; moving links {html.escape(', '.join(mech.moving_links))}.</p>")
    if len(engine.inputs) > 1:
        text += (f"<p>{len(engine.inputs)} inputs: the tables and plots over the cycle follow the model's input "
                 "path, every input over its sweep at once (" + html.escape(_path(engine)) + ").</p>")
    links = [(lk.name, lk.mass, lk.inertia, lk.centre or "") for lk in mech.links.values() if lk.name != mech.ground]
    return (text + html_table(("pair", "type", "links", "x [m]", "y [m]", "guide"), rows, "Table of kinematic pairs")
            + html_table(("link", "mass [kg]", "J_S [kg·m²]", "centre"), links, "Links"))


def _diagram_section(engine, ctx):
    from ._plotting import diagram_figure, vectors_figure
    return (ctx.figure(diagram_figure(engine, cycle=ctx.cycle), "kinematic diagram in the drawn pose")
            + ctx.figure(vectors_figure(engine, cycle=ctx.cycle),
                         "velocities, accelerations and instantaneous centres in the drawn pose"))


def _structure_section(engine, ctx):
    topo = engine.topology
    s = topo.structure
    mech = engine.mech
    if mech.higher:
        n, p5, p4 = len(mech.moving_links), len(mech.joints), len(mech.higher)
        count = (f"W = 3·{n} − 2·{p5} − {p4} = {topo.dof} (Chebyshev, with {p4} higher pair(s): "
                 f"{html.escape(', '.join(f'{h.name} ({h.kind})' for h in mech.higher.values()))}; the Assur groups "
                 "are the equivalent lower-pair mechanism's, each higher pair replaced by a primed link)")
    else:
        count = f"W = {topo.dof} (Chebyshev–Grübler)"
    text = (f"<p>Degrees of freedom {count}, independent loops: {len(topo.loops)}"
            + (f"; loops: {html.escape('; '.join(' – '.join(loop) for loop in topo.loops))}" if topo.loops else "")
            + ".</p>")
    if s is None:
        return text + "<p>No Assur decomposition for this model.</p>"
    rows = [(k + 1, g.group_class, g.order, g.kind or "", ", ".join(g.links), ", ".join(g.internal),
             ", ".join(g.external)) for k, g in enumerate(s.groups)]
    return (text + f"<p>Structural formula: <b>{html.escape(s.formula)}</b>; mechanism class "
            f"{s.mechanism_class}.</p>" + html_table(("#", "class", "order", "kind", "links", "internal pairs",
                                                      "external pairs"), rows, "Assur groups in solving order"))


def _motion_section(engine, ctx):
    """`check`'s verdict: whether the input turns fully, dead points and change points, extreme
    positions, transmission and pressure angles."""
    from ..analysis import check, check_region, format_region, format_report
    if len(engine.inputs) == 2:
        return ("<p>The region the two inputs can reach from the drawn pose (<code>mbplanar check</code>): a "
                "grid over both inputs' sweeps, each grid line walked on the drawn branch, and the singular "
                "curves where the links line up.</p><pre>" + html.escape(format_region(check_region(engine)))
                + "</pre>")
    if len(engine.inputs) != 1:
        return (f"<p>The motion range is checked for one input (a region for two); this model has "
                f"{len(engine.inputs)}.</p>")
    return ("<p>The whole range the input can move through (<code>mbplanar check</code>): dead points are "
            "located exactly, extreme positions refined by Newton on the analogue, transmission and "
            "pressure angles over the range.</p><pre>" + html.escape(format_report(check(engine))) + "</pre>")


def _positions_section(engine, ctx):
    from ._plotting import moving_points, path_analogues
    from ._scene import build_scene
    m = ctx.table
    coords, cols0 = _coordinates(engine, m)
    wq, eq, vq, aq = path_analogues(engine, m)
    links = m.link_names[1:]
    head = coords + [f"φ{n} [°]" for n in links] + [f"ω{n}q" for n in links] + [f"ε{n}q" for n in links]
    rows = np.column_stack(cols0 + [np.degrees(m.angle[:, 1:]), wq[:, 1:], eq[:, 1:]])
    pts = moving_points(engine, build_scene(engine, m, m))
    idx = [m.point(n) for n in pts]
    ph = coords + [f"{n}.{q}" for n in pts for q in ("x", "y", "vqx", "vqy", "aqx", "aqy")]
    cols = list(cols0)
    for k in idx:
        cols += [m.xy[:, k, 0], m.xy[:, k, 1], vq[:, k, 0], vq[:, k, 1], aq[:, k, 0], aq[:, k, 1]]
    note = "" if not m.limits else f"<p class=\"warn\">{html.escape(_limits(engine, m))}</p>"
    by = "dφ" if len(engine.inputs) == 1 else f"d{html.escape(engine.inputs[0].name)}"
    along = "" if len(engine.inputs) == 1 else f" The analogues are taken {html.escape(_path(engine))}."
    return (note + f"<p>Angles of the links' reference lines, analogues of angular velocities ω_q = dφ_k/{by} "
            f"[rad/rad] and accelerations ε_q = d²φ_k/{by}² [rad/rad²]; points: coordinates [m], analogues of "
            f"velocity [m/rad] and acceleration [m/rad²].{along}</p>"
            + html_table(head, rows.tolist(), "Links") + html_table(ph, np.column_stack(cols).tolist(), "Points"))


def _coordinates(engine, motion) -> tuple[list, list]:
    """Column heads and columns (B,) of the input values of `motion` in the model's units, every input."""
    return ([f"{inp.name} [{inp.unit}]" for inp in engine.inputs],
            [inp.from_si(motion.phi[:, k]) for k, inp in enumerate(engine.inputs)])


def _path(engine) -> str:
    """How a multi-input model's cycle moves its inputs ('along the input path: d/dphi1 with phi2 moving 1×
    as fast', with each input's sweep)."""
    from ._plotting import path_note
    sweeps = ", ".join(f"{inp.name} {inp.default_sweep()[0]:g} … {inp.default_sweep()[1]:g} {inp.unit}"
                       for inp in engine.inputs)
    return f"{path_note(engine)}; {sweeps}"


def _limits(engine, motion):
    from ..kinematics import describe_limit
    return "; ".join(describe_limit(engine, lim) for lim in motion.limits)


def _plots_section(engine, ctx):
    from ._plotting import (analogues_figure, kinematics_figure, pressure_series, trajectories_figure,
                           transmission_figure, transmission_series)
    out = ctx.figure(trajectories_figure(engine), "trajectories")
    out += ctx.figure(kinematics_figure(engine, count=121), "real velocities and accelerations")
    out += ctx.figure(analogues_figure(engine, count=121), "analogues")
    if transmission_series(engine, ctx.table) or pressure_series(engine, ctx.table):
        out += ctx.figure(transmission_figure(engine, count=121), "transmission and pressure angles")
    return out


def _reactions_section(engine, ctx):
    """Kinetostatics at the model's speed: the balancing load and every pair's reaction at the table
    positions, a diagram with the reaction arrows, the plots over the cycle, the virtual-power check."""
    from ..forces import has_force_data
    if not has_force_data(engine.mech):
        return ("<p>The model has no loads: no masses, inertias, gravity or load rows, so every reaction "
                "and the balancing moment are zero.</p>")
    from ._forceplots import balancing_label, forces_figure, reaction_label
    from ..forces import kinetostatics
    from ._plotting import diagram_figure, input_speed
    table, cycle = kinetostatics(engine, ctx.table), kinetostatics(engine, ctx.cycle)
    residual = max(float(np.nanmax(r.virtual_power_residual, initial=0.0)) for r in (table, cycle))
    coords, phis = _coordinates(engine, ctx.table)
    out = (f"<p>Kinetostatics at the model's input speed and acceleration ({input_speed(engine)}), "
           "with the d'Alembert inertia loads, gravity and the model's loads; "
           "no flywheel (J_I = 0). F<sub>ij</sub> is the force on link i from link j, applied at the pair "
           "(a prismatic pair: at its slider point, with its moment M about that point); the other link "
           "gets the opposite. Directions in degrees counter-clockwise from +x; moments counter-clockwise "
           "positive.</p>"
           f"<p>Check: the virtual power of all loads plus the balancing power vanishes for every motion the "
           f"pairs allow; its largest relative residual over the {len(ctx.cycle.phi)} positions of the cycle "
           f"and the table is <b>{residual:.2e}</b>.</p>")
    notes = [r.message for r in (table, cycle) if not r.success] + ([_limits(engine, ctx.cycle)]
                                                                     if ctx.cycle.limits else [])
    out += "".join(f"<p class=\"warn\">{html.escape(n)}</p>" for n in dict.fromkeys(notes))
    tiny = 1e-12 * max([0.0] + [float(np.nanmax(r.magnitude, initial=0.0)) for r in table.reactions.values()])
    tiny_m = tiny * engine.size  # round-off of a moment: what is left of the forces' moments

    def clean(x, eps):
        return np.where(np.abs(x) < eps, 0.0, x)

    head, cols = list(coords), list(phis)
    for joint, q in table.balancing.items():
        what, unit = balancing_label(engine, joint)
        head.append(f"{what} at {joint} [{unit}]")
        cols.append(clean(q, tiny_m if unit == "N·m" else tiny))
    head.append("virtual-power residual")
    cols.append(table.virtual_power_residual)
    out += html_table(head, np.column_stack(cols).tolist(), "Balancing load")
    grid = []
    for joint, r in table.reactions.items():
        kind = engine.mech.kind_of(joint)
        prismatic = kind == "P"
        fx, fy = clean(r.fx, tiny), clean(r.fy, tiny)
        mag = np.hypot(fx, fy)
        direction = np.where(mag > 0, np.degrees(np.arctan2(fy, fx)) % 360.0, np.nan)
        head = coords + ["Fx [N]", "Fy [N]", "|F| [N]", "direction [°]"] + (["M [N·m]"] if prismatic else [])
        rows = np.column_stack(phis + [fx, fy, mag, direction] + ([clean(r.moment, tiny_m)] if prismatic else []))
        grid.append(html_table(head, rows.tolist(), f"{reaction_label(r)}: pair {joint} "
                                                    f"({ {'R': 'revolute', 'P': 'prismatic'}.get(kind, kind)}), on link "
                                                    f"{r.on} from link {r.source}"))
    out += '<div class="grid">' + "".join(grid) + "</div>"
    out += ctx.figure(diagram_figure(engine, reactions=True, cycle=ctx.cycle),
                      "reaction arrows in the drawn pose")
    out += ctx.figure(forces_figure(engine, cycle=ctx.cycle), "reactions and balancing moment over the cycle")
    return out


def _shaking_section(engine, ctx):
    """The shaking force and moment on the frame over the cycle (models with masses or loads)."""
    from ..forces import has_force_data
    if not has_force_data(engine.mech):
        return "<p>The model has no masses or loads: nothing shakes the frame.</p>"
    from ._elementplots import shaking_figure
    return ("<p>The forces the mechanism puts on its frame: through the pairs with the frame, the drive's "
            "stator and the loads anchored on it; the hodograph is the tip of the shaking force over the "
            "cycle, the shaking moment is about the origin.</p>"
            + ctx.figure(shaking_figure(engine), "shaking force and moment on the frame"))


def _friction_section(engine, ctx):
    """The efficiency with the model's friction in the pairs (models with [friction])."""
    import warnings

    from ..errors import ModelWarning, MotionError
    if "friction" not in engine.mech.extras:
        return "<p>The model has no <code>[friction]</code> section: its pairs are ideal.</p>"
    from ._elementplots import efficiency_figure
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ModelWarning)
        try:
            figure = ctx.figure(efficiency_figure(engine), "instantaneous efficiency with friction in the pairs")
        except MotionError as exc:  # the iteration converges nowhere: no efficiency to show
            figure = ""
            warnings.warn(ModelWarning(str(exc)), stacklevel=2)
    for w in caught:  # (again for the command line, which prints them)
        warnings.warn(w.message, stacklevel=2)
    notes = "".join(f'<p class="warn">{html.escape(str(w.message))}</p>' for w in caught
                    if "did not converge" in str(w.message))
    return notes + figure


def _animation_section(engine, ctx):
    from ._animation import svg_animation
    return svg_animation(engine, ctx.frames, element_id="report-animation", width=560)


def _flywheel_section(engine, ctx):
    from ..forces import machine_dynamics, summary
    from ._plotting import dynamics_figure
    if len(engine.inputs) != 1:
        return (f"<p>The energy–mass method and the flywheel reduce a machine to its one crank; this model has "
                f"{len(engine.inputs)} inputs ({html.escape(', '.join(i.name for i in engine.inputs))}): "
                "<code>mbplanar simulate</code> gives its motion under given forces.</p>")
    if engine.mech.dynamics is None:
        return "<p>The model has no <code>[dynamics]</code> section (δ and the flywheel's data).</p>"
    d = machine_dynamics(engine)
    inp = engine.inputs[0]
    rows = summary(d, inp)
    state = d.state_at(engine, ctx.table.phi[:, 0])
    head = [f"{inp.name} [{inp.unit}]", "J_II [kg·m²]", "dJ_II/dφ [kg·m²]", "M_red [N·m]", "ΔT_I [J]",
            "ω [rad/s]", "ε [rad/s²]"]
    table = np.column_stack([inp.from_si(ctx.table.phi[:, 0]), state["J_II"], state["dJ_II"], state["M_red"],
                             state["dT_I"], state["omega"], state["epsilon"]])
    return (html_table(("quantity", "value", "unit / note"), rows, "Energy–mass method and flywheel")
            + ctx.figure(dynamics_figure(engine, dynamics=d), "machine dynamics")
            + html_table(head, table.tolist(), "Reduced quantities and the true motion of the crank"))


SECTIONS: dict[str, Section] = {
    "model": Section("Model", _model_section),
    "diagram": Section("Kinematic diagram", _diagram_section),
    "structure": Section("Structure", _structure_section),
    "motion": Section("Motion range, dead points and angles", _motion_section),
    "positions": Section("Positions and analogues", _positions_section),
    "plots": Section("Kinematic plots", _plots_section),
    "animation": Section("Animation", _animation_section),
    "reactions": Section("Joint reactions and balancing moment", _reactions_section),
    "flywheel": Section("Machine dynamics and flywheel", _flywheel_section),
    "shaking": Section("Shaking force on the frame", _shaking_section),
    "friction": Section("Friction in the pairs and efficiency", _friction_section),
}


def register_section(key: str, title: str, function: Callable, after: str | None = None) -> None:
    """Add a section to the HTML report, or replace one in place (same key).

    Parameters
    ----------
    key : str
        The section's key (its anchor in the page).
    title : str
        Its heading.
    function : callable
        function(engine, ctx) -> str or None: the HTML, or None to leave the section out.
    after : str, optional
        Insert a new section after this key (default: at the end).

    Returns
    -------
    None

    Raises
    ------
    Exception
        Nothing is raised here (an unknown `after` appends at the end); what `function` raises comes
        out of `report_html`.

    Examples
    --------
    >>> from mbplanar.viz import SECTIONS, html_table, register_section
    >>> import mbplanar
    >>> def pairs(engine, ctx):
    ...     return html_table(["pair", "kind"], [(j.name, j.kind) for j in engine.mech.joints.values()])
    >>> register_section("pairs", "Pairs", pairs, after="model")
    >>> keys = list(SECTIONS)
    >>> keys[keys.index("pairs") - 1]
    'model'
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/slider_crank.toml"))
    >>> "<td>Bp</td><td>P</td>" in SECTIONS["pairs"].function(engine, None)   # report_html calls it so
    True
    >>> del SECTIONS["pairs"]
    """
    if key in SECTIONS or after is None or after not in SECTIONS:
        SECTIONS[key] = Section(title, function)
        return
    items = list(SECTIONS.items())
    pos = [k for k, _ in items].index(after) + 1
    items.insert(pos, (key, Section(title, function)))
    SECTIONS.clear()                    # the one dict, in place: `mbplanar.viz.SECTIONS` is the same object
    SECTIONS.update(items)


_STYLE = """
body{font-family:system-ui,sans-serif;max-width:1100px;margin:1.5em auto;padding:0 1em;color:#1a1a1a}
h1{font-size:1.6em} h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:1.6em}
table{border-collapse:collapse;margin:.6em 0 1.2em;font-size:.82em;display:block;overflow-x:auto}
th,td{border:1px solid #ccc;padding:2px 6px;text-align:right;white-space:nowrap} th{background:#eef3f8}
caption{text-align:left;font-weight:bold;padding:.3em 0}
figure{margin:.5em 0} img{max-width:100%} .todo{color:#777;font-style:italic} .warn{color:#b03a2e}
nav a{margin-right:1em} .grid{display:flex;flex-wrap:wrap;gap:0 1.5em}
"""


def report_html(engine, *, positions: int = REPORT_POSITIONS, frames: int = 36, dpi: int = 90) -> str:
    r"""The whole report of a model as one HTML page (pictures inlined): what ``mbplanar report`` writes.

    Sections (`SECTIONS`, in order; each left out where the model has nothing for it): the model,
    its diagram, structure, motion, the positions' tables, plots, the animation, reactions, flywheel,
    shaking, friction, and those the cam, gear and synthesis code register.

    Parameters
    ----------
    engine : Engine
        The model.
    positions : int
        Positions in the tables (equally spaced over the cycle).
    frames : int
        Frames of the animation.
    dpi : int
        Resolution of the pictures.

    Returns
    -------
    str
        The page.

    Raises
    ------
    PlotUnavailable
        matplotlib is not installed.
    MotionError
        No position of the cycle can be reached.

    Examples
    --------
    >>> import re, mbplanar
    >>> from mbplanar.viz import report_html
    >>> page = report_html(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), positions=4, frames=4, dpi=20)
    >>> ids = re.findall(r'<section id="(\w+)"', page)
    >>> [key for key in ids if key in ("model", "diagram", "structure", "motion", "positions", "plots")]
    ['model', 'diagram', 'structure', 'motion', 'positions', 'plots']
    """
    from ._plotting import cycle_motion, require_matplotlib
    require_matplotlib()
    ctx = ReportContext(engine, cycle_motion(engine, 72), cycle_motion(engine, positions), dpi, frames)
    mech = engine.mech
    title = html.escape(mech.title or mech.name)
    parts, nav = [], []
    for key, sec in list(SECTIONS.items()):
        body = sec.function(engine, ctx)
        if body is None:
            continue
        nav.append(f'<a href="#{key}">{html.escape(sec.title)}</a>')
        parts.append(f'<section id="{key}"><h2>{html.escape(sec.title)}</h2>\n{body}\n</section>')
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>{title} — mbplanar report</title><style>{_STYLE}</style></head><body>"
            f"<h1>{title}</h1><p>mbplanar report for model <b>{html.escape(mech.name)}</b>.</p>"
            f"<nav>{''.join(nav)}</nav>\n" + "\n".join(parts) + "\n</body></html>\n")


def write_report(engine, path, **kw) -> None:
    """Write the HTML report (`report_html`) to a file.

    Parameters
    ----------
    engine : Engine
        The model.
    path : str or Path
        The HTML file.
    **kw
        Passed to `report_html` (``positions``, ``frames``, ``dpi``).

    Returns
    -------
    None

    Raises
    ------
    PlotUnavailable
        matplotlib is not installed.
    OSError
        The file cannot be written.

    Examples
    --------
    >>> import os, tempfile, mbplanar
    >>> from mbplanar.viz import write_report
    >>> path = os.path.join(tempfile.mkdtemp(), "slider_crank.html")
    >>> write_report(mbplanar.Engine(mbplanar.read_model("models/slider_crank.toml")), path, positions=4, frames=4, dpi=20)
    >>> "<h1>Central slider-crank</h1>" in open(path, encoding="utf-8").read()
    True
    """
    text = report_html(engine, **kw)
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
