"""What `mbplanar cam` prints (a JSON document or text), the command itself, and the report's section.

The JSON keys are a contract, documented in docs/cam.md.
"""

from __future__ import annotations

import json
import math

import numpy as np

from ..errors import ModelError
from ..model import LENGTH_UNITS, add_units_option

__all__ = ["document", "shown", "text", "run_command", "report_section", "register"]


def _deg(x):
    return None if x is None else math.degrees(x)


def _finite(x):
    return float(x) if x is not None and math.isfinite(x) else None


def document(d) -> dict:
    """The JSON document of a `design.CamDesign` (SI units; angles in degrees where keys say `_deg`)."""
    f, g, ch = d.follower, d.geometry, d.check
    follower = {"motion": f.motion, "contact": f.contact, "rotation": "ccw" if f.rotation > 0 else "cw",
                "prime_radius": f.prime_radius, "roller": f.roller}
    if f.motion == "translating":
        follower.update(base_radius=f.base_radius, offset=f.offset)
    else:
        follower.update(centre_distance=f.centre_distance, arm=f.arm, arm_angle_deg=_deg(f.arm_angle),
                        face_offset=f.face_offset)
    phases = []
    for seg in d.program.segments:
        cv, ca, cj = seg.law.peaks()
        vmax, amax, jmax = seg.peaks
        phases.append({"kind": seg.kind, "law": seg.law.name, "start_deg": _deg(seg.start),
                       "angle_deg": _deg(seg.span), "stroke": abs(seg.s_end - seg.s_start),
                       "C_v": _finite(cv), "C_a": _finite(ca), "C_j": _finite(cj),
                       "v_max": _finite(vmax), "a_max": _finite(amax), "j_max": _finite(jmax)})
    s, v, a, _ = d.program.evaluate(g.phi)
    pressure = {}
    for name, ext in (("rise", d.rise), ("return", d.ret)):
        pressure[name] = None if ext is None else {
            "extreme_deg": _deg(ext.value), "at_deg": _deg(ext.at), "limit_deg": _deg(ext.limit),
            "exceeded": ext.exceeded}
    curvature = {"rho_min": _finite(d.rho_min), "at_deg": _finite(_deg(d.rho_min_at)),
                 "profile_rho_min": _finite(float(np.min(np.where(g.rho_profile > 0, g.rho_profile, np.inf)))),
                 "largest_safe_roller": _finite(d.rho_min) if g.rho_pitch is not None else None,
                 "rho_min_over_roller": _finite(d.rho_min / f.roller) if f.roller > 0 else None,
                 "undercut": g.undercut}
    timing = {"events": {name: {"value": r.value, "roots": [{"value": x.value, "direction": x.direction}
                                                             for x in r.roots],
                                "stroke": None if r.stroke is None else r.stroke.stroke}
                         for name, r in d.events.items()},
              "start": d.start if d.timed else None, "window": list(d.window) or None}
    out = {"cam": d.spec.source, "title": d.spec.title,
           "model": d.spec.model or (d.spec.source if d.spec.linkage is not None else None),
           "sized": d.sizing is not None, "follower": follower, "timing": timing,
           "stroke": d.program.stroke, "phases": phases,
           "v_max": float(np.max(np.abs(v))), "a_max": float(np.max(np.abs(a))),
           "pressure_angle": pressure, "curvature": curvature,
           "self_check": {"error": ch.error, "relative": ch.relative,
                          "interference": max(ch.interference, 0.0) if f.contact != "knife" else 0.0,
                          "converged": ch.converged, "angles": int(ch.phi.size)},
           "continuity": [{"angle_deg": _deg(j.angle), "quantity": ("s", "v", "a")[j.order], "jump": j.size}
                          for j in d.program.continuity()],
           "dynamics": _dynamics_doc(d), "warnings": list(d.warnings)}
    if f.contact == "flat":
        x = g.contact_fixed[:, 0] if f.motion == "translating" else None
        out["face"] = None if x is None else {"contact_min": float(x.min()), "contact_max": float(x.max()),
                                              "width": float(x.max() - x.min())}
    return out


def _dynamics_doc(d):
    if d.forces is None:
        return None
    fo, g, sp = d.forces, d.geometry, d.spec.dynamics
    k, j = int(np.argmin(fo.contact)), int(np.argmax(np.abs(fo.torque)))
    return {"omega": sp.speed, "contact_min": float(fo.contact[k]), "contact_min_at_deg": _deg(g.phi[k]),
            "contact_max": float(fo.contact.max()), "torque_max": float(fo.torque[j]),
            "torque_max_at_deg": _deg(g.phi[j]), "lift_off": bool(np.any(fo.lift_off))}


def text(d, system: str = "si") -> str:
    """A human summary of the design (what the JSON holds, in words), lengths in metres or, with
    `system` "model", in the cam's length unit."""
    doc = shown(document(d), d.spec, system)
    u = doc["units"]["length"]
    f = doc["follower"]
    lines = [f"cam {doc['cam']}" + (f" — {doc['title']}" if doc["title"] else "")]
    if doc["timing"]["events"]:
        lines.append("timing from " + str(doc["model"]) + ":")
        for name, ev in doc["timing"]["events"].items():
            roots = ", ".join(f"{r['value']:.6g} ({r['direction']})" for r in ev["roots"])
            lines.append(f"  {name} = {ev['value']:.6g}" + (f"   roots: {roots}" if roots else ""))
        if doc["timing"]["start"] is not None:
            lines.append(f"  cam angle 0 at input {doc['timing']['start']:.6g}")
    lines.append("phases:")
    for p in doc["phases"]:
        coeff = ", ".join(f"{k} {_num(p[k])}" for k in ("C_v", "C_a", "C_j"))
        lines.append(f"  {p['kind']:<10} {p['angle_deg']:8.4f}° from {p['start_deg']:8.4f}°  {p['law']:<22}"
                     f" stroke {p['stroke']:.6g} {u}; {coeff}; v_max {_num(p['v_max'])} {u}/rad,"
                     f" a_max {_num(p['a_max'])} {u}/rad²")
    size = "found by sizing" if doc["sized"] else "given"
    if f["motion"] == "oscillating":
        lines.append(f"follower: oscillating {f['contact']}, l = {f['arm']:.6g} {u}, a_w = "
                     f"{f['centre_distance']:.6g} {u}, φ20 = {f['arm_angle_deg']:.6g}° ({size}); r0 = "
                     f"{f['prime_radius']:.6g} {u}")
    else:
        lines.append(f"follower: translating {f['contact']}, base radius {f['base_radius']:.6g} {u}, offset "
                     f"{f['offset']:.6g} {u} ({size})")
    if f["contact"] == "roller":
        lines.append(f"  roller r = {f['roller']:.6g} {u}")
    for name in ("rise", "return"):
        p = doc["pressure_angle"][name]
        if p:
            lines.append(f"pressure angle on the {name}: {p['extreme_deg']:+.4f}° at {p['at_deg']:.4g}° "
                         f"(limit {p['limit_deg']:.4g}°)")
    c = doc["curvature"]
    lines.append(f"ρ_min = {_num(c['rho_min'])} {u} at {_num(c['at_deg'])}°; profile's smallest radius "
                 f"{_num(c['profile_rho_min'])} {u}" + (f"; ρ_min/r = {c['rho_min_over_roller']:.4g}, largest safe "
                                                      f"roller {_num(c['largest_safe_roller'])} {u}"
                                                      if c["rho_min_over_roller"] else ""))
    if "face" in doc and doc["face"]:
        lines.append(f"face: contact from {doc['face']['contact_min']:.6g} to {doc['face']['contact_max']:.6g} {u}"
                     f" (width ≥ {doc['face']['width']:.6g} {u})")
    sc = doc["self_check"]
    lines.append(f"self-check: follower run on the profile at {sc['angles']} angles departs from the law by "
                 f"{sc['error']:.3g} {u} = {sc['relative']:.3g} of the stroke")
    if doc["dynamics"]:
        dy = doc["dynamics"]
        lines.append(f"forces at ω = {dy['omega']:.6g} rad/s: contact {dy['contact_min']:.6g} … "
                     f"{dy['contact_max']:.6g} N, largest torque {dy['torque_max']:.6g} N·m"
                     + (" — LIFT-OFF" if dy["lift_off"] else ""))
    for w in doc["warnings"]:
        lines.append(f"warning: {w}")
    return "\n".join(lines)


def shown(doc: dict, spec, system: str = "si") -> dict:
    """The JSON document in metres (`system` "si") or in the cam's length unit ("model"), with its
    ``"units"`` object: the lengths of the follower, the phases' strokes and peaks (per rad, rad², rad³),
    the curvature radii, the face's width, the self-check's error, continuity jumps."""
    unit = spec.length_unit if system == "model" else "m"
    k = LENGTH_UNITS[unit]

    def scale(node, keys):
        for key in keys:
            if node is not None and node.get(key) is not None:
                node[key] = node[key] / k
    scale(doc["follower"], ("prime_radius", "roller", "base_radius", "offset", "centre_distance", "arm",
                            "face_offset"))
    for p in doc["phases"]:
        scale(p, ("stroke", "v_max", "a_max", "j_max"))
    scale(doc, ("stroke", "v_max", "a_max"))
    scale(doc["curvature"], ("rho_min", "profile_rho_min", "largest_safe_roller"))
    scale(doc.get("face"), ("contact_min", "contact_max", "width"))
    scale(doc["self_check"], ("error", "interference"))
    for jump in doc["continuity"]:
        scale(jump, ("jump",))
    for event in doc["timing"]["events"].values():
        if event.get("stroke") is not None:
            event["stroke"] = event["stroke"] / k
    doc["units"] = {"system": system, "length": unit, "velocity": f"{unit}/rad", "acceleration": f"{unit}/rad^2",
                    "jerk": f"{unit}/rad^3", "force": "N", "moment": "N*m", "angle": "deg"}
    return doc


def _num(x):
    return "∞" if x is None else f"{x:.6g}"


def _plain(obj):
    if isinstance(obj, dict):
        return {k: _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, (np.floating, float)):
        return float(obj) if math.isfinite(obj) else None
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


def run_command(args) -> int:
    """`mbplanar cam FILE [--json] [--size] [-o CSV] [--dxf F] [--svg F] [--plot WHAT -O PNG]`."""
    from dataclasses import replace

    from .design import design
    from .spec import read_cam
    if getattr(args, "plot", None) and not args.plot_output:
        raise ModelError("--plot needs --plot-output FILE (.png, .svg, .pdf, or .gif for 'animation')")
    spec = read_cam(args.file)
    if args.size:
        spec = replace(spec, size=True)
    d = design(spec)
    from . import export
    if args.output:
        export.write_csv(d.geometry, args.output)
    if args.dxf:
        export.write_dxf(d.geometry, args.dxf)
    if args.svg:
        export.write_svg(d.geometry, args.svg, spec.title or "cam")
    if getattr(args, "plot", None):
        from .plots import save_figure
        save_figure(d, args.plot, args.plot_output, at=args.at)
    if args.json:
        print(json.dumps(_plain(shown(document(d), spec, args.units)), indent=2, ensure_ascii=False))
    else:
        print(text(d, args.units))
    return 0


def add_arguments(parser) -> None:
    """The `mbplanar cam` options (the CLI registers the subcommand and calls `run_command`)."""
    parser.add_argument("file", help="a cam file (its [cam] names a model) or a model with a [cam] section")
    parser.add_argument("--json", action="store_true")
    parser.add_argument("--size", action="store_true", help="find the smallest cam for the pressure limits")
    parser.add_argument("-o", "--output", help="CSV of the pitch and working profiles (mm)")
    parser.add_argument("--dxf", help="DXF of the profile (closed splines, mm; needs ezdxf)")
    parser.add_argument("--svg", help="SVG of the profile (mm)")
    parser.add_argument("--plot", choices=("motion", "pressure", "cam", "construction", "animation"),
                        help="a picture: S/V/A/J diagrams, pressure angle, the cam with its follower, the "
                             "seed's sizing construction, or an animation (GIF)")
    parser.add_argument("--plot-output", help="file for --plot")
    parser.add_argument("--at", type=float, default=0.0, help="cam angle (deg) of the 'cam' picture")
    add_units_option(parser, "the lengths shown (model: the [cam]'s or the model's length_unit)")


def report_section(engine, ctx):
    """The report's cam section: present when the model has a `[cam]` section."""
    if "cam" not in getattr(engine.mech, "extras", {}):
        return None
    import html

    from .design import design
    from dataclasses import replace

    from .plots import cam_figure, motion_figure, pressure_figure
    from .spec import parse_cam
    spec = replace(parse_cam({"cam": engine.mech.extras["cam"]}, source=engine.mech.source),
                   linkage=engine, model=None)
    d = design(spec)
    body = "<pre>" + html.escape(text(d)) + "</pre>"
    return (body + ctx.figure(motion_figure(d), "cam motion diagrams")
            + ctx.figure(pressure_figure(d), "pressure angle") + ctx.figure(cam_figure(d), "cam profile"))


def register() -> None:
    """Add the cam section to `mbplanar report` (after the flywheel)."""
    from ..viz import register_section
    register_section("cam", "Cam", report_section, after="flywheel")
