"""A whole cam design from a `CamSpec`: timing, program, follower (given or sized), exact geometry,
self-check, forces and the warnings a designer must read."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import ModelError, did_you_mean
from . import laws
from .dynamics import CamForces, cam_forces
from .followers import Follower
from .geometry import CamGeometry, cam_geometry
from .selfcheck import SelfCheck, self_check
from .sizing import Sizing, size_follower
from .spec import CamSpec, evaluate
from .timing import EventResult, solve_event

__all__ = ["CamDesign", "Extreme", "design", "pressure_extremes", "smallest_radius", "SELF_CHECK_TOLERANCE"]

SELF_CHECK_TOLERANCE = 1e-6        # of the stroke


@dataclass(frozen=True)
class Extreme:
    """The pressure angle of largest magnitude on one stroke (rad), where, and the limit."""

    value: float
    at: float
    limit: float

    @property
    def exceeded(self) -> bool:
        return abs(self.value) > self.limit * (1 + 1e-9)


@dataclass(frozen=True)
class CamDesign:
    """Everything `design` found for a cam.

    Attributes
    ----------
    spec : CamSpec
        What was asked.
    program : Program
        The motion program (lift s(φ), m, over one turn).
    follower : Follower
        The follower, given or sized (SI).
    geometry : CamGeometry
        Pitch curve, profile, pressure angle and curvature at `spec.samples` cam angles.
    check : SelfCheck
        The follower run on the profile: its lift against the program's (`relative`: error / stroke).
    rise, ret : Extreme or None
        The pressure angle's extreme on the rise and on the return (`value`, `at` cam angle, `limit`;
        rad).
    events : dict
        The events found on the linkage, {name: input value}.
    start : float
        The linkage's input value at cam angle 0.
    window : tuple
        The input range the rise must fit in, when given.
    rho_min, rho_min_at : float
        The profile's smallest radius of curvature (m) and its cam angle (rad).
    sizing : Sizing or None
        How the follower was sized, when asked (`size = true`).
    forces : CamForces or None
        Spring, inertia, contact force and torque, with `[cam.dynamics]`.
    warnings : tuple of str
        Undercut, pressure limits exceeded, jumps of the program.
    timed : bool
        Whether the events were timed on a linkage.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.cam import design, parse_cam
    >>> cam = {"follower": "translating", "contact": "knife", "base_radius": 0.04,
    ...        "phases": [{"kind": "rise", "angle": 180.0, "law": "simple_harmonic", "stroke": 0.02},
    ...                   {"kind": "return", "angle": 180.0, "law": "simple_harmonic"}]}
    >>> d = design(parse_cam({"cam": cam}))
    >>> round(float(np.degrees(d.rise.value)), 4), round(float(np.degrees(d.ret.value)), 4), d.warnings
    (11.537, -11.537, ())
    """

    spec: CamSpec
    program: laws.Program
    follower: Follower
    geometry: CamGeometry
    check: SelfCheck
    rise: Extreme | None
    ret: Extreme | None
    events: dict
    start: float
    window: tuple
    rho_min: float = math.inf
    rho_min_at: float = math.nan
    sizing: Sizing | None = None
    forces: CamForces | None = None
    warnings: tuple[str, ...] = field(default=())
    timed: bool = False  # the events were found on a linkage model (`spec.linkage`)


def design(spec: CamSpec) -> CamDesign:
    """Design the cam a spec describes: program, follower (given or sized), geometry, self-check, forces.

    Parameters
    ----------
    spec : CamSpec
        From `read_cam` or `parse_cam`.

    Returns
    -------
    CamDesign
        Timing, program, follower (given or sized), geometry on `spec.samples` angles, self-check,
        pressure-angle extremes, ρ_min, forces (with `[cam.dynamics]`) and warnings.

    Raises
    ------
    ModelError
        Bad phases (sum ≠ 360°, negative stroke, unknown law or name), a follower that cannot exist,
        events the linkage does not reach, or limits no size can meet.

    Examples
    --------
    A simple-harmonic rise of h = 20 mm over β = 180°, knife-edge at r0 = 40 mm: at φ = 90°,
    s = h/2 and ds/dφ = (h/2)(π/β), so the pressure angle is atan(0.01/0.05):

    >>> import numpy as np
    >>> from mbplanar.cam import design, parse_cam
    >>> cam = {"follower": "translating", "contact": "knife", "base_radius": 0.04,
    ...        "phases": [{"kind": "rise", "angle": 180.0, "law": "simple_harmonic", "stroke": 0.02},
    ...                   {"kind": "return", "angle": 180.0, "law": "simple_harmonic"}]}
    >>> d = design(parse_cam({"cam": cam}))
    >>> g = d.geometry
    >>> k = int(np.argmin(abs(g.phi - np.pi / 2)))
    >>> round(float(g.pressure[k]), 9), round(float(np.arctan(0.01 / 0.05)), 9)
    (0.19739556, 0.19739556)
    >>> bool(d.check.relative < 1e-8)                   # the follower run on the profile
    True
    """
    engine = _linkage(spec)
    events = _events(spec, engine)
    names = {k: r.value for k, r in events.items()}
    program = _program(spec, names)
    sizing = None
    follower = _follower(spec, program)
    if spec.size:
        sizing = size_follower(follower, program, math.radians(spec.rise_limit),
                               math.radians(spec.return_limit), free_offset=spec.offset == "free",
                               min_radius=spec.min_radius)
        follower = sizing.follower
    if spec.roller_ratio is not None and follower.contact == "roller":
        follower = follower.with_size(roller=spec.roller_ratio * follower.prime_radius)
    phi = program.grid(spec.samples)
    geometry = cam_geometry(follower, phi, *program.evaluate(phi)[:3])
    check = self_check(geometry, program)
    rise, ret = pressure_extremes(follower, program, phi, math.radians(spec.rise_limit),
                                  math.radians(spec.return_limit))
    forces = cam_forces(geometry, spec.dynamics) if spec.dynamics else None
    start = evaluate(spec.start, names, f"{spec.source}: [cam] start")
    window = tuple(evaluate(w, names, f"{spec.source}: [cam] window") for w in spec.window)
    rho_min, rho_at = smallest_radius(follower, program, geometry)
    out = CamDesign(spec, program, follower, geometry, check, rise, ret, events, start, window, rho_min,
                    rho_at, sizing, forces, timed=engine is not None)
    return CamDesign(**{**out.__dict__, "warnings": tuple(_warnings(out))})


def _linkage(spec):
    if spec.model is None and spec.linkage is None:
        if spec.events:
            raise ModelError(f"{spec.source}: [cam] has events but names no model ('model = ...')")
        return None
    from ..engine import Engine
    from ..model import read_model
    if isinstance(spec.linkage, Engine):
        return spec.linkage
    return Engine(spec.linkage if spec.linkage is not None else read_model(spec.model))


def _events(spec, engine) -> dict[str, EventResult]:
    out = {}
    known = [*engine.mech.joints, *engine.mech.points] if spec.events else []
    for i, ev in enumerate(spec.events):
        if ev.point not in known:
            raise ModelError(f"{spec.source}: [cam] events[{i}] '{ev.name}': '{ev.point}' is neither a joint nor a "
                             f"point of {engine.mech.source}; {did_you_mean(ev.point, known, 'joints and points')}")
        try:
            out[ev.name] = solve_event(engine, ev.name, ev.point, ev.coordinate, ev.fraction, ev.measure,
                                       ev.direction)
        except ModelError as exc:  # (named by the cam file's row)
            raise ModelError(f"{spec.source}: [cam] events[{i}] '{ev.name}': {exc.message}") from None
    return out


def _program(spec: CamSpec, names) -> laws.Program:
    spans = []
    for ph in spec.phases:
        if ph.angle == "rest":
            spans.append(None)
            continue
        deg = evaluate(ph.angle, names, ph.where)
        if not deg > 0:
            raise ModelError(f"{ph.where}: the phase angle must be positive, got {deg:.6g}°")
        spans.append(math.radians(deg))
    if spans.count(None) > 1:
        raise ModelError(f"{spec.source}: [cam] only one phase may take the 'rest' of the turn")
    if None in spans:
        rest = 2 * np.pi - sum(s for s in spans if s is not None)
        if rest <= 0:
            raise ModelError(f"{spec.source}: [cam] the phases leave nothing for 'rest' "
                             f"({math.degrees(2 * np.pi - rest):.6g}° without it)")
        spans[spans.index(None)] = rest
    total = math.degrees(sum(spans))
    if abs(total - 360.0) > 1e-7:
        raise ModelError(f"{spec.source}: [cam] the phases add up to {total:.6g}°, not 360°")
    segments, start, s = [], 0.0, 0.0
    for ph, span in zip(spec.phases, spans):
        if ph.swing is not None:
            if spec.motion != "oscillating" or spec.arm is None:
                raise ModelError(f"{ph.where}: 'swing' is for an oscillating follower with an 'arm'")
            ph = replace(ph, stroke=spec.arm * math.radians(ph.swing))
        if ph.kind == "polynomial":
            if ph.start and abs(ph.start[0] - s) > 1e-12:
                raise ModelError(f"{ph.where}: starts at s = {ph.start[0]:.6g} m, but the previous phase "
                                 f"ends at {s:.6g} m")
            seg = laws.Segment.through(start, span, ph.start, ph.end)
            segments.append(seg)
            s = ph.end[0]
        else:
            try:
                law = laws.dwell() if ph.kind == "dwell" else laws.make_law(
                    ph.law, **({"k": ph.k} if ph.law == "constant_acceleration" else {}))
            except ModelError as exc:
                raise ModelError(f"{ph.where}: {exc.message}") from None
            if ph.kind == "rise":
                if ph.stroke is None:
                    raise ModelError(f"{ph.where}: a rise needs its 'stroke'")
                end = s + ph.stroke
            elif ph.kind == "return":
                end = s - (ph.stroke if ph.stroke is not None else s)
                if end < -1e-12:
                    raise ModelError(f"{ph.where}: the return of {ph.stroke:g} m goes below the base "
                                     f"(the lift is {s:g} m)")
            else:
                end = s
            segments.append(laws.Segment(ph.kind, law, start, span, s, end))
            s = end
        start += span
    if abs(s) > 1e-12:
        raise ModelError(f"{spec.source}: [cam] the program ends at s = {s:.6g} m, not back at 0")
    return laws.Program(tuple(segments))


def _follower(spec: CamSpec, program) -> Follower:
    where = f"{spec.source}: [cam]"
    roller = spec.roller if spec.roller is not None else 0.0
    if spec.contact == "roller" and spec.roller is None and spec.roller_ratio is None:
        raise ModelError(f"{where}: a roller follower needs 'roller' (m) or 'roller_ratio' (of r0)")
    if spec.contact == "roller" and roller == 0.0:
        roller = 1e-3 * program.stroke                   # placeholder until the ratio is applied
    if spec.motion == "translating":
        base = spec.base_radius
        if base is None:
            if not spec.size:
                raise ModelError(f"{where}: give 'base_radius' or set 'size = true'")
            base = 10 * program.stroke
        offset = 0.0 if spec.offset == "free" else spec.offset
        return Follower("translating", spec.contact, spec.rotation, base_radius=base, offset=offset,
                        roller=roller)
    if spec.arm is None:
        raise ModelError(f"{where}: an oscillating follower needs 'arm' (l)")
    a_w, angle = spec.centre_distance, spec.arm_angle
    if a_w is None or angle is None:
        if not spec.size:
            raise ModelError(f"{where}: give 'centre_distance' and 'arm_angle', or set 'size = true'")
        a_w, angle = 2 * spec.arm, 60.0
    return Follower("oscillating", spec.contact, spec.rotation, roller=roller, centre_distance=a_w,
                    arm=spec.arm, arm_angle=math.radians(angle), face_offset=spec.face_offset)


def _refined(phi, values, k, fun, pick):
    """(value, angle) of the best sample `k` of `values` (on the grid `phi`) improved by resampling
    `fun` at 401 angles within one grid step either side; `pick` is np.argmax or np.argmin."""
    step = float(np.max(np.diff(phi)))
    fine = phi[k] + np.linspace(-step, step, 401)
    got = fun(fine)
    j = int(pick(got))
    better = got[j] >= values[k] if pick is np.argmax else got[j] <= values[k]
    value, at = (got[j], fine[j]) if better else (values[k], phi[k])
    return float(value), float(np.mod(at, 2 * np.pi))


def pressure_extremes(follower, program, phi, rise_limit, return_limit):
    """(rise, return) `Extreme`s: the largest |θ| where v > 0 and where v < 0, refined between the grid's
    samples (None when a stroke is absent)."""
    out = []
    s, v, a, _ = program.evaluate(phi)
    theta = cam_geometry(follower, phi, s, v, a).pressure
    for sign, limit in ((1, rise_limit), (-1, return_limit)):
        on = np.sign(v) == sign
        if not np.any(on):
            out.append(None)
            continue

        def magnitude_on_stroke(angles, sign=sign):
            s2, v2, a2, _ = program.evaluate(angles)
            th = cam_geometry(follower, angles, s2, v2, a2).pressure
            return np.where(np.sign(v2) == sign, np.abs(th), 0.0)

        magnitude = np.where(on, np.abs(theta), 0.0)
        _, at = _refined(phi, magnitude, int(np.argmax(magnitude)), magnitude_on_stroke, np.argmax)
        value = float(cam_geometry(follower, np.array([at]), *program.evaluate(np.array([at]))[:3]).pressure[0])
        out.append(Extreme(value, at, limit))
    return tuple(out)


def smallest_radius(follower, program, geometry) -> tuple[float, float]:
    """(ρ_min, cam angle): the smallest convex radius of curvature of the pitch curve (a flat face: of
    the profile), refined between the grid's samples; (inf, nan) when nothing is convex."""
    def convex(angles):
        g = cam_geometry(follower, angles, *program.evaluate(angles)[:3])
        rho = g.rho_pitch if g.rho_pitch is not None else g.rho_profile
        return np.where(rho > 0, rho, np.inf)

    values = convex(geometry.phi)
    if not np.isfinite(values).any():
        return math.inf, math.nan
    return _refined(geometry.phi, values, int(np.argmin(values)), convex, np.argmin)


def _warnings(d: CamDesign) -> list[str]:
    out = []
    for name, ext in (("rise", d.rise), ("return", d.ret)):
        if ext is not None and ext.exceeded:
            out.append(f"the pressure angle on the {name} reaches {math.degrees(ext.value):.4g}° at cam angle "
                       f"{math.degrees(ext.at):.4g}°, beyond the {math.degrees(ext.limit):.4g}° limit")
    g, f = d.geometry, d.follower
    if f.contact == "roller" and f.roller >= d.rho_min:
        out.append(f"the roller (r = {f.roller:.6g} m) is not smaller than the smallest convex radius of "
                   f"the pitch curve (ρ_min = {d.rho_min:.6g} m, ρ_min/r = {d.rho_min / f.roller:.4g}): the "
                   f"profile is undercut and the follower cannot follow the law")
    if f.contact == "flat" and np.any(g.rho_profile <= 0):
        k = int(np.argmin(g.rho_profile))
        out.append(f"the flat face's profile has a cusp (radius of curvature {g.rho_profile[k]:.6g} m at "
                   f"cam angle {math.degrees(g.phi[k]):.4g}°): enlarge the base radius")
    for jump in d.program.continuity():
        out.append(jump.message)
    if d.check.relative > SELF_CHECK_TOLERANCE:
        out.append(f"self-check: the follower run on the profile departs from the law by "
                   f"{d.check.error:.3g} m ({d.check.relative:.3g} of the stroke)")
    if d.forces is not None and np.any(d.forces.lift_off):
        k = np.flatnonzero(d.forces.lift_off)
        out.append(f"the follower leaves the cam (contact force ≤ 0) between cam angles "
                   f"{math.degrees(d.geometry.phi[k[0]]):.4g}° and {math.degrees(d.geometry.phi[k[-1]]):.4g}°: "
                   f"a stiffer spring or a larger preload is needed")
    out += _window_warnings(d)
    return out


def _window_warnings(d: CamDesign) -> list[str]:
    if not d.window:
        return []
    lo, hi = d.window
    width = np.mod(hi - lo, 360.0)
    out = []
    for seg in d.program.segments:
        if seg.kind != "rise":
            continue
        a = np.mod(d.start + math.degrees(seg.start) - lo, 360.0)
        b = a + math.degrees(seg.span)
        if b > width + 1e-9:
            out.append(f"the rise at cam angles {math.degrees(seg.start):.4g}°–"
                       f"{math.degrees(seg.start + seg.span):.4g}° (input {d.start + math.degrees(seg.start):.6g}°"
                       f"…) leaves the window {lo:.6g}°…{hi:.6g}° of the linkage")
    return out
