"""What a kinematic diagram shows, as plain geometry over a batch of positions (no drawing library).

`build_scene(engine, motion)` turns a `Motion` into the shapes of a mechanism drawing, batch first:
revolute pairs (circles), ground pivots, sliders (blocks on their guides), guide lines fixed on their
carriers, links as bars (two attachment points, or all of them in line) or polygons (three or more),
points of interest. The matplotlib figures (`mbplanar.viz._plotting`) and the browser animation
(`mbplanar.viz._animation`) both draw a `Scene`, so a picture and an animation always agree.

Every shape is fixed on one link: it is given by its coordinates in the drawn pose and placed at each
position by the link's frame (xy = r_k + R(th_k)·s, see `mbplanar.kinematics`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Scene", "LinkShape", "Slider", "PairShape", "build_scene", "place", "joint_groups"]


@dataclass
class LinkShape:
    """How one moving link is drawn: kind 'bar' (outline (B, 2, 2): its two ends), 'polygon'
    (outline (B, n, 2), convex, in order) or 'block' (the link is only a slider block); `label` (B, 2)."""

    name: str
    kind: str
    outline: np.ndarray
    label: np.ndarray
    stubs: np.ndarray  # (B, n, 2, 2): short lines from points beside a bar to the bar


@dataclass
class Slider:
    """A prismatic pair: the block (corners (B, 4, 2), centre (B, 2)) of the slider link on the guide
    segment (B, 2, 2) fixed on the carrier; `grounded` when the carrier is the ground."""

    joint: str
    slider: str
    carrier: str
    centre: np.ndarray
    corners: np.ndarray
    guide: np.ndarray
    grounded: bool


@dataclass
class PairShape:
    """A higher pair's drawing: `lines` (kind, link, (B, n, 2) polyline, closed) — a gear's or a pinion's
    pitch circle ("pitch"), a rack's pitch line ("rack"), a cam's profile ("profile"), a roller or a
    circular face ("roller"), a knife ("knife"), a flat face ("face"), a slot's walls and centre line
    ("slot", "slot-centre") —, `marks` (B, m, 2, 2) the tooth marks, and `contact` (B, 2) the mesh point or
    the contact."""

    name: str
    kind: str
    lines: list
    marks: np.ndarray
    contact: np.ndarray


@dataclass
class Scene:
    """The shapes of a mechanism drawing at B positions (metres, world frame), ready for any renderer.

    Attributes
    ----------
    joint_names : list of str
        Every pair (a prismatic pair: its slider point).
    joint_xy : (B, J, 2) ndarray
        Their positions, m.
    revolute : list of str
        The revolute pairs.
    pivots : list of str
        The revolute pairs on the ground.
    links : list of LinkShape
        One per moving link: a bar, a polygon or a block, with its label's place.
    sliders : list of Slider
        One per prismatic pair: the block and its guide segment.
    point_names : list of str
        Points of interest.
    point_xy : (B, P, 2) ndarray
        Their positions, m.
    centres : set of str
        The points of interest that are centres of mass.
    size : float
        Characteristic length (for symbol sizes), m.
    phi : (B, n_in) ndarray
        Input values, SI.
    labels : dict
        {joint: text shown}: one label per group of coincident pairs.
    pairs : list of PairShape
        One per higher pair (pitch circles, profiles, contacts).

    `batch` is B; `extent()` the drawing's (xmin, xmax, ymin, ymax) with a margin.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.viz import build_scene, cycle_motion
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> scene = build_scene(engine, cycle_motion(engine, 8))
    >>> scene.batch, scene.joint_xy.shape, scene.pivots, [f"{s.name}:{s.kind}" for s in scene.links]
    (8, (8, 4, 2), ['O', 'C'], ['1:bar', '2:polygon', '3:bar'])
    """

    joint_names: list
    joint_xy: np.ndarray
    revolute: list
    pivots: list
    links: list
    sliders: list
    point_names: list
    point_xy: np.ndarray
    centres: set
    size: float
    phi: np.ndarray
    labels: dict = field(default_factory=dict)  # joint name -> text shown (one per group of coincident pairs)
    pairs: list = field(default_factory=list)   # one `PairShape` per higher pair

    @property
    def batch(self) -> int:
        return len(self.joint_xy)

    def extent(self, margin: float = 0.12) -> tuple[float, float, float, float]:
        """(xmin, xmax, ymin, ymax) of every shape over the whole batch, with a margin (fraction of size)."""
        parts = [self.joint_xy.reshape(-1, 2), self.point_xy.reshape(-1, 2)]
        parts += [s.guide.reshape(-1, 2) for s in self.sliders] + [s.corners.reshape(-1, 2) for s in self.sliders]
        parts += [link.outline.reshape(-1, 2) for link in self.links]
        parts += [xy.reshape(-1, 2) for pair in self.pairs for _, _, xy, _ in pair.lines]
        xy = np.concatenate(parts)
        xy = xy[np.all(np.isfinite(xy), axis=1)]
        pad = margin * self.size
        return (xy[:, 0].min() - pad, xy[:, 0].max() + pad, xy[:, 1].min() - pad, xy[:, 1].max() + pad)


def place(motion, link_index: int, at) -> np.ndarray:
    """World coordinates (B, n, 2) of points drawn at `at` (n, 2) on link `link_index`."""
    th = motion.frames.th[:, link_index]
    r = motion.frames.r[:, link_index]
    at = np.asarray(at, float).reshape(-1, 2)
    c, s = np.cos(th)[:, None], np.sin(th)[:, None]
    x = c * at[:, 0] - s * at[:, 1]
    y = s * at[:, 0] + c * at[:, 1]
    return r[:, None, :] + np.stack((x, y), axis=-1)


def joint_groups(mech, tol: float) -> dict:
    """Label of each pair: pairs drawn at one place show one name (a revolute pair's name first)."""
    names = sorted(mech.joints, key=lambda n: (mech.joints[n].kind != "R", list(mech.joints).index(n)))
    labels, shown = {}, []
    for name in names:
        at = np.array(mech.joints[name].at)
        if any(np.linalg.norm(at - np.array(mech.joints[s].at)) < tol for s in shown):
            labels[name] = ""
            continue
        shown.append(name)
        labels[name] = name
    return labels


def _travel(engine, motion, cycle, name: str, block_length: float):
    """(lo, hi): the slider's displacement range along its guide (m), from the drawn pose, plus a margin."""
    src = cycle if cycle is not None and len(cycle.phi) else motion
    d = src.value[:, src.joint(name)] - engine.joint_value_drawn[name]
    lo, hi = float(np.min(d)), float(np.max(d))
    return lo - 0.75 * block_length, hi + 0.75 * block_length


def _unique(points: list, tol: float) -> np.ndarray:
    out = []
    for p in points:
        if not any(np.linalg.norm(np.subtract(p, q)) < tol for q in out):
            out.append(tuple(p))
    return np.array(out, float).reshape(-1, 2)


def _turn(o, a, b) -> float:
    """z of (a − o) × (b − o): > 0 for a left turn."""
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def _hull(points: np.ndarray) -> np.ndarray:
    """Convex hull (counter-clockwise, monotone chain) of (n, 2) points."""
    pts = sorted(map(tuple, points))

    def half(seq):
        h = []
        for p in seq:
            while len(h) >= 2 and _turn(h[-2], h[-1], p) <= 0:
                h.pop()
            h.append(p)
        return h[:-1]

    return np.array(half(pts) + half(pts[::-1]), float)


def _farthest_pair(points: np.ndarray) -> np.ndarray:
    d = np.linalg.norm(points[:, None] - points[None], axis=-1)
    i, j = np.unravel_index(np.argmax(d), d.shape)
    return points[[i, j]]


def _link_outline(nodes: np.ndarray, size: float) -> tuple[str, np.ndarray]:
    """('bar', ends) or ('polygon', hull) or ('block', one node) from a link's attachment points."""
    if len(nodes) <= 1:
        return "block", nodes
    if len(nodes) == 2:
        return "bar", nodes
    hull = _hull(nodes)
    ends = _farthest_pair(nodes)
    x, y = hull[:, 0], hull[:, 1]
    area = 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
    span = np.linalg.norm(ends[1] - ends[0])
    if len(hull) < 3 or area < 0.04 * span * span:  # (nearly) in line: a bar, side points on stubs
        return "bar", ends
    return "polygon", hull


def build_scene(engine, motion, cycle=None) -> Scene:
    """The drawing of a motion's positions: link outlines, slider blocks and guides, pairs, points.

    Parameters
    ----------
    engine : Engine
        The model.
    motion : Motion
        The positions to draw (B of them; `cycle_motion`, `position_motion` or `analyse`).
    cycle : Motion, optional
        A motion over the whole cycle, used to size the guide lines to the sliders' travel (default:
        `motion` itself).

    Returns
    -------
    Scene
        The shapes, batch first.

    Raises
    ------
    KeyError
        A `motion` without the joints' and points' positions (`analyse(..., points=[...])` that left
        some out).

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.viz import build_scene, position_motion
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> scene = build_scene(engine, position_motion(engine))
    >>> scene.joint_names, scene.point_names, round(scene.size, 4)
    (['O', 'A', 'B', 'C'], ['M'], 0.3917)
    """
    mech, size = engine.mech, engine.size
    tol = 1e-6 * size
    block_l, block_h = 0.09 * size, 0.05 * size
    g = mech.ground
    joint_names = list(mech.joints)
    joint_xy = np.stack([motion.xy[:, motion.point(n)] for n in joint_names], axis=1)
    nodes = {link: [] for link in mech.moving_links}
    sliders = []
    for j in mech.joints.values():
        if j.kind == "R":
            for link in j.links:
                if link != g:
                    nodes[link].append(j.at)
            continue
        u0 = np.array([np.cos(np.radians(j.guide_deg)), np.sin(np.radians(j.guide_deg))])
        lo, hi = _travel(engine, motion, cycle, j.name, block_l)
        ends = np.array(j.at) + np.outer([lo, hi], u0)
        if j.slider != g:
            nodes[j.slider].append(j.at)
        if j.carrier != g:
            nodes[j.carrier].append(j.at)  # the guide itself is drawn on the carrier as a line
        ci, si = engine.link_index[j.carrier], engine.link_index[j.slider]
        guide = place(motion, ci, ends)
        centre = motion.xy[:, motion.point(j.name)]
        n0 = np.array([-u0[1], u0[0]])
        box = np.array(j.at) + np.array([s1 * 0.5 * block_l * u0 + s2 * 0.5 * block_h * n0
                                         for s1, s2 in ((-1, -1), (1, -1), (1, 1), (-1, 1))])
        corners = place(motion, si, box)
        sliders.append(Slider(j.name, j.slider, j.carrier, centre, corners, guide, j.carrier == g))
    for p in mech.points.values():
        if p.link != g:
            nodes[p.link].append(p.at)
    for h in mech.higher.values():  # a follower's or a pin's point on its link, a slot's middle on its link
        if h.kind in ("cam", "slot") and h.links[1] != g:
            nodes[h.links[1]].append(h.at)
        if h.kind == "slot" and h.links[0] != g:
            path = engine.laws[h.name].path
            nodes[h.links[0]].append(tuple(path.point(np.array([0.5 * (path.lo + path.hi)]))[:, 0]))
    busy = np.array([j.at for j in mech.joints.values()] + [p.at for p in mech.points.values()], float)
    links = []
    for link in mech.moving_links:
        kind, outline = _link_outline(_unique(nodes[link], tol), size)
        k = engine.link_index[link]
        world = place(motion, k, outline) if len(outline) else np.zeros((motion.phi.shape[0], 0, 2))
        stubs = _stubs(kind, outline, _unique(nodes[link], tol), size)
        spot = _label_spot(kind, outline, busy, size)
        label = place(motion, k, spot)[:, 0] if spot is not None else np.full((len(motion.phi), 2), np.nan)
        links.append(LinkShape(link, kind, world, label, place(motion, k, stubs.reshape(-1, 2)).reshape(
            len(motion.phi), -1, 2, 2)))
    point_names = list(mech.points)
    point_xy = (np.stack([motion.xy[:, motion.point(n)] for n in point_names], axis=1) if point_names
                else np.zeros((len(motion.phi), 0, 2)))
    centres = {lk.centre for lk in mech.links.values() if lk.centre and lk.centre in mech.points}
    revolute = [n for n in joint_names if mech.joints[n].kind == "R"]
    pivots = [n for n in revolute if g in mech.joints[n].links]
    pairs = higher_shapes(engine, motion) if mech.higher else []
    return Scene(joint_names, joint_xy, revolute, pivots, links, sliders, point_names, point_xy, centres,
                 size, motion.phi[:, 0].copy(), joint_groups(mech, tol), pairs)


def _circle(centre, radius, count: int = 72) -> np.ndarray:
    t = np.linspace(0.0, 2 * np.pi, count + 1)
    return np.asarray(centre, float) + radius * np.stack([np.cos(t), np.sin(t)], axis=1)


def _ticks(centre, radius, teeth: int, depth: float) -> np.ndarray:
    """Tooth marks (z, 2, 2): radial strokes across a pitch circle, one per tooth."""
    t = 2 * np.pi * np.arange(teeth) / teeth
    u = np.stack([np.cos(t), np.sin(t)], axis=1)
    c = np.asarray(centre, float)
    return np.stack([c + (radius - depth / 2) * u, c + (radius + depth / 2) * u], axis=1)


def _teeth(h, k: int, radius: float, size: float) -> tuple[int, float]:
    """(tooth number, mark depth) of gear k of a pair: its own numbers, else about one tooth per 4 % of
    the drawing along the pitch circle."""
    if h.teeth is not None and h.teeth[k] >= 1:
        z = int(h.teeth[k])
    else:
        z = max(8, int(round(2 * np.pi * radius / (0.04 * size))))
    module = h.module if h.module is not None else 2 * radius / z
    return z, min(2.25 * module, 0.4 * radius)


def _curve_points(path, count: int = 241) -> np.ndarray:
    u = np.linspace(path.lo, path.hi, count)
    return path.point(u).T


def higher_shapes(engine, motion) -> list:
    """The `PairShape` of every higher pair over the positions of `motion`."""
    from ..kinematics import contact_geometry
    mech, size = engine.mech, engine.size
    batch = len(motion.phi)
    where = contact_geometry(engine, motion)
    out = []
    for name, h in mech.higher.items():
        law = engine.laws[name]
        g = law.geometry
        lines, marks = [], []

        def on(link, pts):
            return place(motion, engine.link_index[link], pts)

        if h.kind in ("gear", "rack"):
            gears = list(zip(h.links, g.centres, h.radii)) if h.kind == "gear" else [(h.links[0], g.centres[0], h.radius)]
            for k, (link, centre, radius) in enumerate(gears):
                lines.append(("pitch", link, on(link, _circle(centre, radius)), True))
                z, depth = _teeth(h, k, radius, size)
                marks.append(on(link, _ticks(centre, radius, z, depth).reshape(-1, 2)).reshape(batch, -1, 2, 2))
            if h.kind == "rack":
                pitch = 2 * np.pi * h.radius / _teeth(h, 0, h.radius, size)[0]
                depth = _teeth(h, 0, h.radius, size)[1]
                u, n = np.array(g.tangent), np.array(g.normal)
                span = max(np.pi * h.radius, 0.5 * size)
                ends = np.array(g.pitch) + np.outer([-span, span], u)
                lines.append(("rack", h.links[1], on(h.links[1], ends), False))
                s = np.arange(-span, span + 1e-12, pitch)
                ticks = np.stack([np.array(g.pitch) + np.outer(s, u) - depth / 2 * n,
                                  np.array(g.pitch) + np.outer(s, u) + depth / 2 * n], axis=1)
                marks.append(on(h.links[1], ticks.reshape(-1, 2)).reshape(batch, -1, 2, 2))
        elif h.kind == "cam":
            cam, follower = h.links
            lines.append(("profile", cam, on(cam, _curve_points(g.profile)), g.profile.closed))
            at = np.asarray(h.at, float)
            if h.follower in ("roller", "circle"):
                lines.append(("roller", follower, on(follower, _circle(at, h.radius, 48)), True))
            elif h.follower == "flat":
                n = np.array(g.normal)
                u = np.array([-n[1], n[0]])
                half = 0.25 * size
                lines.append(("face", follower, on(follower, np.array(g.pitch) + np.outer([-half, half], u)), False))
            else:
                n = np.array(g.normal)
                lines.append(("knife", follower, on(follower, np.array([at, at + 0.06 * size * n])), False))
        else:
            slot, pin = h.links
            pts = _curve_points(g.path)
            d1 = g.path.point(np.linspace(g.path.lo, g.path.hi, len(pts)), 1).T
            n = np.stack([-d1[:, 1], d1[:, 0]], axis=1) / np.hypot(d1[:, 0], d1[:, 1])[:, None]
            for side in (1.0, -1.0):
                lines.append(("slot", slot, on(slot, pts + side * 0.018 * size * n), g.path.closed))
            lines.append(("slot-centre", slot, on(slot, pts), g.path.closed))
        marks = np.concatenate(marks, axis=1) if marks else np.zeros((batch, 0, 2, 2))
        out.append(PairShape(name, h.kind, lines, marks, where[name].point))
    return out


def _stubs(kind, outline, nodes, size):
    """Segments (n, 2, 2) joining the points of a bar link that lie beside the bar to the bar."""
    if kind != "bar":
        return np.zeros((0, 2, 2))
    a, b = outline
    d = b - a
    t = np.clip((nodes - a) @ d / max(d @ d, 1e-300), 0, 1)
    foot = a + t[:, None] * d
    off = np.linalg.norm(nodes - foot, axis=-1) > 1e-4 * size
    return np.stack((nodes[off], foot[off]), axis=1)


def _label_spot(kind, outline, busy, size):
    """Where a link's name goes (drawn pose, link coordinates, (1, 2)): beside a bar or inside a polygon
    or above a block, as far from the pairs and points as the candidates allow."""
    if len(outline) == 0:
        return None
    if kind == "polygon":
        cands = [outline.mean(axis=0)]
    elif kind == "bar":
        a, b = outline
        d = b - a
        n = np.array([-d[1], d[0]]) / max(np.linalg.norm(d), 1e-12)
        cands = [a + f * d + s * 0.05 * size * n for f in (0.5, 0.35, 0.65, 0.22, 0.78) for s in (1, -1)]
    else:
        cands = [outline[0] + np.array([0.0, 0.075 * size]), outline[0] + np.array([0.0, -0.075 * size])]
    score = [np.min(np.linalg.norm(busy - c, axis=-1)) if len(busy) else 0.0 for c in cands]
    return np.asarray(cands[int(np.argmax(score))])[None]
