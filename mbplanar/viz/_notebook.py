"""What Jupyter shows for a mechanism, an engine and each result: an inline SVG diagram, drawn from the same
`Scene` as every other picture (no matplotlib needed), beside a summary table. The result types reach these
functions through `_repr_html_()` (see `mbplanar.model._views`).
"""

from __future__ import annotations

import html
import itertools
import math

import numpy as np

from ..errors import MbplanarError

__all__ = ["mechanism_html", "engine_html", "motion_html", "kinetostatics_html", "dynamics_html", "check_html",
           "VIEWS"]

_IDS = itertools.count()


# -- HTML for Jupyter ------------------------------------------------------------------------------
def _diagram(engine, motion=None) -> str:
    """A still SVG diagram of the first position of `motion` (default: the drawn pose)."""
    from ._animation import svg_animation
    from ..kinematics import analyse
    if motion is None:
        first = analyse(engine, np.asarray(engine.phi_drawn, float).reshape(1, -1))
    elif len(motion.phi):
        first = analyse(engine, motion.phi[:1], motion.omega[:1], motion.epsilon[:1])
    else:
        return ""
    return svg_animation(engine, motion=first, controls=False, trajectories=False, width=360,
                         element_id=f"mbplanar-diagram-{next(_IDS)}")


def _table(rows) -> str:
    cells = "".join(f"<tr><th style='text-align:left'>{html.escape(str(k))}</th>"
                    f"<td style='text-align:left'>{html.escape(str(v))}</td></tr>" for k, v in rows)
    return f"<table>{cells}</table>"


def _page(title, rows, diagram="") -> str:
    head = f"<div><b>{html.escape(title)}</b></div>"
    body = f"<div style='display:flex;gap:1.5em;align-items:flex-start'>{diagram}{_table(rows)}</div>"
    return f"<div class='mbplanar'>{head}{body}</div>"


def _g(x) -> str:
    return f"{x:.6g}"


def _range(inp, phi) -> str:
    if len(phi) == 0:
        return "no position"
    lo, hi = inp.from_si(phi[0, 0]), inp.from_si(phi[-1, 0])
    return f"{inp.name} = {_g(lo)} … {_g(hi)} {inp.unit}" if len(phi) > 1 else f"{inp.name} = {_g(lo)} {inp.unit}"


def mechanism_html(mech) -> str:
    """A table of the mechanism and, when it assembles, its diagram in the drawn pose."""
    rows = [("links", ", ".join(mech.links)), ("joints", ", ".join(f"{j.name} ({j.kind})" for j in
                                                                       mech.joints.values())),
            ("inputs", ", ".join(i.joint for i in mech.inputs))]
    if mech.points:
        rows.append(("points", ", ".join(mech.points)))
    try:
        from ..engine import Engine
        engine = Engine(mech)
    except MbplanarError as exc:
        return _page(f"Mechanism {mech.name}", rows + [("cannot be assembled", str(exc))])
    rows.append(("structure", engine.topology.structure.formula))
    return _page(f"Mechanism {mech.name}: {mech.title}" if mech.title else f"Mechanism {mech.name}", rows,
                 _diagram(engine))


def engine_html(engine) -> str:
    mech = engine.mech
    st = engine.topology.structure
    rows = [("DOF", st.dof), ("independent loops", st.loops), ("structure", st.formula),
            ("links", ", ".join(mech.links)), ("joints", ", ".join(mech.joints)),
            ("inputs", ", ".join(f"{i.name} ({i.joint}, {i.unit})" for i in engine.inputs)),
            ("backend", engine.backend)]
    return _page(f"Engine of {mech.name}", rows, _diagram(engine))


def motion_html(motion) -> str:
    from ..io import engine_for
    engine = engine_for(motion)
    inp = engine.inputs[0]
    rows = [("positions", f"{len(motion.phi)} of {motion.requested}"), ("range", _range(inp, motion.phi)),
            ("links", ", ".join(motion.link_names)), ("points", ", ".join(motion.point_names)),
            ("status", motion.message)]
    return _page(f"Motion of {engine.mech.name}", rows, _diagram(engine, motion))


def kinetostatics_html(result) -> str:
    from ..io import engine_for
    motion = result.motion
    engine = engine_for(result)
    rows = [("positions", len(motion.phi)), ("range", _range(engine.inputs[0], motion.phi))]
    for name, r in result.reactions.items():
        rows.append((f"|F| at {name} (on {r.on} from {r.source})", f"max {_g(float(np.nanmax(r.magnitude)))} N"
                     if len(r.magnitude) else "—"))
    for name, q in result.balancing.items():
        unit = "N·m" if engine.mech.joints[name].kind == "R" else "N"
        rows.append((f"balancing at {name}", f"{_g(float(np.nanmin(q)))} … {_g(float(np.nanmax(q)))} {unit}"
                     if len(q) else "—"))
    residual = result.virtual_power_residual
    rows += [("virtual-power residual", f"max {float(np.nanmax(np.abs(residual))):.3g}" if len(residual) else "—"),
             ("status", result.message)]
    return _page(f"Kinetostatics of {engine.mech.name}", rows, _diagram(engine, motion))


def dynamics_html(dyn) -> str:
    from ..forces import summary
    from ..io import engine_for
    engine = engine_for(dyn.reduced.motion)
    rows = []
    for label, value, unit in summary(dyn, engine.inputs[0]):
        text = _g(value) if isinstance(value, float) and math.isfinite(value) else str(value)
        rows.append((label.strip(), f"{text} {unit}".strip()))
    return _page(f"Machine dynamics of {engine.mech.name}", rows, _diagram(engine))


def check_html(report) -> str:
    rows = [("input", f"{report.input} [{report.unit}]"), ("full turn", "yes" if report.full_turn else "no"),
            ("range", f"{_g(report.range[0])} … {_g(report.range[1])} {report.unit}")]
    rows += [("motion limit", lim.message) for lim in report.limits]
    rows += [("change point", c.message) for c in report.change_points]
    for ang in report.transmission:
        rows.append((f"transmission angle {ang.name}", f"{math.degrees(ang.minimum):.4g}° … "
                     f"{math.degrees(ang.maximum):.4g}°"))
    return _page(f"Check of {report.model}", rows)


#: result type's name → its HTML
VIEWS = {"Mechanism": mechanism_html, "Engine": engine_html, "Motion": motion_html,
         "Kinetostatics": kinetostatics_html, "Dynamics": dynamics_html, "CheckReport": check_html}
