"""What each toleranced dimension means: the geometry of a mechanism made with deviations from its
nominal dimensions, link by link.

A made mechanism differs from the drawn one link by link: each link carries its joints' points (a
revolute pair's hole or pin, a prismatic pair's guide line on its carrier and the block's point on the
slider) and its points of interest, in its own frame. `Sided` holds them for a batch of D designs, in
the frames of the nominal drawn pose (link frames that coincide there with the engine's, centred on `Engine.centre`): `side[(J, L)]`
(2, D) is joint J's point on link L, `guide[J]` (2, D) a prismatic pair's direction on its carrier,
`point[P]` (2, D) a point of interest on its link, `zero` (n_in, D) each input's zero (the joint value
at φ = 0, SI), `alpha[L]` (D,) the direction of link L's reference line in its frame (its reported
angle is the frame's rotation plus alpha) and `higher[H]` a higher pair's made numbers (`higher.py`).
Nominally every joint's two points coincide.

`DesignSpace.sided(delta)` builds the made geometry from deviations `delta` (D, K) of the K toleranced
dimensions (SI), by the table's own rules:

- ``links.L.length``, ``links.L.P-Q``: the link's shape changes so that its declared lengths take the
  new values, its points named by the lengths moving least (the minimum-norm change, solved to the
  rounding floor), its other points staying where they are on it. A length the others contradict (the
  points of a link drawn in line with all three distances given) is refused.
- ``joints.J.x``, ``joints.J.y``: the joint's point moves on each of its links, except on a link whose
  lengths fix it there (a sketch with `length` rows: the joints of a four-bar's moving links keep their
  distances; a ground pivot moves). A joint that every link's lengths fix is refused (no effect).
- ``joints.J.guide``: a prismatic pair's guide line turns on its carrier about the joint's point; the
  slider keeps its orientation to the carrier, as editing `guide` in the table does.
- ``joints.J.offset``: the guide line moves along its normal on the carrier; the slider's point does not.
- ``points.P.x``, ``.y``: the point moves on its link; ``.fraction``, ``.distance``, ``.offset``: the point
  is built along its two points with the new value.
- ``input.zero`` (``inputs.J.zero`` with several inputs): the driven joint's value at φ = 0.
- a higher pair's numbers (``joints.G.radius_a``, ``joints.K.radius``, ``joints.K.guide``, ``joints.K.x``,
  ``joints.K.face``, ``joints.K.profile.radius``, ...): the numbers its law holds (`higher.py`), in
  `Sided.higher`.
- a parameter's name: every field the parameter stands for changes as the template computes it (a polar
  placement moves the joints placed from it, and so on), each field with the meaning above.

Every step is written with arithmetic that is analytic in the deviations (no abs, no comparisons), so
the same function gives the Monte Carlo's designs (real deviations) and, evaluated at imaginary
deviations i·h, the exact first derivatives (`DesignSpace.derivatives`, the complex step: exact to
rounding, no difference quotient). The sensitivities of the motion then follow from the joint laws
(`sensitivity.py`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError
from ..model import reference_points
from . import higher
from .spec import closest

__all__ = ["Dimension", "Sided", "DesignSpace", "catalogue", "STEP"]

STEP = 1e-30   # the complex step: Im f(x + i·STEP)/STEP is f'(x) to rounding
SHAPE_ITERATIONS = 60
RANK = 1e-6    # a link's lengths whose Jacobian's singular values fall below this (relative) repeat one another


@dataclass(frozen=True)
class Dimension:
    """One dimension of a model that a tolerance may name, with its unit and nominal value.

    Attributes
    ----------
    name : str
        As a `[tolerances]` row names it: "links.2.length", "joints.C.x", "points.M.offset",
        "input.zero", a parameter's name, ...
    kind : str
        "length" (target (link, entry index)), "coordinate" (joint, axis), "guide" (joint), "offset"
        (joint), "point" (point, field: "x", "y", "fraction", "distance", "offset"), "zero" (input
        index), "higher" (a higher pair, its number: "radii", "radius", "guide", "at", "face",
        "centre", "curve_radius", entry index; `higher.higher_dimensions`), "parameter" (its name).
    target : tuple
        What the dimension belongs to (see `kind`).
    unit : str
        "length", "deg", "rad", "input", "plain" or a parameter's unit word.
    scale : float
        SI per unit: a band of b units is b·scale in SI.
    nominal : float
        The nominal value, in its unit.

    Examples
    --------
    >>> from mbplanar.accuracy import catalogue
    >>> from mbplanar.accuracy.run import load
    >>> template, raw, engine = load("models/slider_crank.toml")
    >>> guide = catalogue(engine, raw, template)["joints.Bp.guide"]
    >>> guide.kind, guide.unit, round(guide.scale, 6), guide.nominal      # degrees, 0.017453 rad each
    ('guide', 'deg', 0.017453, 0.0)
    """

    name: str
    kind: str
    target: tuple
    unit: str
    scale: float
    nominal: float


@dataclass
class Sided:
    """The made geometry of D designs, link by link, in the frames of the nominal drawn pose.

    Arrays may be complex: evaluated at imaginary deviations they carry the exact first derivatives
    (the complex step, `imag`).

    Attributes
    ----------
    side : dict
        {(joint, link): (2, D) ndarray}: the joint's point on that link, m.
    guide : dict
        {joint: (2, D) ndarray}: a prismatic pair's guide direction on its carrier.
    point : dict
        {point: (2, D) ndarray}: a point of interest on its link, m.
    zero : (n_in, D) ndarray
        Each input's zero (the joint value at φ = 0), SI.
    alpha : dict
        {link: (D,) ndarray}: the direction of the link's reference line in its frame, rad.
    ok : (D,) ndarray of bool
        The designs whose link shapes could be met.
    higher : dict
        Each higher pair's made numbers (`higher.nominal_numbers`' keys, designs last).

    Examples
    --------
    A slider-crank made with its rod 1 mm long: pin B moves on the rod, A stays:

    >>> import numpy as np
    >>> from mbplanar.accuracy import DesignSpace
    >>> from mbplanar.accuracy.run import load
    >>> template, raw, engine = load("models/slider_crank.toml")
    >>> made = DesignSpace(engine, raw, template, ["links.2.length"]).sided(np.array([[0.0], [1e-3]]))
    >>> rod = made.side[("B", "2")] - made.side[("A", "2")]
    >>> np.hypot(*rod).round(12).tolist(), made.ok.tolist()       # nominal and made rod, m
    ([0.3, 0.301], [True, True])
    """

    side: dict
    guide: dict
    point: dict
    zero: np.ndarray
    alpha: dict
    ok: np.ndarray
    higher: dict = field(default_factory=dict)

    def imag(self, step: float = STEP) -> "Sided":
        """The derivative parts (Im / step) of a geometry evaluated at imaginary deviations."""
        im = lambda x: np.imag(x) / step  # noqa: E731
        return Sided({k: im(v) for k, v in self.side.items()}, {k: im(v) for k, v in self.guide.items()},
                     {k: im(v) for k, v in self.point.items()}, im(self.zero),
                     {k: im(v) for k, v in self.alpha.items()}, self.ok,
                     {h: {k: im(v) for k, v in nums.items()} for h, nums in self.higher.items()})


def _cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1]


def _turn(d0, d):
    """The angle from the fixed direction d0 (2,) to d (2, D), analytic (|angle| < 90°)."""
    return np.arctan(_cross(d0, d) / _dot(d0, d))


def _column(v, count):
    return np.broadcast_to(np.asarray(v)[:, None], (2, count)) if np.ndim(v) == 1 else v


@dataclass
class _LinkShape:
    """A link whose declared lengths fix some of its points: those points (`names`, the first of each
    coincident group), their nominal locals x0 (2n,), the lengths' ends (E, 2) as indices into `names`,
    the nominal lengths (E,) and the pseudo-inverse of the lengths' Jacobian (2n, E)."""

    link: str
    names: list
    x0: np.ndarray
    ends: np.ndarray
    nominal: np.ndarray
    pinv: np.ndarray
    jac: np.ndarray
    alias: dict = field(default_factory=dict)

    def lengths(self, x):
        p, q = self.ends[:, 0], self.ends[:, 1]
        dx = x[2 * q] - x[2 * p]
        dy = x[2 * q + 1] - x[2 * p + 1]
        return np.sqrt(dx * dx + dy * dy)


class DesignSpace:
    """The toleranced dimensions of one model, and the geometry of designs made with deviations from them.

    `names` and `dimensions` list the toleranced dimensions in order; `sided(delta)` builds the made
    geometry (`Sided`) of deviations `delta` (D, K, SI), `derivatives()` its exact first derivatives.

    Parameters
    ----------
    engine : Engine
        The nominal model's engine (its exact drawn pose).
    raw : Mechanism
        The same model as read, before its assembly (its declared lengths, points built along others).
    template : Template, optional
        The model's table, for the dimensions a `[parameters]` entry stands for.
    names : sequence of str
        The toleranced dimensions, in order (`catalogue` lists a model's).

    Raises
    ------
    ModelError
        A name that is not a dimension of the model (with the closest), or a dimension without effect or
        that the link's other lengths contradict.

    Examples
    --------
    >>> from mbplanar.accuracy import DesignSpace
    >>> from mbplanar.accuracy.run import load
    >>> template, raw, engine = load("models/slider_crank.toml")
    >>> space = DesignSpace(engine, raw, template, ["links.1.length", "links.2.length"])
    >>> space.names, [d.nominal for d in space.dimensions]
    (('links.1.length', 'links.2.length'), [0.1, 0.3])
    """

    def __init__(self, engine, raw, template=None, names=()):
        self.engine, self.raw, self.template = engine, raw, template
        mech = engine.mech
        self.mech = mech
        self.source = mech.source
        self.centre = np.asarray(engine.centre, float)    # the made geometry sits in the engine's frame
        self.exact = {n: np.array(j.at, float) - self.centre for n, j in mech.joints.items()}
        self.exact.update({n: np.array(p.at, float) - self.centre for n, p in mech.points.items()})
        self.shapes = {s.link: s for s in (_shape(mech, raw, link, self.centre) for link in raw.links)
                       if s is not None}
        every = catalogue(engine, raw, template, self.shapes)
        self.dimensions = []
        for name in names:
            if name not in every:
                raise ModelError(f"'{name}' is not a dimension of the model{closest(name, every)}",
                                 source=self.source, where="[tolerances]")
            self.dimensions.append(every[name])
        self.dimensions = tuple(self.dimensions)
        self.names = tuple(d.name for d in self.dimensions)
        self._nominal_template = None
        self._derivatives = None
        self.derived = {n for n in mech.higher if higher.derived_radius(template, n)}
        if template is not None and any(d.kind == "parameter" for d in self.dimensions):
            self._nominal_template = _template_numbers(template, template.defaults())
        self._check_lengths()

    # -- the geometry of designs ----------------------------------------------------------------------
    def sided(self, delta) -> Sided:
        """The made geometry of designs with deviations `delta` (D, K) from the toleranced dimensions (SI,
        in the order of `names`); real, or complex for the complex step."""
        delta = np.asarray(delta)
        if delta.ndim != 2 or delta.shape[1] != len(self.dimensions):
            raise ValueError(f"delta must be (D, {len(self.dimensions)}), got {delta.shape}")
        count = delta.shape[0]
        mech, raw = self.mech, self.raw
        dtype = np.result_type(delta.dtype, float)
        shift = {n: np.zeros((2, count), dtype) for n in self.exact}
        turn = {n: np.zeros(count, dtype) for n, j in mech.joints.items() if j.kind == "P"}
        offset = {n: np.zeros(count, dtype) for n in turn}
        zero = np.stack([np.full(count, i.zero * i.scale, dtype) for i in mech.inputs])
        lengths = {k: np.broadcast_to(s.nominal[:, None], (len(s.nominal), count)).astype(dtype)
                   for k, s in self.shapes.items()}
        fields = {n: {f: np.full(count, v, dtype) for f, v in _along_fields(p).items()}
                  for n, p in raw.points.items() if p.along is not None}
        pairs = {n: {} for n in mech.higher}
        params = {}
        for k, dim in enumerate(self.dimensions):
            d = delta[:, k]
            if dim.kind == "coordinate":
                shift[dim.target[0]][dim.target[1]] += d
            elif dim.kind == "guide":
                turn[dim.target[0]] += d
            elif dim.kind == "offset":
                offset[dim.target[0]] += d
            elif dim.kind == "length":
                lengths[dim.target[0]][dim.target[1]] += d
            elif dim.kind == "point":
                name, what = dim.target
                if what in ("x", "y"):
                    shift[name]["xy".index(what)] += d
                else:
                    fields[name][what] += d
            elif dim.kind == "zero":
                zero[dim.target[0]] += d
            elif dim.kind == "higher":
                _change(pairs[dim.target[0]], dim.target[1], dim.target[2], d, count)
            else:
                params[dim.name] = dim.nominal + d / dim.scale
        if params:
            self._parameter_changes(params, count, shift, turn, zero, lengths, fields, pairs)
        shaped, ok = self._shapes(lengths, count)
        side = {}
        for name, j in mech.joints.items():
            for link in j.links:
                side[(name, link)] = shaped.get((link, name), _column(self.exact[name], count) + shift[name])
        point = {}
        for name, p in mech.points.items():
            if raw.points[name].along is None:
                point[name] = shaped.get((p.link, name), _column(self.exact[name], count) + shift[name])
        guide = {}
        for name, j in mech.joints.items():
            if j.kind == "P":
                side[(name, j.carrier)], guide[name] = self._guide(name, j, side, point, turn[name],
                                                                   offset[name], count)
        for name, p in raw.points.items():
            if p.along is not None:
                a, b = (self._local(p.link, n, side, point) for n in p.along)
                point[name] = _along(a, b, fields[name])
        alpha = {link: self._alpha(link, side, point, guide, count) for link in self.engine.links}
        made = {}
        for name, changes in pairs.items():
            made[name] = higher.nominal_numbers(self.engine, name, count, dtype)
            higher.apply(self.engine, name, made[name], changes, side, point, name in self.derived)
        return Sided(side, guide, point, zero, alpha, ok, made)

    def derivatives(self) -> Sided:
        """d(made geometry)/d(each dimension) at nominal: arrays (2, K) and (K,), per SI unit (computed
        once, kept)."""
        if self._derivatives is None:
            k = len(self.dimensions)
            self._derivatives = self.sided(np.eye(k) * (1j * STEP)).imag()
        return self._derivatives

    def nominal(self) -> Sided:
        """The nominal geometry (one design)."""
        return self.sided(np.zeros((1, len(self.dimensions))))

    # -- the steps ------------------------------------------------------------------------------------
    def _parameter_changes(self, params, count, shift, turn, zero, lengths, fields, pairs):
        """What the toleranced parameters change, as the template computes it: the changes of the drawn
        coordinates, guides, zeros, link lengths, point fields and higher pairs' numbers from their
        nominal values."""
        values = {**self.template.defaults(), **params}
        new, old = _template_numbers(self.template, values), self._nominal_template
        scale = self.mech.units.length_scale
        for name, got in new["higher"].items():
            for what, v in got.items():
                before = old["higher"][name][what]
                unit = math.pi / 180.0 if what in ("guide", "face") else scale
                if isinstance(v, tuple):
                    for k, (a, b) in enumerate(zip(v, before)):
                        _change(pairs[name], what, k, (a - b) * unit, count)
                else:
                    _change(pairs[name], what, 0, (v - before) * unit, count)
        for name, (x, y) in new["at"].items():
            if name in shift:
                shift[name][0] += (x - old["at"][name][0]) * scale
                shift[name][1] += (y - old["at"][name][1]) * scale
        for name, g in new["guide"].items():
            if name in turn:
                turn[name] += (g - old["guide"][name]) * (math.pi / 180.0)
        for i, (z, inp) in enumerate(zip(new["zero"], self.mech.inputs)):
            zero[i] += (z - old["zero"][i]) * inp.scale
        for link, shape in self.shapes.items():
            for e, key in enumerate(shape_keys(self.raw, link)):
                if key in new["lengths"]:
                    lengths[link][e] += (new["lengths"][key] - old["lengths"][key]) * scale
        for name, got in new["fields"].items():
            for what, v in got.items():
                change = v - old["fields"][name][what]
                if what in ("x", "y") and name in shift:
                    shift[name]["xy".index(what)] += change * scale
                elif name in fields and what in fields[name]:
                    fields[name][what] += change * (1.0 if what == "fraction" else scale)

    def _shapes(self, lengths, count):
        """The locals of every link's length-fixed points (by (link, name), aliases included), by chord
        iterations x ← x − J0⁺(ℓ(x) − L) from the nominal shape, and which designs met their lengths."""
        out, ok = {}, np.ones(count, bool)
        for link, s in self.shapes.items():
            target = lengths[link]
            x = np.broadcast_to(s.x0[:, None], (len(s.x0), count)).astype(target.dtype)
            scale = 1e-14 * max(1.0, float(np.max(s.nominal)))
            for _ in range(SHAPE_ITERATIONS):
                miss = s.lengths(x) - target
                x = x - s.pinv @ miss
                if np.all(np.abs(miss) <= scale):
                    break
            miss = s.lengths(x) - target
            with np.errstate(invalid="ignore"):
                ok &= np.all(np.abs(miss.real) <= 1e-9 * max(1.0, float(np.max(s.nominal))), axis=0)
            for k, name in enumerate(s.names):
                out[(link, name)] = x[2 * k:2 * k + 2]
            for name, first in s.alias.items():
                out[(link, name)] = out[(link, first)]
        return out, ok

    def _local(self, link, name, side, point):
        """Point `name` (a joint or a point of interest) in link `link`'s frame."""
        return side[(name, link)] if name in self.mech.joints else point[name]

    def _guide(self, name, j, side, point, turn, offset, count):
        """A prismatic pair's line point and direction on its carrier."""
        if j.guide_points is not None:
            a, b = (self._local(j.carrier, n, side, point) for n in j.guide_points)
            a0, b0 = (self.exact[n] for n in j.guide_points)
            t = float(np.dot(self.exact[name] - a0, b0 - a0) / np.dot(b0 - a0, b0 - a0))
            d = b - a
            u = d / np.sqrt(_dot(d, d))
            line = a + t * d
        else:
            u0 = np.array([math.cos(math.radians(j.guide_deg)), math.sin(math.radians(j.guide_deg))])
            c, s = np.cos(turn), np.sin(turn)
            u = np.stack([c * u0[0] - s * u0[1], s * u0[0] + c * u0[1]])
            line = side[(name, j.carrier)]
        n = np.stack([-u[1], u[0]])
        return line + offset * n, u

    def _alpha(self, link, side, point, guide, count):
        """The direction of a link's reference line in its frame (rad, with the link's angle offset)."""
        alpha0 = self.engine.reference_angle[link]
        if link == self.mech.ground:
            return np.full(count, alpha0)
        ref = reference_points(self.mech, link)
        if ref is not None:
            p, q = (self._local(link, n, side, point) for n in ref)
            return alpha0 + _turn(self.exact[ref[1]] - self.exact[ref[0]], q - p)
        g = next((j for j in self.mech.joints_of(link) if j.kind == "P"), None)
        if g is None:
            return np.full(count, alpha0)
        u0 = np.array([math.cos(math.radians(g.guide_deg)), math.sin(math.radians(g.guide_deg))])
        return alpha0 + _turn(u0, guide[g.name])

    def _check_lengths(self):
        """Refuse a toleranced length (or a parameter moving lengths) that the link's other lengths
        contradict to first order: its change is not in the range of the lengths' Jacobian."""
        if not self.dimensions:
            return
        k = len(self.dimensions)
        count = k
        lengths = {}
        for link, s in self.shapes.items():
            lengths[link] = np.zeros((len(s.nominal), count))
        for i, dim in enumerate(self.dimensions):
            if dim.kind == "length":
                lengths[dim.target[0]][dim.target[1], i] = 1.0
        if self._nominal_template is not None:
            d = self.template_length_derivatives()
            for link in lengths:
                lengths[link] += d.get(link, 0.0)
        for link, s in self.shapes.items():
            change = lengths[link]
            met = s.jac @ (s.pinv @ change)
            for i in np.flatnonzero(np.max(np.abs(met - change), axis=0) > 1e-8 * np.max(np.abs(change), axis=0)):
                names = ", ".join(f"{s.names[a]}-{s.names[b]}" for a, b in s.ends)
                raise ModelError(f"'{self.dimensions[i].name}' changes the lengths of link '{link}', which its "
                                 f"other lengths ({names}) fix together: its points are drawn in line or the "
                                 "lengths repeat one another, so that one of them cannot change alone",
                                 source=self.source, where="[tolerances]")

    def template_length_derivatives(self) -> dict:
        """d(each declared length)/d(each toleranced parameter) (link → (E, K)), by the complex step."""
        k = len(self.dimensions)
        values = {**self.template.defaults()}
        out = {}
        for i, dim in enumerate(self.dimensions):
            if dim.kind != "parameter":
                continue
            got = _template_numbers(self.template, {**values, dim.name: dim.nominal + 1j * STEP / dim.scale})
            for link in self.shapes:
                for e, key in enumerate(shape_keys(self.raw, link)):
                    if key in got["lengths"]:
                        out.setdefault(link, np.zeros((len(self.shapes[link].nominal), k)))[e, i] = \
                            np.imag(got["lengths"][key]) / STEP * self.mech.units.length_scale
        return out


def _change(changes: dict, what: str, k: int, d, count: int):
    """Add the deviation d (D,) of entry k of a higher pair's number `what` to its `changes`: a pair of
    values ("at", "centre", a gear's "radii") as (2, D), one value as (D,)."""
    if what in ("at", "centre", "radii"):
        out = changes.get(what, np.zeros((2, count))).astype(np.result_type(d, float))
        out[k] = out[k] + d
        changes[what] = out
    else:
        changes[what] = changes.get(what, 0.0) + d


def _along_fields(p) -> dict:
    """The numbers that build a point along two others: fraction or distance, and offset (SI)."""
    out = {"distance": p.distance} if p.distance is not None else {"fraction": p.fraction}
    out["offset"] = p.offset
    return out


def _along(a, b, fields):
    """The point at `distance` (or `fraction`) from a towards b and `offset` to its left; (2, D)."""
    d = b - a
    length = np.sqrt(_dot(d, d))
    u = d / length
    dist = fields["distance"] if "distance" in fields else fields["fraction"] * length
    return a + dist * u + fields["offset"] * np.stack([-u[1], u[0]])


def shape_keys(raw, link) -> list:
    """The keys of a link's declared lengths as `_template_numbers` names them: (link, P, Q) in order."""
    out = []
    for p, q, _ in raw.links[link].lengths:
        out.append((link, p, q))
    return out


def _resolved(raw, link, p, q):
    """A lengths entry's two points ('length' rows name the link's two revolute joints)."""
    if p == "" and q == "":
        revolute = [j.name for j in raw.joints_of(link) if j.kind == "R"]
        if len(revolute) != 2:
            return None
        return revolute[0], revolute[1]
    return p, q


def _shape(mech, raw, link, centre=(0.0, 0.0)) -> _LinkShape | None:
    """The length-fixed points of `link` (None when it declares no lengths), in the frame centred on
    `centre` (world coordinates, (2,))."""
    entries = [(_resolved(raw, link, p, q), v) for p, q, v in raw.links[link].lengths]
    entries = [(pq, v) for pq, v in entries if pq is not None]
    if not entries:
        return None
    own = {j.name: np.array(j.at, float) - centre for j in mech.joints_of(link)}
    own.update({n: np.array(p.at, float) - centre for n, p in mech.points.items() if p.link == link})
    size = max([1e-300] + [float(np.hypot(*(a - b))) for a in own.values() for b in own.values()])
    first = {}
    for name, xy in own.items():
        twin = next((f for f in first if float(np.hypot(*(own[f] - xy))) <= 1e-12 * size), None)
        first[name] = twin if twin is not None else name
    names = []
    for (p, q), _ in entries:
        for n in (first.get(p, p), first.get(q, q)):
            if n not in names:
                names.append(n)
    x0 = np.concatenate([own[n] for n in names])
    ends = np.array([(names.index(first.get(p, p)), names.index(first.get(q, q))) for (p, q), _ in entries])
    nominal = np.array([float(np.hypot(*(own[names[b]] - own[names[a]]))) for a, b in ends])
    jac = np.zeros((len(ends), len(x0)))
    for e, (a, b) in enumerate(ends):
        u = (x0[2 * b:2 * b + 2] - x0[2 * a:2 * a + 2]) / nominal[e]
        jac[e, 2 * b:2 * b + 2], jac[e, 2 * a:2 * a + 2] = u, -u
    alias = {n: f for n, f in first.items() if f != n and f in names}
    return _LinkShape(link, names, x0, ends, nominal, np.linalg.pinv(jac, rcond=RANK), jac, alias)


def _template_numbers(template, values) -> dict:
    """The numbers of the table that `values` (parameters in their units) set: every joint's drawn
    coordinates and guide angle, each input's zero (file units), each declared length and each point's
    coordinates and along numbers."""
    return {"at": template.positions(values), "guide": template.guides(values), "zero": template.input_zero(values),
            "lengths": template.link_lengths(values), "fields": template.point_fields(values),
            "higher": higher.template_numbers(template, values)}


def catalogue(engine, raw, template=None, shapes=None) -> dict:
    """Every dimension of a model that a tolerance may name.

    In the model's order: lengths, joints' coordinates, guides and offsets, points, the higher pairs'
    numbers, the inputs' zeros, then the parameters. A coordinate that every link's lengths fix (it
    changes nothing) is left out.

    Parameters
    ----------
    engine : Engine
        The nominal model's engine.
    raw : Mechanism
        The same model as read, before its assembly.
    template : Template, optional
        The model's table (adds its parameters).
    shapes : dict, optional
        The links' shapes when the caller has them (`DesignSpace` passes its own); built otherwise.

    Returns
    -------
    dict
        {name: `Dimension`}.

    Raises
    ------
    KeyError
        `raw` not the model `engine` was built from (a joint or link of one missing in the other); a
        model that reads and assembles gives no error here.

    Examples
    --------
    >>> from mbplanar.accuracy import catalogue
    >>> from mbplanar.accuracy.run import load
    >>> template, raw, engine = load("models/slider_crank.toml")
    >>> names = list(catalogue(engine, raw, template))
    >>> names[:4], names[-3:]
    (['links.1.length', 'links.2.length', 'joints.O.x', 'joints.O.y'], ['joints.Bp.guide', 'joints.Bp.offset', 'input.zero'])
    """
    mech = engine.mech
    units = mech.units
    length, deg = units.length_scale, math.pi / 180.0
    shapes = shapes if shapes is not None else {
        s.link: s for s in (_shape(mech, raw, link) for link in raw.links) if s is not None}
    out = {}

    def add(name, kind, target, unit, scale, nominal):
        out[name] = Dimension(name, kind, target, unit, scale, nominal)

    for link, lk in raw.links.items():
        s = shapes.get(link)
        for e, (p, q, v) in enumerate(lk.lengths):
            if s is None or _resolved(raw, link, p, q) is None:
                continue
            name = f"links.{link}.length" if p == q == "" else f"links.{link}.{p}-{q}"
            add(name, "length", (link, e), "length", length, v / length)
    fixed = {(link, n) for link, s in shapes.items() for n in list(s.names) + list(s.alias)}
    for name, j in mech.joints.items():
        if not all((link, name) in fixed for link in j.links):
            for axis, word in enumerate("xy"):
                add(f"joints.{name}.{word}", "coordinate", (name, axis), "length", length, j.at[axis] / length)
        if j.kind == "P":
            if j.guide_points is None:
                add(f"joints.{name}.guide", "guide", (name,), "deg", deg, j.guide_deg)
            add(f"joints.{name}.offset", "offset", (name,), "length", length, 0.0)
    for name, p in raw.points.items():
        if p.along is None:
            if (p.link, name) not in fixed:
                for axis, word in enumerate("xy"):
                    add(f"points.{name}.{word}", "point", (name, word), "length", length,
                        mech.points[name].at[axis] / length)
        else:
            for what, v in _along_fields(p).items():
                add(f"points.{name}.{what}", "point", (name, what), "plain" if what == "fraction" else "length",
                    1.0 if what == "fraction" else length, v if what == "fraction" else v / length)
    higher.higher_dimensions(engine, add, template)
    several = len(mech.inputs) > 1
    for i, inp in enumerate(mech.inputs):
        add(f"inputs.{inp.joint}.zero" if several else "input.zero", "zero", (i,), inp.unit, inp.scale, inp.zero)
    if template is not None:
        for name, (unit, scale) in template_parameters(template, mech).items():
            if name not in out:
                add(name, "parameter", (name,), unit, scale, template.parameters[name].value)
    return out


def template_parameters(template, mech) -> dict:
    """The parameters that change the geometry (a length, coordinate, guide, zero or point field), with
    their unit word and SI scale: a parameter with a unit uses it; one without takes the kind of the
    fields it stands for."""
    kinds = template.parameter_kinds()
    for name, got in higher.parameter_kinds(template).items():
        kinds.setdefault(name, set()).update(got)
    out = {}
    for name, p in template.parameters.items():
        used = kinds.get(name, set()) - {"mass", "inertia", "omega", "drawn_at"}
        if not used:
            continue
        if p.unit in ("m", "mm", "cm"):
            out[name] = (p.unit, {"m": 1.0, "mm": 1e-3, "cm": 1e-2}[p.unit])
        elif p.unit in ("deg", "rad"):
            out[name] = (p.unit, 1.0 if p.unit == "rad" else math.pi / 180.0)
        elif used <= {"length"}:
            out[name] = ("length", mech.units.length_scale)
        elif used <= {"angle"}:
            out[name] = ("deg", math.pi / 180.0)
        elif used <= {"input"}:
            inp = mech.inputs[0]
            out[name] = (inp.unit, inp.scale)
        elif used <= {"plain"}:
            out[name] = ("plain", 1.0)
    return out
