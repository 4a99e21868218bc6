"""Made designs as a design batch: each design's links (`geometry.Sided`, joints' points that no longer
coincide) closed in its drawn pose, and that pose written as the drawn geometry of a `DesignBatch`.

The engine's joint laws hold one point per joint, shared by its two links; a made link holds its own.
A higher pair's law holds its made numbers (`higher.made_law`); the design batch gets them with each
link's place in its design's closed pose (`higher.MadePairs`), so that it solves every made design over
the cycle with its own pairs.
`_SidedRevolute` and `_SidedPrismatic` are the same laws with a point on each side (`JointLaw.point`: a
revolute pair's two points, a prismatic pair's line point on the carrier and the slider's point), so that
the engine's block Newton closes the made mechanism at the nominal drawn input from the nominal pose
(q = 0): the nearest
assembly, on the drawn branch (a design whose Jacobians change sign there, or that does not close, does
not assemble). In the closed pose every joint's two points coincide again: those points, the guides'
directions, the links' reference angles and the inputs' zeros are then the design's drawn geometry,
the constants a design batch works from.
"""

from __future__ import annotations

import numpy as np

from ..engine import BlockSolver, Prismatic, Revolute, perp
from ..study.geometry import DesignGeometry
from .higher import MadePairs, made_law

__all__ = ["made_geometry", "ASSEMBLY_REASON", "SHAPE_REASON"]

SHAPE_REASON = "its links' lengths cannot be met together"
ASSEMBLY_REASON = "it cannot be assembled on the drawn branch at the drawn input value"


class _SidedRevolute(Revolute):
    """A revolute pair whose two links hold their own points `sides[link]` (2, D)."""

    def __init__(self, law, sides: dict):
        self.name, self.links, self.s0, self.sides = law.name, law.links, law.s0, sides

    def point(self, link):
        return self.sides[link]


class _SidedPrismatic(Prismatic):
    """A prismatic pair with the guide line through `line` (2, D) along `u0` (2, D) on the carrier and the
    slider's point `slide` (2, D) on the slider (both links keep their drawn relative angle). As a tree
    joint it places the child with the offset between the two points."""

    def __init__(self, law, line, slide, u0):
        self.name, self.links, self.s0 = law.name, law.links, law.s0
        self.line, self.slide, self.u0, self.n0 = line, slide, u0, perp(u0)

    def point(self, link):
        return self.line if link == self.carrier else self.slide

    def place(self, pose, parent, child, q, relative):
        sign = 1.0 if parent == self.carrier else -1.0
        u = pose.rot(parent, self.u0)
        off = pose.rot(parent, self.line - self.slide)
        pose.th[child], pose.c[child], pose.s[child] = pose.th[parent], pose.c[parent], pose.s[parent]
        pose.r[child] = pose.r[parent] + sign * (off + q * u)
        return sign, u[:, None], q, perp(u)[:, None], perp(off)[:, None]

    def place_rates(self, cache, rates, parent, child, qd, relative, vel=None, qd_vel=None):
        if vel is not None:
            raise NotImplementedError("a made prismatic pair closes positions only")
        sign, u, q, pu, p_off = cache
        wp, vp = rates.get(parent)
        rates.set(child, wp, vp + sign * (qd * u + (q * wp) * pu + wp * p_off))


def _laws(engine, sided) -> dict:
    laws = {name: made_law(engine.laws[name], numbers) for name, numbers in sided.higher.items()}
    for name, j in engine.mech.joints.items():
        law = engine.laws[name]
        if j.kind == "R":
            laws[name] = _SidedRevolute(law, {k: sided.side[(name, k)] for k in j.links})
        else:
            laws[name] = _SidedPrismatic(law, sided.side[(name, j.carrier)], sided.side[(name, j.slider)],
                                         sided.guide[name])
    return laws


def input_changes(engine, sided) -> np.ndarray:
    """Each input's joint value at the nominal drawn input, measured in the nominal link frames (n_in, D):
    its zero's change less the turn of its links' reference lines (a revolute input)."""
    out = []
    for i, inp in enumerate(engine.inputs):
        j = engine.mech.joints[inp.joint]
        change = sided.zero[i] - inp.zero * inp.scale
        if j.kind == "R":
            a, b = j.links
            change = change - (sided.alpha[b] - engine.reference_angle[b]) + (sided.alpha[a] - engine.reference_angle[a])
        out.append(change)
    return np.stack(out)


def made_geometry(engine, sided) -> DesignGeometry:
    """The drawn geometry of the made designs `sided` (D designs), closed at the nominal drawn input, as a
    design batch takes it; a design that cannot be closed there gets its reason."""
    count = len(sided.ok)
    senses = np.array([inp.sense for inp in engine.inputs])
    phi0 = np.broadcast_to(engine.phi_drawn, (count, len(engine.inputs)))
    drawn = phi0 - (input_changes(engine, sided) / senses[:, None]).T   # q_in = sense·(φ0 − drawn)
    solver = BlockSolver(engine.mech, _laws(engine, sided), engine.topology.blocks, engine.links, engine.size,
                         drawn, engine.tol)
    with np.errstate(all="ignore"):
        sol = solver.solve_batch(phi0.copy(), [np.repeat(bp.q0[:, None], count, axis=1) for bp in solver.blocks])
        nominal = engine.solver.solve_batch(engine.phi_drawn[None, :], [bp.q0[:, None] for bp in solver.blocks])
    signs = np.sign(solver.dets(sol)) == np.sign(engine.solver.dets(nominal))
    assembled = sol.valid & np.all(signs, axis=1) & (solver.pivots(sol) >= engine.tol.pivot_cross)
    pose = sol.pose
    at = {}
    for name, j in engine.mech.joints.items():
        link = j.slider if j.kind == "P" else j.links[0]
        at[name] = pose.r[link] + pose.rot(link, sided.side[(name, link)])
    for name, p in engine.mech.points.items():
        at[name] = pose.r[p.link] + pose.rot(p.link, sided.point[name])
    centre = np.asarray(engine.centre, float)[:, None]   # (solved in the engine's frame; a batch reads the world's)
    at = {name: xy + centre for name, xy in at.items()}
    guide = {name: pose.rot(j.carrier, sided.guide[name]) for name, j in engine.mech.joints.items() if j.kind == "P"}
    reference = {link: pose.th[link] + sided.alpha[link] for link in engine.links}
    zero = np.stack([sided.zero[i] / inp.scale for i, inp in enumerate(engine.inputs)])
    finite = np.all([np.all(np.isfinite(a), axis=0) for a in at.values()], axis=0)
    reasons = [None if ok else (SHAPE_REASON if not shape else ASSEMBLY_REASON)
               for ok, shape in zip(sided.ok & assembled & finite, sided.ok)]
    good = np.array([r is None for r in reasons])
    if not good.all():   # placeholders where a design has none (a design batch reads only the good ones)
        pick = np.flatnonzero(good)[0] if good.any() else None
        for arr in list(at.values()) + list(guide.values()):
            arr[:, ~good] = arr[:, pick][:, None] if pick is not None else 0.0
        for arr in reference.values():
            arr[~good] = arr[pick] if pick is not None else 0.0
    pairs = None
    if sided.higher:   # the higher pairs' numbers and where each link sits in its design's closed pose
        frame = {link: (pose.c[link], pose.s[link], pose.r[link] + centre, pose.th[link])
                 for link in [engine.mech.ground] + list(engine.links) if link in pose.th}
        pairs = MadePairs(sided.higher, frame)
    return DesignGeometry(count, at, guide, zero, reference, phi0[:, 0].copy(), reasons, pairs)
