"""The higher pairs of a made mechanism: their dimensions, their made numbers and their laws with them.

A higher pair's law (`mbplanar.engine._higher`) holds a few numbers of its links, in the link frames of
the drawn pose; a made mechanism has its own:

- a gear pair: the pitch radii r_a, r_b (the law r_a(θ_a − θ_c) ± r_b(θ_b − θ_c) = 0);
- a rack: the pinion's pitch radius r, the pitch point A and the pitch line's direction U on the rack, the
  pinion's centre C on the pinion (its revolute joint's point there);
- a cam or a slot: the follower's or the pin's point on its link (the point or joint `at` names, or the
  drawn [x, y]), a flat face's normal on the follower, a roller's or a circular face's radius, and the
  curve on the other link: a circle's centre and radius (a spline's points are not dimensions: a
  `[parameters]` entry cannot name them).

`numbers(...)` gives them for a batch of made designs (arrays with the designs last), with arithmetic
analytic in the deviations (so that the complex step differentiates them, as `geometry.DesignSpace`
does the rest); `made_law(law, numbers)` is the pair's law holding them (one value per batch element),
optionally placed by per-design rigid motions of its links (`frame`): a made design's links sit
slightly off the nominal drawn pose once it is closed (`made.made_geometry`), and a design batch works
in each design's own drawn pose. `sources` differentiates each law's residual with respect to the
dimensions at a solved pose by the complex step through the law's own closure (`closure(pose)` with
complex numbers), so that every law, present or future, is differentiated from its definition.
"""

from __future__ import annotations

import copy
import math

import numpy as np

from ..model import Circle, Offset, Shape

__all__ = ["higher_dimensions", "nominal_numbers", "apply", "made_law", "MadePairs", "sources", "derived_radius",
           "parameter_kinds", "template_numbers"]


def _deg(v) -> float:
    return math.degrees(math.atan2(v[1], v[0]))


def derived_radius(template, name) -> bool:
    """Whether slot `name`'s circle takes its radius from the pin (its table gives none: the pin's distance
    from the centre, which then follows the pin and the centre as editing the table would)."""
    if template is None:
        return False
    for pair, kind, row in _higher_rows(template):
        if pair == name:
            return kind == "slot" and isinstance(row.get("path"), dict) and "radius" not in row["path"]
    return False


def higher_dimensions(engine, add, template=None):
    """Offer every higher pair's dimensions through `add(name, kind, target, unit, scale, nominal)`
    (kind "higher", target (pair, what)): a gear's `radius_a`, `radius_b`; a rack's `radius`, `guide`,
    `x`, `y` (its pitch point on the rack); a cam's `radius` (roller, circle), `face` (flat), a cam's or
    slot's `x`, `y` (its point drawn as [x, y]); a circle's `profile.x`, `.y`, `.radius` (cam) or
    `path.x`, `.y`, `.radius` (slot; no radius where the table takes it from the pin)."""
    mech = engine.mech
    length = mech.units.length_scale
    deg = math.pi / 180.0
    for name, h in mech.higher.items():
        law = engine.laws[name]
        head = f"joints.{name}"
        if h.kind == "gear":
            for k, word in enumerate("ab"):
                add(f"{head}.radius_{word}", "higher", (name, "radii", k), "length", length, h.radii[k] / length)
            continue
        if h.kind == "rack":
            add(f"{head}.radius", "higher", (name, "radius", 0), "length", length, h.radius / length)
            add(f"{head}.guide", "higher", (name, "guide", 0), "deg", deg, _deg(law.geometry.tangent))
            for k, word in enumerate("xy"):
                add(f"{head}.{word}", "higher", (name, "at", k), "length", length, law.geometry.pitch[k] / length)
            continue
        if h.point is None:
            for k, word in enumerate("xy"):
                add(f"{head}.{word}", "higher", (name, "at", k), "length", length, h.at[k] / length)
        if h.kind == "cam" and h.follower in ("roller", "circle"):
            add(f"{head}.radius", "higher", (name, "radius", 0), "length", length, h.radius / length)
        if h.kind == "cam" and h.follower == "flat":
            n = law.geometry.normal
            face = math.degrees(h.face) if h.face is not None else _deg((n[1], -n[0]))
            add(f"{head}.face", "higher", (name, "face", 0), "deg", deg, face)
        if h.curve.kind == "circle":
            key = "profile" if h.kind == "cam" else "path"
            for k, word in enumerate("xy"):
                add(f"{head}.{key}.{word}", "higher", (name, "centre", k), "length", length,
                    h.curve.centre[k] / length)
            if not derived_radius(template, name):
                add(f"{head}.{key}.radius", "higher", (name, "curve_radius", 0), "length", length,
                    h.curve.radius / length)


def _curve_of(law):
    """The curve the law's contact runs on before a roller's offset (in the engine's frame) and the
    offset's sign (0: none)."""
    h = law.pair
    if law.kind == "point" and h.kind == "cam" and h.follower in ("roller", "circle"):
        return law.local.profile, law.geometry.side
    return (law.local.profile if law.kind == "face" else law.local.path), 0.0


def nominal_numbers(engine, name, count, dtype=float) -> dict:
    """The nominal made numbers of higher pair `name` for `count` designs (arrays, designs last)."""
    law = engine.laws[name]
    col = lambda v: np.broadcast_to(np.asarray(v, float)[:, None], (2, count)).astype(dtype)  # noqa: E731
    full = lambda v: np.full(count, float(v), dtype)  # noqa: E731
    if law.kind == "gear":
        return {"radii": col(law.pair.radii)}
    if law.kind == "rack":
        return {"radius": full(law.pair.radius), "at": col(law.at), "line": col(law.line), "centre": col(law.centre)}
    curve, _ = _curve_of(law)
    out = {"at": col(law.at), "radius": full(law.pair.radius)}
    if law.kind == "face":
        out["normal"] = col(law.n0)
    if isinstance(curve, Circle):
        out["centre"], out["curve_radius"] = col(curve.centre), full(curve.radius)
    return out


def rack_pivot(engine, name) -> str | None:
    """The pinion's revolute joint at a rack pair's pinion centre (None if none is drawn there)."""
    law = engine.laws[name]
    pinion = law.links[0]
    for j in engine.mech.joints_of(pinion):
        centre = np.asarray(j.at, float) - np.asarray(engine.centre, float)
        if j.kind == "R" and math.dist(centre, law.centre) <= 1e-9 * engine.size:
            return j.name
    return None


def _turned(u, t):
    c, s = np.cos(t), np.sin(t)
    return np.stack([c * u[0] - s * u[1], s * u[0] + c * u[1]])


def apply(engine, name, out: dict, changes: dict, side: dict, point: dict, derived: bool = False):
    """The made numbers `out` of pair `name` with the changes of its own dimensions (`changes`: what →
    (2, D) or (D,) array, "at", "radius", "guide", "face", "centre", "curve_radius") and the made points
    of its links (`side`, `point` of `geometry.Sided`) where the law holds a joint's or a point's;
    `derived`: a slot's radius is the pin's distance from the centre (`derived_radius`)."""
    law = engine.laws[name]
    h = law.pair
    if law.kind == "gear":
        out["radii"] = out["radii"] + changes.get("radii", 0.0)
        return
    if law.kind == "rack":
        out["radius"] = out["radius"] + changes.get("radius", 0.0)
        out["at"] = out["at"] + changes.get("at", 0.0)
        pivot = rack_pivot(engine, name)
        if pivot is not None:
            out["centre"] = side[(pivot, law.links[0])]
        if h.guide is None and "guide" not in changes:     # the line square to the centre and the pitch point
            d = out["at"] - out["centre"]
            d0 = np.asarray(law.at - law.centre, float)
            line0 = np.asarray(law.line, float)
            sign = 1.0 if d0[0] * line0[1] - d0[1] * line0[0] > 0 else -1.0
            size = np.sqrt(d[0] * d[0] + d[1] * d[1])
            out["line"] = sign * np.stack([-d[1], d[0]]) / size
        else:
            out["line"] = _turned(out["line"], changes.get("guide", 0.0))
        return
    if h.point is not None:
        out["at"] = side[(h.point, law.links[1])] if h.point in engine.mech.joints else point[h.point]
    out["at"] = out["at"] + changes.get("at", 0.0)
    out["radius"] = out["radius"] + changes.get("radius", 0.0)
    if "normal" in out:
        out["normal"] = _turned(out["normal"], changes.get("face", 0.0))
    if "centre" in out:
        out["centre"] = out["centre"] + changes.get("centre", 0.0)
        out["curve_radius"] = out["curve_radius"] + changes.get("curve_radius", 0.0)
        if derived:
            d = out["at"] - out["centre"]
            out["curve_radius"] = np.sqrt(d[0] * d[0] + d[1] * d[1])


# -- curves with a value per batch element -------------------------------------------------------------
class _Circles(Circle):
    """Circles (or arcs) with a centre (2, B) and radius (B,) per batch element (real or complex)."""

    def __init__(self, like: Circle, centre, radius):
        self.centre, self.radius = centre, radius
        self.closed, self.lo, self.hi, self.scale = like.closed, like.lo, like.hi, like.scale


class _Offsets(Offset):
    """A curve offset by a distance (B,) per batch element."""

    def __init__(self, base: Shape, distance):
        self.base, self.distance = base, distance
        self.closed, self.lo, self.hi, self.scale = base.closed, base.lo, base.hi, base.scale


class _Placed(Shape):
    """A curve carried by a rigid motion per batch element: R·c(u) + r (cos, sin (B,), r (2, B))."""

    def __init__(self, base: Shape, c, s, r):
        self.base, self.c, self.s, self.r = base, c, s, r
        self.closed, self.lo, self.hi, self.scale = base.closed, base.lo, base.hi, base.scale

    def wrap(self, u):
        return self.base.wrap(u)

    def point(self, u, n: int = 0):
        p = self.base.point(u, n)
        out = np.stack([self.c * p[0] - self.s * p[1], self.s * p[0] + self.c * p[1]])
        return out + self.r if n == 0 else out


def made_law(law, numbers: dict, frame: dict | None = None):
    """`law` holding the made `numbers` (arrays with one value per batch element, designs last), each
    link's numbers carried by `frame[link]` = (cos, sin (B,), r (2, B), θ (B,)) when given (a design placed
    in its closed drawn pose: a rack's pitch point then moves along its line by what the pinion rolled
    there, so that the law holds with zero in that pose)."""
    new = copy.copy(law)

    def place(link, p, shift=True):
        if frame is None or link not in frame:
            return p
        c, s, r = frame[link][:3]
        out = np.stack([c * p[0] - s * p[1], s * p[0] + c * p[1]])
        return out + r if shift else out

    if law.kind == "gear":
        ra, rb = numbers["radii"]
        sb = -1.0 if law.pair.internal else 1.0
        a, b = law.links
        new.coef = ((a, ra), (b, sb * rb), (law.carrier, -(ra + sb * rb)))
        return new
    if law.kind == "rack":
        p, k = law.links
        new.sigma_r = law.sigma_r / law.pair.radius * numbers["radius"]
        new.centre = place(p, numbers["centre"])
        new.line = place(k, numbers["line"], shift=False)
        new.at = place(k, numbers["at"])
        if frame is not None:      # the pitch point moved along the line by what the pinion rolled there
            rolled = new.sigma_r * (frame[p][3] - frame[k][3])
            new.at = new.at - rolled * new.line
        return new
    curve_link, other = law.links
    base, sign = _curve_of(law)
    if "centre" in numbers:
        base = _Circles(base, numbers["centre"], numbers["curve_radius"])
    path = _Offsets(base, sign * numbers["radius"]) if sign else base
    if frame is not None and curve_link in frame:
        c, s, r = frame[curve_link][:3]
        path = _Placed(path, c, s, r)
    new.path = path
    new.at = place(other, numbers["at"])
    if law.kind == "face":
        new.n0 = place(other, numbers["normal"], shift=False)
    return new


class MadePairs:
    """The higher pairs of D made designs closed in their drawn poses, for a design batch: `numbers`
    (pair → made numbers, in the nominal link frames of the engine) and `frame` (link → cos, sin (D,),
    r (2, D) world, θ (D,)) each link's place in its design's closed drawn pose. `law(base, index, shift)`
    is pair `base.name`'s law for designs `index` in frames moved by `shift` (2, B) (each design's own)."""

    def __init__(self, numbers: dict, frame: dict):
        self.numbers, self.frame = numbers, frame

    def take(self, index) -> "MadePairs":
        """The designs `index` only."""
        return MadePairs({h: {k: v[..., index] for k, v in nums.items()} for h, nums in self.numbers.items()},
                         {link: (c[index], s[index], r[:, index], th[index]) for link, (c, s, r, th) in self.frame.items()})

    def law(self, base, index, shift):
        nums = {k: v[..., index] for k, v in self.numbers[base.name].items()}
        frame = {link: (c[index], s[index], r[:, index] + shift, th[index])
                 for link, (c, s, r, th) in self.frame.items()}
        return made_law(base, nums, frame)


def sources(engine, pose, nominal: dict, deriv: dict, columns: int, step: float) -> dict:
    """∂(each higher pair's residuals)/∂(each dimension) at the solved `pose` (fixed q, u): pair →
    (cols (n,), value (rows, n, B)) for the columns that change its numbers, by the complex step through
    the law's closure (`nominal`, `deriv`: its numbers and their derivatives (..., K), per SI unit)."""
    out = {}
    for name, d in deriv.items():
        law = engine.laws[name]
        moved = np.zeros(columns, bool)
        for v in d.values():
            moved |= np.any(np.abs(v.reshape(-1, columns)) > 0, axis=0) if columns else moved
        cols = np.flatnonzero(moved)
        if not len(cols):
            continue
        got = []
        for k in cols:
            nums = {key: (nominal[name][key][..., 0] + 1j * step * d[key][..., k])[..., None]
                    for key in d}
            res, _ = made_law(law, nums).closure(pose)
            got.append(np.imag(res) / step)
        out[name] = (cols, np.stack(got, axis=1))
    return out


# -- what a `[parameters]` entry changes in a higher pair's row -----------------------------------------
_LENGTHS = ("module", "radius")
_ANGLES = ("guide", "face")


def _higher_rows(template):
    from ..model import higher_rows
    return higher_rows(template.data)


def _curve(row):
    curve = row.get("profile", row.get("path"))
    return curve if isinstance(curve, dict) else {}


def parameter_kinds(template) -> dict:
    """The kinds ("length", "angle") of the higher pairs' numbers each parameter stands for."""
    out: dict = {}

    def note(raw, kind):
        if isinstance(raw, str) and raw in template.parameters:
            out.setdefault(raw, set()).add(kind)

    for _, _, row in _higher_rows(template):
        for key in _LENGTHS:
            note(row.get(key), "length")
        for key in _ANGLES:
            note(row.get(key), "angle")
        for key in ("radii", "at"):
            for x in row.get(key) if isinstance(row.get(key), list) else []:
                note(x, "length")
        curve = _curve(row)
        note(curve.get("radius"), "length")
        for x in curve.get("centre") if isinstance(curve.get("centre"), list) else []:
            note(x, "length")
    return out


def template_numbers(template, values) -> dict:
    """Each higher pair's numbers that parameters may stand for, for parameter `values` (numbers, complex
    for the complex step), in the table's units (lengths in its unit, angles in degrees): "radii" (a
    gear's (r_a, r_b)), "radius" (a rack's, a roller's), "at" (x, y), "guide", "face", "centre" (x, y),
    "curve_radius"."""
    out = {}
    for name, kind, row in _higher_rows(template):
        where = f"joints '{name}'"
        val = lambda raw, k="length": template._value(raw, k, values, where)  # noqa: E731
        got = {}
        teeth = row.get("teeth")
        module = val(row["module"]) if "module" in row else None
        if kind == "gear":
            if isinstance(row.get("radii"), list):
                got["radii"] = tuple(val(x) for x in row["radii"])
            elif module is not None and isinstance(teeth, list):
                got["radii"] = tuple(module * z / 2 for z in teeth)
        elif "radius" in row:
            got["radius"] = val(row["radius"])
        elif kind == "rack" and module is not None and teeth is not None:
            got["radius"] = module * (teeth[0] if isinstance(teeth, list) else teeth) / 2
        for key in _ANGLES:
            if key in row:
                got[key] = val(row[key], "angle")
        if isinstance(row.get("at"), list):
            got["at"] = tuple(val(x) for x in row["at"])
        curve = _curve(row)
        if isinstance(curve.get("centre"), list):
            got["centre"] = tuple(val(x) for x in curve["centre"])
        if "radius" in curve:
            got["curve_radius"] = val(curve["radius"])
        out[name] = got
    return out
