"""Compiled design batches (optional, needs numba): D designs of one structure × N input values each,
the design axis and the position axis both in compiled loops.

It is the numpy design batch (`mbplanar.study.batch.DesignBatch`) with another loop order, not a second
method. Per design the kernel

1. solves the drawn pose (unknowns 0) and its rates: a pose that does not close, or is singular, gets its
   status (the batch words the reason);
2. marches the input up and down from the drawn pose with the engine's continuation rules, as
   `DesignBatch._march` does for all designs at once (second-order predictor, block Newton, a step
   judged by `engine._continuation.step_verdict`, halved where it is refused); a step below `h_min` is a
   motion limit, whose bracket is handed back for the engine's fold Newton; a change point hands the
   design back;
3. predicts every requested position by the quintic Hermite interpolant of its nodes
   (`engine._continuation`), corrects it by the block Newton, checks it (converged, same signs as the
   nearest node, a correction within `max_correction`) and writes the chosen links' angles and analogue
   rates and the chosen points' positions, velocity (and acceleration) analogues. A position it cannot
   vouch for hands the design back.

When a design's input values are an ordered sweep with no gap wider than `h_max` (`_walk`), steps 2
and 3 are one: the sweep itself is walked from the drawn pose, every requested position a march node
accepted by the march's rule and written at once; a position it refuses sends the design to step 2.

The kernels take named bundles: the request's designs (`DesignIn`), the answer's arrays (`engine._tables.DesignResult`, which it writes),
the tolerances (`engine._tables.KernelTol`, every threshold named in it) and a thread's work arrays
(`DesignWork`, whose unknowns come in `Unknowns` bundles). The per-design constants (every joint's point
in the link frames, each guide's direction, the drawn input value, each link's drawn angle, the chosen
points, the higher pairs' and their curves' reals, the drawn contact parameters) have a design axis;
before a design the kernel copies its row into its own copy of the engine's step, cut, higher-pair and
curve tables (`engine._tables.sweep_tables`, the sweep kernel's), so that the per-position arithmetic
(placement, closure, the higher pairs' laws of `_numba_higher`, Jacobian, LU, rates) runs on them
unchanged.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from . import _threads
from ._jit import njit
from ._numba_blocks import (_closure, _hermite_coefficients, _hermite_slope, _hermite_value, _interval, _lu,
                            _lu_solve, _place, _rate_jump, _step_verdict)
from ._numba_higher import _higher_closure, _higher_rates
from ..engine import higher_layout as ht  # (the tables' column names)
from ..engine import HERMITE5, CutTables, DesignResult, DesignTables, StepTables

__all__ = ["solve", "DesignIn", "DesignWork", "Unknowns"]

MAX_NODES = 4096  # march nodes per design (more: the design is handed back)
MIN_DESIGNS = 64  # designs per thread below which another thread costs more than it saves


class DesignIn(NamedTuple):
    """What the kernel solves: the designs' `tables` (`engine._tables.DesignTables`: the engine's blocks,
    and per design (D designs) the constants that differ), whether each block's row and unknown scales
    are `uniform` (n_blocks,), the input's `sense`, the ground's link index, the march parameter's unit
    `scale`, whether the `accelerations` are wanted, the input values x (D, N) with their lo, hi (D,),
    and the quintic Hermite interpolant's weights `hermite` (6, 6) (`engine._continuation.HERMITE5`)."""

    tables: DesignTables
    uniform: np.ndarray
    sense: float
    ground: int
    scale: float
    accelerations: bool
    x: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    hermite: np.ndarray


class Unknowns(NamedTuple):
    """Every block's unknowns q (M,), their derivatives qd, qdd (M,) and each block's determinant (or its
    sign) `dets` (n_blocks,)."""

    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    dets: np.ndarray


class DesignWork(NamedTuple):
    """One thread's work arrays: its own copies of the step and cut tables and of the higher pairs' and
    their curves' reals (a design's rows are copied in), the higher pairs' caches `hc` (H,
    `HIGHER_CACHE`) and the curves' work vector `wk` (`backends._numba_higher`);
    the pose `ps` (8, L): θ, cos θ, sin θ, r_x, r_y per link, then each link's anchor angle θa, cos θa,
    sin θa (`_turn`); rates `rt` (slots, 3, L) and the step and cut caches `sc`, `cc` of
    `_numba_kinematics`; a block's Jacobian as solved and scaled (`jac`, `jac_s`) with their permutations,
    its residual, Newton step and the unknowns' rates (`res`, `step`, `qd_u`, `qdd_u`); the unknowns of the
    position being solved (`now`), of the drawn pose (`drawn`) and of the march's current node (`node`,
    its dets holding the signs); the prediction `guess` and its rates' `qdp` (M,); the last two positions
    followed `prev` (2, 2, M) (q and dq/dφ); the march's nodes (node_phi, node_q (nodes, 3, M),
    node_sign) and their interpolant `coef` (nodes, 6, M)."""

    steps: StepTables
    cuts: CutTables
    higher: ht.HigherTables
    curves: ht.CurveTables
    hc: np.ndarray
    wk: np.ndarray
    ps: np.ndarray
    rt: np.ndarray
    sc: np.ndarray
    cc: np.ndarray
    jac: np.ndarray
    jac_s: np.ndarray
    perm: np.ndarray
    perm_s: np.ndarray
    res: np.ndarray
    step: np.ndarray
    qd_u: np.ndarray
    qdd_u: np.ndarray
    now: Unknowns
    drawn: Unknowns
    node: Unknowns
    guess: np.ndarray
    qdp: np.ndarray
    prev: np.ndarray
    node_phi: np.ndarray
    node_q: np.ndarray
    node_sign: np.ndarray
    coef: np.ndarray

    @classmethod
    def new(cls, tables: DesignTables, n_links: int, m_all: int, m_max: int, n_blocks: int) -> "DesignWork":
        """Work arrays for the `tables`' steps, cuts and higher pairs, L links, M unknowns, the largest
        block's unknowns."""
        vec = lambda n: np.zeros(max(n, 1))  # noqa: E731
        m1 = max(m_all, 1)
        steps, cuts, higher, curves = tables.steps, tables.cuts, tables.higher, tables.curves

        def unknowns():
            return Unknowns(vec(m_all), vec(m_all), vec(m_all), np.ones(n_blocks))
        return cls(steps._replace(s0=steps.s0.copy(), u0=steps.u0.copy()),
                   cuts._replace(s0=cuts.s0.copy(), n0=cuts.n0.copy()), higher._replace(reals=higher.reals.copy()),
                   curves._replace(reals=curves.reals.copy()), np.zeros((max(len(higher.ints), 1), ht.HIGHER_CACHE)),
                   np.zeros(ht.CURVE_WORK), np.zeros((8, n_links)), np.zeros((m_max + 2, 3, n_links)),
                   np.zeros((max(len(steps.parent), 1), 5)),
                   np.zeros((max(len(cuts.a), 1), 9)), np.zeros((m_max, m_max)), np.zeros((m_max, m_max)),
                   np.zeros(m_max, np.int64), np.zeros(m_max, np.int64), vec(m_max), vec(m_max), vec(m_max),
                   vec(m_max), unknowns(), unknowns(), unknowns(), vec(m_all), vec(m_all), np.zeros((2, 2, m1)),
                   np.zeros(MAX_NODES), np.zeros((MAX_NODES, 3, m1)), np.zeros((MAX_NODES, n_blocks)),
                   np.zeros((MAX_NODES, 6, m1)))


def solve(request) -> DesignResult:
    """The kernel over a design request's designs (D,) at their input values x (D, N) (SI): march, then
    every position (`engine._tables.DesignJob`); the designs split over `request.threads` threads.

    Returns
    -------
    DesignResult
    """
    tables, accelerations = request.tables, request.accelerations
    x = np.ascontiguousarray(request.x, float)
    count, n = x.shape
    n_links, n_points = tables.link_out.shape[0], tables.point_link.shape[0]
    n_blocks = len(tables.blocks.m)
    m_all = int(tables.blocks.m.sum())
    m_max = max([1] + [int(m) for m in tables.blocks.m])
    m1 = max(m_all, 1)
    out = DesignResult(np.zeros(count, np.int64), np.empty((count, n), np.bool_), np.empty((count, n, n_links)),
                       np.empty((count, n, n_links)),
                       np.empty((count, n, n_links)) if accelerations else np.empty((0, 0, n_links)),
                       np.empty((count, n, n_points, 2)), np.empty((count, n, n_points, 2)),
                       np.empty((count, n, n_points, 2)) if accelerations else np.empty((0, 0, n_points, 2)),
                       np.zeros((count, 2), np.bool_), np.zeros((count, 2)), np.zeros((count, 2)),
                       *(np.zeros((count, 2, m1)) for _ in range(3)), np.zeros((count, 2, n_blocks)))
    lo, hi = x.min(axis=1) if n else tables.phi0, x.max(axis=1) if n else tables.phi0
    inp = DesignIn(tables, request.uniform, float(request.sense), int(request.ground), float(request.scale),
                   bool(accelerations), x, lo, hi, HERMITE5)
    sizes = (len(tables.reference[0]), m_all, m_max, n_blocks)
    k = 1 if count < 2 * MIN_DESIGNS else max(1, min(request.threads or _threads.available(), count // MIN_DESIGNS))
    cuts_at = [count * i // k for i in range(k + 1)]
    parts = [slice(a, b) for a, b in zip(cuts_at[:-1], cuts_at[1:])]
    store = request.store.setdefault(sizes + tables.higher.reals.shape + tables.curves.reals.shape, [])
    work = _threads.work_arrays(store, lambda: DesignWork.new(tables, *sizes), len(parts))
    # (the request's integers: which pair, which curve; the work arrays' reals, a design's copied in)
    work = [w._replace(higher=tables.higher._replace(reals=w.higher.reals),
                       curves=tables.curves._replace(reals=w.curves.reals)) for w in work]
    _threads.run([lambda p=p, w=w: _designs(_part_in(inp, p), _part_out(out, p, accelerations), request.tol, w)
                  for p, w in zip(parts, work)])
    failed = out.status != 0  # rows the kernel left unwritten
    if failed.any():
        out.valid[failed] = False
        for arr in (out.angle, out.wq, out.xy, out.vq) + ((out.eq, out.aq) if accelerations else ()):
            arr[failed] = np.nan
    return out if accelerations else out._replace(eq=None, aq=None)


def _part_in(inp: DesignIn, p: slice) -> DesignIn:
    """The designs `p` of a request (the per-design arrays sliced)."""
    t = inp.tables
    return inp._replace(tables=t._replace(step_s0=t.step_s0[p], step_u0=t.step_u0[p], cut_s0=t.cut_s0[p],
                                          cut_n0=t.cut_n0[p], phi0=t.phi0[p], reference=t.reference[p],
                                          point_at=t.point_at[p], higher_reals=t.higher_reals[p],
                                          curve_reals=t.curve_reals[p], q0=t.q0[p]),
                        x=inp.x[p], lo=inp.lo[p], hi=inp.hi[p])


def _part_out(out: DesignResult, p: slice, accelerations: bool) -> DesignResult:
    """The designs `p` of the answer's arrays (eq, aq left empty without accelerations)."""
    return DesignResult(*(a if not accelerations and name in ("eq", "aq") else a[p] for name, a in zip(out._fields, out)))


# -- kernels ----------------------------------------------------------------------------------------
# As in `_numba_kinematics`: scalar loops over arrays indexed in place, compiled without numba's reference
# counting, nothing allocated, every work array passed by the caller. Pose ps (8, L): θ, cos θ, sin θ,
# r_x, r_y per link, then each link's anchor angle θa, cos θa, sin θa (`_turn`). Rates rt (slots, 3, L):
# ω, v_x, v_y per link; slots 0 … m−1 hold a block's sensitivities to its unknowns, then the velocities,
# then the accelerations. q, qd, qdd (M,) hold every block's unknowns and their derivatives. The
# per-position building blocks (placement, closure, their rates, the Jacobian, a block's rate pass) are the
# joint laws' arithmetic (`engine._constraints`), as the sweep kernel has it written out in its loop. The
# floating-point options are the building blocks' (fastmath off: no contraction into fused multiply-adds).
# LLVM's level 3, not the sweep's 2 (`_jit._scalar_codegen`): the batch asked for the sweep's work took
# 1.53-1.56 s at level 3 against 1.71 s at level 2 (10,000 four-bars × 360 positions, `benchmarks/study.py`).
_jit = njit(cache=True, error_model="numpy", nogil=True, _nrt=False, fastmath=False, opt=3)
_inline = njit(cache=True, error_model="numpy", nogil=True, _nrt=False, inline="always", fastmath=False, opt=3)


@_inline
def _factor(a, m, perm):
    """`_lu` of a[:m, :m] (the same operations in the same order), written out for the 1 × 1 and 2 × 2
    blocks of dyads and single joints so that it is inlined where a position is solved; larger blocks
    call `_lu`."""
    if m == 2:
        sign = 1.0
        perm[0], perm[1] = 0, 1
        if abs(a[1, 0]) > abs(a[0, 0]):
            a[0, 0], a[1, 0] = a[1, 0], a[0, 0]
            a[0, 1], a[1, 1] = a[1, 1], a[0, 1]
            perm[0], perm[1] = 1, 0
            sign = -1.0
        a[1, 0] /= a[0, 0]
        a[1, 1] -= a[1, 0] * a[0, 1]
        p0, p1 = abs(a[0, 0]), abs(a[1, 1])
        return sign * a[0, 0] * a[1, 1], min(p0, p1) / max(max(p0, p1), 1e-300)
    if m == 1:
        perm[0] = 0
        p0 = abs(a[0, 0])
        return a[0, 0], p0 / max(p0, 1e-300)
    return _lu(a, m, perm)


@_inline
def _solve_factored(a, m, perm, b, x):
    """`_lu_solve` (x = A⁻¹ b from the factors of `_factor`), written out for m ≤ 2 as `_factor` is."""
    if m == 2:
        x0 = b[perm[0]]
        x1 = (b[perm[1]] - a[1, 0] * x0) / a[1, 1]
        x[0], x[1] = (x0 - a[0, 1] * x1) / a[0, 0], x1
    elif m == 1:
        x[0] = b[0] / a[0, 0]
    else:
        _lu_solve(a, m, perm, b, x)


@_inline
def _step_rates(k, steps, sc, rt, slot, qd, vel, qv):
    """Rates in rt[slot] of step k's child from its parent's and the tree variable's rate qd; with
    vel >= 0 they are accelerations, rt[vel] holding the velocities and qv the variable's velocity."""
    parent, child, rel = steps.parent[k], steps.child[k], steps.relative[k]
    wp, vpx, vpy = rt[slot, 0, parent], rt[slot, 1, parent], rt[slot, 2, parent]
    if not steps.prismatic[k]:
        rpx, rpy, rcx, rcy = sc[k, 0], sc[k, 1], sc[k, 2], sc[k, 3]
        wc = qd + wp if rel else qd
        cx = vpx + wp * -rpy - wc * -rcy
        cy = vpy + wp * rpx - wc * rcx
        if vel >= 0:
            Wp, Wc = rt[vel, 0, parent], rt[vel, 0, child]
            cx = cx - (Wp * Wp) * rpx + (Wc * Wc) * rcx
            cy = cy - (Wp * Wp) * rpy + (Wc * Wc) * rcy
        rt[slot, 0, child], rt[slot, 1, child], rt[slot, 2, child] = wc, cx, cy
    else:
        sign, ux, uy, q = steps.carrier[k], sc[k, 0], sc[k, 1], sc[k, 4]
        cx = vpx + sign * (qd * ux + (q * wp) * -uy)
        cy = vpy + sign * (qd * uy + (q * wp) * ux)
        if vel >= 0:
            Wp = rt[vel, 0, parent]
            cx = cx + sign * ((2 * qv * Wp) * -uy - (q * Wp * Wp) * ux)
            cy = cy + sign * ((2 * qv * Wp) * ux - (q * Wp * Wp) * uy)
        rt[slot, 0, child], rt[slot, 1, child], rt[slot, 2, child] = wp, cx, cy


@_inline
def _closure_rates(k, cuts, cc, rt, slot, vel, out, row):
    """Rate rows of cut k from rt[slot] (its Jacobian column when the slot holds sensitivities); with
    vel >= 0 the centripetal and Coriolis terms from the velocities rt[vel]."""
    a, b = cuts.a[k], cuts.b[k]
    rax, ray, rbx, rby = cc[k, 0], cc[k, 1], cc[k, 2], cc[k, 3]
    wa, wb = rt[slot, 0, a], rt[slot, 0, b]
    if not cuts.prismatic[k]:
        ox = rt[slot, 1, a] + wa * -ray - rt[slot, 1, b] - wb * -rby
        oy = rt[slot, 2, a] + wa * rax - rt[slot, 2, b] - wb * rbx
        if vel >= 0:
            Wa, Wb = rt[vel, 0, a], rt[vel, 0, b]
            ox = ox - (Wa * Wa) * rax + (Wb * Wb) * rbx
            oy = oy - (Wa * Wa) * ray + (Wb * Wb) * rby
        out[row], out[row + 1] = ox, oy
    else:  # a carrier, b slider
        nx, ny, dx, dy, pnd = cc[k, 4], cc[k, 5], cc[k, 6], cc[k, 7], cc[k, 8]
        drx = rt[slot, 1, b] + wb * -rby - rt[slot, 1, a] - wa * -ray
        dry = rt[slot, 2, b] + wb * rbx - rt[slot, 2, a] - wa * rax
        o1 = drx * nx + dry * ny + wa * pnd
        if vel >= 0:
            Ws, Wc = rt[vel, 0, b], rt[vel, 0, a]
            dvx = rt[vel, 1, b] + Ws * -rby - rt[vel, 1, a] - Wc * -ray
            dvy = rt[vel, 2, b] + Ws * rbx - rt[vel, 2, a] - Wc * rax
            bx = -(Ws * Ws) * rbx + (Wc * Wc) * rax
            by = -(Ws * Ws) * rby + (Wc * Wc) * ray
            o1 += -(Wc * Wc) * (nx * dx + ny * dy) + 2 * Wc * (-ny * dvx + nx * dvy) + (nx * bx + ny * by)
        out[row], out[row + 1] = wb - wa, o1


@_inline
def _higher_into(h, hp, hc, rt, slot, pu, vel, big_u, out):
    """Rate rows of higher pair h (from its H_ROW on in out) from rt[slot] and its contact parameter's
    rate pu (`_numba_higher._higher_rates`; vel >= 0: the acceleration's, big_u its parameter's velocity)."""
    row = hp.ints[h, ht.H_ROW]
    o0, o1 = _higher_rates(h, hp, hc, rt, slot, pu, vel, big_u)
    out[row] = o0
    if hp.ints[h, ht.H_EQUATIONS] == 2:
        out[row + 1] = o1


@_inline
def _jacobian(bk, blocks, steps, cuts, work):
    """Closure Jacobian (m, m) of block bk in work.jac, and in rt[0 … m − 1] the sensitivities of its links'
    rates to each unknown (the links outside the block stay at 0); work.step holds a column."""
    k0, k1, c0, c1 = blocks.step0[bk], blocks.step1[bk], blocks.cut0[bk], blocks.cut1[bk]
    m, var0, anchors = blocks.m[bk], blocks.var0[bk], blocks.anchors
    sc, cc, rt, jac, col = work.sc, work.cc, work.rt, work.jac, work.step
    hp, hc = work.higher, work.hc
    for j in range(m):
        for t in range(blocks.anchor0[bk], blocks.anchor1[bk]):  # the links the block reads but does not place
            for comp in range(3):                                # are at rest
                rt[j, comp, anchors[t]] = 0.0
        for k in range(k0, k1):
            _step_rates(k, steps, sc, rt, j, 1.0 if steps.var[k] - var0 == j and steps.var[k] >= 0 else 0.0, -1,
                        0.0)
        for k in range(c0, c1):
            _closure_rates(k, cuts, cc, rt, j, -1, col, 2 * (k - c0))
        for h in range(hp.first[bk], hp.first[bk + 1]):  # a contact parameter's column: its unit rate
            _higher_into(h, hp, hc, rt, j, 1.0 if hp.ints[h, ht.H_VAR] - var0 == j else 0.0, -1, 0.0, col)
        for i in range(m):
            jac[i, j] = col[i]


@_jit
def _block_rates(bk, blocks, work, slot, vel, q_in_rate, qd_vel, q_in_vel, out):
    """Block bk's link rates into rt[slot] (accelerations with vel >= 0), its unknowns' rates into
    out[:m]; qd_vel, q_in_vel: the unknowns' and the input's velocities (for the Coriolis terms). It is
    `_refine` from rates 0 (compiled on its own and called: it runs off the followed path only)."""
    for i in range(blocks.m[bk]):
        out[i] = 0.0
    _refine(bk, blocks, work, slot, vel, q_in_rate, qd_vel, q_in_vel, out)


@_inline
def _refine(bk, blocks, work, slot, vel, q_in_rate, qd_vel, q_in_vel, out):
    """One step of iterative refinement of block bk's rates out[:m] (and its links' rates in rt[slot]) with
    the factors in work.jac, work.perm and the sensitivities rt[0 … m − 1] (those of the pose as placed,
    or of a nearby one, the Newton iterate before the last): the rates of the block's links recomputed
    forward from out at the pose as placed, the closure's rate residual r, out += δ with J δ = −r (δ in
    work.step), the links' rates moved by the sensitivities times δ. From out = 0 with the pose's own
    factors it is the rate pass itself (`_block_rates`); the error left otherwise is bounded in
    `_lazy_rates`."""
    k0, k1, c0, c1 = blocks.step0[bk], blocks.step1[bk], blocks.cut0[bk], blocks.cut1[bk]
    m, var0 = blocks.m[bk], blocks.var0[bk]
    steps, cuts, sc, cc, rt, rhs, delta = work.steps, work.cuts, work.sc, work.cc, work.rt, work.res, work.step
    for k in range(k0, k1):
        var, sign = steps.var[k], steps.sign[k]
        qd = out[var - var0] if var >= 0 else sign * q_in_rate
        qv = qd_vel[var - var0] if var >= 0 else sign * q_in_vel
        _step_rates(k, steps, sc, rt, slot, qd, vel, qv)
    if m == 0:
        return
    for k in range(c0, c1):
        _closure_rates(k, cuts, cc, rt, slot, vel, rhs, 2 * (k - c0))
    hp = work.higher
    for h in range(hp.first[bk], hp.first[bk + 1]):  # (a contact parameter's rate is an unknown's)
        par = hp.ints[h, ht.H_VAR] - var0
        _higher_into(h, hp, work.hc, rt, slot, out[par] if par >= 0 else 0.0, vel,
                     qd_vel[par] if vel >= 0 and par >= 0 else 0.0, rhs)
    for i in range(m):
        rhs[i] = -rhs[i]
    _solve_factored(work.jac, m, work.perm, rhs, delta)
    for i in range(m):
        out[i] += delta[i]
    for k in range(k0, k1):
        link = steps.child[k]
        for j in range(m):
            for comp in range(3):
                rt[slot, comp, link] += rt[j, comp, link] * delta[j]


@_inline
def _lazy_rates(bk, blocks, work, slot, vel, q_in_rate, qd_vel, q_in_vel, out, unit, reach, polish):
    """Block bk's rates (as `_block_rates`) from the factors and sensitivities of the Newton iterate before
    the last, a scaled distance s away, starting from the guess in out[:m]: `_refine` steps until the
    error left is below `polish` (relative to 1 + |rate|, in the input's `unit`). A step from a guess e
    away leaves at most ‖J₀⁻¹(J₀ − J₁)‖·e ≤ `reach`·e (`reach` = 4·m·s / pivot ratio, a bound with a
    safety factor of 4 on ‖J₀⁻¹‖·‖∂J/∂q‖·s), e being about the step's own size: with the followed
    sweep's guesses (e ~ 1e-9 at 1° steps) and s ~ 3e-9 one step is enough for 98 % of the positions;
    each further step gains a factor `reach` (≤ 2e-5 with s ≤ `lazy_step`), so at most four are taken."""
    m, var0, var_scale, delta = blocks.m[bk], blocks.var0[bk], blocks.var_scale, work.step
    for _ in range(4):
        _refine(bk, blocks, work, slot, vel, q_in_rate, qd_vel, q_in_vel, out)
        done = True
        for i in range(m):
            vs = var_scale[var0 + i] * unit
            if not reach * abs(delta[i]) * vs <= polish * (1.0 + abs(out[i]) * vs):
                done = False
        if done:
            return


@_jit
def _solve(inp, work, tol, state, q_in, rate, accelerations, lazy, unit, gain):
    """Block Newton at input variable q_in from the guesses in state.q (solved in place), then the rates
    for input rate `rate` (state.qd) and, with `accelerations`, input acceleration 0 (state.qdd). Fills
    state.dets (n_blocks,) with each block's scaled determinant. Returns (converged, smallest scaled pivot
    ratio).

    With `lazy`, a block whose last Newton step was below `tol.lazy_step` (scaled), taken from a Jacobian
    whose pivot ratio is at least twice `pivot_polish`, and whose residual after it is below `polish`
    is accepted without a new Jacobian: the iteration a converged block ends with only confirms the
    rounding floor, and what it would compute besides, the Jacobian's determinant sign and pivot
    ratio, cannot differ from the last one's by more than that step moves them (a relative ~1e-6 at
    most against a ratio of 0.1 or more: the same sign, the same side of every threshold). Its rates
    are solved with the last factors from the guesses the caller leaves in qd and qdd (the predicted
    rates; anything finite will do) to within `polish` (`_lazy_rates`; `unit`: the input's unit, 1 for
    a revolute input, the mechanism's size for a slider). The rates' guess is first moved by `gain`
    times Newton's correction of the positions: a predictor's error in q' is that factor times its
    error in q (to leading order), which Newton has just measured."""
    closure, max_newton, pivot_polish, pivot_cross, polish = (tol.closure, tol.max_newton, tol.pivot_polish,
                                                              tol.pivot_cross, tol.polish)
    lazy_ratio, lazy_step, turn, nudge = 2 * pivot_polish, tol.lazy_step, tol.turn, tol.nudge
    steps, cuts, blocks = work.steps, work.cuts, inp.tables.blocks
    uniform, sense, ground = inp.uniform, inp.sense, inp.ground
    q, qd, qdd, dets = state
    ps, rt, sc, cc, jac, jac_s, perm, perm_s = work.ps, work.rt, work.sc, work.cc, work.jac, work.jac_s, work.perm, \
        work.perm_s
    res, step, qd_u, qdd_u = work.res, work.step, work.qd_u, work.qdd_u
    hp, cv, hc, wk = work.higher, work.curves, work.hc, work.wk
    n_blocks = len(blocks.m)
    row_scale, var_scale = blocks.row_scale, blocks.var_scale
    vel, acc = len(rt) - 2, len(rt) - 1
    ps[0, ground], ps[1, ground], ps[2, ground], ps[3, ground], ps[4, ground] = 0.0, 1.0, 0.0, 0.0, 0.0
    for comp in range(3):
        for link in range(rt.shape[2]):
            rt[vel, comp, link] = 0.0
            if accelerations:
                rt[acc, comp, link] = 0.0
    smallest = 1.0
    for bk in range(n_blocks):
        k0, k1, c0, c1 = blocks.step0[bk], blocks.step1[bk], blocks.cut0[bk], blocks.cut1[bk]
        var0, m = blocks.var0[bk], blocks.m[bk]
        polished, ok, det, ratio, err, small, stale, moved = False, False, 1.0, 1.0, 0.0, False, False, 0.0
        if lazy:
            for i in range(m):
                qd_u[i] = q[var0 + i]  # the guess, for the rates' guess (qd_u is free until the rates)
        for it in range(max_newton + 1):
            for k in range(k0, k1):
                if steps.prismatic[k]:
                    _place(k, steps, q, q_in, ps, sc)
                elif not (it > 0 and _nudge(k, steps, q, q_in, ps, sc, nudge)):
                    # turned from where the link is (the position before, or the last iterate), unless
                    # moved by a step at the rounding floor (`_nudge`)
                    _turn(k, steps, q, q_in, ps, sc, turn)
            err = 0.0
            for k in range(c0, c1):
                _closure(k, cuts, ps, cc, res, 2 * (k - c0))
            for h in range(hp.first[bk], hp.first[bk + 1]):  # (Gear, Rack, PointOnCurve, FaceOnCurve.closure)
                _higher_closure(h, hp, cv, ps, q, hc, wk, res)
            for i in range(m):
                err = max(err, abs(res[i]) * row_scale[var0 + i])
            if m == 0:
                ok = True
                break
            if small and err < polish:  # at the rounding floor after a tiny step (see the docstring)
                ok, stale = True, True
                break
            _jacobian(bk, blocks, steps, cuts, work)
            if uniform[bk]:  # R·J·V⁻¹ a multiple of J: the same pivot ratio and sign
                det, ratio = _factor(jac, m, perm)
            else:  # the dimensionless Jacobian R·J·V⁻¹: its pivots and sign, as numpy's
                for i in range(m):
                    for j in range(m):
                        jac_s[i, j] = jac[i, j] * row_scale[var0 + i] / var_scale[var0 + j]
                det, ratio = _lu(jac_s, m, perm_s)  # (called: blocks mixing R and P rows or unknowns)
                _lu(jac, m, perm)
            ok = err < closure
            if ok:  # converged: polished to `polish` (as in a batch whose other positions still step), and
                # near a singular position one more step, as `BlockSolver.newton` does
                if polished or (err < polish and not pivot_cross * 1e3 <= ratio < pivot_polish):
                    break
                polished = True
            if it == max_newton:
                break
            for i in range(m):
                res[i] = -res[i]
            _solve_factored(jac, m, perm, res, step)
            small = lazy and ratio >= lazy_ratio
            moved = 0.0
            for i in range(m):
                if math.isfinite(step[i]):
                    q[var0 + i] += step[i]
                moved = max(moved, abs(step[i]) * var_scale[var0 + i])
            small = small and moved <= lazy_step
        for h in range(hp.first[bk], hp.first[bk + 1]):  # a contact past an open curve's end (`law.inside`)
            var = hp.ints[h, ht.H_VAR]
            if var >= 0 and not (hp.reals[h, ht.H_LO] <= q[var] <= hp.reals[h, ht.H_HI]):
                ok = False
        if not (ok and math.isfinite(err)):
            return False, smallest
        dets[bk] = det
        smallest = min(smallest, ratio)
        reach = 4.0 * m * moved / ratio
        # the velocities, then the accelerations: one pass of code for both (each inlined pass is compiled
        # again wherever `_solve` is inlined); a block without unknowns is its forward pass (`_refine`)
        fresh = m > 0 and not stale
        for p in range(2 if accelerations else 1):
            if p == 0:
                slot, before, in_rate, in_vel, out, unit_p = vel, -1, sense * rate, 0.0, qd_u, unit
            else:
                slot, before, in_rate, in_vel, out, unit_p = acc, vel, 0.0, sense * rate, qdd_u, unit * unit
            if fresh:
                _block_rates(bk, blocks, work, slot, before, in_rate, qd_u, in_vel, out)
            else:
                for i in range(m):
                    guess = qd[var0 + i] + gain * (q[var0 + i] - qd_u[i]) if p == 0 else qdd[var0 + i]
                    out[i] = guess if math.isfinite(guess) else 0.0
                _lazy_rates(bk, blocks, work, slot, before, in_rate, qd_u, in_vel, out, unit_p, reach, polish)
            for i in range(m):
                if p == 0:
                    qd[var0 + i] = out[i]
                else:
                    qdd[var0 + i] = out[i]
    return True, smallest


#: `_solve` inlined where it runs per requested position (a call passes every table and work array,
#: a few hundred words, which costs as much as the arithmetic of a small block)
_solve_inline = _inline(_solve.py_func)


@_inline
def _turn(k, steps, q, q_in, ps, sc, turn):
    """`_place` of a revolute step k by turning its child from an anchor angle θa, whose cos and sin were
    computed by `_place` (ps[5:8, child]): cos and sin of the new angle by the angle-addition formulas,
    those of the turn δ = θ − θa by their series (|δ| < `turn`, ``Tolerances.turn``: the first omitted
    terms, δ¹⁰/10! and δ¹¹/11!, are below 1e-19 at 0.05), so that every placement is one rotation from
    exactly computed values and no rounding accumulates. A larger turn is placed by `_place` and becomes
    the anchor."""
    parent, child, rel, var = steps.parent[k], steps.child[k], steps.relative[k], steps.var[k]
    value = q[var] if var >= 0 else steps.sign[k] * q_in
    t = ps[0, parent] + value if rel else value
    delta = t - ps[5, child]
    if not abs(delta) < turn:
        _place(k, steps, q, q_in, ps, sc)
        ps[5, child], ps[6, child], ps[7, child] = ps[0, child], ps[1, child], ps[2, child]
        return
    d2 = delta * delta
    cd = 1.0 - 0.5 * d2 * (1.0 - d2 * (1.0 / 12.0) * (1.0 - d2 * (1.0 / 30.0) * (1.0 - d2 * (1.0 / 56.0))))
    sd = delta * (1.0 - d2 * (1.0 / 6.0) * (1.0 - d2 * (1.0 / 20.0) * (1.0 - d2 * (1.0 / 42.0)
                                                                         * (1.0 - d2 * (1.0 / 72.0)))))
    c0, s0 = ps[6, child], ps[7, child]
    _pose_at(k, steps, ps, sc, parent, child, t, c0 * cd - s0 * sd, s0 * cd + c0 * sd)


@_inline
def _nudge(k, steps, q, q_in, ps, sc, nudge):
    """`_turn` of a revolute step k whose child moved by less than `nudge` (``Tolerances.nudge``) since it
    was placed (a Newton step at the rounding floor): cos and sin from the placed ones to first order,
    cos(θ + ε) = cos θ − ε sin θ, sin(θ + ε) = sin θ + ε cos θ (the terms left out, ε²/2, below 5e-17 at
    1e-8: a rounding of its own, no more). Used only within one solve, after its first placement by
    `_turn`: a solve's Newton steps below `nudge` are its last one or two, so a position is at most that
    many such rotations from exactly computed values and nothing accumulates from one position to the
    next. Returns False, placing nothing, for a larger move (placed by `_turn`)."""
    parent, child, rel, var = steps.parent[k], steps.child[k], steps.relative[k], steps.var[k]
    value = q[var] if var >= 0 else steps.sign[k] * q_in
    t = ps[0, parent] + value if rel else value
    eps = t - ps[0, child]
    if not abs(eps) < nudge:
        return False
    c0, s0 = ps[1, child], ps[2, child]
    _pose_at(k, steps, ps, sc, parent, child, t, c0 - eps * s0, s0 + eps * c0)
    return True


@_inline
def _pose_at(k, steps, ps, sc, parent, child, t, cc, ss):
    """Step k's child at angle t (cos cc, sin ss): its frame origin from the parent's, and the cached
    joint vectors in sc[k]."""
    cp, sp = ps[1, parent], ps[2, parent]
    s0x, s0y = steps.s0[k, 0], steps.s0[k, 1]
    rpx, rpy = cp * s0x - sp * s0y, sp * s0x + cp * s0y
    ps[0, child], ps[1, child], ps[2, child] = t, cc, ss
    rcx, rcy = cc * s0x - ss * s0y, ss * s0x + cc * s0y
    ps[3, child] = ps[3, parent] + rpx - rcx
    ps[4, child] = ps[4, parent] + rpy - rcy
    sc[k, 0], sc[k, 1], sc[k, 2], sc[k, 3] = rpx, rpy, rcx, rcy


@_jit
def _reverse(node_phi, node_q, node_sign, count):
    """Reverse the first `count` nodes in place (the march down gives them in decreasing φ)."""
    for a in range(count // 2):
        b = count - 1 - a
        node_phi[a], node_phi[b] = node_phi[b], node_phi[a]
        for r in range(node_q.shape[1]):
            for i in range(node_q.shape[2]):
                node_q[a, r, i], node_q[b, r, i] = node_q[b, r, i], node_q[a, r, i]
        for i in range(node_sign.shape[1]):
            node_sign[a, i], node_sign[b, i] = node_sign[b, i], node_sign[a, i]


@_jit
def _blank(d, n, out, accelerations):
    """NaN in every output of position n of design d (not on the design's branch)."""
    angle, wq, eq, xy, vq, aq = out.angle, out.wq, out.eq, out.xy, out.vq, out.aq
    for l in range(angle.shape[2]):  # noqa: E741
        angle[d, n, l], wq[d, n, l] = np.nan, np.nan
        if accelerations:
            eq[d, n, l] = np.nan
    for p in range(xy.shape[2]):
        for c in range(2):
            xy[d, n, p, c], vq[d, n, p, c] = np.nan, np.nan
            if accelerations:
                aq[d, n, p, c] = np.nan


@_inline
def _sign(v):
    """The sign of v as numpy's (0 at 0)."""
    return 1.0 if v > 0 else -1.0 if v < 0 else 0.0


@_jit
def _march(d, inp, out, tol, work, target, direction, start, side):
    """Walk design d from its drawn pose (work.drawn: q, dq/dφ, d²q/dφ² per unit input, dets) towards
    `target` in `direction`, as `DesignBatch._march`: the accepted nodes go to node_*[start:] (q, dq/dφ,
    d²q/dφ²); returns (nodes added, status). A motion limit fills out.limit*[d, side]."""
    max_correction, h_start, h_max, h_min = tol.max_correction, tol.h_start, tol.h_max, tol.h_min
    blocks, scale, phi0 = inp.tables.blocks, inp.scale, inp.tables.phi0[d]
    q0, qd0, qdd0, dets0 = work.drawn
    qc, qdc, qddc, signs = work.node
    now = work.now
    q, qd, qdd, dets = now
    node_phi, node_q, node_sign = work.node_phi, work.node_q, work.node_sign
    m_all = len(blocks.var_scale)
    n_blocks = len(blocks.m)
    var_scale = blocks.var_scale
    span = abs(target - phi0) / scale
    rate = direction * scale
    yes, no = start >= 0, start < 0  # run-time booleans for `_solve` (see `_designs`)
    for i in range(m_all):
        qc[i], qdc[i], qddc[i] = q0[i], qd0[i] * rate, qdd0[i] * scale * scale
    for b in range(n_blocks):
        signs[b] = _sign(dets0[b])
    s, h, added = 0.0, h_start, 0
    while s < span:
        h_try = min(h, span - s)
        end = s + h_try >= span
        phi = target if end else phi0 + rate * (s + h_try)
        for i in range(m_all):
            q[i] = qc[i] + qdc[i] * h_try + 0.5 * qddc[i] * h_try * h_try
        converged, ratio = _solve(inp, work, tol, now, inp.sense * (phi - phi0), rate, yes, no, scale, 0.0)
        dist, jump = 0.0, 0.0
        for i in range(m_all):
            guess = qc[i] + qdc[i] * h_try + 0.5 * qddc[i] * h_try * h_try
            dist = max(dist, abs(q[i] - guess) * var_scale[i])
            err = _rate_jump(qd[i], qdc[i], qddc[i], h_try, var_scale[i])
            jump = max(jump, err) if math.isfinite(err) else math.inf
        same = True
        for b in range(n_blocks):
            if _sign(dets[b]) != signs[b]:
                same = False
        verdict = _step_verdict(converged, ratio, dist, jump, same, h_try, tol)
        if verdict == 1:  # (engine._continuation.ACCEPT)
            k = start + added
            if k >= len(node_phi):
                return added, 4
            for i in range(m_all):
                qc[i], qdc[i], qddc[i] = q[i], qd[i], qdd[i]
                node_q[k, 0, i], node_q[k, 1, i], node_q[k, 2, i] = q[i], qd[i] / rate, qdd[i] / (scale * scale)
            for b in range(n_blocks):
                signs[b] = _sign(dets[b])
                node_sign[k, b] = signs[b]
            node_phi[k] = phi
            added += 1
            s += h_try
            if dist < 0.1 * max_correction:
                h = min(h_try * 1.6, h_max)
            continue
        if verdict == 2:  # (CROSS) a change point: the design's own engine goes through it
            return added, 3
        h = h_try / 2
        if h < h_min:
            out.limit[d, side] = True
            out.limit_phi[d, side] = phi0 + rate * s
            out.limit_h[d, side] = 2 * h
            for i in range(m_all):
                out.limit_q[d, side, i], out.limit_qd[d, side, i], out.limit_qdd[d, side, i] = qc[i], qdc[i], qddc[i]
            for b in range(n_blocks):
                out.limit_signs[d, side, b] = signs[b]
            return added, 0
    return added, 0


@_inline
def _store(d, n, inp, out, work):
    """Write position n of design d from the solved pose and rates: the chosen links' angle and ω_q (ε_q),
    the chosen points' positions and velocity (acceleration) analogues."""
    ps, rt = work.ps, work.rt
    t = inp.tables
    reference, point_at, point_link, link_out = t.reference, t.point_at, t.point_link, t.link_out
    accelerations = inp.accelerations
    angle, wq, eq, xy, vq, aq = out.angle, out.wq, out.eq, out.xy, out.vq, out.aq
    vel, acc = len(rt) - 2, len(rt) - 1
    out.valid[d, n] = True
    for j in range(link_out.shape[0]):
        l = link_out[j]  # noqa: E741
        angle[d, n, j] = ps[0, l] + reference[d, l]
        wq[d, n, j] = rt[vel, 0, l]
        if accelerations:
            eq[d, n, j] = rt[acc, 0, l]
    for p in range(point_link.shape[0]):
        l = point_link[p]  # noqa: E741
        c, s = ps[1, l], ps[2, l]
        ax, ay = point_at[d, p, 0], point_at[d, p, 1]
        rx, ry = c * ax - s * ay, s * ax + c * ay
        w = rt[vel, 0, l]
        xy[d, n, p, 0], xy[d, n, p, 1] = ps[3, l] + rx, ps[4, l] + ry
        vq[d, n, p, 0], vq[d, n, p, 1] = rt[vel, 1, l] + w * -ry, rt[vel, 2, l] + w * rx
        if accelerations:
            e = rt[acc, 0, l]
            aq[d, n, p, 0] = rt[acc, 1, l] + e * -ry - (w * w) * rx
            aq[d, n, p, 1] = rt[acc, 2, l] + e * rx - (w * w) * ry


@_jit
def _walk(d, follow, total, inp, out, tol, work):
    """Every requested position of design d, solved and written, in one loop around one inlined copy of
    the block solver (each copy lengthens the kernel's first compile): with `follow`, the followed sweep
    below (returns 1, or 0 when x[d] is not such a sweep or a position is not accepted); else every
    position predicted by the interpolant of the march's `total` nodes (work.node_phi, node_q, node_sign
    and the intervals' coefficients `coef`), its rates' guess the interpolant's derivative, corrected and
    checked (converged, same signs as the nearer node, within `max_correction` of the prediction);
    positions outside the nodes are blanked; returns 0, or 4 when a position cannot be vouched for.

    Followed: design d's positions x[d] (increasing, no gap wider than the march's largest step) followed
    from its drawn pose (work.drawn: q, dq/dφ, d²q/dφ² per unit input, dets) up through those above it
    and down through those below, every position a march node: predicted from the two positions before it
    (the cubic Hermite extrapolant of their q and dq/dφ; the first by the drawn pose's Taylor polynomial),
    corrected by the block Newton and accepted by the march's rule (`engine._continuation.step_verdict`:
    converged, not singular, within `max_correction` of its prediction, dq/dφ within `rate_jump` of the
    predicted one, no change of sign of a block's determinant), then written. At 1° the prediction is
    within ~1e-8 and one Newton step ends at the rounding floor. Returns False when x[d] is not such a
    sweep or a position is not accepted: the design then takes the march (which meets the limit or change
    point there)."""
    max_correction, h_max = tol.max_correction, tol.h_max
    blocks, x, scale, phi0, accelerations = inp.tables.blocks, inp.x, inp.scale, inp.tables.phi0[d], inp.accelerations
    q0, qd0, qdd0, dets0 = work.drawn
    now = work.now
    q, qd, qdd, dets = now
    guess, qdp, prev, signs = work.guess, work.qdp, work.prev, work.node.dets
    node_phi, node_q, node_sign, coef = work.node_phi, work.node_q, work.node_sign, work.coef
    n_pos = x.shape[1]
    m_all, n_blocks = len(blocks.var_scale), len(blocks.m)
    var_scale = blocks.var_scale
    reach = h_max * scale
    up = n_pos  # the first position at or above the drawn one
    if follow:
        for n in range(n_pos):
            if n > 0 and not (x[d, n] > x[d, n - 1] and x[d, n] - x[d, n - 1] <= reach):
                return 0
            if up == n_pos and x[d, n] >= phi0:
                up = n
        if (up < n_pos and not x[d, up] - phi0 <= reach) or (up > 0 and not phi0 - x[d, up - 1] <= reach):
            return 0
    first, last = node_phi[0], node_phi[max(total, 1) - 1]
    phi_a, phi_b, older = phi0, phi0, False
    for side in range(2 if follow else 1):
        if follow:
            for i in range(m_all):
                prev[1, 0, i], prev[1, 1, i] = q0[i], qd0[i]
            for b in range(n_blocks):
                signs[b] = _sign(dets0[b])
            phi_a, phi_b, older = phi0, phi0, False
        for k in range((n_pos - up if side == 0 else up) if follow else n_pos):
            n = (up + k if side == 0 else up - 1 - k) if follow else k
            xb = x[d, n]
            gain, near = 0.0, 0
            if not follow:  # the march's interpolant and its derivative (the rates' guess)
                if xb < first or xb > last:  # past a limit (or outside the march): not on the branch
                    out.valid[d, n] = False
                    _blank(d, n, out, accelerations)
                    continue
                j, t, width = 0, 0.0, 0.0
                if total > 1:
                    j = _interval(node_phi, total, xb)
                    width = node_phi[j + 1] - node_phi[j]
                    t = (xb - node_phi[j]) / width if width > 0 else 0.0
                    near = j if abs(xb - node_phi[j]) <= abs(xb - node_phi[j + 1]) else j + 1
                for i in range(m_all):
                    if total > 1:
                        value = _hermite_value(coef[j, 0, i], coef[j, 1, i], coef[j, 2, i], coef[j, 3, i],
                                               coef[j, 4, i], coef[j, 5, i], t)
                        slope = _hermite_slope(coef[j, 1, i], coef[j, 2, i], coef[j, 3, i], coef[j, 4, i],
                                               coef[j, 5, i], t)
                        slope = slope / width if width > 0 else node_q[near, 1, i]
                    else:
                        value, slope = node_q[0, 0, i], node_q[0, 1, i]
                    guess[i], qdp[i] = value, slope
            elif older:  # the cubic through (φa, qa, q'a) and (φb, qb, q'b), extended to xb
                w = phi_b - phi_a
                inv_w = 1.0 / w
                t = (xb - phi_a) * inv_w
                t2 = t * t
                t3 = t2 * t
                h00, h10, h01, h11 = 2 * t3 - 3 * t2 + 1, t3 - 2 * t2 + t, 3 * t2 - 2 * t3, t3 - t2
                g00, g10, g11 = 6 * t2 - 6 * t, 3 * t2 - 4 * t + 1, 3 * t2 - 2 * t
                for i in range(m_all):
                    qa, qda, qb, qdb = prev[0, 0, i], prev[0, 1, i], prev[1, 0, i], prev[1, 1, i]
                    guess[i] = h00 * qa + h10 * w * qda + h01 * qb + h11 * w * qdb
                    qdp[i] = g00 * (qa - qb) * inv_w + g10 * qda + g11 * qdb
                # the extrapolant's error ~ t²(t − 1)², its derivative's 2t(t − 1)(2t − 1)/w: their ratio
                bend = t * (t - 1.0) * w
                gain = 2.0 * (2.0 * t - 1.0) / bend if bend != 0.0 else 0.0
            else:  # from the drawn pose: its Taylor polynomial
                h = xb - phi_b
                for i in range(m_all):
                    guess[i] = prev[1, 0, i] + prev[1, 1, i] * h + 0.5 * qdd0[i] * h * h
                    qdp[i] = prev[1, 1, i] + qdd0[i] * h
                gain = 3.0 / h if h != 0.0 else 0.0  # the errors ~ h³/6 and h²/2
            for i in range(m_all):
                q[i], qd[i] = guess[i], qdp[i]  # qd: the rates' guess (`_solve`'s lazy rates)
            converged, ratio = _solve_inline(inp, work, tol, now, inp.sense * (xb - phi0), 1.0, accelerations, True,
                                             scale, gain)
            if not follow:
                ok = converged
                for b in range(n_blocks):
                    if _sign(dets[b]) != node_sign[near, b]:
                        ok = False
                for i in range(m_all):
                    if abs(q[i] - guess[i]) * var_scale[i] > max_correction:
                        ok = False
                if not ok:
                    return 4
                _store(d, n, inp, out, work)
                continue
            dist, jump = 0.0, 0.0
            for i in range(m_all):  # (NaN counts as infinitely far)
                vs = var_scale[i]
                gap = abs(q[i] - guess[i]) * vs
                dist = max(dist, gap) if gap == gap else math.inf
                err = _rate_jump(qd[i], qdp[i], 0.0, 0.0, vs * scale)
                jump = max(jump, err) if err == err else math.inf
            same = True
            for b in range(n_blocks):
                if _sign(dets[b]) != signs[b]:
                    same = False
            if _step_verdict(converged, ratio, dist, jump, same, 0.0, tol) != 1:  # (not ACCEPT)
                return 0
            _store(d, n, inp, out, work)
            if xb != phi_b:
                phi_a, older = phi_b, True
                for i in range(m_all):
                    prev[0, 0, i], prev[0, 1, i] = prev[1, 0, i], prev[1, 1, i]
            phi_b = xb
            for i in range(m_all):
                prev[1, 0, i], prev[1, 1, i] = q[i], qd[i]
    return 1 if follow else 0


@_jit
def _designs(inp, out, tol, work):
    """Every design of a part: its drawn pose, its march both ways, then its positions (see the module
    docstring); out.status (D,) as `engine._tables.DESIGN_STATUS`."""
    blocks, x, lo, hi, phi0 = inp.tables.blocks, inp.x, inp.lo, inp.hi, inp.tables.phi0
    steps, cuts, ps, status, valid = work.steps, work.cuts, work.ps, out.status, out.valid
    h_reals, c_reals = work.higher.reals, work.curves.reals
    drawn, node_phi, node_q, node_sign, coef, hermite = work.drawn, work.node_phi, work.node_q, work.node_sign, \
        work.coef, inp.hermite
    q0, qd0, qdd0, dets0 = drawn
    n_designs, n_pos = x.shape
    m_all = len(blocks.var_scale)
    n_blocks = len(blocks.m)
    for l in range(ps.shape[1]):  # noqa: E741
        for r in range(8):
            ps[r, l] = 0.0
        ps[1, l], ps[6, l] = 1.0, 1.0  # cos 0 of every link and of its anchor (`_turn`) at 0
    # `_march`'s first node and sides as run-time integers: a constant 0 or 1 would be typed as a literal,
    # and numba would compile `_march` once for each (a second first compile of it)
    origin, down = n_pos - n_pos, n_pos - n_pos + 1
    yes, no = n_pos >= 0, n_pos < 0  # and `_solve`'s flags as run-time booleans, for the same reason
    for d in range(n_designs):
        for k in range(len(steps.parent)):
            steps.s0[k, 0], steps.s0[k, 1] = inp.tables.step_s0[d, k, 0], inp.tables.step_s0[d, k, 1]
            steps.u0[k, 0], steps.u0[k, 1] = inp.tables.step_u0[d, k, 0], inp.tables.step_u0[d, k, 1]
        for k in range(len(cuts.a)):
            cuts.s0[k, 0], cuts.s0[k, 1] = inp.tables.cut_s0[d, k, 0], inp.tables.cut_s0[d, k, 1]
            cuts.n0[k, 0], cuts.n0[k, 1] = inp.tables.cut_n0[d, k, 0], inp.tables.cut_n0[d, k, 1]
        for h in range(h_reals.shape[0]):
            for c in range(h_reals.shape[1]):
                h_reals[h, c] = inp.tables.higher_reals[d, h, c]
        for j in range(c_reals.shape[0]):
            for c in range(c_reals.shape[1]):
                c_reals[j, c] = inp.tables.curve_reals[d, j, c]
        for i in range(n_pos):
            valid[d, i] = False
        # 1. the drawn pose (its unknowns: 0, a contact parameter its drawn value)
        for i in range(m_all):
            q0[i] = inp.tables.q0[d, i]
        converged, ratio = _solve(inp, work, tol, drawn, 0.0, 1.0, yes, no, 1.0, 0.0)
        if not converged:
            status[d] = 1
            continue
        if not ratio >= tol.pivot_cross:
            status[d] = 2
            continue
        # 2. an ordered sweep at steps the march could take: followed position by position
        if _walk(d, yes, origin, inp, out, tol, work):
            continue
        # 3. else the march down (stored reversed), the drawn pose, the march up
        total, state = 0, 0
        if lo[d] < phi0[d]:
            total, state = _march(d, inp, out, tol, work, lo[d], -1.0, origin, down)
            _reverse(node_phi, node_q, node_sign, total)
        if state != 0:
            status[d] = state
            continue
        if total >= len(node_phi):
            status[d] = 4
            continue
        node_phi[total] = phi0[d]
        for i in range(m_all):
            node_q[total, 0, i], node_q[total, 1, i], node_q[total, 2, i] = q0[i], qd0[i], qdd0[i]
        for b in range(n_blocks):
            node_sign[total, b] = _sign(dets0[b])
        total += 1
        if hi[d] > phi0[d]:
            added, state = _march(d, inp, out, tol, work, hi[d], 1.0, total, origin)
            total += added
            if state != 0:
                status[d] = state
                continue
        # the interpolant of every interval (`engine._continuation.hermite_coefficients`, as numpy's)
        for j in range(total - 1):
            width = node_phi[j + 1] - node_phi[j]
            for i in range(m_all):
                c0, c1, c2, c3, c4, c5 = _hermite_coefficients(
                    node_q[j, 0, i], node_q[j + 1, 0, i], width * node_q[j, 1, i], width * node_q[j + 1, 1, i],
                    width * width * node_q[j, 2, i], width * width * node_q[j + 1, 2, i], hermite)
                coef[j, 0, i], coef[j, 1, i], coef[j, 2, i], coef[j, 3, i], coef[j, 4, i], coef[j, 5, i] = \
                    c0, c1, c2, c3, c4, c5
        # 4. the requested positions
        status[d] = _walk(d, no, total, inp, out, tol, work)
    return 0
