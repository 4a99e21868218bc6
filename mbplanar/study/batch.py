"""A design batch: the kinematics of D designs × N input values in one call, the design axis
vectorised like the batch axis of a sweep.

The joint laws' constants (joint points in the link frames, guide directions) and the input's drawn
value become arrays with one entry per batch element, so the engine's block Newton and rate passes run
unchanged over a flat batch of (design, position) pairs. Each design keeps the branch it was drawn in:

1. March (`_march`): from every design's drawn pose the input is walked up and down with the engine's
   own continuation rules (second-order predictor, Newton corrector, steps accepted when converged,
   close to the prediction in positions and derivatives, with no change of sign of a block's
   determinant; halved otherwise), all designs at once, each with its own step. A design whose step
   falls below `H_MIN` has met a motion limit there.
2. Every requested position is predicted by the quintic Hermite interpolant of its design's march nodes
   and corrected by one batched Newton over all (design, position) pairs, then checked.

Designs that cannot be assembled, are drawn at a singular position, or cannot be followed (a change
point, a position the batched corrector cannot vouch for) are reported with a reason; with
`fallback=True` the last kind is solved by the design's own engine (`with_dimensions`), one by one.
Motion limits are located by the engine's bordered Newton on the fold (`exact_limits`), one locking
design at a time, to the rounding floor, as a single-model sweep locates them.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field, replace

import numpy as np

from ..engine import Atlas, BlockSolver, dispatch, perp
from ..engine import (ACCEPT, CROSS, HERMITE5, hermite_coefficients, hermite_value, rate_jump,
                                    step_verdict)
from ..engine import (DESIGN_STATUS, DesignJob, DesignTables, Node, higher_layout, higher_laws,
                      limit_after, sweep_tables)
from ..errors import MbplanarError
from ..kinematics import analyse
from ..model import assemble, frame_origin, parse_model
from .dimensions import with_dimensions
from .geometry import DesignGeometry, mechanism_of

__all__ = ["DesignBatch", "DesignMotion", "DesignLimit", "design_batch", "compile_sample"]

CHUNK = 25_000  # (design, position) pairs corrected at once
OWN = "a model with higher pairs (each design solved by its own engine)"  # (numpy's, until it is solved)


@dataclass(frozen=True)
class DesignLimit:
    """A motion limit met by one design of a batch.

    Attributes
    ----------
    design : int
        The design's index in the batch.
    phi : float
        The input value there, SI.
    direction : int
        +1: met going up, −1: going down.
    links, joints : tuple of str
        The block's links and joints that lock.
    kind : str
        The limit, as `Engine` words it ("stretched at B (A, B, C in line)", ...).
    limit : Limit or None
        The configuration there, when located exactly.

    Examples
    --------
    A coupler of 0.12 m locks the crank of models/fourbar_design.toml at ±100.503°:

    >>> import numpy as np
    >>> from mbplanar.study import design_batch
    >>> batch = design_batch("models/fourbar_design.toml", {"b": np.array([0.3, 0.12])})
    >>> motion = batch.solve(np.radians(np.arange(0.0, 360.0, 30.0)))
    >>> [(lim.design, round(float(np.degrees(lim.phi)), 3), lim.direction) for lim in motion.limits]
    [(1, 100.503, 1)]
    """

    design: int
    phi: float
    direction: int
    links: tuple = ()
    joints: tuple = ()
    kind: str = ""
    limit: object = None  # the engine's `Limit` when located by the fold Newton


@dataclass(frozen=True, eq=False)
class DesignMotion:
    """Kinematics of D designs at N input values each (batch first: design, then position).

    Attributes
    ----------
    phi : (D, N) ndarray
        Input values, SI.
    valid : (D, N) ndarray of bool
        The positions solved on each design's drawn branch.
    ok : (D,) ndarray of bool
        The designs that could be analysed.
    reasons : list
        Why a design could not be (None where it could).
    links : list of str
        The links' order in `angle`, `wq`, `eq`; `link(name)` gives an index.
    points : list of str
        The joints' and points' order in `xy`, `vq`, `aq`; `point(name)` gives an index.
    angle, wq : (D, N, L) ndarray
        Link angles (rad) and their velocity analogues (rad/rad).
    eq : (D, N, L) ndarray or None
        Acceleration analogues (rad/rad²); None with ``accelerations=False``.
    xy, vq : (D, N, P, 2) ndarray
        Positions (m) and velocity analogues (m/rad).
    aq : (D, N, P, 2) ndarray or None
        Acceleration analogues (m/rad²).
    limits : list of DesignLimit
        Motion limits met inside the range asked for (`limits_of(d)` gives a design's).
    th : ndarray or None
        The higher pairs' contact parameters, where the model has higher pairs.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.study import design_batch
    >>> batch = design_batch("models/fourbar_design.toml", {"b": np.array([0.3, 0.35])})
    >>> motion = batch.solve(np.radians([0.0, 90.0, 180.0]))
    >>> motion.xy.shape, bool(motion.valid.all()), motion.points
    ((2, 3, 5, 2), True, ['O', 'A', 'B', 'C', 'M'])
    >>> motion.xy[0, 1, motion.point("A")].round(12).tolist()          # the crank's end at 90°
    [0.0, 0.1]
    """

    phi: np.ndarray
    valid: np.ndarray
    ok: np.ndarray
    reasons: list
    links: list
    points: list
    angle: np.ndarray
    wq: np.ndarray
    eq: np.ndarray
    xy: np.ndarray
    vq: np.ndarray
    aq: np.ndarray
    limits: list = field(default_factory=list)
    th: np.ndarray | None = None

    def limits_of(self, design: int) -> list:
        return [lim for lim in self.limits if lim.design == design]

    def point(self, name: str) -> int:
        return self.points.index(name)

    def link(self, name: str) -> int:
        return self.links.index(name)


class _Nodes:
    """March nodes of many designs: design index, φ, per block q, dq/dφ, d²q/dφ² and the signs."""

    def __init__(self, blocks: int):
        self.parts = []
        self.blocks = blocks

    def add(self, design, phi, q, qd, qdd, dets):
        self.parts.append((design, phi, q, qd, qdd, dets))

    def arrays(self):
        """Sorted by (design, φ): design (K,), φ (K,), per block (q, qd, qdd) (m, K), dets (K, n_b)."""
        design = np.concatenate([p[0] for p in self.parts])
        phi = np.concatenate([p[1] for p in self.parts])
        order = np.lexsort((phi, design))
        per_block = [tuple(np.concatenate([p[i][b] for p in self.parts], axis=1)[:, order] for i in (2, 3, 4))
                     for b in range(self.blocks)]
        dets = np.concatenate([p[5] for p in self.parts])[order]
        return design[order], phi[order], per_block, dets


class DesignBatch:
    """D designs of one model, ready to solve together: a reference engine and the designs' constants.

    `solve(phi)` gives every design's kinematics at input values `phi` (SI), batch first
    (`DesignMotion`); `engine_of(d)` a design's own `Engine`; `count` is D.

    Parameters
    ----------
    engine : Engine
        The reference design's engine (its structure serves every design). One input.
    geometry : DesignGeometry
        The designs' drawn coordinates (`design_geometry`).
    template, variants : Template, Variants, optional
        The model and the designs' values: a model with higher pairs solves each design from its own
        table (`model_of`).

    Raises
    ------
    ValueError
        From `solve`: `phi` with another number of rows than designs, values that are not finite,
        unknown points or links.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.study import design_batch
    >>> batch = design_batch("models/fourbar_design.toml", {"b": np.array([0.3, 0.35])})
    >>> batch.count, batch.engine_of(1).mech.joints["B"].at == batch.engine_of(0).mech.joints["B"].at
    (2, False)
    """

    def __init__(self, engine, geometry: DesignGeometry, template=None, variants=None):
        self.engine = engine
        self.geometry = geometry
        self.count = geometry.count
        self.reasons = list(geometry.reasons)
        mech = engine.mech
        self.points = list(mech.joints) + list(mech.points)
        self.point_link = [engine.link_index[j.slider if j.kind == "P" else j.links[0]] for j in mech.joints.values()]
        self.point_link += [engine.link_index[p.link] for p in mech.points.values()]
        self.scale = 1.0 if mech.joints[engine.inputs[0].joint].kind == "R" else engine.size
        # each design is solved in its own frame, centred on its drawn joints as an engine's is
        # (`Engine.centre`): its positions are vectors within the mechanism, wherever it is drawn
        self.centre = frame_origin([geometry.at[name] for name in mech.joints], engine.size)  # (2, D)
        self.local = {name: at - self.centre for name, at in geometry.at.items()}
        self._engines = {}
        self._want = (list(self.points), True, list(engine.links))  # the points, rates and links asked for
        self.nodes = None
        self.motion = None
        # a model with higher pairs: its laws hold curves and radii numpy's batched laws cannot vary over
        # the designs, so numpy solves each design by its own engine, made from its own table (`model_of`),
        # and the compiled kernel takes each design's pairs from that table (`_higher_reals`) (unless the
        # geometry carries each design's higher pairs: made designs, `mbplanar.accuracy`)
        self.own = bool(mech.higher) and geometry.higher is None
        self.model_of = None
        if self.own and template is not None:
            self.model_of = lambda d: parse_model(template.bind(variants.row(d)), source=template.source)

    # -- engines over batches of designs --------------------------------------------------------------
    def bound(self, index: np.ndarray, tol=None) -> BlockSolver:
        """The engine's block solver with joint laws that hold the constants of designs `index` (B,), one
        per batch element, each in its design's frame (`centre`): its Newton and rate passes then solve
        batches of exactly those designs (with tolerances `tol`, default the engine's)."""
        base, g = self.engine, self.geometry
        laws = {}
        for name, j in base.mech.joints.items():
            law = copy.copy(base.laws[name])
            law.s0 = self.local[name][:, index]
            if j.kind == "P":
                law.u0 = g.guide[name][:, index]
                law.n0 = perp(law.u0)
            laws[name] = law
        if g.higher is not None:
            for name in base.mech.higher:
                laws[name] = g.higher.law(base.laws[name], index, -self.centre[:, index])
        return BlockSolver(base.mech, laws, base.topology.blocks, base.links, base.size, g.phi0[index][:, None],
                           base.tol if tol is None else tol)

    def engine_of(self, design: int):
        """Design `design`'s own engine (the reference re-dimensioned, `with_dimensions`)."""
        if design not in self._engines:
            if self.own:
                mech = self._mechanism(design)
            else:
                mech = mechanism_of(self.engine.mech, self.geometry, design)
            made = None
            if self.geometry.higher is not None:   # its higher pairs' laws as the geometry holds them
                index = np.array([design])
                made = lambda centre: {name: self.geometry.higher.law(  # noqa: E731
                    self.engine.laws[name], index, -np.asarray(centre, float)[:, None]) for name in mech.higher}
            self._engines[design] = with_dimensions(self.engine, mech, made)
        return self._engines[design]

    def _mechanism(self, design: int):
        """Design `design` of a model with higher pairs as its own table gives it: assembled one by one
        already (a sketch: `DesignGeometry.mechanisms`), else made from its table (`model_of`), or, without
        one, the reference with the design's coordinates."""
        if self.geometry.mechanisms is not None and self.geometry.mechanisms[design] is not None:
            return self.geometry.mechanisms[design]
        if self.model_of is not None:
            return self.model_of(design)
        return mechanism_of(self.engine.mech, self.geometry, design)

    def seeded_engine(self, design: int):
        """Design `design`'s own engine with the branch atlas its march built (the nodes, densified as
        the engine does, and the located limits), so that `check` and `analyse` on it walk no further
        than the batch did. Call after `solve` (with exact limits); a design the batch left to its own
        engine gets that engine as it is."""
        eng = self.engine_of(design)
        if eng._atlas is not None or self.nodes is None:
            return eng
        d, phi, per_block, dets = self.nodes
        rows = np.flatnonzero(d == design)
        limits = self.motion.limits_of(design)
        if not len(rows) or any(lim.limit is None for lim in limits) or self.scale != 1.0:
            return eng
        one = np.ones(1)
        atlas = Atlas.__new__(Atlas)
        atlas.solver, atlas.crossings, atlas._arrays = eng.solver, [], None
        atlas.nodes = [Node(phi[i:i + 1].copy(), one, [b[0][:, i].copy() for b in per_block],
                                     [b[1][:, i].copy() for b in per_block], [b[2][:, i].copy() for b in per_block],
                                     dets[i].copy()) for i in rows]
        atlas.limits = {+1: None, -1: None}
        for lim in limits:
            atlas.limits[lim.direction] = lim.limit
        atlas._densify()
        eng._atlas = atlas
        return eng

    # -- 1. the march -----------------------------------------------------------------------------------
    def _solve_nodes(self, designs, phi, guesses, rate):
        """Solve designs (B,) at φ (B,) from guesses; rates along s (dφ/ds = `rate` (B,))."""
        eng = self.bound(designs)
        with np.errstate(all="ignore"):
            sol = eng.solve_batch(phi[:, None], guesses)
            eng.rates(sol, rate[:, None], np.zeros((len(designs), 1)))
        return eng, sol

    def _origin(self, designs):
        """Every design's drawn pose (q = 0 there) with its derivatives along +φ; designs drawn at a
        singular position or not closing get their reason."""
        g = self.geometry
        drawn = [np.repeat(bp.q0[:, None], len(designs), axis=1) for bp in self.engine.blocks]
        eng, sol = self._solve_nodes(designs, g.phi0[designs], drawn, np.ones(len(designs)))
        pivots, dets = eng.pivots(sol), eng.dets(sol)
        singular = sol.valid & ~(pivots >= self.engine.tol.pivot_cross)
        for k in np.flatnonzero(~sol.valid):
            self.reasons[designs[k]] = "the drawn pose does not close: it cannot be assembled"
        for k in np.flatnonzero(singular):
            self.reasons[designs[k]] = ("the drawn pose is a singular position (links in line: a dead point "
                                        "or a change point)")
        return sol, dets

    def _march(self, designs, origin, dets, target, direction: int, nodes: _Nodes, limits: list):
        """Walk every design from its drawn pose towards target (B,) (all on the same side), adding the
        accepted nodes; a design stops at its target, at a motion limit (added to `limits`) or at a
        change point (its reason set)."""
        S = self.engine.tol
        g, blocks = self.geometry, self.engine.blocks
        count = len(designs)
        phi0 = g.phi0[designs]
        span = np.abs(target - phi0) / self.scale
        rate = np.full(count, direction * self.scale)
        q = [st.q.copy() for st in origin.blocks]
        qd = [st.qd * direction * self.scale for st in origin.blocks]  # per unit s
        qdd = [st.qdd * self.scale ** 2 for st in origin.blocks]
        signs = np.sign(dets)
        s, h = np.zeros(count), np.full(count, S.h_start)
        active = span > 0
        while active.any():
            a = np.flatnonzero(active)
            h_try = np.minimum(h[a], span[a] - s[a])
            end = s[a] + h_try >= span[a]
            phi = np.where(end, target[a], phi0[a] + direction * self.scale * (s[a] + h_try))
            guesses = [qk[:, a] + qdk[:, a] * h_try + 0.5 * qddk[:, a] * h_try * h_try
                       for qk, qdk, qddk in zip(q, qd, qdd)]
            eng, sol = self._solve_nodes(designs[a], phi, guesses, rate[a])
            new_dets = eng.dets(sol)
            with np.errstate(all="ignore"):
                dist = np.zeros(len(a))
                jump = np.zeros(len(a))
                for k, (bp, st, gk) in enumerate(zip(blocks, sol.blocks, guesses)):
                    if not bp.m:
                        continue
                    vs = bp.var_scale[:, None]
                    dist = np.maximum(dist, np.max(np.abs(st.q - gk) * vs, axis=0))
                    err = rate_jump(st.qd, qd[k][:, a], qdd[k][:, a], h_try, vs)
                    jump = np.maximum(jump, np.where(np.all(np.isfinite(err), axis=0), np.max(err, axis=0), np.inf))
            same = np.all(np.sign(new_dets) == signs[a], axis=1)
            verdict = step_verdict(sol.valid, eng.pivots(sol), dist, jump, same, h_try, S)
            ok, cross = verdict == ACCEPT, verdict == CROSS
            if ok.any():
                acc = a[ok]
                for k, st in enumerate(sol.blocks):
                    q[k][:, acc], qd[k][:, acc], qdd[k][:, acc] = st.q[:, ok], st.qd[:, ok], st.qdd[:, ok]
                signs[acc] = np.sign(new_dets[ok])
                s[acc] += h_try[ok]
                grow = dist[ok] < 0.1 * S.max_correction
                h[acc] = np.where(grow, np.minimum(h_try[ok] * 1.6, S.h_max), h[acc])
                nodes.add(designs[acc], phi[ok], [st.q[:, ok] for st in sol.blocks],
                          [st.qd[:, ok] / (direction * self.scale) for st in sol.blocks],
                          [st.qdd[:, ok] / self.scale ** 2 for st in sol.blocks], new_dets[ok])
            for k in np.flatnonzero(cross):
                d = designs[a[k]]
                self.reasons[d] = self.reasons[d] or "passes a change point (the batch leaves it to its own engine)"
                active[a[k]] = False
            rejected = ~ok & ~cross
            h[a[rejected]] = h_try[rejected] / 2
            stop = a[rejected][h[a[rejected]] < S.h_min]
            for i in stop:
                d = designs[i]
                state = [(qk[:, i].copy(), qdk[:, i].copy(), qddk[:, i].copy()) for qk, qdk, qddk in zip(q, qd, qdd)]
                phi_node = phi0[i] + direction * self.scale * s[i]
                limits.append((d, direction, phi_node, 2 * h[i], state, signs[i].copy()))
                active[i] = False
            active &= s < span

    # -- 2. the requested positions -----------------------------------------------------------------
    def solve(self, phi, exact_limits: bool = True, fallback: bool = True, points=None,
              accelerations: bool = True, links=None) -> DesignMotion:
        """Kinematics (positions, analogues) of every design at input values `phi` (SI): (N,) the same
        for every design, or (D, N) one row per design.

        The reference engine's backend chooses the loops: numpy (the reference) over flat batches of
        (design, position) pairs, or numba (`backends._numba_design`) over designs × positions, handing
        the designs it cannot follow to numpy.

        Parameters
        ----------
        phi : array_like
            Input values, SI (rad or m).
        exact_limits : bool
            Locate each design's motion limits by the engine's fold Newton (one locking design at a time).
        fallback : bool
            Solve designs the batch cannot follow (change points, positions it cannot vouch for) with their
            own engines, one by one.
        points : sequence of str, optional
            The joints and points whose xy, vq (and aq) are wanted (default: all).
        accelerations : bool
            Also the acceleration analogues (eq, aq); else they are None.
        links : sequence of str, optional
            The links whose angle, ω_q (and ε_q) are wanted (default: all; ``[]``: none).

        Returns
        -------
        DesignMotion
        """
        D = self.count
        phi = np.asarray(phi, float)
        phi = np.broadcast_to(phi, (D, phi.shape[-1])) if phi.ndim == 1 else phi
        if phi.shape[0] != D:
            raise ValueError(f"phi must have one row per design ({D}), not {phi.shape[0]}")
        if not np.all(np.isfinite(phi)):
            raise ValueError("input values must be finite")
        names = list(self.points) if points is None else [str(p) for p in points]
        unknown = [p for p in names if p not in self.points]
        if unknown:
            raise ValueError(f"{', '.join(unknown)}: neither a joint nor a point of the model")
        link_names = list(self.engine.links) if links is None else [str(n) for n in links]
        unknown = [n for n in link_names if n not in self.engine.links]
        if unknown:
            raise ValueError(f"{', '.join(unknown)}: not a link of the model")
        return dispatch(self.engine, "design", int(phi.size),
                        lambda: self._solve_numpy(phi, exact_limits, fallback, names, accelerations, link_names),
                        lambda: self._design_request(phi, names, accelerations, link_names),
                        lambda job, got: self._from_compiled(job, got, phi, exact_limits, fallback, names,
                                                             accelerations, link_names))

    def _solve_numpy(self, phi, exact_limits: bool, fallback: bool, names=None,
                     accelerations: bool = True, links=None) -> DesignMotion:
        """`solve` with numpy's loops (the points `names` and links `links`, default all)."""
        self._want = (list(self.points) if names is None else list(names), accelerations,
                      list(self.engine.links) if links is None else list(links))
        D = self.count
        if self.own:
            for d in np.flatnonzero(self.geometry.ok):
                self.reasons[d] = self.reasons[d] or OWN
        designs = np.flatnonzero(self.geometry.ok & ~self.own)
        limits, nodes = [], _Nodes(len(self.engine.blocks))
        if len(designs):
            origin, dets = self._origin(designs)
            good = np.array([self.reasons[d] is None for d in designs], bool)
            designs = designs[good]
            origin = _take_solution(origin, good)
            dets = dets[good]
            if len(designs):
                nodes.add(designs, self.geometry.phi0[designs], [st.q for st in origin.blocks],
                          [st.qd for st in origin.blocks], [st.qdd for st in origin.blocks], dets)
                for direction in (+1, -1):
                    lo, hi = phi[designs].min(axis=1), phi[designs].max(axis=1)
                    target = hi if direction > 0 else lo
                    side = (target - self.geometry.phi0[designs]) * direction > 0
                    if side.any():
                        self._march(designs[side], _take_solution(origin, side), dets[side], target[side],
                                    direction, nodes, limits)
        self.nodes = nodes.arrays() if nodes.parts else None
        motion = replace(self._positions(phi, nodes, designs), limits=self._limits(limits, exact_limits))
        self._past_limits(motion)
        if fallback or self.own:   # (a model with higher pairs: its designs' own engines are the only way)
            motion = self._fall_back(motion, phi)
        return self._finished(motion, D)

    def _finished(self, motion: DesignMotion, count: int) -> DesignMotion:
        """The motion with every design's verdict (`ok`, `reasons`), kept as the batch's last."""
        ok = np.array([r is None for r in self.reasons], bool)
        self.motion = replace(motion, ok=ok, reasons=[None if ok[d] else self.reasons[d] for d in range(count)])
        return self.motion

    def _design_request(self, phi, names: list, accelerations: bool, links: list) -> DesignJob | str:
        """The compiled design job's request: the designs that can be analysed, their tables and input
        values (or why no kernel can take them). A model with higher pairs gets each design's pairs
        (`_higher_reals`); a design whose table does not give them gets its reason here, and one whose
        curve is not the engine's spline is left to numpy (`_from_compiled`)."""
        g, eng = self.geometry, self.engine
        designs = np.flatnonzero(g.ok)
        higher = None
        if eng.mech.higher and len(designs):
            higher, kept = self._higher_reals(designs)
            designs = designs[kept]
        if not len(designs):
            return "no design can be assembled"
        point_link = [self.point_link[self.points.index(p)] for p in names]
        tables = design_tables(eng, self.local, g.guide, g.phi0, g.reference, names, point_link, designs,
                               [eng.link_index[n] for n in links], higher)
        x = np.ascontiguousarray(phi if len(designs) == self.count else phi[designs], float)
        uniform = np.array([bool(np.all(bp.row_scale == bp.row_scale[:1]) and np.all(bp.var_scale == bp.var_scale[:1]))
                            for bp in eng.blocks], np.bool_)
        return DesignJob(tables, x, float(self.scale), bool(accelerations), eng.threads, float(eng.inputs[0].sense),
                         eng.link_index[eng.mech.ground], eng.tol.kernel(), uniform,
                         eng.prepare("design kernel store", dict), designs)

    def _higher_reals(self, designs) -> tuple[tuple, np.ndarray]:
        """The higher pairs of designs `designs` (B,) for the design kernel, each in its design's frame
        (`centre`): (`HigherTables`, `CurveTables`, the pairs' reals (B', H, H_REALS), the curves' (B', K,
        C_REALS), the unknowns' drawn values (B', M)) of the designs kept (B,) bool. Made designs' from
        the geometry (`DesignGeometry.higher`); else each design's from its own table, as its own engine
        has them (`higher_laws`): a design whose table gives no such pair (gears that cannot mesh, ...)
        gets the reason numpy's engine would give, one whose curve is another spline than the engine's
        is not kept (numpy's batch takes it)."""
        eng, g = self.engine, self.geometry
        if g.higher is not None:
            laws = {name: g.higher.law(eng.laws[name], designs, -self.centre[:, designs]) for name in eng.mech.higher}
            tables = (*higher_layout.higher_tables(eng, laws), *higher_layout.design_reals(eng, laws, len(designs)))
            return tables, np.ones(len(designs), bool)
        kept, rows = np.zeros(len(designs), bool), []
        for k, d in enumerate(designs):
            try:
                laws = higher_laws(assemble(self._mechanism(d)), self.centre[:, d])
            except MbplanarError as exc:
                self.reasons[d] = str(exc)
                continue
            kept[k] = all(higher_layout.shared_curves(eng.laws[name].path, law.path) for name, law in laws.items()
                          if law.parameters)
            if kept[k]:
                rows.append(higher_layout.design_reals(eng, laws, 1))
        hr, cr, q0 = (np.concatenate(parts) for parts in zip(*rows)) if rows else (None, None, None)
        return (*higher_layout.higher_tables(eng), hr, cr, q0), kept

    def _from_compiled(self, job, got, phi, exact_limits: bool, fallback: bool, names: list,
                       accelerations: bool, links: list) -> DesignMotion:
        """`solve` from the compiled kernel's answer (designs × positions in one call); the designs it
        hands back (a change point passed, a position it cannot vouch for) are solved by numpy's batch."""
        D, N = phi.shape
        eng = self.engine
        designs = job.designs
        self.nodes = None
        whole = len(designs) == D
        arrays = dict.fromkeys(("angle", "wq", "eq", "xy", "vq", "aq"))
        got.xy[...] += self.centre.T[designs][:, None, None, :]  # (solved in each design's frame)
        for name, shape in (("angle", (len(links),)), ("wq", (len(links),)), ("eq", (len(links),)),
                            ("xy", (len(names), 2)), ("vq", (len(names), 2)), ("aq", (len(names), 2))):
            if not accelerations and name in ("eq", "aq"):
                continue
            if whole:
                arrays[name] = getattr(got, name)
            else:
                arrays[name] = np.full((D, N) + shape, np.nan)
                arrays[name][designs] = getattr(got, name)
        valid = got.valid if whole else np.zeros((D, N), bool)
        if not whole:
            valid[designs] = got.valid
        words = {DESIGN_STATUS["open"]: "the drawn pose does not close: it cannot be assembled",
                 DESIGN_STATUS["singular"]: ("the drawn pose is a singular position (links in line: a dead point "
                                             "or a change point)")}
        for k in np.flatnonzero(got.status):
            self.reasons[designs[k]] = words.get(int(got.status[k]))
        found = []
        offsets = np.cumsum([0] + [bp.m for bp in eng.blocks])
        for k, side in zip(*np.nonzero(got.limit)):
            per = [tuple(arr[k, side, offsets[b]:offsets[b + 1]].copy() for arr in
                         (got.limit_q, got.limit_qd, got.limit_qdd)) for b in range(len(eng.blocks))]
            found.append((int(designs[k]), 1 if side == 0 else -1, float(got.limit_phi[k, side]),
                          float(got.limit_h[k, side]), per, got.limit_signs[k, side].copy()))
        out = DesignMotion(phi.copy(), valid, np.zeros(D, bool), [None] * D, links, names, **arrays,
                           limits=self._limits(found, exact_limits))
        self._past_limits(out)
        handed = designs[(got.status == DESIGN_STATUS["crossing"]) | (got.status == DESIGN_STATUS["numpy"])]
        left = np.setdiff1d(np.flatnonzero(self.geometry.ok), designs)  # (not in the request: see `_higher_reals`)
        handed = np.union1d(handed, left[[self.reasons[d] is None for d in left]]).astype(np.int64)
        if len(handed):
            out = self._by_numpy(out, phi, handed, exact_limits, fallback, names, accelerations, links)
        return self._finished(out, D)

    def _by_numpy(self, out: DesignMotion, phi, handed, exact_limits, fallback, names, accelerations,
                  links) -> DesignMotion:
        """`out` with the designs `handed` solved by numpy's batch (a batch of their own)."""
        sub = DesignBatch(self.engine, _take_geometry(self.geometry, handed))
        if self.model_of is not None:
            sub.model_of = lambda k: self.model_of(int(handed[k]))
        got = sub._solve_numpy(phi[handed], exact_limits, fallback, names, accelerations, links)
        out.valid[handed] = got.valid
        for name in ("angle", "wq", "eq", "xy", "vq", "aq"):
            if getattr(out, name) is not None:
                getattr(out, name)[handed] = getattr(got, name)
        for k, d in enumerate(handed):
            self.reasons[d] = got.reasons[k]
            if sub._engines.get(k) is not None:
                self._engines[int(d)] = sub._engines[k]
        kept = [lim for lim in out.limits if lim.design not in set(handed.tolist())]
        return replace(out, limits=kept + [replace(lim, design=int(handed[lim.design])) for lim in got.limits])

    def _positions(self, phi, nodes: _Nodes, designs) -> DesignMotion:
        """Predict every (design, position) from its design's nodes, correct in one batch, check."""
        D, N = phi.shape
        names, acc, links = self._want
        L, P = len(links), len(names)
        out = DesignMotion(phi.copy(), np.zeros((D, N), bool), np.zeros(D, bool), [None] * D, list(links),
                           names, np.full((D, N, L), np.nan), np.full((D, N, L), np.nan),
                           np.full((D, N, L), np.nan) if acc else None, np.full((D, N, P, 2), np.nan),
                           np.full((D, N, P, 2), np.nan), np.full((D, N, P, 2), np.nan) if acc else None)
        if not len(designs) or not nodes.parts:
            return out
        arrays = self.nodes
        coefs = _interval_coefficients(arrays)
        per = max(1, CHUNK // max(N, 1))  # whole designs per chunk: the working arrays stay in cache
        for start in range(0, len(designs), per):
            self._correct(out, arrays, coefs, designs[start:start + per], phi)
        out.ok[designs] = True
        return out

    def _correct(self, out: DesignMotion, arrays, coefs, chunk, phi):
        """Correct the (design, position) pairs of designs `chunk` (C,) and copy them into `out`; pairs
        outside their design's march (past a limit) are left out of the Newton batch.

        A batched Newton takes as many iterations as its worst element needs, and the interpolant's
        guesses are mostly within ~1e-9 (one step from the rounding floor) but a few are ~1e-6 away. So
        the batch takes one step and one more evaluation (`_one_step`), and only the pairs not at the
        rounding floor then (residual not below `polish`, or near a singular position, where the engine
        polishes once more) go on, from where they are, in a batch of their own with the engine's full
        iteration: each pair ends where the engine's Newton over the whole chunk would end it."""
        tol = self.engine.tol
        N = phi.shape[1]
        rows = np.repeat(chunk, N)
        x = phi[chunk].reshape(-1)
        guesses, inside, node_signs = _interpolate(arrays, coefs, chunk, rows, x)
        take = np.flatnonzero(inside)
        good = np.zeros(len(x), bool)
        if not len(take):
            return
        where = rows[take]
        if len(take) < len(x):
            guesses = [g[:, take] for g in guesses]
        eng = self.bound(where, _one_step(tol))
        parts = []
        with np.errstate(all="ignore"):
            sol = eng.solve_batch(x[take, None], guesses)
            done = sol.valid.copy()
            for st in sol.blocks:
                if st.lu is not None:
                    r = st.lu.pivot_ratio
                    done &= ~((r >= tol.pivot_cross * 1e3) & (r < tol.pivot_polish))
            parts.append((np.arange(len(take)), eng, sol))
            redo = np.flatnonzero(~done)
            if len(redo):
                eng2 = self.bound(where[redo])
                parts.append((redo, eng2, eng2.solve_batch(x[take[redo], None], [st.q[:, redo] for st in sol.blocks])))
            ok = np.zeros(len(take), bool)
            for idx, e, sl in parts:
                ok_part = sl.valid & np.all(e.signs(sl) == node_signs[take[idx]], axis=1)
                for bp, st, gk in zip(e.blocks, sl.blocks, guesses):
                    if bp.m:
                        ok_part &= np.max(np.abs(st.q - gk[:, idx]) * bp.var_scale[:, None], axis=0) <= tol.max_correction
                ok[idx] = ok_part
                e.rates(sl, np.ones((len(idx), 1)), np.zeros((len(idx), 1)))
        good[take] = ok
        for d in np.unique(where[~ok]):
            self.reasons[d] = self.reasons[d] or "a position the batch could not vouch for (left to its own engine)"
        values = self._values(out, parts[0][2], where)
        if len(parts) > 1:
            for name, value in self._values(out, parts[1][2], where[redo]).items():
                values[name][redo] = value
        self._fill(out, chunk, take, values, good)

    def _values(self, out: DesignMotion, sol, where) -> dict:
        """What `out` holds (its links' angle, wq, eq and its points' xy, vq, aq) of a solved batch of
        designs `where` (T,), batch first: (T, K) and (T, P, 2)."""
        pose, links = sol.pose, list(self.engine.links)
        T = len(where)
        values = {}
        chosen = [links.index(n) for n in out.links]  # the links asked for
        if chosen:
            th = np.empty((T, len(chosen)))
            for k, i in enumerate(chosen):
                th[:, k] = pose.th[links[i]] + self.geometry.reference[links[i]][where]
            values["angle"], values["wq"] = th, sol.w[:, chosen]
            if out.eq is not None:
                values["eq"] = sol.e[:, chosen]
        P = len(out.points)
        xy, vq = np.empty((T, P, 2)), np.empty((T, P, 2))
        aq = np.empty((T, P, 2)) if out.aq is not None else None
        for p, name in enumerate(out.points):
            li = self.point_link[self.points.index(name)]
            link = links[li]
            at, centre = self.local[name][:, where], self.centre[:, where]  # (in each design's frame)
            c, s = pose.c[link], pose.s[link]
            rx, ry = c * at[0] - s * at[1], s * at[0] + c * at[1]
            w = sol.w[:, li]
            xy[:, p, 0], xy[:, p, 1] = (pose.r[link][0] + rx) + centre[0], (pose.r[link][1] + ry) + centre[1]
            vq[:, p, 0], vq[:, p, 1] = sol.v[:, li, 0] + w * -ry, sol.v[:, li, 1] + w * rx
            if aq is not None:
                e, ww = sol.e[:, li], w * w
                aq[:, p, 0] = sol.a[:, li, 0] + e * -ry - ww * rx
                aq[:, p, 1] = sol.a[:, li, 1] + e * rx - ww * ry
        values["xy"], values["vq"] = xy, vq
        if aq is not None:
            values["aq"] = aq
        return values

    def _fill(self, out: DesignMotion, chunk, take, values: dict, good):
        """Copy `values` (`_values`) of the pairs `take` of the C × N pairs of designs `chunk` into `out`,
        whole designs at a time; the pairs not solved or not good are NaN."""
        C, N = len(chunk), out.phi.shape[1]
        rows = slice(chunk[0], chunk[-1] + 1) if chunk[-1] - chunk[0] + 1 == C else chunk
        out.valid[rows] = good.reshape(C, N)
        bad = ~good
        for name, value in values.items():
            if len(take) == C * N:
                block = value
            else:
                block = np.empty((C * N,) + value.shape[1:])
                block[take] = value
            block[bad] = np.nan
            getattr(out, name)[rows] = block.reshape((C, N) + value.shape[1:])

    def _limits(self, found, exact: bool) -> list:
        """The motion limits the march met, located by the engine's fold Newton when `exact`."""
        out = []
        for d, direction, phi_node, h, state, signs in found:
            lim = DesignLimit(int(d), float(phi_node + direction * self.scale * h / 2), direction)
            if exact:
                eng = self.engine_of(int(d))
                q, qd, qdd = ([s[i] for s in state] for i in range(3))
                dirs = np.array([direction * self.scale])
                node = Node(np.array([phi_node]), dirs, q, qd, qdd, signs, 1.0)
                with np.errstate(all="ignore"):
                    located = limit_after(eng.solver, node, dirs, h)
                lim = replace(lim, phi=float(located.phi[0]), links=located.links, joints=located.joints,
                              kind=located.kind, limit=located)
            out.append(lim)
        return out

    def _past_limits(self, motion: DesignMotion):
        """Positions beyond a design's limit are not on its branch: invalid."""
        for lim in motion.limits:
            past = (motion.phi[lim.design] - lim.phi) * lim.direction > 0
            motion.valid[lim.design] &= ~past

    def _fall_back(self, motion: DesignMotion, phi) -> DesignMotion:
        """`motion` with the designs the batch left to their own engines solved one by one (`analyse`)."""
        for d in range(self.count):
            reason = self.reasons[d]
            if reason is None or not reason.endswith("own engine)") or not self.geometry.ok[d]:
                continue
            try:
                eng = self.engine_of(d)
                m = analyse(eng, phi[d])
            except MbplanarError as exc:   # (a design's own table that gives no mechanism: its reason)
                self.reasons[d] = str(exc)
                motion.valid[d] = False
                continue
            hit = np.isin(phi[d], m.phi[:, 0])
            idx = np.flatnonzero(hit)
            motion.valid[d] = hit
            chosen = [list(eng.links).index(n) for n in motion.links]
            for name in ("angle", "wq", "eq"):
                if getattr(motion, name) is not None:
                    getattr(motion, name)[d] = np.nan
                    getattr(motion, name)[d, idx] = getattr(m, name)[:, chosen]
            for name in ("xy", "vq", "aq"):
                if getattr(motion, name) is not None:
                    getattr(motion, name)[d] = np.nan
                    getattr(motion, name)[d, idx] = getattr(m, name)[:, [m.point(p) for p in motion.points]]
            motion = replace(motion, limits=[lim for lim in motion.limits if lim.design != d] + [
                DesignLimit(d, float(lim.phi[0]), lim.direction, lim.links, lim.joints, lim.kind, lim)
                for lim in m.limits])
            self.reasons[d] = None
        return motion


def _step_joints(engine) -> tuple[list, list]:
    """The joint of every tree step and of every cut, in the kernel tables' order."""
    steps = [st.law.name for bp in engine.blocks for st in bp.steps]
    cuts = [law.name for bp in engine.blocks for law in bp.cuts if law.kind in ("R", "P")]
    return steps, cuts


def design_tables(engine, at: dict, guide: dict, phi0, reference: dict, points, point_link,
                  designs, link_out=None, higher=None) -> DesignTables:
    """`DesignTables` of designs `designs` (B,) from the batch's drawn geometry: at {joint or point: (2, D)},
    guide {prismatic joint: (2, D)}, phi0 (D,), reference {link: (D,)}; `points` the chosen points' names,
    `point_link` their links' indices; `link_out` the indices of the links whose angle and rates are
    wanted (default all); `higher` the designs' higher pairs (`DesignBatch._higher_reals`; default: the
    engine's, the same for every design)."""
    base = sweep_tables(engine)
    steps, cuts, blocks = base.steps, base.cuts, base.blocks
    step_names, cut_names = _step_joints(engine)
    kind = {name: j.kind for name, j in engine.mech.joints.items()}

    def stacked(names, table):
        out = np.zeros((len(designs), len(names), 2))
        for k, n in enumerate(names):
            if table is at or kind[n] == "P":
                out[:, k] = table[n][:, designs].T
        return out

    if higher is None:
        count = len(designs)
        q0 = np.concatenate([bp.q0 for bp in engine.blocks] + [np.zeros(0)])
        every = lambda a: np.array(np.broadcast_to(a, (count,) + a.shape))  # noqa: E731  (a writable copy:
        # a read-only array is another type to numba, another compiled kernel)
        higher = (base.higher, base.curves, every(base.higher.reals), every(base.curves.reals), every(q0))
    hp, cv, hr, cr, q0 = higher
    u0 = stacked(step_names, guide)
    n = stacked(cut_names, guide)
    cut_n0 = np.stack([-n[..., 1], n[..., 0]], axis=-1)  # perp(u0)
    return DesignTables(steps, cuts, blocks, stacked(step_names, at), u0, stacked(cut_names, at), cut_n0,
                        np.ascontiguousarray(phi0[designs], float),
                        np.ascontiguousarray(np.stack([reference[n][designs] for n in engine.links], axis=1)),
                        np.ascontiguousarray(np.stack([at[p][:, designs].T for p in points], axis=1)
                                             .reshape(len(designs), len(points), 2) if len(points)
                                             else np.zeros((len(designs), 0, 2))),   # (links only asked for)
                        np.asarray(point_link, np.int64),
                        np.arange(len(engine.links)) if link_out is None else np.asarray(link_out, np.int64),
                        hp, cv, np.ascontiguousarray(hr, float), np.ascontiguousarray(cr, float),
                        np.ascontiguousarray(q0, float))


def _one_step(tol):
    """The engine's tolerances for a first pass over a batch of good guesses: one Newton step and one
    more evaluation, a position counted converged when its residual is below `polish` (the level the
    engine polishes a converged position to)."""
    return replace(tol, closure=tol.polish, max_newton=1)


def _take_geometry(g: DesignGeometry, index) -> DesignGeometry:
    """The designs `index` (B,) of a batch's geometry."""
    return DesignGeometry(len(index), {n: a[:, index] for n, a in g.at.items()},
                          {n: a[:, index] for n, a in g.guide.items()}, g.zero[:, index],
                          {n: a[index] for n, a in g.reference.items()}, g.phi0[index],
                          [g.reasons[k] for k in index], g.higher and g.higher.take(index),
                          None if g.mechanisms is None else [g.mechanisms[k] for k in index])


def _take_solution(sol, mask):
    """The rows `mask` of a solved batch's block states (for the march's start)."""
    out = copy.copy(sol)
    out.blocks = [copy.copy(st) for st in sol.blocks]
    for st in out.blocks:
        st.q, st.qd, st.qdd = st.q[:, mask], st.qd[:, mask], st.qdd[:, mask]
    return out


def _interval_coefficients(arrays) -> list:
    """Per block, the quintic Hermite coefficients (6, m, K) of the interval from every node k to node
    k + 1 (the same sums as `HERMITE5 @ ends`); a design's last node gets its own values as the first
    coefficient (its interval, to the next design's first node, is used only at t = 0)."""
    design, phi, per_block, dets = arrays
    width = np.zeros(len(phi))
    width[:-1] = np.diff(phi)
    out = []
    for q, qd, qdd in per_block:
        def after(a):
            return np.concatenate([a[:, 1:], a[:, -1:]], axis=1)
        out.append(np.stack(hermite_coefficients(q, after(q), width * qd, width * after(qd), width * width * qdd,
                                                 width * width * after(qdd), HERMITE5)))  # (6, m, K)
    return out


def _interpolate(arrays, coefs, chunk, rows, x):
    """Guesses (per block (m, B)) for designs `rows` (B,) (whole designs `chunk`, each repeated) at x (B,)
    from their nodes: the quintic Hermite interpolant between the two nodes around x (coefficients
    `coefs` of `_interval_coefficients`). Also whether x lies within the design's nodes and the signs of
    the node nearer to it."""
    design, phi, per_block, dets = arrays
    repeat = len(rows) // len(chunk)
    first = np.repeat(np.searchsorted(design, chunk, "left"), repeat)
    last = np.repeat(np.searchsorted(design, chunk, "right") - 1, repeat)
    inside = (last >= first) & (x >= phi[first]) & (x <= phi[np.maximum(last, first)])
    # the interval of x within its design's nodes: a search in the (design, φ) order by offsetting φ
    span = float(phi.max() - phi.min()) + 1.0
    key = design * (2 * span) + (phi - phi.min())
    lo = np.searchsorted(key, rows * (2 * span) + (x - phi.min()), "right") - 1
    lo = np.clip(lo, first, np.maximum(last - 1, first))
    hi = np.minimum(lo + 1, last)
    left = phi[lo]
    width = phi[hi] - left
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where(width > 0, (x - left) / np.where(width > 0, width, 1.0), 0.0)
    guesses = []
    for coef in coefs:
        c = coef.take(lo, axis=2)  # (6, m, B)
        guesses.append(hermite_value(c[0], c[1], c[2], c[3], c[4], c[5], t))
    near = np.where(np.abs(x - left) <= np.abs(x - phi[hi]), lo, hi)
    return guesses, inside, np.sign(dets[near])


def design_batch(model, variants, engine=None, backend: str = "numpy") -> DesignBatch:
    """A `DesignBatch` of the variants of a model with parameters.

    Parameters
    ----------
    model : str, Path, dict or Template
        The model (see `load_template`).
    variants : Variants, dict or str
        The designs: a `Variants`, a dict of parameter arrays (D,) each, or a CSV variant table's path.
    engine : Engine, optional
        The reference design's engine (default: compiled from the model's declared parameter values).
    backend : {"numpy", "numba"}
        The default engine's backend: numba runs the design batch in compiled loops (extra `fast`).

    Returns
    -------
    DesignBatch
        The designs, ready to `solve`.

    Raises
    ------
    ValueError
        A model with more than one input.
    ModelError
        A model or variant table that cannot be read, or values the parameters refuse (see
        `variants_from`).

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.study import design_batch
    >>> batch = design_batch("models/fourbar_design.toml", {"b": np.array([0.3, 0.12])})
    >>> motion = batch.solve(np.radians(np.arange(0.0, 360.0, 30.0)))
    >>> motion.valid.sum(axis=1).tolist()              # the short coupler reaches 4 of the 12 positions
    [12, 4]
    """
    from ..engine import Engine
    from .geometry import design_geometry
    from .run import load_template
    from .variants import Variants, read_variants, variants_from

    template = load_template(model)
    if isinstance(variants, dict):
        variants = variants_from(template, variants)
    elif not isinstance(variants, Variants):
        variants = read_variants(variants, template)
    if engine is None:
        engine = Engine(parse_model(template.bind(), source=template.source), backend=backend)
    if len(engine.inputs) != 1:
        raise ValueError(f"{template.source}: a design batch drives one input; this model has {len(engine.inputs)}")
    return DesignBatch(engine, design_geometry(template, variants, engine.mech), template, variants)


def compile_sample() -> None:
    """Run the compiled design kernels once on a small batch of four-bars, with the argument types the
    design studies pass (with and without accelerations, every point and one): the design batch's part
    of ``mbplanar compile`` (`backends._aot.build`). Needs numba."""
    import tomllib
    template = tomllib.loads(_SAMPLE)
    batch = design_batch(template, {"a": np.linspace(0.09, 0.11, 4)}, backend="numba")
    phi = batch.geometry.phi0[:, None] + np.linspace(0.0, 0.5, 3)
    batch.solve(phi)
    batch.solve(phi, points=["M"], links=[], accelerations=False)


#: `compile_sample`'s model: a crank-rocker four-bar, its crank length a parameter
_SAMPLE = """
name = "sample"
ground = "0"
links = [{ name = "1" }, { name = "2" }, { name = "3" }]
joints = [{ name = "O", type = "R", links = ["0", "1"], at = [0.0, 0.0] },
          { name = "A", type = "R", links = ["1", "2"], at = { from = "O", length = "a", angle = 60.0 } },
          { name = "B", type = "R", links = ["2", "3"], at = { from = "A", length = 0.3, angle = 33.0 } },
          { name = "C", type = "R", links = ["3", "0"], at = [0.3, 0.0] }]
points = [{ name = "M", link = "2", along = ["A", "B"], fraction = 0.5 }]
[parameters]
a = 0.10
[input]
joint = "O"
"""
