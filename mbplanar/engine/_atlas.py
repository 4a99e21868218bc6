"""Continuation along the drawn branch: the atlas of solved nodes with their derivatives (`Atlas`),
walked up and down the input with adaptive steps (`_walk`: second-order predictor, Newton corrector,
acceptance checks, steps through change points), filled in to `H_DENSE`, and the batch solve that
predicts every requested position from the atlas' quintic Hermite interpolant and corrects it
(`solve_along`; `solve_sequence` for several inputs)."""

from __future__ import annotations

import math
import warnings
from dataclasses import replace

import numpy as np

from ..errors import ModelError, MotionError, PrecisionWarning

from ._blocks import BlockSolver, Solution
from ._continuation import (ACCEPT, CROSS, HERMITE5, hermite_coefficients, hermite_curvature, hermite_slope,
                            hermite_value, rate_jump, step_verdict)
from ._nodes import Node, hermite_between, node_at
from ._singular import Crossing, limit_after, limit_kind, locate_crossing

__all__ = ["Atlas", "solve_along", "solve_sequence", "met_along", "far_span", "FAR_TURNS", "FAR_SIZES",
           "LOST_PRECISION"]

FAR_TURNS = 2          # a revolute input is walked at most this many turns from the drawn pose: farther
                       # values are reduced by the branch's period (one or two turns), or refused
FAR_SIZES = 100.0      # a prismatic input is walked at most this many sizes of the mechanism
LOST_PRECISION = 1e-6  # refuse input values whose floating-point spacing (SI) exceeds this
MAX_REPEATED = 1000    # change points reported per change point of the period, over a span of many turns
PERIOD_TOL = 1e-8      # largest scaled difference of the unknowns one period apart (besides whole turns)


class Atlas:
    """Nodes of the drawn branch along a single input, sorted by φ, with q, q', q'' per block.

    `nodes` are the solved nodes (`Node`), `limits` the motion limit met in each direction (+1, −1; None:
    none yet), `crossings` the change points walked through. `cover(lo, hi)` extends the walk from the
    drawn pose to cover an input range (up to a limit), `arrays()` gives the nodes and their quintic
    Hermite coefficients as arrays, `period()` the branch's period. Built once per engine on first use
    (`Engine.atlas`) and extended on demand.

    Examples
    --------
    >>> from mbplanar.engine import Engine
    >>> from mbplanar.model import read_model
    >>> atlas = Engine(read_model("models/crank_slider_rocker_locking.toml")).atlas()
    >>> atlas.cover(0.0, 3.0)                      # walks up to the dead point at 1.8 rad
    >>> limit = atlas.limits[+1]
    >>> round(float(limit.phi[0]), 6), limit.kind
    (1.799912, 'stretched at B (C, B, D in line)')
    >>> bool(atlas.arrays()[0][-1] <= limit.phi[0])                 # no node past it
    True
    """

    def __init__(self, solver: BlockSolver):
        self.solver = solver
        self.nodes = [_origin(solver, np.ones(1))]
        self.limits = {+1: None, -1: None}
        self.crossings = []

    _period = ()  # not looked for yet

    def period(self):
        """(T, shift) of the branch along a revolute input: the period T (rad, one or two turns) and
        per block the change of its unknowns over one period (whole turns of relative angles, see
        `_period_shift`); None when there is none within `FAR_TURNS` turns (a limit, or no return)."""
        if self._period != ():
            return self._period
        self._period = None
        solver = self.solver
        if solver.mech.joints[solver.inputs[0].joint].kind != "R":
            return None
        phi0 = float(solver.phi_drawn[0])
        origin = next(n for n in self.nodes if n.phi[0] == phi0)
        candidates = [2 * math.pi * turns for turns in range(1, FAR_TURNS + 1)]
        for k, period in enumerate(candidates):
            end = phi0 + period
            self.cover(phi0, end)
            if self.limits[+1] is not None and self.arrays()[0][-1] < end:
                return None
            q_end = self._solve_at(end)
            shift = None if q_end is None else _period_shift(solver, origin.q, q_end)
            if shift is not None:
                self._period = (period, shift)
                break
            if k == FAR_TURNS - 1:  # gears: links turning at a constant ratio to the input come back later
                candidates += [t for t in _geared_periods(self) if t > candidates[-1]]
        return self._period

    def _solve_at(self, x: float):
        """Every block's unknowns (m,) at input x inside the atlas, or None."""
        grid, per_block, _ = self.arrays()
        xs = np.array([x])
        guesses = _interpolate(grid, per_block, xs, _nearest(grid, xs), np.ones(1, bool))
        sol = self.solver.solve_batch(xs[:, None], guesses)
        return [s.q[:, 0] for s in sol.blocks] if sol.valid[0] else None

    def cover(self, lo: float, hi: float):
        """Extend the atlas to cover [lo, hi], or up to a motion limit."""
        grown = False
        for direction, target in ((+1, hi), (-1, lo)):
            start = self.nodes[-1] if direction > 0 else self.nodes[0]
            if self.limits[direction] is not None or direction * (target - start.phi[0]) <= 0:
                continue
            new, limit, crossings = _walk(self.solver, start, np.array([target]))
            self.limits[direction] = limit
            self.crossings = sorted(self.crossings + crossings, key=lambda c: c.phi[0])
            self.nodes = self.nodes + new if direction > 0 else new[::-1] + self.nodes
            self._arrays, grown = None, True
        if grown:
            self._densify()

    def _densify(self):
        """Add nodes, solved in one batch, so that no interval is wider than `H_DENSE` input units: the
        predictor's error (~h⁶) then stays below the closure tolerance and Newton needs no step."""
        solver = self.solver
        grid = np.array([n.phi[0] for n in self.nodes])
        width = solver.tol.h_dense * _input_scale(solver)[0]
        parts = np.ceil(np.diff(grid) / width).astype(int)
        x = np.concatenate([grid[i] + (grid[i + 1] - grid[i]) * np.arange(1, k) / k
                            for i, k in enumerate(parts) if k > 1] or [np.zeros(0)])
        x = x[~in_brackets(self.crossings, x)]  # nothing between the two nodes around a change point
        if not len(x):
            return
        inside = np.ones(len(x), bool)
        left = np.clip(np.searchsorted(grid, x) - 1, 0, len(grid) - 2)
        with np.errstate(invalid="ignore", over="ignore"):
            guesses = _interpolate(grid, self.arrays()[1], x, left, inside)
        sol = solver.solve_batch(x[:, None], guesses)
        solver.rates(sol, np.ones((len(x), 1)), np.zeros((len(x), 1)))
        dets, pivots = solver.dets(sol), solver.pivots(sol)
        good = (sol.valid & (pivots >= solver.tol.pivot_cross)
                & np.all(np.sign(dets) == self.arrays()[2][left], axis=1))
        for state, g, bp in zip(sol.blocks, guesses, solver.blocks):
            if bp.m:
                good &= np.max(np.abs(state.q - g) * bp.var_scale[:, None], axis=0) <= solver.tol.max_correction
        one = np.ones(1)
        extra = [Node(x[i:i + 1], one, [s.q[:, i] for s in sol.blocks], [s.qd[:, i] for s in sol.blocks],
                       [s.qdd[:, i] for s in sol.blocks], dets[i], float(pivots[i]))
                 for i in np.flatnonzero(good)]
        self.nodes = sorted(self.nodes + extra, key=lambda n: n.phi[0])
        self._arrays = None

    _arrays = None

    def arrays(self):
        """φ (K,), per block (q, q', q'') as (m, K) with derivatives along +φ and the quintic Hermite
        coefficients (6, m, K − 1) of every interval, and signs (K, n_blocks); computed once per
        extension of the atlas."""
        if self._arrays is None:
            phi = np.array([n.phi[0] for n in self.nodes])
            h = np.diff(phi)
            derivatives = [n.per_input() for n in self.nodes]
            per_block = []
            for k in range(len(self.solver.blocks)):
                q = np.stack([n.q[k] for n in self.nodes], axis=1)
                qd = np.stack([d[0][k] for d in derivatives], axis=1)
                qdd = np.stack([d[1][k] for d in derivatives], axis=1)
                coef = hermite_coefficients(q[:, :-1], q[:, 1:], h * qd[:, :-1], h * qd[:, 1:], h * h * qdd[:, :-1],
                                            h * h * qdd[:, 1:], HERMITE5)
                per_block.append((q, qd, qdd, np.stack(coef)))  # (6, m, K − 1)
            self._arrays = phi, per_block, np.stack([n.signs for n in self.nodes])
        return self._arrays



def _origin(solver: BlockSolver, direction) -> Node:
    node = node_at(solver, solver.phi_drawn, direction, [bp.q0[:, None] for bp in solver.blocks])
    if node is None:
        raise MotionError("the drawn pose does not close: it cannot be assembled", source=solver.mech.source)
    if node.pivot < solver.tol.pivot_cross:
        k = int(np.argmin(np.abs(node.dets)))
        raise MotionError("the drawn pose is a singular position of the group of links "
                          f"{', '.join(solver.blocks[k].links)} (links in line: a dead point or a change "
                          "point), where the assembly branch is ambiguous; draw the mechanism in another "
                          "position", source=solver.mech.source)
    return node


def _predict(node: Node, s: float):
    """Taylor guess of every block's unknowns a distance s along the node's direction."""
    return [(q + qd * s + 0.5 * qdd * s * s)[:, None] for q, qd, qdd in zip(node.q, node.qd, node.qdd)]


def _accept(solver: BlockSolver, node: Node, new: Node | None, guesses, h: float) -> tuple[str, float]:
    """Verdict on a step of length h from `node` (`engine._continuation.step_verdict`): "ok" when it
    converged on the same branch, close to its prediction in position and in derivatives; "cross" when it
    went smoothly through a change point (a determinant changed sign, but positions and derivatives follow
    the prediction closely, which the other branch crossing there does not, and a dead point has no
    solution beyond it); else "reject". No node is placed on a singular position (its rates are unknown)."""
    if new is None:
        return "reject", math.inf
    dist = _distance(solver, new, guesses)
    verdict = step_verdict(True, new.pivot, dist, _rate_jump(solver, node, new, h),
                           np.array_equal(new.signs, node.signs), h, solver.tol)
    return ("ok" if verdict == ACCEPT else "cross" if verdict == CROSS else "reject"), dist


def _distance(solver: BlockSolver, new: Node, guesses) -> float:
    """Largest distance of the corrector from the predictor (scaled unknowns)."""
    return max([np.max(np.abs(q - g[:, 0]) * bp.var_scale, initial=0.0)
                for q, g, bp in zip(new.q, guesses, solver.blocks)] + [0.0])


def _rate_jump(solver: BlockSolver, node: Node, new: Node, h: float) -> float:
    """Largest change of the unknowns' derivatives from `node` to `new` against the Taylor prediction,
    relative to 1 + |q'| (scaled unknowns)."""
    worst = 0.0
    for qd, qdd, qd_new, bp in zip(node.qd, node.qdd, new.qd, solver.blocks):
        if bp.m:
            err = rate_jump(qd_new, qd, qdd, h, bp.var_scale)
            worst = max(worst, float(np.max(err)) if np.all(np.isfinite(err)) else math.inf)
    return worst


def _input_scale(solver: BlockSolver) -> np.ndarray:
    """Natural step unit of each input: 1 rad for an angle, the mechanism's size for a slider."""
    return np.array([1.0 if solver.mech.joints[i.joint].kind == "R" else solver.size for i in solver.inputs])


def _walk(solver: BlockSolver, start: Node, target: np.ndarray, overshoot: bool = True):
    """Continuation on the straight segment from `start` to `target` in input space.
    Returns the new nodes (the last at `target` unless a limit stops it, or a little past it when the
    target is a change point and `overshoot`), a `Limit` or None, and the change points passed."""
    span = target - start.phi
    scale = float(np.max(np.abs(span) / _input_scale(solver)))
    if scale == 0:
        return [], None, []
    direction = span / scale  # one unit of s moves the inputs by one natural unit at most
    node = start
    if not np.array_equal(node.direction, direction):
        node = node_at(solver, start.phi, direction, [q[:, None] for q in start.q])
    nodes, crossings, s, h = [], [], 0.0, solver.tol.h_start
    while s < scale:
        h_try = min(h, scale - s)
        guesses = _predict(node, h_try)
        phi = start.phi + direction * (s + h_try) if s + h_try < scale else target.astype(float)
        new = node_at(solver, phi, direction, guesses)
        if new is not None and new.pivot < solver.tol.pivot_cross and s + h_try >= scale and overshoot:
            # the target is a change point itself: go a little past it, so that nodes bracket it
            scale, overshoot = scale + solver.tol.h_cross, False
            target = start.phi + direction * scale
            continue
        verdict, dist = _accept(solver, node, new, guesses, h_try)
        if verdict == "cross":
            bracket = _bracket(solver, start, node, new, direction)
            if bracket is not None:
                crossing, before, after = bracket
                crossings.append(crossing)
                s_before = _along(before, start.phi, direction)
                nodes = [n for n in nodes if _along(n, start.phi, direction) < s_before]
                nodes += [before, after] if before is not start else [after]
                node, s = after, _along(after, start.phi, direction)
                if s > scale:  # the target lay between the bracketing nodes
                    scale, target = s, after.phi.copy()
                continue
            verdict = "reject"
        if verdict == "ok":
            nodes.append(new)
            node, s = new, s + h_try
            if dist < 0.1 * solver.tol.max_correction:
                h = min(h_try * 1.6, solver.tol.h_max)
            continue
        h = h_try / 2
        if h < solver.tol.h_min:
            return nodes, limit_after(solver, node, direction, h_try), crossings
    return nodes, None, crossings


def _along(node: Node, origin: np.ndarray, direction: np.ndarray) -> float:
    """Distance s of a node along a walk from `origin` in `direction`."""
    k = int(np.argmax(np.abs(direction)))
    return float((node.phi[k] - origin[k]) / direction[k])


def _bracket(solver: BlockSolver, start: Node, node: Node, new: Node, direction: np.ndarray):
    """Nodes on either side of the change point between `node` and `new`, half of `H_CROSS` away from
    it (so that both are well conditioned and the interpolant between them gives the rates at the
    change point; the walk's start node serves as the first when it is nearer), or None when they do
    not converge on the branch. The change point is located by the secant on the block's determinant,
    linear in φ near a simple change point. Returns (Crossing, before, after)."""
    origin = start.phi
    k = int(np.flatnonzero(node.signs != new.signs)[0])
    s0, s1 = _along(node, origin, direction), _along(new, origin, direction)
    s_c = s0 + (s1 - s0) * node.dets[k] / (node.dets[k] - new.dets[k])
    # half of H_CROSS in the unknowns' own units: a branch that turns fast needs closer nodes
    speed = max([1.0] + [float(np.max(np.abs(qd) * bp.var_scale, initial=0.0)) / abs(direction).max()
                         for qd, bp in zip(node.qd, solver.blocks)])
    half = 0.5 * solver.tol.h_cross / speed
    sides = []
    for s_side in (s_c - half, s_c + half):
        if s_side <= 0:
            sides.append(start)
            continue
        guesses = _predict(node, s_side - s0)
        side = node_at(solver, origin + direction * s_side, direction, guesses)
        # the crossing branch is |Δq'|·half away; the prediction's own error grows as half³
        if (side is None or side.pivot < solver.tol.pivot_cross
                or _distance(solver, side, guesses) > 0.01 * half * speed
                or _rate_jump(solver, node, side, s_side - s0) > solver.tol.rate_jump):
            return None
        sides.append(side)
    before, after = sides
    if not (np.array_equal(before.signs, node.signs) and np.array_equal(after.signs, new.signs)):
        return None
    bp = solver.blocks[k]
    lo, hi = sorted((before.phi[0], after.phi[0]))
    phi_c = locate_crossing(solver, k, before, after)
    kind = limit_kind(solver, bp, solver.solve_batch(phi_c[None, :], hermite_between(before, after, phi_c)))
    return Crossing(phi_c, bp.links, bp.joints, (lo, hi), kind), before, after



def far_span(solver: BlockSolver) -> float:
    """How far from the drawn pose the walk goes along a single input before a period is needed.

    Parameters
    ----------
    solver : BlockSolver
        An engine's solver (`Engine.solver`), of one input.

    Returns
    -------
    float
        `FAR_TURNS` turns (rad) for a revolute input, `FAR_SIZES` times the mechanism's size (m) for a
        prismatic one.

    Raises
    ------
    IndexError
        A solver without an input.

    Examples
    --------
    >>> import math
    >>> from mbplanar.engine import FAR_TURNS, Engine, far_span
    >>> from mbplanar.model import read_model
    >>> far_span(Engine(read_model("models/fourbar.toml")).solver) == FAR_TURNS * 2 * math.pi
    True
    """
    return 2 * math.pi * FAR_TURNS if solver.mech.joints[solver.inputs[0].joint].kind == "R" else \
        FAR_SIZES * solver.size


GEARED_TURNS = 64   # the longest period (input turns) looked for where gears turn links at a constant ratio


def _geared_periods(atlas: Atlas) -> list:
    """Candidate periods (rad) of a mechanism with gears, beyond `FAR_TURNS` turns: whole turns of every link
    that turns at a constant, not whole, ratio to the input over the first turn (a planetary train's
    carrier, the slow shaft of a reducer): multiples of 2π/|ω_q| up to `GEARED_TURNS` turns of the input,
    each also a multiple of the other such links' turns where they share one."""
    solver = atlas.solver
    if not getattr(solver, "wheels", None) and not any(h.kind in ("gear", "rack") for h in solver.mech.higher.values()):
        return []
    phi0 = float(solver.phi_drawn[0])
    x = phi0 + np.linspace(0.0, 2 * math.pi, 9)
    grid, per_block, _ = atlas.arrays()
    sol = solver.solve_batch(x[:, None], _interpolate(grid, per_block, x, _nearest(grid, x), np.ones(len(x), bool)))
    if not sol.valid.all():
        return []
    solver.rates(sol, np.ones((len(x), 1)), np.zeros((len(x), 1)))
    wheels = getattr(solver, "wheels", frozenset())   # (their angles need not come back)
    ratios = [float(np.mean(np.abs(w))) for link, w in zip(solver.links, sol.w.T) if link not in wheels
              and np.ptp(w) <= 1e-12 * (1.0 + np.abs(w).max()) and abs(w[0]) > 1e-9]
    turns = [1.0 / r for r in ratios if abs(1.0 / r - round(1.0 / r)) > 1e-9 and 1.0 / r <= GEARED_TURNS]
    out = set()
    for t in turns:
        for m in range(1, int(GEARED_TURNS / t) + 1):
            if all(abs(m * t / other - round(m * t / other)) <= 1e-9 * m * t for other in turns):
                out.add(round(m * t, 12))
                break
    return sorted(2 * math.pi * t for t in out)


def _period_shift(solver: BlockSolver, q0: list, q1: list) -> list | None:
    """Per block the change q1 − q0 of its unknowns when it is whole turns of the relative angles, whole
    periods of a closed curve's contact parameter, and any turn of a wheel (a gear's angle, which places
    nothing but the gear itself), and nothing else (within `PERIOD_TOL`, scaled), else None."""
    out = []
    wheels = getattr(solver, "wheels", frozenset())
    for bp, a, b in zip(solver.blocks, q0, q1):
        period = bp.var_period
        free = np.zeros(bp.m, bool)
        for st in bp.steps:
            if st.var is not None and st.child in wheels:
                free[st.var] = True
        d = b - a
        with np.errstate(invalid="ignore", divide="ignore"):
            whole = np.where(period > 0, period * np.round(d / np.where(period > 0, period, 1.0)), 0.0)
        whole = np.where(free, d, whole)
        if np.any(np.abs(d - whole) * bp.var_scale > PERIOD_TOL):
            return None
        out.append(whole)
    return out


def _periods_away(atlas: Atlas, x: np.ndarray):
    """Whole periods n (B,) to take off x for the walk, or None when every row is within reach
    (`far_span`) or past a motion limit found within it. Rows beyond reach on a side without a limit
    need a period; a mechanism without one gets a `MotionError` naming the range walked, a value whose
    float spacing exceeds `LOST_PRECISION` a `ModelError`."""
    solver = atlas.solver
    phi0, span = float(solver.phi_drawn[0]), far_span(solver)
    far = np.abs(x - phi0) > span
    if not far.any():
        return None
    atlas.cover(max(float(x.min()), phi0 - span), min(float(x.max()), phi0 + span))
    open_side = (far & (x > phi0) & (atlas.limits[+1] is None)) | (far & (x < phi0) & (atlas.limits[-1] is None))
    if not open_side.any():
        return None  # far rows lie past a limit: the walk stops there
    inp = solver.inputs[0]
    spacing = float(np.spacing(np.abs(x[far])).max())
    if spacing > LOST_PRECISION:
        raise ModelError(f"{inp.name} = {inp.from_si(float(np.abs(x).max())):g} {inp.unit}: at this size "
                         f"floating-point numbers are {spacing:.3g} (SI) apart, so the position within a turn "
                         "is lost; give the value reduced by whole turns", source=solver.mech.source)
    found = atlas.period()
    if found is None:
        lo = float(atlas.limits[-1].phi[0]) if atlas.limits[-1] is not None else phi0 - span
        hi = float(atlas.limits[+1].phi[0]) if atlas.limits[+1] is not None else phi0 + span
        raise MotionError(f"{inp.name} = {inp.from_si(float(x[open_side][0])):g} {inp.unit} is beyond the range "
                          f"the analysis walks from the drawn pose ({inp.from_si(lo):g} … {inp.from_si(hi):g} "
                          f"{inp.unit}), and the motion does not repeat within {FAR_TURNS} turns",
                          source=solver.mech.source)
    n = np.floor((x - phi0) / found[0])
    error = spacing + float(np.abs(n).max()) * np.spacing(found[0])
    if error > 1e-12:
        warnings.warn(f"{solver.mech.source}: input values as large as {float(np.abs(x).max()):.6g} rad are "
                      f"reduced by whole periods with an uncertainty of {error:.2g} rad", PrecisionWarning,
                      stacklevel=5)
    return n


def _solve_periodic(atlas: Atlas, phi: np.ndarray, n: np.ndarray) -> Solution:
    """Rows far along a periodic branch: solved n periods back, near the drawn pose, then moved on by
    n periods (whole turns of the relative angles) and confirmed at the values asked."""
    period, shift = atlas.period()
    near = solve_along(atlas, (phi[:, 0] - n * period)[:, None], reduce=False)  # (within a period: walked)
    guesses = [s.q + d[:, None] * n[None, :] for s, d in zip(near.blocks, shift)]
    sol = atlas.solver.solve_batch(phi, guesses)
    sol.valid &= near.valid
    sol.limits, sol.given_rates = near.limits, near.given_rates
    sol.crossings = _crossings_over(atlas, float(phi[:, 0].min()), float(phi[:, 0].max()), period)
    return sol


def _crossings_over(atlas: Atlas, lo: float, hi: float, period: float) -> list:
    """The change points of a periodic branch between lo and hi: those of the atlas' first period
    from the drawn pose, repeated every period."""
    phi0 = float(atlas.solver.phi_drawn[0])
    out = []
    for c in atlas.crossings:
        if not phi0 <= c.phi[0] < phi0 + period:
            continue
        first, last = math.ceil((lo - c.phi[0]) / period), math.floor((hi - c.phi[0]) / period)
        last = min(last, first + MAX_REPEATED - 1)  # a span of many turns: the first ones only
        out += [replace(c, phi=c.phi + k * period, bracket=(c.bracket[0] + k * period, c.bracket[1] + k * period))
                for k in range(first, last + 1)]
    return sorted(out, key=lambda c: c.phi[0])


def solve_along(atlas: Atlas, phi: np.ndarray, reduce: bool = True) -> Solution:
    """Batch solve of one input's values phi (B, 1) on the drawn branch: predict from the atlas,
    correct, check, walk the rest. Values beyond `far_span` are reduced by the branch's period
    (`_periods_away`; not with `reduce` False: values within a period, which the atlas covers)."""
    n = _periods_away(atlas, phi[:, 0]) if reduce else None
    if n is not None:
        return _solve_periodic(atlas, phi, n)
    solver = atlas.solver
    x = phi[:, 0]
    atlas.cover(float(x.min()), float(x.max()))
    nodes_phi, per_block, node_signs = atlas.arrays()
    inside = np.ones(len(x), bool)
    if atlas.limits[+1] is not None:
        inside &= x <= nodes_phi[-1]
    if atlas.limits[-1] is not None:
        inside &= x >= nodes_phi[0]
    idx = _nearest(nodes_phi, x)
    with np.errstate(invalid="ignore", over="ignore"):
        guesses = _interpolate(nodes_phi, per_block, x, idx, inside)
    sol = solver.solve_batch(phi, guesses)
    at_crossing = in_brackets(atlas.crossings, x) & inside
    good = sol.valid & inside & (np.all(solver.signs(sol) == node_signs[idx], axis=1) | at_crossing)
    for state, g, bp in zip(sol.blocks, guesses, solver.blocks):
        if bp.m:
            dist = np.max(np.abs(state.q - g) * bp.var_scale[:, None], axis=0)
            good &= (dist <= solver.tol.max_correction) & ((dist <= solver.tol.cross_dist) | ~at_crossing)
    if at_crossing.any():
        rows = np.flatnonzero(at_crossing)
        sol.given_rates = (rows, _hermite_rates(nodes_phi, per_block, x[rows]))
    retry = np.flatnonzero(~good & inside & ~at_crossing)
    if len(retry):
        good[retry] = _repair(atlas, sol, retry, idx)
    sol.valid = good
    sol.limits, sol.crossings = met_along(atlas, float(x.min()), float(x.max()))
    return sol


def met_along(atlas: Atlas, lo: float, hi: float) -> tuple[list, list]:
    """The motion limits and change points of the atlas that a batch of one input from lo to hi runs into.

    Parameters
    ----------
    atlas : Atlas
        The branch's atlas, covering the range already (`Atlas.cover`).
    lo, hi : float
        The batch's smallest and largest input values, SI.

    Returns
    -------
    limits : list of Limit
        The limits the batch runs past (those beyond the atlas' last node on either side).
    crossings : list of Crossing
        The change points within [lo, hi].

    Raises
    ------
    Nothing on an atlas that has nodes (every atlas has the drawn pose's).

    Examples
    --------
    >>> from mbplanar.engine import Engine, met_along
    >>> from mbplanar.model import read_model
    >>> atlas = Engine(read_model("models/crank_slider_rocker_locking.toml")).atlas()
    >>> atlas.cover(0.0, 2.5)
    >>> met_along(atlas, 0.0, 1.0), len(met_along(atlas, 0.0, 2.5)[0])    # within reach; past the dead point
    (([], []), 1)
    """
    # only the limits this batch ran into: a row past the atlas' last node towards a limit is left out
    # because of it, even a row short of the located limit (the walk's last node can be a few H_MIN
    # short of a fold); the atlas may know limits beyond the range asked for
    grid = atlas.arrays()[0]
    past = {-1: lo < grid[0], +1: hi > grid[-1]}
    limits = [atlas.limits[d] for d in (-1, +1) if atlas.limits[d] is not None and past[d]]
    return limits, [c for c in atlas.crossings if lo <= c.phi[0] <= hi]


def in_brackets(crossings: list, x: np.ndarray) -> np.ndarray:
    """Which of x (B,) lie between the atlas nodes on either side of a change point."""
    out = np.zeros(len(x), bool)
    for c in crossings:
        out |= (x >= c.bracket[0]) & (x <= c.bracket[1])
    return out


def _hermite_rates(grid, per_block, x):
    """q' and q'' (m, R) of every block at x from the derivatives of the atlas' quintic Hermite
    interpolant: the rates at and near a change point, where the Jacobian is singular. The nodes on
    either side are at most `H_CROSS` apart, so the interpolant's error there is ~1e-15."""
    lo = np.clip(np.searchsorted(grid, x) - 1, 0, len(grid) - 2)
    width = grid[lo + 1] - grid[lo]
    t = (x - grid[lo]) / width
    out = []
    for _, _, _, coef in per_block:
        c = coef.take(lo, axis=2)  # (6, m, R)
        out.append((hermite_slope(c[1], c[2], c[3], c[4], c[5], t) / width,
                    hermite_curvature(c[2], c[3], c[4], c[5], t) / (width * width)))
    return out


def _interpolate(grid, per_block, x, idx, inside):
    """Guess (m, B) of every block's unknowns at x: the quintic Hermite interpolant of q, q', q'' between
    the two atlas nodes around x (error ~ h⁶, below the tolerance on the filled-in atlas), evaluated by
    Horner's rule from the interval's coefficients, or the Taylor expansion about the nearest node where
    x is past the last node."""
    if len(grid) == 1:
        between = np.zeros(len(x), bool)
        lo, t = np.zeros(len(x), int), np.zeros(len(x))
    else:
        lo = np.clip(np.searchsorted(grid, x) - 1, 0, len(grid) - 2)
        left = grid[lo]
        between = inside & (x >= left) & (x <= grid[lo + 1])
        t = np.where(between, (x - left) / (grid[lo + 1] - left), 0.0)
    every = between.all()
    if not every:
        dphi = np.where(inside, x - grid[idx], 0.0)
    out = []
    for q, qd, qdd, coef in per_block:
        if len(grid) > 1:
            c = coef.take(lo, axis=2)  # (6, m, B)
            inner = hermite_value(c[0], c[1], c[2], c[3], c[4], c[5], t)
        else:
            inner = q.take(lo, axis=1)
        if not every:
            taylor = (q.take(idx, axis=1) + qd.take(idx, axis=1) * dphi
                      + 0.5 * qdd.take(idx, axis=1) * (dphi * dphi))
            inner = np.where(between, inner, taylor)
        out.append(inner)
    return out


def _nearest(grid: np.ndarray, x: np.ndarray) -> np.ndarray:
    if len(grid) == 1:
        return np.zeros(len(x), int)
    idx = np.clip(np.searchsorted(grid, x), 1, len(grid) - 1)
    left = idx - 1
    return np.where(np.abs(x - grid[left]) <= np.abs(x - grid[idx]), left, idx)


def _repair(atlas: Atlas, sol: Solution, rows, idx) -> np.ndarray:
    """Walk individually to the positions the batch corrector could not trust; returns their validity."""
    solver = atlas.solver
    ok = np.zeros(len(rows), bool)
    for k, row in enumerate(rows):
        near = int(idx[row])
        other = near + (1 if sol.phi[row, 0] > atlas.nodes[near].phi[0] else -1)
        for start in (near, other):  # from the nearest node, else from the one on x's other side
            if not 0 <= start < len(atlas.nodes):
                continue
            nodes, limit, _ = _walk(solver, atlas.nodes[start], sol.phi[row], overshoot=False)
            if limit is None and nodes:
                for state, q in zip(sol.blocks, nodes[-1].q):
                    state.q[:, row] = q
                ok[k] = True
                break
    fixed = solver.solve_batch(sol.phi, [s.q for s in sol.blocks])
    sol.pose, sol.blocks = fixed.pose, fixed.blocks
    return ok & fixed.valid[rows]


def solve_sequence(solver: BlockSolver, phi: np.ndarray) -> Solution:
    """Several inputs: walk from the drawn pose through the requested positions in their order."""
    node = _origin(solver, np.ones(len(solver.inputs)))
    q = [np.zeros((bp.m, len(phi))) for bp in solver.blocks]
    reached, limits, passed = np.zeros(len(phi), bool), [], []
    for row, target in enumerate(phi):
        nodes, limit, crossings = _walk(solver, node, target, overshoot=False)
        passed += crossings
        if limit is not None:
            limits.append(limit)
            break
        node = nodes[-1] if nodes else node
        for k, qk in enumerate(node.q):
            q[k][:, row] = qk
        reached[row] = True
    sol = solver.solve_batch(phi, q)
    sol.valid &= reached
    sol.limits, sol.crossings = limits, passed
    return sol
