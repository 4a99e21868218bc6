"""`mbplanar gear pair ...` and `mbplanar gear planetary ...`: options, the JSON documents (a contract,
docs/gears.md), the text summaries, the exports and pictures. The CLI only registers the command and
calls `add_arguments` and `run`."""

from __future__ import annotations

import json
import math

from ..errors import ModelError

__all__ = ["add_arguments", "run", "pair_document", "planetary_document", "pair_text", "planetary_text",
           "design_pair", "search_trains"]


# -- arguments --------------------------------------------------------------------------------------
def _pair_of(text, option, kind=float):
    parts = [p.strip() for p in str(text).split(",")]
    if len(parts) != 2:
        raise ModelError(f"{option} needs two comma-separated values, got {text!r}")
    out = []
    for p in parts:
        try:
            v = kind(p)
        except ModelError:
            raise
        except ValueError:
            raise ModelError(f"{option}: {p!r} is not a {'whole number' if kind is int else 'number'}") from None
        if kind is float and not math.isfinite(v):
            raise ModelError(f"{option}: {p!r} is not finite")
        out.append(v)
    return tuple(out)


def add_arguments(parser) -> None:
    """The `gear` sub-commands and their options."""
    sub = parser.add_subparsers(dest="problem", required=True)
    s = sub.add_parser("pair", help="a spur pair with profile shift: geometry, checks, block contour, shifts "
                                    "chosen by a criterion, tooth profiles (DXF, SVG, CSV)")
    s.add_argument("file", nargs="?", help="a TOML file with a [gears.pair] section (its values are the defaults)")
    s.add_argument("--module", type=float, help="module m, mm")
    s.add_argument("--teeth", help="z1,z2 (gear 2 the ring with --internal)")
    s.add_argument("--internal", action="store_true", default=None, help="gear 2 has internal teeth")
    s.add_argument("--shift", help="'auto' (chosen by --criterion) or x1,x2 (default auto)")
    s.add_argument("--criterion", choices=("balanced", "contact", "sum"),
                   help="how 'auto' chooses: balanced specific sliding (least, on the balanced curve), largest "
                        "contact ratio, or a given sum split to balance the sliding (default balanced)")
    s.add_argument("--shift-sum", type=float, help="x1 + x2 (internal: x2 − x1) to hold")
    s.add_argument("--centre-distance", type=float, help="a fixed working centre distance a_w, mm (fixes x_Σ)")
    s.add_argument("--pressure-angle", type=float, help="α of the basic rack, degrees (default 20)")
    s.add_argument("--addendum", type=float, help="h_a* (default 1)")
    s.add_argument("--clearance", type=float, help="c* (default 0.25)")
    s.add_argument("--tip-radius", type=float, help="ρ_f* of the tool's tip round (default c*/(1 − sin α))")
    s.add_argument("--min-tip", type=float, help="smallest tip thickness s_a, in modules (default 0.25)")
    s.add_argument("--min-contact", type=float, help="smallest contact ratio ε_α (default 1.2)")
    s.add_argument("--ring-tip", choices=("standard", "cut"),
                   help="internal pairs: the ring's tip circle as the formula gives it, or cut back so that it "
                        "meets the pinion on its involute (default standard)")
    s.add_argument("--force", action="store_true",
                   help="print the geometry even when given shifts fail a check (exit 0)")
    s.add_argument("--json", action="store_true")
    s.add_argument("-o", "--output", help="CSV of both tooth outlines (mm, each gear in its own frame)")
    s.add_argument("--dxf", help="DXF of both gears in mesh (mm; needs ezdxf)")
    s.add_argument("--svg", help="SVG of both gears in mesh (mm)")
    s.add_argument("--plot", choices=("contour", "mesh", "gear1", "gear2", "sliding"),
                   help="a picture: the block contour, the meshing pair with its line of action, one gear, "
                        "the specific sliding along the path of contact")
    s.add_argument("--plot-output", help="file for --plot (.png, .svg, .pdf)")
    p = sub.add_parser("planetary", help="planetary (2K-H) trains by tooth numbers for a ratio: admissible sets "
                                         "ranked by size, the chosen one written as a model with gear joints")
    p.add_argument("file", nargs="?", help="a TOML file with a [gears.planetary] section (its values are the "
                                           "defaults; with stage = true its [gears.pair] follows the train)")
    p.add_argument("--ratio", type=float, help="input speed / output speed (with --stage: of the whole drive)")
    p.add_argument("--scheme", choices=("A", "B", "C", "D", "all"),
                   help="A single row; B two rows, external + internal; C two external meshes; D two internal "
                        "meshes (default all)")
    p.add_argument("--planets", type=int, help="k, equally spaced (default 3)")
    p.add_argument("--tolerance", type=float, help="relative tolerance of the ratio (default 0.01)")
    p.add_argument("--module", type=float, help="module of the train, mm (default 1)")
    p.add_argument("--min-teeth", type=int, help="smallest tooth number of an external gear (default: the "
                                                 "smallest without undercut, 18)")
    p.add_argument("--max-teeth", type=int, help="largest tooth number of any gear (default 150)")
    p.add_argument("--limit", type=int, default=10, help="trains listed (default 10; the CSV has them all)")
    p.add_argument("--choose", type=int, help="the listed train written and drawn (1 = the smallest; default 1)")
    p.add_argument("--stage", help="z1,z2: a pair on fixed axes after the train's output (--ratio is then the "
                                   "whole drive's); designed as `gear pair --shift auto` does")
    p.add_argument("--stage-module", type=float, help="module of the stage, mm")
    p.add_argument("--rpm", type=float, help="input speed for the model's [input], rev/min")
    p.add_argument("--json", action="store_true")
    p.add_argument("-o", "--output", help="the chosen train as a model (TOML with gear joints)")
    p.add_argument("--csv", help="every admissible train as a CSV table")
    p.add_argument("--plot", choices=("velocity",), help="the train's scheme and velocity diagram")
    p.add_argument("--plot-output", help="file for --plot (.png, .svg, .pdf)")


# -- the pair ---------------------------------------------------------------------------------------
def _pair_settings(args):
    """The pair's settings: the file's [gears.pair] overridden by the options (SI)."""
    from .spec import PairSpec, read_gears
    base = None
    if args.file:
        spec = read_gears(args.file)
        if spec.pair is None:
            raise ModelError("no [gears.pair] section", source=args.file)
        base = spec.pair
    if base is None and (args.module is None or args.teeth is None):
        raise ModelError("gear pair needs --module and --teeth (or a file with a [gears.pair] section)")
    s = base if base is not None else PairSpec(module=_mm(args.module, "--module"),
                                              teeth=_pair_of(args.teeth, "--teeth", _teeth))
    from dataclasses import replace
    changes = {}
    if base is not None and args.module is not None:
        changes["module"] = _mm(args.module, "--module")
    if base is not None and args.teeth is not None:
        changes["teeth"] = _pair_of(args.teeth, "--teeth", _teeth)
    if args.internal:
        changes["internal"] = True
    if args.shift is not None:
        changes["shifts"] = "auto" if args.shift.strip() == "auto" else _pair_of(args.shift, "--shift")
    for key in ("criterion", "shift_sum", "pressure_angle", "addendum", "clearance", "tip_radius", "min_tip",
                "min_contact", "ring_tip"):
        value = getattr(args, key)
        if value is not None:
            changes[key] = value
    if args.centre_distance is not None:
        changes["centre_distance"] = _mm(args.centre_distance, "--centre-distance")
    return replace(s, **changes)


def _teeth(text):
    try:
        v = float(text)
    except ValueError:
        raise ModelError(f"--teeth: {text!r} is not a whole number") from None
    if not math.isfinite(v) or v != int(v):
        raise ModelError(f"--teeth: tooth numbers are whole numbers, got {text!r}")
    return int(v)


def _mm(value, option):
    if value is None:
        return None
    if not math.isfinite(value) or value <= 0:
        raise ModelError(f"{option} must be > 0 (mm), got {value:g}")
    return value * 1e-3


def _rack(s):
    from .rack import Rack
    return Rack(math.radians(s.pressure_angle), s.addendum, s.clearance, s.tip_radius)


def design_pair(s):
    """(pair, choice or None, contour) for a `PairSpec`: the shifts given, or chosen by its criterion."""
    from .pair import gear_pair, validate_module, validate_teeth
    from .shifts import block_contour, choose_shifts
    validate_module(s.module, "--module")
    validate_teeth(*s.teeth, internal=s.internal, where="--teeth")
    rack = _rack(s)
    common = dict(internal=s.internal, rack=rack, min_tip=s.min_tip, min_contact=s.min_contact)
    if s.ring_tip not in ("standard", "cut"):
        raise ModelError(f"--ring-tip must be 'standard' or 'cut', got {s.ring_tip!r}")
    if s.shifts == "auto":
        choice = choose_shifts(s.module, s.teeth, s.criterion, centre_distance=s.centre_distance,
                               shift_sum=s.shift_sum, ring_tip=s.ring_tip, **common)
        return choice.pair, choice, choice.contour
    pair = gear_pair(s.module, s.teeth, s.shifts, ring_tip=s.ring_tip, **common)
    if s.centre_distance is not None and abs(pair.centre_distance - s.centre_distance) > 1e-9 * s.module:
        raise ModelError(f"--shift {pair.shifts[0]:g},{pair.shifts[1]:g} gives a_w = {pair.centre_distance * 1e3:.6g} mm, "
                         f"not the --centre-distance {s.centre_distance * 1e3:g} mm")
    shift_sum = (pair.shifts[1] - pair.shifts[0]) if s.internal else sum(pair.shifts)
    contour = block_contour(s.module, s.teeth, shift_sum=shift_sum if s.centre_distance is not None else None,
                            ring_tip=s.ring_tip, **common)
    return pair, None, contour


def _f(x):
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def pair_document(pair, choice=None, contour=None, profiles=()) -> dict:
    """The JSON document of a pair (SI: metres; angles in degrees where a key says `_deg`)."""
    r = pair.rack
    shift_sum = (pair.shifts[1] - pair.shifts[0]) if pair.internal else sum(pair.shifts)
    gears = []
    for g in pair.gears:
        gears.append({"teeth": g.teeth, "shift": g.shift, "internal": g.internal,
                      "pitch_diameter": g.pitch_diameter, "base_diameter": g.base_diameter,
                      "working_diameter": g.working_diameter, "tip_diameter": g.tip_diameter,
                      "root_diameter": g.root_diameter, "pitch_thickness": g.pitch_thickness,
                      "tip_thickness": _f(g.tip_thickness), "tip_pressure_angle_deg": _f(math.degrees(g.tip_pressure_angle)),
                      "min_shift": _f(g.min_shift), "form_diameter": _f(2 * g.form_radius) if g.form_radius else None,
                      "active_diameter": _f(g.active_diameter),
                      "sliding": {"root": _f(g.root_sliding), "tip": _f(g.tip_sliding)}})
    doc = {"module": pair.module, "teeth": [g.teeth for g in pair.gears], "internal": pair.internal,
           "ring_tip": pair.ring_tip if pair.internal else None,
           "rack": {"pressure_angle_deg": math.degrees(r.pressure_angle), "addendum": r.addendum,
                    "clearance": r.clearance, "tip_radius": r.tip_radius},
           "shifts": list(pair.shifts), "shift_sum": shift_sum,
           "working_pressure_angle_deg": pair.working_pressure_angle_deg,
           "inv_working_pressure_angle": pair.inv_working,
           "reference_centre_distance": pair.reference_centre_distance, "centre_distance": pair.centre_distance,
           "centre_factor": pair.centre_factor, "tip_reduction": pair.tip_reduction, "ratio": pair.ratio,
           "base_pitch": pair.base_pitch, "line_of_action": pair.line_of_action,
           "path": {"A": pair.path[0], "E": pair.path[1], "length": pair.path_length},
           "contact_ratio": pair.contact_ratio, "gears": gears,
           "checks": [{"name": c.name, "gear": c.gear, "value": _f(c.value), "limit": _f(c.limit),
                       "margin": _f(c.margin), "ok": c.ok, "message": c.message} for c in pair.checks],
           "success": pair.success, "message": pair.message, "choice": None, "contour": None, "profiles": []}
    if choice is not None:
        doc["choice"] = {"criterion": choice.criterion, "shift_sum": choice.shift_sum, "message": choice.message}
    if contour is not None:
        doc["contour"] = {"x1": [float(contour.x1[0]), float(contour.x1[-1])],
                          "x2": [float(contour.x2[0]), float(contour.x2[-1])],
                          "grid": [int(contour.x1.size), int(contour.x2.size)], "area": contour.area,
                          "admissible_fraction": float(contour.admissible.mean())}
    for k, prof in enumerate(profiles, 1):
        ch = prof.check
        doc["profiles"].append({"gear": k, "undercut": prof.undercut, "pointed": prof.pointed,
                                "form_diameter": 2 * prof.form_radius, "points": int(prof.outline.shape[0]),
                                "check": {"involute_error": ch.involute_error, "thickness_error": ch.thickness_error,
                                          "undercut_agrees": ch.undercut_agrees, "tolerance": ch.tolerance,
                                          "success": ch.success}})
    return doc


def pair_text(pair, choice=None, profiles=()) -> str:
    """A human summary of a pair (lengths in mm)."""
    mm = lambda v: "—" if v is None or not math.isfinite(v) else f"{v * 1e3:.4f}"   # noqa: E731
    z1, z2 = (g.teeth for g in pair.gears)
    r = pair.rack
    lines = [f"gear pair m = {pair.module * 1e3:g} mm, z = {z1}, {z2}" + (" (internal)" if pair.internal else "")
             + f"; rack α = {math.degrees(r.pressure_angle):g}°, h_a* = {r.addendum:g}, c* = {r.clearance:g}, "
             f"ρ_f* = {r.tip_radius:.5g}"]
    if choice is not None:
        lines.append(f"shifts chosen ({choice.criterion}): {choice.message}")
    lines.append(f"x1 = {pair.shifts[0]:.6f}, x2 = {pair.shifts[1]:.6f}; inv α_w = {pair.inv_working:.9f}, "
                 f"α_w = {pair.working_pressure_angle_deg:.6f}°")
    lines.append(f"a = {mm(pair.reference_centre_distance)} mm, a_w = {mm(pair.centre_distance)} mm, "
                 f"y = {pair.centre_factor:.6f}, Δy = {pair.tip_reduction:.6f}")
    rows = [("", "gear 1", "gear 2")]
    g1, g2 = pair.gears
    for label, f in (("d  (pitch)", lambda g: mm(g.pitch_diameter)), ("d_b (base)", lambda g: mm(g.base_diameter)),
                     ("d_w (working)", lambda g: mm(g.working_diameter)), ("d_a (tip)", lambda g: mm(g.tip_diameter)),
                     ("d_f (root)", lambda g: mm(g.root_diameter)), ("s (pitch)", lambda g: mm(g.pitch_thickness)),
                     ("s_a (tip)", lambda g: mm(g.tip_thickness)),
                     ("x_min", lambda g: "—" if g.min_shift is None else f"{g.min_shift:.4f}"),
                     ("d_l (involute from)", lambda g: mm(2 * g.form_radius) if g.form_radius else "—"),
                     ("active from d", lambda g: mm(g.active_diameter)),
                     ("ζ at root / tip", lambda g: f"{g.root_sliding:.4f} / {g.tip_sliding:.4f}")):
        rows.append((label, f(g1), f(g2)))
    width = max(len(a) for a, _, _ in rows)
    for a, b, c in rows:
        lines.append(f"  {a:<{width}}  {b:>18}  {c:>18}")
    lines.append(f"path of contact g_α = {mm(pair.path_length)} mm, p_b = {mm(pair.base_pitch)} mm, "
                 f"ε_α = {pair.contact_ratio:.6f}")
    lines.append("checks:")
    for c in pair.checks:
        who = f" {c.gear}" if c.gear else ""
        lines.append(f"  {'ok  ' if c.ok else 'FAIL'} {c.name}{who}: margin {c.margin:.4g}"
                     + (f" — {c.message}" if c.message else ""))
    for k, prof in enumerate(profiles, 1):
        ch = prof.check
        inv_err = "drawn from the formula" if ch.involute_error is None else f"{ch.involute_error:.2g} m"
        lines.append(f"profile {k}: {prof.outline.shape[0]} points" + (", undercut" if prof.undercut else "")
                     + (", pointed" if prof.pointed else "") + f"; self-check: involute {inv_err}, thickness at "
                     f"the pitch circle {ch.thickness_error:.2g} m (tolerance {ch.tolerance:.2g} m) — "
                     + ("passed" if ch.success else "FAILED"))
    return "\n".join(lines)


def _run_pair(args) -> int:
    from . import export, plots
    from .profile import gear_profile
    if args.plot and not args.plot_output:
        raise ModelError("--plot needs --plot-output FILE (.png, .svg or .pdf)")
    s = _pair_settings(args)
    pair, choice, contour = design_pair(s)
    if not pair.success and choice is None and not args.force:
        raise ModelError(f"--shift {pair.shifts[0]:g},{pair.shifts[1]:g} lies outside the block contour of "
                         f"z = {pair.gears[0].teeth}, {pair.gears[1].teeth}: {pair.message} (--force prints the "
                         f"geometry anyway)")
    if choice is not None and not choice.success:
        raise ModelError(f"no admissible shifts for z = {pair.gears[0].teeth}, {pair.gears[1].teeth}: {choice.message}")
    profiles = (gear_profile(pair, 1), gear_profile(pair, 2))
    if args.output:
        export.write_csv(profiles, args.output)
    if args.dxf:
        export.write_dxf(pair, profiles, args.dxf)
    if args.svg:
        export.write_svg(pair, profiles, args.svg,
                         f"gear pair z = {pair.gears[0].teeth}, {pair.gears[1].teeth}, m = {pair.module * 1e3:g} mm")
    if args.plot:
        figure = {"contour": lambda: plots.contour_figure(contour, pair.shifts),
                  "mesh": lambda: plots.mesh_figure(pair, profiles),
                  "gear1": lambda: plots.gear_figure(pair, profiles[0], 1),
                  "gear2": lambda: plots.gear_figure(pair, profiles[1], 2),
                  "sliding": lambda: plots.sliding_figure(pair)}[args.plot]
        plots.save_figure(figure(), args.plot_output)
    if args.json:
        print(json.dumps(pair_document(pair, choice, contour, profiles), indent=2, ensure_ascii=False))
    else:
        print(pair_text(pair, choice, profiles))
    return 0


# -- planetary --------------------------------------------------------------------------------------
def _planetary_settings(args):
    from dataclasses import replace

    from .spec import PlanetarySpec, read_gears
    spec = read_gears(args.file) if args.file else None
    base = spec.planetary if spec is not None else None
    if args.file and base is None:
        raise ModelError("no [gears.planetary] section", source=args.file)
    if base is None and args.ratio is None:
        raise ModelError("gear planetary needs --ratio (or a file with a [gears.planetary] section)")
    s = base if base is not None else PlanetarySpec(ratio=args.ratio)
    changes = {}
    if args.ratio is not None:
        changes["ratio"] = args.ratio
    if args.scheme is not None:
        changes["scheme"] = None if args.scheme == "all" else args.scheme
    for key in ("planets", "tolerance", "min_teeth", "max_teeth", "choose"):
        value = getattr(args, key)
        if value is not None:
            changes[key] = value
    if args.module is not None:
        changes["module"] = _mm(args.module, "--module")
    s = replace(s, **changes)
    stage = None
    if args.stage is not None:
        teeth = _pair_of(args.stage, "--stage", _teeth)
        if args.stage_module is None:
            raise ModelError("--stage needs --stage-module (mm)")
        from .spec import PairSpec
        stage = PairSpec(module=_mm(args.stage_module, "--stage-module"), teeth=teeth)
    elif s.stage:
        if spec is None or spec.pair is None:
            raise ModelError("[gears.planetary] stage = true needs a [gears.pair] section", source=args.file)
        stage = spec.pair
    return s, stage


def search_trains(s, stage_pair=None):
    """The `PlanetarySearch` of a `PlanetarySpec`; with a stage (a designed `GearPair` after the train's
    output) the train is searched for ratio / (z₂/z₁)."""
    from .planetary import planetary_trains
    target = s.ratio
    if stage_pair is not None:
        target = s.ratio / stage_pair.ratio
    return planetary_trains(target, s.scheme, planets=s.planets, tolerance=s.tolerance, module=s.module,
                            min_teeth=s.min_teeth, max_teeth=s.max_teeth)


def _train_doc(t) -> dict:
    return {"scheme": t.scheme, "teeth": list(t.teeth), "planets": t.planets, "ratio": t.ratio, "error": t.error,
            "willis": t.willis, "module": t.module, "centre_distance": t.centre_distance, "diameter": t.diameter,
            "neighbour_gap": t.neighbour_gap}


def planetary_document(search, chosen=None, stage_pair=None, model=None, limit=None) -> dict:
    """The JSON document of a search (SI)."""
    from .planetary import train_speeds
    trains = search.trains if limit is None else search.trains[:limit]
    doc = {"ratio": search.target, "schemes": list(search.schemes), "planets": search.planets,
           "tolerance": search.tolerance, "teeth_range": list(search.teeth_range), "count": len(search.trains),
           "trains": [_train_doc(t) for t in trains], "rejected": dict(search.rejected),
           "success": search.success, "message": search.message, "chosen": None}
    if chosen is not None:
        c = _train_doc(chosen)
        c["speeds"] = train_speeds(chosen)
        c["stage"] = None
        total = chosen.ratio
        if stage_pair is not None:
            total = chosen.ratio * -stage_pair.ratio
            c["stage"] = {"teeth": [g.teeth for g in stage_pair.gears], "shifts": list(stage_pair.shifts),
                          "module": stage_pair.module, "centre_distance": stage_pair.centre_distance,
                          "ratio": -stage_pair.ratio}
        c["total_ratio"] = total
        c["model"] = model
        doc["chosen"] = c
    return doc


def planetary_text(search, chosen=None, stage_pair=None, model=None, limit=10) -> str:
    """A human summary: the best trains as a table, the chosen one."""
    m = search.trains[0].module if search.trains else None
    lines = [f"planetary trains for ratio {search.target:.6g} ± {search.tolerance:g}, k = {search.planets}, "
             f"{search.teeth_range[0]} ≤ z ≤ {search.teeth_range[1]}, schemes {', '.join(search.schemes)}: "
             f"{len(search.trains)} admissible"]
    if stage_pair is not None:
        lines.append(f"  (the whole drive's {search.target * stage_pair.ratio:.6g} over the pair's {stage_pair.ratio:.6g} "
                     f"after the train)")
    rej = ", ".join(f"{k} {v}" for k, v in search.rejected.items() if v)
    if rej:
        lines.append(f"  (sets with the ratio rejected by: {rej})")
    if m:
        lines.append(f"  #  scheme  teeth               ratio       error      diameter [mm]  a_w [mm]  (m = {m * 1e3:g} mm)")
    for n, t in enumerate(search.trains[:limit], 1):
        teeth = ", ".join(str(z) for z in t.teeth)
        lines.append(f"{n:>3}  {t.scheme:<6}  {teeth:<18}  {t.ratio:<10.6g}  {t.error:+.3e}  {t.diameter * 1e3:>13.4f}"
                     f"  {t.centre_distance * 1e3:>8.4f}")
    if chosen is not None:
        from .planetary import SCHEMES, train_speeds
        w = train_speeds(chosen)
        lines.append(f"chosen: scheme {chosen.scheme} ({SCHEMES[chosen.scheme].title}), z = "
                     + ", ".join(str(z) for z in chosen.teeth) + f", ratio {chosen.ratio:.9g}, Willis u^H = "
                     f"{chosen.willis:.9g}")
        lines.append("  speeds for ω_in = 1: " + ", ".join(f"{k} {v:.6g}" for k, v in w.items()))
        if stage_pair is not None:
            z1, z2 = (g.teeth for g in stage_pair.gears)
            lines.append(f"  then the pair z = {z1}, {z2} (x = {stage_pair.shifts[0]:.4f}, {stage_pair.shifts[1]:.4f}, "
                         f"a_w = {stage_pair.centre_distance * 1e3:.4f} mm): whole ratio "
                         f"{chosen.ratio * -stage_pair.ratio:.9g}")
        if model:
            lines.append(f"  model written to {model}")
    return "\n".join(lines)


def _write_csv(search, path):
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("rank,scheme,z1,z2,z3,z4,planets,ratio,error,willis,diameter[mm],centre_distance[mm],"
                 "neighbour_gap[mm]\n")
        for n, t in enumerate(search.trains, 1):
            z = list(t.teeth) + [""] * (4 - len(t.teeth))
            fh.write(f"{n},{t.scheme},{z[0]},{z[1]},{z[2]},{z[3]},{t.planets},{t.ratio:.12g},{t.error:.6g},"
                     f"{t.willis:.12g},{t.diameter * 1e3:.9g},{t.centre_distance * 1e3:.9g},"
                     f"{t.neighbour_gap * 1e3:.9g}\n")


def _run_planetary(args) -> int:
    from .trainmodel import Stage, write_train_model
    if args.plot and not args.plot_output:
        raise ModelError("--plot needs --plot-output FILE (.png, .svg or .pdf)")
    if args.limit is not None and args.limit < 0:
        raise ModelError(f"--limit must be ≥ 0, got {args.limit}")
    s, stage_spec = _planetary_settings(args)
    stage_pair = None
    if stage_spec is not None:
        stage_pair, _, _ = design_pair(stage_spec)
        if stage_pair.internal:
            raise ModelError("the stage after the train must be an external pair")
    search = search_trains(s, stage_pair)
    if not search.success:
        raise ModelError(search.message)
    if not 1 <= s.choose <= len(search.trains):
        raise ModelError(f"--choose {s.choose}: there are {len(search.trains)} admissible trains")
    chosen = search.trains[s.choose - 1]
    if args.csv:
        _write_csv(search, args.csv)
    if args.output:
        omega = None if args.rpm is None else args.rpm * 2 * math.pi / 60
        write_train_model(chosen, args.output, omega=omega,
                          stage=None if stage_pair is None else Stage.from_pair(stage_pair))
    if args.plot:
        from . import plots
        plots.save_figure(plots.velocity_figure(chosen), args.plot_output)
    if args.json:
        print(json.dumps(planetary_document(search, chosen, stage_pair, args.output, args.limit), indent=2,
                         ensure_ascii=False))
    else:
        print(planetary_text(search, chosen, stage_pair, args.output, args.limit))
    return 0


def run(args) -> int:
    """Run `mbplanar gear pair|planetary`."""
    return {"pair": _run_pair, "planetary": _run_planetary}[args.problem](args)
