"""Exact drawn pose from a sketch: the step between the table and the engine.

A table gives every joint and point in one drawn pose. When links carry exact dimensions (`lengths`) or
the input states its value in the drawn pose (`drawn_at`), that pose is only a sketch. `assemble` finds
the exact pose nearest to it: the unknowns are each moving link's placement (a small rigid motion about
its centroid) and the link-fixed coordinates of the points that dimensions constrain; the equations are
the joints (revolute: coincident points; prismatic: slider point on the guide, relative angle kept),
the dimensions and the drawn input value. Minimum-norm Gauss-Newton from the sketch keeps the sketch's
assembly mode (branch). The result is a `Mechanism` with `exact=True` whose coordinates the engine trusts.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import replace

import numpy as np

from ..errors import ModelError, ModelWarning, MotionError, did_you_mean
from ._scale import SLACK, frame_origin
from ._model import Joint, Link, Mechanism, Point

__all__ = ["assemble", "reference_points", "input_reference"]


def _unit(deg):
    return np.array([math.cos(math.radians(deg)), math.sin(math.radians(deg))])


def _link_point_names(mech: Mechanism, link: str) -> dict[str, tuple[float, float]]:
    """Named points of a link and their sketch coordinates: its joints, then points given by `at`."""
    names = {j.name: j.at for j in mech.joints_of(link)}
    names.update({p.name: p.at for p in mech.points.values() if p.link == link and p.at is not None})
    return names


def reference_points(mech: Mechanism, link: str) -> tuple[str, str] | None:
    """The two points whose direction is the link's reported angle.

    A link's angle is that of the line from its first point to its second: the pair its table's
    ``angle`` names, else its first two revolute joints at distinct places.

    Parameters
    ----------
    mech : Mechanism
        The model.
    link : str
        A link's name.

    Returns
    -------
    tuple of str or None
        The two points' (or joints') names; None where the link has neither (its angle is then a
        prismatic pair's guide, or 0).

    Raises
    ------
    Nothing: a name that is not a link's gives None.

    Examples
    --------
    >>> from mbplanar.model import read_model, reference_points
    >>> mech = read_model("models/fourbar.toml")
    >>> reference_points(mech, "2"), reference_points(mech, "0")
    (('A', 'B'), ('O', 'C'))
    """
    spec = mech.links[link].angle if link in mech.links else None
    if spec is not None:
        return spec
    revolute = [j for j in mech.joints_of(link) if j.kind == "R"]
    for k, first in enumerate(revolute):
        for second in revolute[k + 1:]:
            if math.dist(first.at, second.at) > 0:
                return first.name, second.name
    return None


def _resolve_lengths(mech: Mechanism, link: Link, names) -> list[tuple[str, str, float]]:
    where = f"links '{link.name}'"
    out = []
    for p, q, value in link.lengths:
        if p == "" and q == "":
            revolute = [j.name for j in mech.joints_of(link.name) if j.kind == "R"]
            if len(revolute) != 2:
                raise ModelError("'length' needs exactly two revolute joints on the link "
                                 f"(it has {len(revolute)}); use lengths = [[P, Q, value], ...]",
                                 source=mech.source, where=where)
            p, q = revolute
        for name in (p, q):
            if name not in names:
                raise ModelError(f"length {p}-{q}: '{name}' is not a joint or point of this link; "
                                 f"{did_you_mean(name, names, 'joints and points of the link')}",
                                 source=mech.source, where=where)
        if p == q:
            raise ModelError(f"length {p}-{q} joins a point to itself", source=mech.source, where=where)
        out.append((p, q, value))
    return out


def _check_references(mech: Mechanism):
    for link in mech.links.values():
        names = _link_point_names(mech, link.name)
        where = f"links '{link.name}'"
        if link.angle is not None:
            for name in link.angle:
                if name not in names:
                    raise ModelError(f"angle point '{name}' is not on this link; "
                                     f"{did_you_mean(name, names, 'joints and points of the link')}",
                                     source=mech.source, where=where)
        if link.centre is not None and link.centre not in names and link.centre not in mech.points:
            raise ModelError(f"centre '{link.centre}' is not a point of this link; "
                             f"{did_you_mean(link.centre, names, 'joints and points of the link')}",
                             source=mech.source, where=where)
        if link.centre is not None and link.centre in mech.points and mech.points[link.centre].link != link.name:
            raise ModelError(f"centre '{link.centre}' belongs to link '{mech.points[link.centre].link}'",
                             source=mech.source, where=where)
    for j in mech.joints.values():
        if j.kind == "P" and j.guide_points is not None:
            names = _link_point_names(mech, j.carrier)
            for name in j.guide_points:
                if name not in names:
                    raise ModelError(f"joints '{j.name}': guide point '{name}' is not on "
                                     f"its carrier link '{j.carrier}'; "
                                     f"{did_you_mean(name, names, 'joints and points of the carrier')}",
                                     source=mech.source)
            a, b = (names[n] for n in j.guide_points)
            if math.dist(a, b) == 0:
                raise ModelError(f"joints '{j.name}': guide points coincide", source=mech.source)
    for p in mech.points.values():
        if p.along is not None:
            names = _link_point_names(mech, p.link)
            for name in p.along:
                if name not in names:
                    raise ModelError(f"points '{p.name}': '{name}' is not a joint or "
                                     f"point (with 'at') of link '{p.link}'; "
                                     f"{did_you_mean(name, names, 'joints and points of the link')}",
                                     source=mech.source)


def _coincident(names: dict, tol: float) -> dict[str, str]:
    """Points of one link drawn at the same place (within tol) are one material point: name → the first
    such name (only for the names that have an earlier twin)."""
    alias, firsts = {}, []
    for name, xy in names.items():
        twin = next((f for f in firsts if math.dist(names[f], xy) <= tol), None)
        if twin is None:
            firsts.append(name)
        else:
            alias[name] = twin
    return alias


class _Sketch:
    """The assembly problem: unknown vector layout and residuals."""

    def __init__(self, mech: Mechanism):
        self.mech = mech
        self.moving = mech.moving_links
        self.scale = max([math.dist(a.at, b.at) for a in mech.joints.values() for b in mech.joints.values()]
                         + [0.0]) or 1.0  # (no absolute floor: the tolerances below are relative to it)
        self.local: dict[str, dict[str, np.ndarray]] = {}
        self.centroid: dict[str, np.ndarray] = {}
        self.alias: dict[str, dict[str, str]] = {}
        for link in mech.all_links:
            names = _link_point_names(mech, link)
            self.local[link] = {n: np.array(xy, float) for n, xy in names.items()}
            self.alias[link] = _coincident(names, 1e-12 * self.scale)
            pts = np.array(list(names.values()) or [(0.0, 0.0)], float)
            self.centroid[link] = pts.mean(axis=0)
        self.lengths = [(link.name, self.alias[link.name].get(p, p), self.alias[link.name].get(q, q), value)
                        for link in mech.links.values()
                        for p, q, value in _resolve_lengths(mech, link, self.local[link.name])]
        shape_points = sorted({(link, p) for link, p, q, _ in self.lengths}
                              | {(link, q) for link, p, q, _ in self.lengths})
        self.shape_index = {key: 3 * len(self.moving) + 2 * k for k, key in enumerate(shape_points)}
        self.size = 3 * len(self.moving) + 2 * len(shape_points)

    def initial(self) -> np.ndarray:
        x = np.zeros(self.size)
        for (link, name), k in self.shape_index.items():
            x[k:k + 2] = self.local[link][name]
        return x

    def placement(self, x, link):
        if link == self.mech.ground:
            return (0.0, 0.0), 0.0
        k = 3 * self.moving.index(link)
        return x[k:k + 2], x[k + 2]

    def local_point(self, x, link, name):
        name = self.alias[link].get(name, name)
        k = self.shape_index.get((link, name))
        return x[k:k + 2] if k is not None else self.local[link][name]

    def world(self, x, link, name):
        """World coordinates of a link's point (plain floats: this runs thousands of times)."""
        t, th = self.placement(x, link)
        c = self.centroid[link]
        p = self.local_point(x, link, name)
        dx, dy = p[0] - c[0], p[1] - c[1]
        cos, sin = math.cos(th), math.sin(th)
        return np.array((c[0] + t[0] + cos * dx - sin * dy, c[1] + t[1] + sin * dx + cos * dy))

    def direction(self, x, link, local_dir):
        th = self.placement(x, link)[1]
        cos, sin = math.cos(th), math.sin(th)
        return np.array((cos * local_dir[0] - sin * local_dir[1], sin * local_dir[0] + cos * local_dir[1]))

    def guide(self, x, j: Joint):
        """(point on the line, unit direction) of a prismatic joint's guide, in the world."""
        if j.guide_points is not None:
            a = self.world(x, j.carrier, j.guide_points[0])
            b = self.world(x, j.carrier, j.guide_points[1])
            return a, (b - a) / np.linalg.norm(b - a)
        return self.world(x, j.carrier, j.name), self.direction(x, j.carrier, _unit(j.guide_deg))

    def link_angle(self, x, link):
        if link == self.mech.ground:
            return 0.0
        ref = reference_points(self.mech, link)
        if ref is not None:
            d = self.world(x, link, ref[1]) - self.world(x, link, ref[0])
            return math.atan2(d[1], d[0])
        guide = next((j for j in self.mech.joints_of(link) if j.kind == "P"), None)
        if guide is None:
            return self.placement(x, link)[1]
        d = self.guide(x, guide)[1]
        return math.atan2(d[1], d[0])

    def residuals(self, x) -> tuple[np.ndarray, list[str]]:
        x = np.asarray(x, float).tolist()  # plain floats are faster than numpy scalars here
        res, what = [], []
        for j in self.mech.joints.values():
            a, b = j.links
            if j.kind == "R":
                d = (self.world(x, a, j.name) - self.world(x, b, j.name)) / self.scale
                res += list(d)
                what += [f"joint '{j.name}'"] * 2
            else:
                point, u = self.guide(x, j)
                d = self.world(x, j.slider, j.name) - point
                res.append((u[0] * d[1] - u[1] * d[0]) / self.scale)
                res.append(self.placement(x, j.slider)[1] - self.placement(x, j.carrier)[1])
                what += [f"joint '{j.name}'"] * 2
        for link, p, q, value in self.lengths:
            a, b = self.local_point(x, link, p), self.local_point(x, link, q)
            res.append((math.hypot(b[0] - a[0], b[1] - a[1]) - value) / self.scale)
            what.append(f"length {p}-{q} of link '{link}'")
        for inp in self.mech.inputs:
            if inp.drawn_at is None:
                continue
            j = self.mech.joints[inp.joint]
            target = inp.joint_value(inp.to_si(inp.drawn_at))
            if j.kind == "R":
                rel = self.link_angle(x, j.links[1]) - self.link_angle(x, j.links[0]) - target
                res.append(math.remainder(rel, 2 * math.pi))
                what.append(f"input '{inp.joint}' at drawn_at = {inp.drawn_at:g}")
        return np.array(res), what

    def jacobian(self, x) -> np.ndarray:
        h = 1e-7
        cols = []
        for k in range(self.size):
            e = np.zeros(self.size)
            e[k] = h
            cols.append((self.residuals(x + e)[0] - self.residuals(x - e)[0]) / (2 * h))
        return np.array(cols).T


def _gauss_newton(sketch: _Sketch, tol=1e-13, max_iter=60):
    x = sketch.initial()
    res, what = sketch.residuals(x)
    for _ in range(max_iter):
        if not res.size or np.max(np.abs(res)) < tol:
            return x, res, what, True
        step = np.linalg.lstsq(sketch.jacobian(x), -res, rcond=1e-12)[0]
        # a damped step keeps the nearest solution when the sketch is far off
        for damping in (1.0, 0.5, 0.25, 0.125):
            trial = x + damping * step
            trial_res = sketch.residuals(trial)[0]
            if np.linalg.norm(trial_res) < np.linalg.norm(res) or damping == 0.125:
                break
        x, res = trial, trial_res
    return x, res, what, bool(not res.size or np.max(np.abs(res)) < 1e-10)


def _construct_along(p: Point, a, b) -> tuple[float, float]:
    d = b - a
    length = float(np.hypot(*d))
    if length == 0:
        raise ModelError(f"points '{p.name}': the two points of 'along' coincide")
    u = d / length
    dist = p.distance if p.distance is not None else p.fraction * length
    xy = a + dist * u + p.offset * np.array([-u[1], u[0]])
    return (float(xy[0]), float(xy[1]))


LENGTH_MISMATCH = 0.10        # a length 10 % or more off the sketch's distance is flagged (the boundary too)
INPUT_MISMATCH_DEG = 1.0      # a drawn_at more than 1° off the sketch's angle is flagged


#: every length given this many times off the sketch (or its inverse), all by one factor: another unit
UNIFORM_SCALE = 5.0


def _refuse_uniform_scale(mech: Mechanism, sketch: _Sketch):
    """A `ModelError` when every length given (two or more) differs from what the sketch draws by one
    factor, at least `UNIFORM_SCALE` either way (within 10 %): lengths and coordinates written in two
    units (metres in a mm table: 1/1000), which no assembly can reconcile without moving the drawing by
    its own size."""
    ratios = [(value / math.dist(sketch.local[link][p], sketch.local[link][q]), link)
              for link, p, q, value in sketch.lengths if math.dist(sketch.local[link][p], sketch.local[link][q]) > 0]
    if len(ratios) < 2:
        return
    values = [r for r, _ in ratios]
    lo, hi = min(values), max(values)
    if hi > (1 + LENGTH_MISMATCH) * lo or 1 / UNIFORM_SCALE < math.sqrt(lo * hi) < UNIFORM_SCALE:
        return
    factor = math.sqrt(lo * hi)
    shown = f"1/{1 / factor:.4g}" if factor < 1 else f"{factor:.4g}"
    raise ModelError(f"every length given ({len(ratios)}, links {', '.join(dict.fromkeys(n for _, n in ratios))}) is "
                     f"{shown} × what the sketch draws: the lengths and the coordinates are in different units "
                     f"(both are read in length_unit '{mech.units.length}')", source=mech.source)


def _warn_disagreements(mech: Mechanism, sketch: _Sketch):
    """A `ModelWarning` for a length 10 % or more off the distance the sketch draws (measured against the
    drawing, the boundary included to rounding: `mbplanar.model._scale.SLACK`), and for a
    revolute input's `drawn_at` more than 1° from the angle the sketch is drawn at (radians typed for
    degrees, a wrong `zero`): the assembly would move the drawing far, silently."""
    units = mech.units
    k = units.length_scale
    _refuse_uniform_scale(mech, sketch)
    for link, p, q, value in sketch.lengths:
        drawn = math.dist(sketch.local[link][p], sketch.local[link][q])
        if abs(value - drawn) >= LENGTH_MISMATCH * drawn * (1 - SLACK):
            off = f"{100 * (value - drawn) / drawn:+.1f} % of it" if drawn else "two points at one place"
            _warn(mech, f"links '{link}'", f"length {p}-{q} = {value / k:.6g} {units.length}, but the sketch "
                  f"draws {drawn / k:.6g} {units.length} ({off}); the assembly moves the joints to the length")
    x = sketch.initial()
    for i, inp in enumerate(mech.inputs):
        j = mech.joints[inp.joint]
        if inp.drawn_at is None or j.kind != "R":
            continue
        measured = sketch.link_angle(x, j.links[1]) - sketch.link_angle(x, j.links[0])
        drawn = inp.drawn_at * inp.scale + math.remainder(measured - inp.joint_value(inp.to_si(inp.drawn_at)),
                                                           2 * math.pi) * inp.sense
        if abs(math.degrees(drawn - inp.drawn_at * inp.scale)) > INPUT_MISMATCH_DEG:
            _warn(mech, f"inputs[{i}] (joint '{inp.joint}')",
                  f"drawn_at = {inp.drawn_at:g} {inp.unit}, but the sketch is drawn at "
                  f"{inp.from_si(drawn):.6g} {inp.unit} ({math.degrees(abs(drawn - inp.drawn_at * inp.scale)):.3g}° "
                  f"apart); the assembly moves the drawing to drawn_at. {input_reference(mech, inp)}")


def _line(mech: Mechanism, link: str) -> str:
    """The line a link's angle is measured along, in words."""
    if link == mech.ground:
        ref = reference_points(mech, link) if link in mech.links else None
        return "the x axis" if ref is None else f"line {ref[0]}→{ref[1]} of the ground"
    ref = reference_points(mech, link)
    if ref is not None:
        return f"line {ref[0]}→{ref[1]} of link '{link}'"
    guide = next((j for j in mech.joints_of(link) if j.kind == "P"), None)
    return f"the guide of joint '{guide.name}' on link '{link}'" if guide else f"link '{link}' as drawn"


def input_reference(mech: Mechanism, inp) -> str:
    """How a revolute input's value is measured, in words: which line of which link, the sense, the
    zero and the unit."""
    a, b = mech.joints[inp.joint].links
    sense = "counter-clockwise (sense = 1)" if inp.sense > 0 else "clockwise (sense = -1)"
    return (f"The input {inp.name} [{inp.unit}] is the angle from {_line(mech, a)} to {_line(mech, b)}, "
            f"{sense}, less zero = {inp.zero:g} {inp.unit}.")


def _warn(mech, where, message):
    warnings.warn(ModelWarning(str(ModelError(message, source=mech.source, where=where))), stacklevel=4)


def assemble(mech: Mechanism) -> Mechanism:
    """Return the exact drawn pose of `mech` (a new `Mechanism` with `exact=True`).

    Parameters
    ----------
    mech : Mechanism
        A mechanism whose drawn positions are a sketch (`Mechanism.exact` False): the pose nearest to it
        that meets every length and guide is found.

    Returns
    -------
    Mechanism
        A new mechanism at that pose, ``exact=True`` (`mech` is not changed).

    Raises
    ------
    MotionError
        The dimensions cannot be met near the sketch (the message names the worst joint or length).
    ModelError
        Dimensions that name points not on their link.

    Examples
    --------
    >>> import mbplanar
    >>> exact = mbplanar.assemble(mbplanar.read_model("models/fourbar.toml"))
    >>> exact.exact, [round(x, 6) for x in exact.joints["B"].at]       # B closed onto AB = 0.3, CB = 0.25
    (True, [0.301601, 0.249995])
    """
    if mech.exact:
        return mech
    _check_references(mech)
    _warn_disagreements(mech, _Sketch(mech))  # at the model's own scale: its numbers are the model's
    size = max((math.dist(a.at, b.at) for a in mech.joints.values() for b in mech.joints.values()), default=0.0)
    if size and not SIZE_RANGE[0] <= size <= SIZE_RANGE[1]:
        raise ModelError(f"scale out of range: the joints are up to {size:.3g} m apart; mbplanar works with "
                         f"mechanisms from {SIZE_RANGE[0]:g} to {SIZE_RANGE[1]:g} m (squares of lengths must stay "
                         "within floating point)", source=mech.source)
    # assembled in the mechanism's own frame (`frame_origin`: the residuals compare coordinates of the
    # mechanism's size, not ones 1000 sizes from the origin whose rounding exceeds the tolerance; 0 near
    # the origin) and at unit size, scaled by a power of two (exact both ways): every tolerance is relative
    centre = tuple(float(c) for c in frame_origin([j.at for j in mech.joints.values()] or [(0.0, 0.0)], size))
    near = translated(mech, (-centre[0], -centre[1]))
    if not size:
        return translated(_assemble(near), centre)
    k = 2.0 ** -round(math.log2(size))
    return translated(scaled(_assemble(scaled(near, k), 1.0 / k), 1.0 / k), centre)


SIZE_RANGE = (1e-100, 1e100)  # sizes (m) whose squares, products and their ratios stay well inside floating point


def scaled(mech: Mechanism, k: float) -> Mechanism:
    """`mech` with every length multiplied by k: joints, points (coordinates, distances, offsets) and
    link lengths (the loads, in `extras`, are not touched)."""
    def xy(at):
        return None if at is None else (at[0] * k, at[1] * k)
    joints = {n: replace(j, at=xy(j.at)) for n, j in mech.joints.items()}
    points = {n: replace(p, at=xy(p.at), distance=None if p.distance is None else p.distance * k,
                         offset=p.offset * k) for n, p in mech.points.items()}
    links = {n: replace(lk, lengths=tuple((a, b, v * k) for a, b, v in lk.lengths)) for n, lk in mech.links.items()}
    extras = dict(mech.extras)
    if "_assembly_correction" in extras:
        extras["_assembly_correction"] *= k
    times = lambda v: None if v is None else v * k  # noqa: E731
    higher = {n: replace(h, at=xy(h.at), radii=None if h.radii is None else (h.radii[0] * k, h.radii[1] * k),
                         module=times(h.module), radius=h.radius * k,
                         curve=None if h.curve is None else h.curve.scaled(k)) for n, h in mech.higher.items()}
    return replace(mech, joints=joints, points=points, links=links, extras=extras, higher=higher)


def _moved_higher(mech: Mechanism, sketch: "_Sketch", x, exact_at: dict) -> dict:
    """The higher pairs carried by their links from the sketch to the exact pose: a curve and a rack's
    line with their link, a follower's or pin's point with its link (a named one where it now is), a
    flat face's direction with the follower."""
    def mover(link):
        t, th = sketch.placement(x, link)
        c = sketch.centroid[link]
        cos, sin = math.cos(th), math.sin(th)
        return (lambda p: (float(c[0] + t[0] + cos * (p[0] - c[0]) - sin * (p[1] - c[1])),
                           float(c[1] + t[1] + sin * (p[0] - c[0]) + cos * (p[1] - c[1])))), th

    out = {}
    for name, h in mech.higher.items():
        a, b = h.links
        move_a, turn_a = mover(a)
        move_b, turn_b = mover(b)
        fields = {}
        if h.kind == "gear":
            if h.at is not None and h.carrier is not None:
                fields["at"] = mover(h.carrier)[0](h.at)
        elif h.kind == "rack":
            fields["at"] = move_b(h.at)
            if h.guide is not None:
                fields["guide"] = h.guide + turn_b
        else:
            fields["curve"] = h.curve.moved(move_a)
            fields["at"] = tuple(float(v) for v in exact_at[h.point]) if h.point in exact_at else move_b(h.at)
            if h.face is not None:
                fields["face"] = h.face + turn_b
        out[name] = replace(h, **fields)
    return out


def translated(mech: Mechanism, d) -> Mechanism:
    """`mech` with every drawn coordinate moved by a vector: the same mechanism drawn elsewhere.

    Parameters
    ----------
    mech : Mechanism
        The model.
    d : sequence of float
        The move (2,), m.

    Returns
    -------
    Mechanism
        A copy whose joints, points and higher pairs' points and curves are moved by `d`; lengths,
        angles and the loads (given on the links) are not touched.

    Raises
    ------
    Nothing on a valid mechanism; a `d` of other than two numbers gives an `IndexError` or `TypeError`.

    Examples
    --------
    >>> from mbplanar.model import read_model, translated
    >>> mech = read_model("models/fourbar.toml")
    >>> translated(mech, (1.0, -2.0)).joints["C"].at, mech.joints["C"].at
    ((1.3, -2.0), (0.3, 0.0))
    """
    def xy(at):
        return None if at is None else (at[0] + d[0], at[1] + d[1])
    higher = {n: replace(h, at=xy(h.at), curve=None if h.curve is None else h.curve.moved(xy))
              for n, h in mech.higher.items()}
    return replace(mech, joints={n: replace(j, at=xy(j.at)) for n, j in mech.joints.items()},
                   points={n: replace(p, at=xy(p.at)) for n, p in mech.points.items()}, higher=higher)


def _assemble(mech: Mechanism, metres: float = 1.0) -> Mechanism:
    """`assemble` at the mechanism's own scale (`metres`: one of its length units in metres, for the
    messages)."""
    sketch = _Sketch(mech)
    x, res, what, ok = _gauss_newton(sketch)
    if not ok:
        worst = int(np.argmax(np.abs(res)))
        inp = next((i for i in mech.inputs if what[worst].startswith(f"input '{i.joint}'")), None)
        miss = (f"{math.degrees(abs(res[worst])):.3g}°" if inp is not None
                else f"{abs(res[worst]) * sketch.scale * metres / mech.units.length_scale:.3g} {mech.units.length}")
        hint = input_reference(mech, inp) if inp is not None else "Check the lengths and the sketch."
        raise MotionError("the drawn pose cannot be assembled with the given dimensions and input: "
                          f"{what[worst]} misses by {miss}. {hint}", source=mech.source)
    joints = {}
    for j in mech.joints.values():
        at = sketch.world(x, j.slider if j.kind == "P" else j.links[0], j.name)
        guide = None
        if j.kind == "P":
            u = sketch.guide(x, j)[1]
            guide = math.degrees(math.atan2(u[1], u[0]))
        joints[j.name] = replace(j, at=(float(at[0]), float(at[1])), guide_deg=guide)
    exact_at = {name: np.array(j.at) for name, j in joints.items()}
    points = {}
    for p in mech.points.values():
        if p.at is not None:
            xy = sketch.world(x, p.link, p.name)
            points[p.name] = replace(p, at=(float(xy[0]), float(xy[1])))
            exact_at[p.name] = xy
    for p in mech.points.values():
        if p.along is not None:
            a, b = (exact_at.get(n) for n in p.along)
            points[p.name] = Point(p.name, p.link, _construct_along(p, a, b))
            exact_at[p.name] = np.array(points[p.name].at)
    links = {name: replace(link, lengths=()) for name, link in mech.links.items()}
    correction = max((math.dist(joints[n].at, j.at) for n, j in mech.joints.items()), default=0.0)
    higher = _moved_higher(mech, sketch, x, exact_at) if mech.higher else {}
    return replace(mech, links=links, joints=joints, points=points, exact=True, assembly_correction=correction,
                   higher=higher)
