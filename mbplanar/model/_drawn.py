"""The higher pairs in the drawn pose of an assembled mechanism: where each one's centres, pitch point or
contact are, checked against the drawing, and the lower pairs that replace it.

`drawn_pairs(mech)` gives a `PairGeometry` per higher pair:

- gear: the centre of each gear (a revolute joint of the gear where a joint of the carrier is: the
  centre is a point of both), the carrier (named, or the one link that holds both centres), the pitch
  point, and the check that the centres are r_a + r_b (external) or r_b − r_a (internal) apart;
- rack: the pinion's centre (its revolute joint at the pitch radius from the pitch line) and the line;
- cam: the curve the follower's point runs on (the profile for a knife, the profile's offset by the
  radius for a roller or a circular face), the contact's parameter on it and the check that the follower
  touches the profile; for a flat face, the contact where the profile's tangent is along the face;
- slot: the pin's parameter on the slot's centre line and the check that the pin is on it.

`replacement` gives the two pairs of the link that replaces a higher pair in the equivalent lower-pair
mechanism (the textbook rule): revolute pairs at the centres of curvature of the two contacting profiles
at the contact, a prismatic pair where a profile is straight (a rack, a flat face, a straight stretch).
A pair that does not fit the drawing is a `ModelError` naming the joint and the numbers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ._curves import Offset, Shape, curvature, shape
from ._model import HigherPair, Mechanism
from ._scale import drawing_size

__all__ = ["PairGeometry", "drawn_pairs", "drawn_pair", "replacement", "mechanism_size", "CONTACT_TOL"]

CONTACT_TOL = 1e-6   # how far (relative to the mechanism's size) a drawn contact may miss: gears whose centre
                     # distance is off by more cannot mesh, a follower farther from its cam does not touch it


@dataclass(frozen=True)
class PairGeometry:
    """A higher pair in the drawn pose.

    `centres` (gear: both gears' centres; rack: the pinion's), `carrier` (gear), `pitch` the pitch point
    (gear, rack) or the contact point (cam, slot), `normal` the unit common normal there, from the first
    link's side into the second's (a gear: on the line of centres, from the first gear's teeth into the
    second's; a rack: from the pinion's centre), `tangent` the line's
    direction (rack), `path` the curve the follower's or the pin's point runs on, drawn on the first link
    (a `Shape`), `profile` the cam's profile itself, `u0` the contact's parameter on `path` (on `profile`
    for a flat face), `side` the side of the profile the follower is on (+1 left of its direction).

    `pair` is the table's `HigherPair`. Points are in the drawing's coordinates (m), made by `drawn_pairs`.

    Examples
    --------
    >>> from mbplanar.model import drawn_pairs, read_model
    >>> gear = drawn_pairs(read_model("models/geared_five_bar.toml"))["G"]
    >>> [float(v) for v in gear.pitch], [float(v) for v in gear.normal]
    ([0.04, 0.0], [1.0, 0.0])
    """

    pair: HigherPair
    pitch: tuple
    normal: tuple
    centres: tuple = ()
    carrier: str | None = None
    tangent: tuple | None = None
    path: Shape | None = None
    profile: Shape | None = None
    u0: float = 0.0
    side: float = 1.0


def mechanism_size(mech: Mechanism) -> float:
    """The length every tolerance of a model is relative to: the drawing's size.

    Parameters
    ----------
    mech : Mechanism
        The model.

    Returns
    -------
    float
        `drawing_size` (m), or 1 for a drawing of one place.

    Raises
    ------
    Nothing on a `Mechanism`.

    Examples
    --------
    >>> from mbplanar.model import mechanism_size, read_model
    >>> round(mechanism_size(read_model("models/cam_follower.toml")), 6)
    0.05
    """
    return drawing_size(mech) or 1.0


def drawn_pairs(mech: Mechanism) -> dict[str, PairGeometry]:
    """Every higher pair of a model placed in its drawn pose, checked against the drawing.

    Parameters
    ----------
    mech : Mechanism
        The model (its higher pairs and the joints they hang on).

    Returns
    -------
    dict of str to PairGeometry
        By the pair's name; empty for a model of lower pairs only.

    Raises
    ------
    ModelError
        A pair that does not fit the drawing: gears whose centre distance is not the sum (or difference)
        of their radii, a follower that does not touch its cam, a pin off its slot, ... naming the pair.

    Examples
    --------
    >>> from mbplanar.model import drawn_pairs, read_model
    >>> slot = drawn_pairs(read_model("models/scotch_yoke.toml"))["S"]
    >>> slot.pair.kind, slot.u0, [round(float(v), 6) for v in slot.pitch]
    ('slot', 0.08, [0.05, -0.0])
    """
    size = mechanism_size(mech)
    return {name: drawn_pair(mech, h, size) for name, h in mech.higher.items()}


def _fail(mech: Mechanism, h: HigherPair, message: str):
    raise ModelError(message, source=mech.source, where=f"joint '{h.name}' ({h.kind})")


def _length(mech: Mechanism, value: float) -> str:
    unit = mech.units
    return f"{value / unit.length_scale:.6g} {unit.length}"


def drawn_pair(mech: Mechanism, h: HigherPair, size: float | None = None) -> PairGeometry:
    size = mechanism_size(mech) if size is None else size
    return {"gear": _gear, "rack": _rack, "cam": _cam, "slot": _slot}[h.kind](mech, h, size)


def _pivots(mech: Mechanism, link: str) -> list[tuple[str, np.ndarray]]:
    """(name, drawn place) of the revolute joints of a link."""
    return [(j.name, np.array(j.at, float)) for j in mech.joints_of(link) if j.kind == "R"]


def _holds(mech: Mechanism, link: str, at: np.ndarray, tol: float) -> bool:
    """Whether a joint of `link` is drawn at `at`: the point is then one of the link's own."""
    return any(math.dist(j.at, at) <= tol for j in mech.joints_of(link))


def _gear(mech, h, size) -> PairGeometry:
    a, b = h.links
    ra, rb = h.radii
    tol = CONTACT_TOL * size
    need = abs(rb - ra) if h.internal else ra + rb
    links = [h.carrier] if h.carrier is not None else [c for c in mech.all_links if c not in h.links]
    found = []
    for c in links:
        ca = [p for _, p in _pivots(mech, a) if _holds(mech, c, p, tol)]
        cb = [p for _, p in _pivots(mech, b) if _holds(mech, c, p, tol)]
        pairs = [(pa, pb) for pa in ca for pb in cb if math.dist(pa, pb) > tol]
        if pairs:
            found.append((c, pairs))
    if not found:
        if h.carrier is not None:
            _fail(mech, h, f"the carrier '{h.carrier}' holds no centre of gear '{a}' and of gear '{b}': each gear "
                  "turns about a revolute joint drawn where a joint of the carrier is")
        _fail(mech, h, f"no link holds the centres of both gears '{a}' and '{b}' (each gear turns about a revolute "
              "joint drawn where a joint of the carrier is): name the 'carrier'")
    best = None
    for c, pairs in found:
        for pa, pb in pairs:
            miss = abs(math.dist(pa, pb) - need)
            if best is None or miss < best[0]:
                best = (miss, c, pa, pb)
    carriers = {c for c, pairs in found if any(abs(math.dist(pa, pb) - need) <= tol for pa, pb in pairs)}
    if len(carriers) > 1 and h.carrier is None:
        _fail(mech, h, f"links {', '.join(sorted(carriers))} all hold both gears' centres: name the 'carrier'")
    miss, carrier, pa, pb = best
    if miss > tol:
        _fail(mech, h, f"the gears' centres are {_length(mech, math.dist(pa, pb))} apart, but their pitch radii "
              f"{_length(mech, ra)} and {_length(mech, rb)} need {_length(mech, need)} "
              f"({'the difference, internal' if h.internal else 'their sum'}): they cannot mesh in the drawn pose")
    if h.internal:   # the larger gear has the internal teeth (a ring), whichever is named first
        (pin, r_pin), ring = ((pa, ra), pb) if ra < rb else ((pb, rb), pa)
        pitch = pin + r_pin * (pin - ring) / np.linalg.norm(pin - ring)
    else:
        pitch = pa + ra * (pb - pa) / np.linalg.norm(pb - pa)
    if h.at is not None and math.dist(h.at, pitch) > tol:
        _fail(mech, h, f"the pitch point 'at' = ({_length(mech, h.at[0])}, {_length(mech, h.at[1])}) is not where "
              f"the centres and radii put it, ({_length(mech, pitch[0])}, {_length(mech, pitch[1])})")
    # the normal from gear a's teeth into gear b's: towards b's centre, away from it for a ring
    towards_b = (pb - pitch) / np.linalg.norm(pb - pitch)
    normal = -towards_b if h.internal and rb > ra else towards_b
    return PairGeometry(h, tuple(pitch), tuple(normal), (tuple(pa), tuple(pb)), carrier)


def _rack(mech, h, size) -> PairGeometry:
    pinion = h.links[0]
    tol = CONTACT_TOL * size
    at = np.array(h.at, float)
    near = [(abs(math.dist(p, at) - h.radius), name, p) for name, p in _pivots(mech, pinion)]
    if not near:
        _fail(mech, h, f"the pinion '{pinion}' has no revolute joint: it turns about its centre")
    miss, _, centre = min(near, key=lambda t: t[0])
    if miss > tol:
        _fail(mech, h, f"the pinion's centre is {_length(mech, math.dist(centre, at))} from the pitch point 'at', "
              f"not its pitch radius {_length(mech, h.radius)}: the rack's line does not touch its pitch circle")
    out = (at - centre) / np.linalg.norm(at - centre)
    line = np.array([-out[1], out[0]])
    if h.guide is not None:
        given = np.array([math.cos(h.guide), math.sin(h.guide)])
        if abs(float(np.dot(given, out))) > 1e-6:
            _fail(mech, h, f"the rack's line (guide {math.degrees(h.guide):.6g}°) must be square to the line from "
                  f"the pinion's centre to the pitch point (at {math.degrees(math.atan2(out[1], out[0])):.6g}°)")
        line = given
    return PairGeometry(h, tuple(at), tuple(out), (tuple(centre),), tangent=tuple(line))


def _outward_side(mech, h, profile: Shape, u0: float, follower_at) -> float:
    """+1 when the side of the profile away from the cam's material is to the left of its direction at
    u0, −1 when to the right: a closed profile's outside; an open one's side where the follower is."""
    if profile.closed:
        u = np.linspace(profile.lo, profile.hi, 721)[:-1]
        x, y = profile.point(u)
        area = 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
        return -1.0 if area > 0 else 1.0       # counter-clockwise: the outside is on the right
    others = [j.at for j in mech.joints_of(h.links[1])]
    ref = np.mean(others, axis=0) if others else np.asarray(follower_at, float)
    c, d = profile.point(np.array([u0]))[:, 0], profile.point(np.array([u0]), 1)[:, 0]
    return 1.0 if d[0] * (ref[1] - c[1]) - d[1] * (ref[0] - c[0]) >= 0 else -1.0


def _unit_normal(path: Shape, u: float, side: float) -> np.ndarray:
    d = path.point(np.array([u]), 1)[:, 0]
    return side * np.array([-d[1], d[0]]) / np.hypot(*d)


def _cam(mech, h, size) -> PairGeometry:
    tol = CONTACT_TOL * size
    profile = shape(h.curve)
    at = np.asarray(h.at, float)
    if h.follower == "flat":
        return _flat(mech, h, profile, at, tol)
    u, dist = profile.closest(at)
    c, d1 = profile.point(np.array([u]))[:, 0], profile.point(np.array([u]), 1)[:, 0]
    left = 1.0 if d1[0] * (at[1] - c[1]) - d1[1] * (at[0] - c[0]) >= 0 else -1.0
    if h.follower == "knife":
        if dist > tol:
            _fail(mech, h, f"the knife's tip is {_length(mech, dist)} from the cam's profile: the follower does not "
                  "touch its cam in the drawn pose")
        side = _outward_side(mech, h, profile, u, at)
        return PairGeometry(h, tuple(c), tuple(_unit_normal(profile, u, side)), path=profile, profile=profile,
                            u0=u, side=side)
    if abs(dist - h.radius) > tol:
        _fail(mech, h, f"the {h.follower}'s centre is {_length(mech, dist)} from the cam's profile, not its radius "
              f"{_length(mech, h.radius)}: the follower does not touch its cam in the drawn pose")
    path = Offset(profile, left * h.radius)
    if path.stretch(np.array([u]))[0] <= 0:
        _fail(mech, h, f"the {h.follower} (radius {_length(mech, h.radius)}) is larger than the profile's radius of "
              "curvature at the contact: the profile is undercut there")
    return PairGeometry(h, tuple(c), tuple(_unit_normal(profile, u, left)), path=path, profile=profile, u0=u,
                        side=left)


def _flat(mech, h, profile: Shape, at: np.ndarray, tol: float) -> PairGeometry:
    """The contact of a flat face through `at` along `face` (default: the profile's tangent at the point
    nearest to `at`): where the profile's tangent is along the face and the profile touches its line."""
    if h.face is None:
        u, dist = profile.closest(at)
        if dist > tol:
            _fail(mech, h, f"the flat face's point 'at' is {_length(mech, dist)} from the cam's profile: without "
                  "'face' it is the contact point, and the follower does not touch its cam there")
    else:
        e = np.array([math.cos(h.face), math.sin(h.face)])
        grid = np.linspace(profile.lo, profile.hi, 4097)
        d1 = profile.point(grid, 1)
        cross = d1[0] * e[1] - d1[1] * e[0]
        roots = []
        for k in np.flatnonzero(np.sign(cross[:-1]) != np.sign(cross[1:])):
            lo, hi = grid[k], grid[k + 1]
            for _ in range(80):                 # bisection on the tangent's direction
                mid = 0.5 * (lo + hi)
                dm = profile.point(np.array([mid]), 1)[:, 0]
                if np.sign(dm[0] * e[1] - dm[1] * e[0]) == np.sign(cross[k]):
                    lo = mid
                else:
                    hi = mid
            roots.append(0.5 * (lo + hi))
        n = np.array([-e[1], e[0]])
        gaps = [(abs(float(np.dot(n, profile.point(np.array([r]))[:, 0] - at))), r) for r in roots]
        if not gaps:
            _fail(mech, h, f"the cam's profile is nowhere along the face's direction {math.degrees(h.face):.6g}°")
        dist, u = min(gaps)
        if dist > tol:
            _fail(mech, h, f"the flat face is {_length(mech, dist)} from the cam's profile where the profile runs along "
                  "it: the follower does not touch its cam in the drawn pose")
    c = profile.point(np.array([u]))[:, 0]
    side = _outward_side(mech, h, profile, u, at)
    return PairGeometry(h, tuple(c), tuple(_unit_normal(profile, u, side)), path=profile, profile=profile, u0=u,
                        side=side)


def _slot(mech, h, size) -> PairGeometry:
    tol = CONTACT_TOL * size
    path = shape(h.curve)
    at = np.asarray(h.at, float)
    u, dist = path.closest(at)
    if dist > tol:
        _fail(mech, h, f"the pin is {_length(mech, dist)} from the slot's centre line: it is not in its slot in the "
              "drawn pose")
    if not path.inside(np.array([u]), 1e-9 * path.period)[0]:
        _fail(mech, h, "the pin is beyond the end of its slot in the drawn pose")
    return PairGeometry(h, tuple(path.point(np.array([u]))[:, 0]), tuple(_unit_normal(path, u, 1.0)), path=path,
                        u0=u)


# -- the equivalent lower-pair mechanism ------------------------------------------------------------------
@dataclass(frozen=True)
class Replacement:
    """The link replacing a higher pair: its pairs (kind "R" or "P", the link, the drawn place: a centre of
    curvature for R, a point and direction (rad) for P), on the pair's first link, then on its second."""

    pairs: tuple


def _centre_of_curvature(curve: Shape, u: float, size: float):
    """("R", centre) of a curve at u, or ("P", (point, direction)) where it is straight."""
    d1, d2 = curve.point(np.array([u]), 1), curve.point(np.array([u]), 2)
    kappa = float(curvature(d1, d2)[0])
    c, d = curve.point(np.array([u]))[:, 0], d1[:, 0]
    if abs(kappa) * size < 1e-9:
        return "P", (tuple(c), math.atan2(d[1], d[0]))
    n = np.array([-d[1], d[0]]) / np.hypot(*d)
    return "R", tuple(c + n / kappa)


def replacement(g: PairGeometry, size: float) -> Replacement:
    """The link that replaces a higher pair in the equivalent lower-pair mechanism (for the structure).

    A gear pair is replaced by a link between the feet of its line of action on the two gears' centres,
    a rack by a revolute and a prismatic pair along the flank, a cam or slot by a pair at the profile's
    centre of curvature (prismatic where it is straight) and one at the follower.

    Parameters
    ----------
    g : PairGeometry
        The pair in its drawn pose (`drawn_pairs`).
    size : float
        The mechanism's size (m, `mechanism_size`): a curvature below 1e-9 / size counts as straight.

    Returns
    -------
    Replacement
        ``pairs``: (kind, link, place) on the pair's first link, then on its second; place a point for
        "R", (point, direction in rad) for "P".

    Raises
    ------
    Nothing on a `PairGeometry` from `drawn_pairs`.

    Examples
    --------
    >>> from mbplanar.model import drawn_pairs, mechanism_size, read_model, replacement
    >>> mech = read_model("models/geared_five_bar.toml")
    >>> pairs = replacement(drawn_pairs(mech)["G"], mechanism_size(mech)).pairs
    >>> [(kind, link, [round(float(v), 4) for v in at]) for kind, link, at in pairs]
    [('R', '1', [0.0047, 0.0129]), ('R', '4', [0.1106, -0.0257])]
    """
    h = g.pair
    a, b = h.links
    if h.kind == "gear":
        (pa, pb), m = (np.array(c) for c in g.centres), np.array(g.normal)
        t = np.array([-m[1], m[0]])
        line = math.cos(h.pressure_angle) * t + math.sin(h.pressure_angle) * m   # a line of action
        foot = lambda c: tuple(c + np.dot(np.array(g.pitch) - c, line) * line)  # noqa: E731
        return Replacement((("R", a, foot(pa)), ("R", b, foot(pb))))
    if h.kind == "rack":
        centre, m = np.array(g.centres[0]), np.array(g.normal)
        t = np.array(g.tangent)
        line = math.cos(h.pressure_angle) * t + math.sin(h.pressure_angle) * m
        foot = tuple(centre + np.dot(np.array(g.pitch) - centre, line) * line)
        flank = math.atan2(-line[0], line[1])
        return Replacement((("R", a, foot), ("P", b, (g.pitch, flank))))
    if h.kind == "slot":
        kind, where = _centre_of_curvature(g.path, g.u0, size)
        return Replacement(((kind, a, where), ("R", b, tuple(h.at))))
    kind, where = _centre_of_curvature(g.profile, g.u0, size)
    if h.follower == "flat":
        follower = ("P", b, (g.pitch, h.face if h.face is not None else math.atan2(-g.normal[0], g.normal[1])))
    else:
        follower = ("R", b, tuple(h.at))
    return Replacement(((kind, a, where), follower))
