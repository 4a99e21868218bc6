"""Results in notebooks: pandas DataFrames with the CSV tables' columns, and the HTML that Jupyter shows for a
mechanism, an engine and each result (an inline SVG diagram, drawn from the same `Scene` as every other
picture, beside a summary table).

The result types keep one-line methods (`to_frame`, `_repr_html_`) that call this module lazily, so that
neither pandas nor this module is imported until a notebook asks. The diagrams need no matplotlib.
"""

from __future__ import annotations

import html
import itertools
import math

import numpy as np

from .errors import MbplanarError

__all__ = ["frame", "motion_frame", "kinetostatics_frame", "dynamics_frame", "mechanism_html", "engine_html",
           "motion_html", "kinetostatics_html", "dynamics_html", "check_html"]

_IDS = itertools.count()


# -- DataFrames --------------------------------------------------------------------------------------
def frame(header, columns):
    """A pandas DataFrame of a table (`header` names, `columns` (B, k)); a clear error without pandas."""
    try:
        import pandas as pd
    except ImportError:
        raise MbplanarError("DataFrames need pandas: pip install mbplanar[pandas]") from None
    columns = np.asarray(columns, float).reshape(-1, len(header))
    return pd.DataFrame(columns, columns=list(header))


def motion_frame(motion):
    """The sweep table of a `Motion` (the columns of `mbplanar sweep` without forces), one row per position."""
    from .cli import sweep_table
    engine = motion.engine
    unit = "rad" if engine.inputs[0].unit == "rad" else "deg"
    return frame(*sweep_table(engine, motion, unit))


def kinetostatics_frame(result):
    """The force columns of `mbplanar sweep` for a `Kinetostatics`, with the input column first."""
    from .cli import forces_columns
    engine = result.motion.engine
    inp = engine.inputs[0]
    header, cols = forces_columns(engine, result)
    header = [f"{inp.name}[{inp.unit}]"] + header
    return frame(header, np.column_stack([inp.from_si(result.motion.phi[:, 0]), cols]))


def dynamics_frame(dyn):
    """The cycle table of `mbplanar dynamics -o` for a `Dynamics`."""
    from .cli import dynamics_table
    return frame(*dynamics_table(dyn))


# -- HTML for Jupyter ------------------------------------------------------------------------------
def _diagram(engine, motion=None) -> str:
    """A still SVG diagram of the first position of `motion` (default: the drawn pose)."""
    from .animation import svg_animation
    from .kinematics import analyse
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
        from .solver import Engine
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
    engine = motion.engine
    inp = engine.inputs[0]
    rows = [("positions", f"{len(motion.phi)} of {motion.requested}"), ("range", _range(inp, motion.phi)),
            ("links", ", ".join(motion.link_names)), ("points", ", ".join(motion.point_names)),
            ("status", motion.message)]
    return _page(f"Motion of {engine.mech.name}", rows, _diagram(engine, motion))


def kinetostatics_html(result) -> str:
    motion = result.motion
    engine = motion.engine
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
    from .dynamics import summary
    engine = dyn.reduced.motion.engine
    rows = []
    for label, value, unit in summary(dyn, engine.inputs[0]):
        text = _g(value) if isinstance(value, float) and math.isfinite(value) else str(value)
        rows.append((label.strip(), f"{text} {unit}".strip()))
    return _page(f"Machine dynamics of {engine.mech.name}", rows, _diagram(engine))


def check_html(report) -> str:
    rows = [("input", f"{report.input} [{report.unit}]"), ("full turn", "yes" if report.full_turn else "no"),
            ("range", f"{_g(report.range[0])} … {_g(report.range[1])} {report.unit}")]
    rows += [("motion limit", lim["message"]) for lim in report.limits]
    rows += [("change point", c["message"]) for c in report.change_points]
    for ang in report.transmission:
        rows.append((f"transmission angle {ang.name}", f"{math.degrees(ang.minimum):.4g}° … "
                     f"{math.degrees(ang.maximum):.4g}°"))
    return _page(f"Check of {report.model}", rows)
