"""The drawn geometry of D designs as arrays: every joint's and point's drawn coordinates, the guide
directions of prismatic pairs, each input's zero, and what follows from them (each link's drawn
reference angle, the input's drawn value). These are the constants of the joint laws, one per design.

Designs whose drawn pose is exact (coordinates, polar placements) are evaluated all at once from the
parameter arrays with the template's own arithmetic. Designs given as sketches (link `lengths`, the
input's `drawn_at`) are assembled one by one, each with its own error when it cannot be.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..model import assemble, reference_points
from ..errors import MbplanarError
from ..model import Template, parse_model
from .variants import Variants

__all__ = ["DesignGeometry", "design_geometry", "mechanism_of"]


@dataclass
class DesignGeometry:
    """Per-design constants (D designs), SI.

    at : {joint or point: (2, D)} drawn coordinates (a prismatic pair: its point on the slider).
    guide : {prismatic joint: (2, D)} unit vector of the guide in the drawn pose.
    zero : (n_in, D) each input's `zero`, in the input's unit.
    reference : {link: (D,)} the drawn angle of each link's reference line (rad).
    phi0 : (D,) the input's value in the drawn pose (SI).
    reasons : per design, None or why it cannot be analysed (then its arrays hold placeholders).
    higher : the higher pairs' laws per design, or None (each design then solved by its own engine):
        an object whose `law(base, index, shift)` is pair `base.name`'s law for designs `index` (B,) in
        frames moved by `shift` (2, B) (`mbplanar.accuracy.higher.MadePairs`).
    """

    count: int
    at: dict
    guide: dict
    zero: np.ndarray
    reference: dict
    phi0: np.ndarray
    reasons: list
    higher: object = None

    @property
    def ok(self) -> np.ndarray:
        return np.array([r is None for r in self.reasons], bool)


def _full(value, count) -> np.ndarray:
    return np.broadcast_to(np.asarray(value, float), (count,)).copy()


def _construct_along(a, b, fraction, distance, offset):
    """Points on P→Q: at `distance` (or `fraction` of PQ) from P and `offset` to its left; arrays (D,)."""
    d = (b[0] - a[0], b[1] - a[1])
    length = np.hypot(d[0], d[1])
    with np.errstate(invalid="ignore", divide="ignore"):
        u = (d[0] / length, d[1] / length)
    dist = distance if distance is not None else fraction * length
    return a[0] + dist * u[0] + offset * (-u[1]), a[1] + dist * u[1] + offset * u[0]


def _exact(template: Template, mech, values: dict, count: int):
    """Coordinates, guides and zeros of exact designs from parameter arrays, all at once."""
    unit = template.length_unit
    joints = template.positions(values)
    at = {name: np.stack([_full(joints[name][0], count), _full(joints[name][1], count)]) * unit
          for name in mech.joints}
    guides = template.guides(values)
    rows = {str(r.get("name")): (i, r) for i, r in enumerate(template.data.get("points", []))}
    for name in mech.points:
        i, row = rows[name]
        if row.get("at") is not None:
            xy = [template._value(x, "length", values, f"points[{i}] at") for x in row["at"]]
            at[name] = np.stack([_full(xy[0], count), _full(xy[1], count)]) * unit
    for name in mech.points:  # built on the exact coordinates, after those given by `at`
        i, row = rows[name]
        if row.get("along") is not None:
            along = [str(n) for n in row["along"]]
            get = lambda key: (None if row.get(key) is None else  # noqa: E731
                               _full(template._value(row[key], "plain" if key == "fraction" else "length",
                                                     values, f"points[{i}] {key}"), count))
            dist, off = get("distance"), get("offset")
            xy = _construct_along(at[along[0]], at[along[1]], get("fraction"),
                                  None if dist is None else dist * unit, 0.0 if off is None else off * unit)
            at[name] = np.stack(xy)
    guide = {}
    for name, j in mech.joints.items():
        if j.kind != "P":
            continue
        if j.guide_points is not None:
            p, q = (at[n] for n in j.guide_points)
            d = q - p
            guide[name] = d / np.hypot(d[0], d[1])
        else:
            g = np.radians(_full(guides[name], count))
            guide[name] = np.stack([np.cos(g), np.sin(g)])
    zero = np.stack([_full(z, count) for z in template.input_zero(values)])
    return at, guide, zero, [None] * count


def _one_by_one(template: Template, variants: Variants):
    """Coordinates, guides and zeros of sketched designs, each assembled on its own."""
    mechs, reasons = [], []
    for k in range(len(variants)):
        try:
            mechs.append(assemble(parse_model(template.bind(variants.row(k)),
                                              source=f"{template.source} [variant {variants.names[k]}]")))
            reasons.append(None)
        except MbplanarError as exc:
            mechs.append(None)
            reasons.append(str(exc))
    ref = next((m for m in mechs if m is not None), None)
    if ref is None:
        return {}, {}, np.zeros((0, len(variants))), reasons
    mechs = [m if m is not None else ref for m in mechs]
    names = list(ref.joints) + list(ref.points)
    at = {n: np.array([(m.joints[n].at if n in m.joints else m.points[n].at) for m in mechs], float).T
          for n in names}
    guide = {}
    for n, j in ref.joints.items():
        if j.kind == "P":
            g = np.radians([m.joints[n].guide_deg for m in mechs])
            guide[n] = np.stack([np.cos(g), np.sin(g)])
    zero = np.array([[inp.zero for inp in m.inputs] for m in mechs], float).T
    return at, guide, zero, reasons


def _reference_angles(mech, at: dict, guide: dict, count: int) -> dict:
    """Each link's drawn reference angle (D,), as `Engine` measures it."""
    out = {mech.ground: np.zeros(count)}
    for link in mech.moving_links:
        ref = reference_points(mech, link)
        if ref is not None:
            p, q = (at[n] for n in ref)
            out[link] = np.arctan2(q[1] - p[1], q[0] - p[0])
            continue
        g = next((j for j in mech.joints_of(link) if j.kind == "P"), None)
        out[link] = np.arctan2(guide[g.name][1], guide[g.name][0]) if g is not None else np.zeros(count)
    return out


def _drawn_input(mech, reference: dict, zero: np.ndarray) -> np.ndarray:
    """The (single) input's drawn value φ0 (D,), SI, as `Engine` measures it."""
    inp = mech.inputs[0]
    j = mech.joints[inp.joint]
    if inp.drawn_at is not None:
        return np.full(zero.shape[1], inp.to_si(inp.drawn_at))
    if j.kind == "P":
        return -zero[0] * inp.scale / inp.sense
    value = reference[j.links[1]] - reference[j.links[0]]
    phi = (value - zero[0] * inp.scale) / inp.sense
    lo = inp.to_si(inp.default_sweep()[0])
    return lo + (phi - lo) % (2 * math.pi)


def design_geometry(template: Template, variants: Variants, mech) -> DesignGeometry:
    """The per-design constants of `variants` of `template` (`mech`: its reference design, assembled)."""
    count = len(variants)
    if template.needs_assembly:
        at, guide, zero, reasons = _one_by_one(template, variants)
        if not at:
            return DesignGeometry(count, {}, {}, zero, {}, np.zeros(count), reasons)
    else:
        values = {**{n: np.full(count, v) for n, v in template.defaults().items()}, **variants.values}
        at, guide, zero, reasons = _exact(template, mech, values, count)
    reference = _reference_angles(mech, at, guide, count)
    phi0 = _drawn_input(mech, reference, zero)
    reasons = list(reasons)
    finite = np.isfinite(phi0)
    for arr in list(at.values()) + list(guide.values()):
        finite &= np.all(np.isfinite(arr), axis=0)
    for k in np.flatnonzero(~finite):
        reasons[k] = reasons[k] or "the parameters give a drawn pose with undefined coordinates"
    return DesignGeometry(count, at, guide, zero, reference, phi0, reasons)


def mechanism_of(mech, geometry: DesignGeometry, k: int):
    """Design k as an exact `Mechanism` (the reference `mech` with design k's coordinates)."""
    joints = {}
    for name, j in mech.joints.items():
        xy = geometry.at[name][:, k]
        guide = j.guide_deg
        if j.kind == "P":
            u = geometry.guide[name][:, k]
            guide = math.degrees(math.atan2(u[1], u[0]))
        joints[name] = replace(j, at=(float(xy[0]), float(xy[1])), guide_deg=guide)
    points = {n: replace(p, at=tuple(float(x) for x in geometry.at[n][:, k]), along=None, fraction=None,
                         distance=None, offset=0.0) for n, p in mech.points.items()}
    inputs = [replace(inp, zero=float(geometry.zero[i, k])) for i, inp in enumerate(mech.inputs)]
    return replace(mech, joints=joints, points=points, inputs=inputs, exact=True)
