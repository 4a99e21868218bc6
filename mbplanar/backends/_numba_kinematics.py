"""Compiled kinematics of a one-input sweep (optional, needs numba): the engine's corrector, checks and
rate passes run position by position as scalar loops, and the outputs of `Motion` the caller asked for
are written in the same pass, straight into the arrays `Motion` returns (batch first, no copies).

It is the same engine, not a second one: the branch atlas, its nodes and interpolant, the joint laws'
formulas, the tolerances (the engine's `Tolerances`, passed as an argument), the scaled block Jacobians
(explicit inverse up to 2 × 2, else LU with partial pivoting, as `engine._linalg.factor`) and the
acceptance checks are the engine's; only the loop order differs (per position instead of per operation
over the batch). It takes the common case only: every position between two atlas nodes or past a
located limit, corrected on the branch at the first try. Anything else (a change point's bracket, a
position the batch corrector would hand to `_repair`, an atlas of one node) returns None and the numpy
path does the whole batch. Tests hold both paths equal to rounding on every model.

Per position the kernel writes: the link angles (B, L); the requested points' positions (B, P, 2);
with rates their real velocities and accelerations (B, P, 2) and the links' ω, ε (B, L); and a record
of the link frames and joint values (`FIELDS`, `RATE_FIELDS` with rates) from which `Motion` derives
the rest (the analogues of the points, the joints' real rates, the instantaneous centres) when first
read, and which the compiled kinetostatics reads.

The plan is the engine's `BlockPlan`s as named tables of arrays (`_tables`), built once per engine.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import _threads
from ._jit import njit
from ._numba_blocks import _closure, _interval, _lu, _lu_solve, _place  # (LLVM inlines these)
from ._tables import kinematics_tables
from ..engine._atlas import _in_brackets

__all__ = ["FIELDS", "RATE_FIELDS", "Outputs", "record_dtype", "sweep"]

# the record of a position, in this order: (name, per link / joint, components); `RATE_FIELDS` only
# with rates. The kinetostatics kernel reads it by offset.
FIELDS = (("th", "L", 1), ("cos", "L", 1), ("sin", "L", 1), ("r", "L", 2), ("value", "J", 1))
RATE_FIELDS = (("wq", "L", 1), ("eq", "L", 1), ("fv", "L", 2), ("fa", "L", 2), ("rate_q", "J", 1),
               ("accel_q", "J", 1))
_ORDER = ("th", "cos", "sin", "r", "value", "wq", "eq", "fv", "fa", "rate_q", "accel_q")  # offsets' order

_LIMITS = {(lo, hi): np.array([lo, hi], np.bool_) for lo in (False, True) for hi in (False, True)}


@dataclass
class Outputs:
    """What `sweep` wrote for the valid positions: angle (B, L), xy (B, P, 2), and with rates w, e
    (B, L), v, a (B, P, 2) (else None); rows (B,) structured records (`FIELDS`, `RATE_FIELDS`); valid
    (B,) the positions solved (the rest lie past a motion limit), complete: all of them."""

    angle: np.ndarray
    xy: np.ndarray
    w: np.ndarray | None
    e: np.ndarray | None
    v: np.ndarray | None
    a: np.ndarray | None
    rows: np.ndarray | None
    valid: np.ndarray
    complete: bool  # every position valid



@dataclass
class _KernelPlan:
    """An engine compiled for the kernel, built once: `args`, the engine's blocks, joints and reference
    angles as arrays in `_sweep`'s order; `rows` the record dtypes (without, with rates) and their
    offsets; `sizes` of the kernel's work arrays, `scratch` one set of them per thread (so that an
    engine is not for several callers at once)."""

    args: tuple
    rows: dict
    sizes: tuple
    scratch: list
    entry: object = None  # the compiled `_sweep` for these argument types, once known (`_run`)
    empty: dict = field(default_factory=dict)  # the empty arrays standing for outputs not asked for (`_none`)


def _plan(engine, joint_table) -> _KernelPlan:
    return engine.prepare("numba kinematics", lambda: _make_plan(engine, joint_table))


def _record(per: dict, fields) -> tuple:
    """The structured dtype of `fields` and the offsets (in float64s) of `_ORDER` in it (−1: absent)."""
    dtype = np.dtype([(name, float, (per[kind], comp) if comp > 1 else (per[kind],)) for name, kind, comp in fields])
    offsets = np.array([dtype.fields[n][1] // 8 if n in dtype.names else -1 for n in _ORDER], np.int64)
    return dtype, offsets


def _make_plan(engine, joint_table) -> _KernelPlan:
    """The engine's blocks and output tables as the kernel's arguments (`_tables.kinematics_tables`)."""
    steps, cuts, blocks, joints = kinematics_tables(engine, joint_table)
    alpha = np.array([engine.reference_angle[n] for n in engine.links], float)
    args = (steps, cuts, blocks, joints, alpha, float(engine.inputs[0].sense), float(engine.phi_drawn[0]),
            engine.link_index[engine.mech.ground], engine.tol.as_array(), np.array(engine.centre, float))
    per = {"L": len(engine.links), "J": len(joints.drawn)}
    rows = {False: _record(per, FIELDS), True: _record(per, FIELDS + RATE_FIELDS)}
    m_max = max([1] + [bp.m for bp in engine.blocks])
    sizes = (len(steps.parent), len(cuts.a), per["L"], len(blocks.var_scale), m_max)
    return _KernelPlan(args, rows, sizes, [])


def record_dtype(engine, joint_table, rates: bool) -> np.dtype:
    """The dtype of the records `sweep` writes (`Outputs.rows`), with or without rates."""
    return _plan(engine, joint_table).rows[bool(rates)][0]


def _scratch(n_steps: int, n_cuts: int, n_links: int, m_all: int, m_max: int) -> tuple:
    """Work arrays of `_sweep`: pose (5, L), rates (slots, 3, L), step and cut caches, unknowns and
    their guesses, a block's Jacobian with its row permutation, and four vectors of a block's size."""
    vec = lambda n: np.zeros(max(n, 1))  # noqa: E731
    return (np.zeros((5, n_links)), np.zeros((m_max + 2, 3, n_links)), np.zeros((max(n_steps, 1), 5)),
            np.zeros((max(n_cuts, 1), 9)), vec(m_all), vec(m_all), np.zeros((m_max, m_max)),
            np.zeros(m_max, np.int64), vec(m_max), vec(m_max), vec(m_max), vec(m_max))  # res, col, sol, qd_u


def _atlas_tables(engine, atlas):
    """The atlas' interpolant with every block's unknowns stacked: grid (K,), coefficients
    (K − 1, 6, M), node signs (K, n_blocks); made again when the atlas has grown."""
    arrays = atlas.arrays()
    cached = engine.prepared.get("numba atlas")
    if cached is not None and cached[0] is arrays:
        return cached[1]
    grid, per_block, signs = arrays
    coefs = [coef for _, _, _, coef in per_block if coef.shape[1]]
    coef = (np.ascontiguousarray(np.concatenate(coefs, axis=1).transpose(2, 0, 1)) if coefs
            else np.zeros((len(grid) - 1, 6, 0)))
    tables = (np.ascontiguousarray(grid), coef, np.ascontiguousarray(signs, float))
    engine.prepared["numba atlas"] = (arrays, tables)
    return tables


def _covering_tables(engine, atlas, lo: float, hi: float):
    """`_atlas_tables` of the atlas covering lo … hi (`Atlas.cover`). A sweep inside the nodes the tables
    were made from (the usual case: the same range again) neither asks the atlas to grow nor makes them
    again: `cover` would find nothing to do there."""
    found = engine.prepared.get("numba covered")
    if found is not None and found[0] <= lo and hi <= found[1] and found[2] is atlas.arrays():
        return found[3]
    atlas.cover(lo, hi)
    tables = _atlas_tables(engine, atlas)
    grid = tables[0]
    span = (float(grid[0]), float(grid[-1])) if len(grid) else (np.inf, -np.inf)
    engine.prepared["numba covered"] = (*span, atlas.arrays(), tables)
    return tables


def sweep(engine, x, lo, hi, joint_table, om, ep, p_link, p_at, rates, records=True) -> Outputs | None:
    """Kinematics of the one-input positions x (B,) (SI, contiguous, between lo and hi) with input speed
    om and acceleration ep (B,), for the points on links p_link (P,) drawn at p_at (P, 2); with `rates`
    the velocities and accelerations too; with `records` the frames and joints (`Outputs.rows`, else
    None). None where the numpy path must take the batch."""
    atlas = engine.atlas()
    grid, coef, signs = _covering_tables(engine, atlas, lo, hi)
    if len(grid) < 2:
        return None
    if atlas.crossings and _in_brackets(atlas.crossings, x).any():
        return None
    plan = _plan(engine, joint_table)
    batch, n_l, n_p = len(x), plan.sizes[2], len(p_link)
    rates = bool(rates)
    dtype, offsets = plan.rows[rates]
    rows = np.empty(batch, dtype) if records else None
    flat = rows.view(np.float64).reshape(batch, -1) if records else _none(plan, "flat", (0, 0))
    angle, xy = np.empty((batch, n_l)), np.empty((batch, n_p, 2))
    if rates:
        w, e, v, a = np.empty((batch, n_l)), np.empty((batch, n_l)), np.empty((batch, n_p, 2)), np.empty((batch, n_p, 2))
    else:  # (not written: empty arrays of the kernel's types)
        w = e = _none(plan, "links", (0, n_l))
        v = a = _none(plan, "points", (0, n_p, 2))
    valid = np.empty(batch, np.bool_)
    limits = _LIMITS[atlas.limits[-1] is not None, atlas.limits[+1] is not None]
    ep_any = rates and bool(ep.any())
    parts = _threads.chunks(batch, engine.threads)
    work = _threads.work_arrays(plan.scratch, lambda: _scratch(*plan.sizes), len(parts))
    fixed = (*plan.args, grid, coef, signs, limits)
    if len(parts) == 1:  # (one thread: no slicing)
        status = [_run(plan, (*fixed, x, om, ep, ep_any, rates, p_link, p_at, offsets, angle, xy, w, e, v, a, flat,
                              valid, *work[0]))]
    else:
        every = slice(None)
        status = _threads.run([
            lambda p=p, wk=wk, r=(p if rates else every): _run(plan, (
                *fixed, x[p], om[p], ep[p], ep_any, rates, p_link, p_at, offsets,
                angle[p], xy[p], w[r], e[r], v[r], a[r], flat[p], valid[p], *wk))
            for p, wk in zip(parts, work)])
    if any(status):
        return None
    complete = bool(valid.all())
    out = Outputs(angle, xy, w if rates else None, e if rates else None, v if rates else None,
                  a if rates else None, rows, valid, complete)
    if not complete:
        keep = np.flatnonzero(valid)
        for name in ("angle", "xy", "w", "e", "v", "a", "rows"):  # (None where not asked for)
            if getattr(out, name) is not None:
                setattr(out, name, getattr(out, name)[keep])
    return out


def _none(plan: _KernelPlan, name: str, shape: tuple) -> np.ndarray:
    """An empty float array of `shape` (a zero in it) standing for an output not asked for, made once
    per plan and shape."""
    key = (name, shape)
    found = plan.empty.get(key)
    if found is None:
        found = plan.empty[key] = np.empty(shape)
    return found


def _run(plan: _KernelPlan, args: tuple) -> int:
    """`_sweep(*args)`. The first call looks the compiled function up for the arguments' types (the
    ahead-of-time build's, else numba's, compiled or loaded now: `_jit.Kernel.entry`); later calls with
    the same plan pass the same types (the plan's tables, and arrays made here as C-contiguous float64,
    int64 and bool arrays of fixed dimensions), so they call it directly."""
    if plan.entry is None:
        plan.entry = _sweep.entry(args)
    return plan.entry(*args)


# -- kernel -----------------------------------------------------------------------------------------
# One function, each piece of the engine written once (the placement, the closure and LU of
# `_numba_blocks` are compiled on their own and inlined by LLVM, not by numba): per position
# the atlas' predictor, then per block a loop in three phases: Newton (place, closure, the Jacobian's
# columns by rate passes with unit unknown rates, factor, step), the velocity pass and the acceleration
# pass (a rate pass, the closure's rates, the solve, the correction by the sensitivities).
# Scalar loops over whole arrays indexed in place, compiled without numba's reference counting (its
# atomic increments on every array passed or aliased would cost more than the arithmetic): nothing is
# allocated here, the caller passes every work array (`_scratch`).
# Pose ps (5, L): θ, cos θ, sin θ, r_x, r_y per link. Rates rt (slots, 3, L): ω, v_x, v_y per link;
# slots 0 … m−1 hold a block's sensitivities to its unknowns, then the velocities, then the accelerations.
_jit = njit(cache=True, error_model="numpy", nogil=True, _nrt=False, lean=True)


@_jit
def _sweep(steps, cuts, blocks, joints, alpha, sense, phi_drawn, ground, tol, centre, grid, coef, signs, limits, x,
           om, ep, ep_any, rates, p_link, p_at, offsets, angle, xy, w_out, e_out, v_out, a_out, rows, valid,
           ps, rt, sc, cc, q, guess, jac, perm, res, col, sol, qd_u):
    """Solve and write every position; returns 0, or 1 when a position needs the numpy path. tol: the
    engine's `Tolerances.as_array()` (an argument, so that no tolerance is frozen into numba's cache).
    The pose is solved in the engine's frame (centred on `centre` (2,), `Engine.centre`; the tables'
    points are in it, `p_at` is drawn in the world), and so are the joint values; the records'
    link frames converted to the world convention (`engine._constraints.world_frames`), and the points
    follow from those."""
    closure, max_newton, pivot_polish, pivot_cross, max_correction = (  # Tolerances.KERNEL_FIELDS
        tol[0], int(tol[1]), tol[2], tol[3], tol[4])
    n_blocks, n_grid, m_all, n_l = len(blocks.m), len(grid), coef.shape[2], ps.shape[1]
    row_scale, var_scale = blocks.row_scale, blocks.var_scale
    vel, acc = len(rt) - 2, len(rt) - 1
    cx0, cy0 = centre[0], centre[1]
    for l in range(n_l):  # noqa: E741  (the ground stays at rest; every other link is placed at every position)
        ps[0, l], ps[1, l], ps[2, l], ps[3, l], ps[4, l] = 0.0, 1.0, 0.0, 0.0, 0.0
        for sl in range(len(rt)):
            rt[sl, 0, l], rt[sl, 1, l], rt[sl, 2, l] = 0.0, 0.0, 0.0
    lo, lo_inv, inv = 0, -1, 1.0
    for b in range(len(x)):
        xb = x[b]
        if (limits[0] and xb < grid[0]) or (limits[1] and xb > grid[n_grid - 1]):
            valid[b] = False  # past a located limit: no solution on the branch
            continue
        if xb < grid[0] or xb > grid[n_grid - 1]:
            return 1
        valid[b] = True
        # the interval around x (numpy's searchsorted − 1, clipped): the last one or the next, else bisection
        last = n_grid - 2
        if not ((lo == 0 or grid[lo] < xb) and (lo == last or xb <= grid[lo + 1])):
            if lo < last and grid[lo + 1] < xb and (lo + 1 == last or xb <= grid[lo + 2]):
                lo += 1
            else:
                lo = _interval(grid, n_grid, xb)
        # the quintic Hermite interpolant between the two nodes around x, and the nearest node
        left, right = grid[lo], grid[lo + 1]
        if lo != lo_inv:  # (1 / the interval's width, once per interval: no division per position)
            lo_inv, inv = lo, 1.0 / (right - left)
        t = (xb - left) * inv
        near = lo if abs(xb - left) <= abs(xb - right) else lo + 1
        for i in range(m_all):
            value = coef[lo, 5, i]
            for p in range(4, -1, -1):
                value = value * t + coef[lo, p, i]
            q[i] = value
            guess[i] = value
        q_in = sense * (xb - phi_drawn)
        for bk in range(n_blocks):
            k0, k1, c0, c1 = blocks.step0[bk], blocks.step1[bk], blocks.cut0[bk], blocks.cut1[bk]
            var0, m = blocks.var0[bk], blocks.m[bk]
            # phase 0: Newton (BlockSolver.newton); 1: velocity analogues (input rate sense·1);
            # 2: acceleration analogues (input acceleration 0) (BlockSolver._block_rates)
            phase, it, polished, err, finite = 0, 0, False, 0.0, True
            det, ratio, inverted = 1.0, 1.0, False
            while True:
                if phase == 0:
                    for k in range(k0, k1):  # place the child of tree step k (Revolute/Prismatic.place)
                        _place(k, steps, q, q_in, ps, sc)
                    if m == 0:
                        if not rates:
                            break
                        phase = 1
                    else:
                        err, finite = 0.0, True
                        for k in range(c0, c1):  # closure rows of cut k (Revolute/Prismatic.closure)
                            _closure(k, cuts, ps, cc, res, 2 * (k - c0))
                        for i in range(m):
                            r = abs(res[i]) * row_scale[var0 + i]
                            finite = finite and np.isfinite(r)
                            err = max(err, r)
                # the rate passes, step by step: the sensitivities to each unknown (slots 0 … m − 1, the
                # Jacobian's columns), or the velocities, or the accelerations (with the velocities' terms)
                s_lo = 0 if phase == 0 else (vel if phase == 1 else acc)
                s_hi = m if phase == 0 else s_lo + 1
                if phase == 0:
                    for t_ in range(blocks.anchor0[bk], blocks.anchor1[bk]):  # read, not placed, moved by an earlier block
                        link = blocks.anchors[t_]
                        for sl in range(m):
                            rt[sl, 0, link], rt[sl, 1, link], rt[sl, 2, link] = 0.0, 0.0, 0.0
                for k in range(k0, k1):  # (Revolute/Prismatic.place_rates)
                    parent, child, var = steps.parent[k], steps.child[k], steps.var[k]
                    if var >= 0:
                        qd, qv = 0.0, (qd_u[var - var0] if phase == 2 else 0.0)
                    else:
                        qd, qv = steps.sign[k] * (sense if phase == 1 else 0.0), steps.sign[k] * sense
                    sign, rpx, rpy, rcx, rcy = steps.carrier[k], sc[k, 0], sc[k, 1], sc[k, 2], sc[k, 3]
                    qq = sc[k, 4]  # (prismatic: the guide's direction in rpx, rpy, the displacement in qq)
                    prismatic, relative = steps.prismatic[k], steps.relative[k]
                    wvp = rt[vel, 0, parent]
                    wvc = rt[vel, 0, child]
                    for sl in range(s_lo, s_hi):
                        if phase == 0 and var >= 0:
                            qd = 1.0 if var - var0 == sl else 0.0
                        wp, vpx, vpy = rt[sl, 0, parent], rt[sl, 1, parent], rt[sl, 2, parent]
                        if not prismatic:
                            wc = qd + wp if relative else qd
                            cx = vpx + wp * -rpy - wc * -rcy
                            cy = vpy + wp * rpx - wc * rcx
                            if phase == 2:
                                cx = cx - (wvp * wvp) * rpx + (wvc * wvc) * rcx
                                cy = cy - (wvp * wvp) * rpy + (wvc * wvc) * rcy
                        else:
                            wc = wp
                            cx = vpx + sign * (qd * rpx + (qq * wp) * -rpy)
                            cy = vpy + sign * (qd * rpy + (qq * wp) * rpx)
                            if phase == 2:
                                cx = cx + sign * ((2 * qv * wvp) * -rpy - (qq * wvp * wvp) * rpx)
                                cy = cy + sign * ((2 * qv * wvp) * rpx - (qq * wvp * wvp) * rpy)
                        rt[sl, 0, child], rt[sl, 1, child], rt[sl, 2, child] = wc, cx, cy
                for k in range(c0, c1):  # the closure's rates (Revolute/Prismatic.closure_rates)
                    row, a, bb = 2 * (k - c0), cuts.a[k], cuts.b[k]
                    rax, ray, rbx, rby = cc[k, 0], cc[k, 1], cc[k, 2], cc[k, 3]
                    nx, ny, dx, dy, pnd = cc[k, 4], cc[k, 5], cc[k, 6], cc[k, 7], cc[k, 8]
                    prismatic = cuts.prismatic[k]
                    wva, wvb = rt[vel, 0, a], rt[vel, 0, bb]
                    for sl in range(s_lo, s_hi):
                        wa, wb = rt[sl, 0, a], rt[sl, 0, bb]
                        if not prismatic:
                            ox = rt[sl, 1, a] + wa * -ray - rt[sl, 1, bb] - wb * -rby
                            oy = rt[sl, 2, a] + wa * rax - rt[sl, 2, bb] - wb * rbx
                            if phase == 2:
                                ox = ox - (wva * wva) * rax + (wvb * wvb) * rbx
                                oy = oy - (wva * wva) * ray + (wvb * wvb) * rby
                        else:  # a carrier, bb slider
                            drx = rt[sl, 1, bb] + wb * -rby - rt[sl, 1, a] - wa * -ray
                            dry = rt[sl, 2, bb] + wb * rbx - rt[sl, 2, a] - wa * rax
                            ox, oy = wb - wa, drx * nx + dry * ny + wa * pnd
                            if phase == 2:
                                dvx = rt[vel, 1, bb] + wvb * -rby - rt[vel, 1, a] - wva * -ray
                                dvy = rt[vel, 2, bb] + wvb * rbx - rt[vel, 2, a] - wva * rax
                                bx = -(wvb * wvb) * rbx + (wva * wva) * rax
                                by = -(wvb * wvb) * rby + (wva * wva) * ray
                                oy += -(wva * wva) * (nx * dx + ny * dy) + 2 * wva * (-ny * dvx + nx * dvy) + (nx * bx + ny * by)
                        if phase == 0:
                            jac[row, sl], jac[row + 1, sl] = ox, oy
                        else:
                            col[row], col[row + 1] = ox, oy
                if phase == 0:
                    # the Jacobian made dimensionless (BlockSolver's ScaledLU); its determinant and pivot
                    # ratio as _linalg.factor has them: explicit inverse up to 2 × 2 (made when a solve
                    # needs it), else LU
                    for i in range(m):
                        for j in range(m):
                            jac[i, j] = jac[i, j] * row_scale[var0 + i]
                            if var_scale[var0 + j] != 1.0:
                                jac[i, j] = jac[i, j] / var_scale[var0 + j]
                    inverted = False
                    if m == 1:
                        det = jac[0, 0]
                        ratio = abs(det) / max(abs(det), 1e-300)
                    elif m == 2:
                        det = jac[0, 0] * jac[1, 1] - jac[0, 1] * jac[1, 0]
                        first = max(abs(jac[0, 0]), abs(jac[1, 0]))
                        p0, p1 = abs(first), abs(det / first)
                        ratio = min(p0, p1) / max(max(p0, p1), 1e-300)
                    else:
                        det, ratio = _lu(jac, m, perm)
                    ok = err < closure and finite
                    done = False
                    if ok and not polished:
                        # near a singular position one more step, as BlockSolver.newton does
                        polished = True
                        done = ratio >= pivot_polish or ratio < pivot_cross * 1e3
                    elif ok or it == max_newton:
                        done = True
                    if done:  # the checks of atlas.solve_along; a position failing one goes to numpy
                        if not ok:
                            return 1
                        if not (det != 0.0 and np.isfinite(det)) or (det > 0) != (signs[near, bk] > 0):
                            return 1
                        for i in range(m):
                            if not abs(q[var0 + i] - guess[var0 + i]) * var_scale[var0 + i] <= max_correction:
                                return 1
                        if not rates:
                            break
                        phase = 1
                        continue
                    rhs = res
                elif m == 0:
                    phase += 1
                    if phase == 3:
                        break
                    continue
                else:
                    rhs = col
                # sol = J⁻¹ (−rhs): the Newton step, or the unknowns' rates (ScaledLU.solve)
                if m <= 2 and not inverted:
                    inverted = True
                    if m == 1:
                        jac[0, 0] = 1.0 / det
                    else:
                        a00, a01, a10, a11 = jac[0, 0], jac[0, 1], jac[1, 0], jac[1, 1]
                        jac[0, 0], jac[0, 1], jac[1, 0], jac[1, 1] = a11 / det, -a01 / det, -a10 / det, a00 / det
                for i in range(m):
                    rhs[i] = -rhs[i] * row_scale[var0 + i]
                if m == 1:
                    sol[0] = jac[0, 0] * rhs[0]
                elif m == 2:
                    sol[0] = jac[0, 0] * rhs[0] + jac[0, 1] * rhs[1]
                    sol[1] = jac[1, 0] * rhs[0] + jac[1, 1] * rhs[1]
                else:
                    _lu_solve(jac, m, perm, rhs, sol)
                for i in range(m):
                    if var_scale[var0 + i] != 1.0:
                        sol[i] = sol[i] / var_scale[var0 + i]
                if phase == 0:
                    for i in range(m):
                        if np.isfinite(sol[i]):
                            q[var0 + i] += sol[i]
                    it += 1
                    continue
                slot = vel if phase == 1 else acc
                for k in range(k0, k1):  # the block's links corrected by the sensitivities
                    link = steps.child[k]
                    for comp in range(3):
                        total = rt[0, comp, link] * sol[0]
                        for j in range(1, m):
                            total += rt[j, comp, link] * sol[j]
                        rt[slot, comp, link] += total
                if phase == 1:
                    for i in range(m):
                        qd_u[i] = sol[i]
                phase += 1
                if phase == 3:
                    break
        # the outputs: angles, points, real rates (x' = x_q ω, x'' = x_qq ω² + x_q ε, as kinematics._real)
        omb, epb = om[b], ep[b]
        om2 = omb * omb
        for l in range(n_l):  # noqa: E741
            angle[b, l] = ps[0, l] + alpha[l]
        if rates:
            for l in range(n_l):  # noqa: E741
                wq, eq = rt[vel, 0, l], rt[acc, 0, l]
                w_out[b, l] = wq * omb
                e_out[b, l] = eq * om2 + wq * epb if ep_any else eq * om2
        # the points from the link frames in the world convention (as the records hold them, see below)
        for p in range(len(p_link)):
            k = p_link[p]
            c, s, atx, aty = ps[1, k], ps[2, k], p_at[p, 0], p_at[p, 1]
            rhx, rhy = s * cy0 - c * cx0, -(s * cx0 + c * cy0)
            rx, ry = c * atx - s * aty, s * atx + c * aty
            xy[b, p, 0], xy[b, p, 1] = ((ps[3, k] + rhx) + cx0) + rx, ((ps[4, k] + rhy) + cy0) + ry
            if rates:
                # v + ω·perp(ρ), a + ε·perp(ρ) − ω²ρ (kinematics._moving_points)
                wl, el = rt[vel, 0, k], rt[acc, 0, k]
                w2 = wl * wl
                vx, vy = (rt[vel, 1, k] - wl * rhy) - wl * ry, (rt[vel, 2, k] + wl * rhx) + wl * rx
                ax = (rt[acc, 1, k] - (el * rhy + w2 * rhx)) - el * ry - w2 * rx
                ay = (rt[acc, 2, k] + (el * rhx - w2 * rhy)) + el * rx - w2 * ry
                v_out[b, p, 0], v_out[b, p, 1] = vx * omb, vy * omb
                if ep_any:
                    a_out[b, p, 0], a_out[b, p, 1] = ax * om2 + vx * epb, ay * om2 + vy * epb
                else:
                    a_out[b, p, 0], a_out[b, p, 1] = ax * om2, ay * om2
        if rows.shape[1] == 0:
            continue
        # the record: frames and joints (offsets in _ORDER)
        o_th, o_cos, o_sin, o_r, o_val = offsets[0], offsets[1], offsets[2], offsets[3], offsets[4]
        # the link frames in the world convention, as `world_frames`: ρ = −R(θ)·c
        o_wq, o_eq, o_fv, o_fa = offsets[5], offsets[6], offsets[7], offsets[8]
        for l in range(n_l):  # noqa: E741
            rows[b, o_th + l], rows[b, o_cos + l], rows[b, o_sin + l] = ps[0, l], ps[1, l], ps[2, l]
            rhx, rhy = ps[2, l] * cy0 - ps[1, l] * cx0, -(ps[2, l] * cx0 + ps[1, l] * cy0)
            rows[b, o_r + 2 * l], rows[b, o_r + 2 * l + 1] = (ps[3, l] + rhx) + cx0, (ps[4, l] + rhy) + cy0
            if rates:
                wl, el = rt[vel, 0, l], rt[acc, 0, l]
                rows[b, o_wq + l], rows[b, o_eq + l] = wl, el
                rows[b, o_fv + 2 * l], rows[b, o_fv + 2 * l + 1] = rt[vel, 1, l] - wl * rhy, rt[vel, 2, l] + wl * rhx
                rows[b, o_fa + 2 * l] = rt[acc, 1, l] - (el * rhy + wl * wl * rhx)
                rows[b, o_fa + 2 * l + 1] = rt[acc, 2, l] + (el * rhx - wl * wl * rhy)
        o_rq, o_aq = offsets[9], offsets[10]
        for j in range(len(joints.a)):
            la, lb = joints.a[j], joints.b[j]
            if not joints.prismatic[j]:
                rows[b, o_val + j] = ps[0, lb] - ps[0, la] + joints.drawn[j]
                if rates:
                    rows[b, o_rq + j] = rt[vel, 0, lb] - rt[vel, 0, la]
                    rows[b, o_aq + j] = rt[acc, 0, lb] - rt[acc, 0, la]
                continue
            # slider point minus carrier point, along the carrier's guide (kinematics._joint_values)
            atx, aty = joints.at[j, 0], joints.at[j, 1]
            psx, psy = ps[1, lb] * atx - ps[2, lb] * aty, ps[2, lb] * atx + ps[1, lb] * aty
            pcx, pcy = ps[1, la] * atx - ps[2, la] * aty, ps[2, la] * atx + ps[1, la] * aty
            dx, dy = ps[3, lb] + psx - ps[3, la] - pcx, ps[4, lb] + psy - ps[4, la] - pcy
            ux = ps[1, la] * joints.u0[j, 0] - ps[2, la] * joints.u0[j, 1]
            uy = ps[2, la] * joints.u0[j, 0] + ps[1, la] * joints.u0[j, 1]
            pud, ud = -uy * dx + ux * dy, ux * dx + uy * dy
            rows[b, o_val + j] = joints.drawn[j] + ud
            if rates:
                ws, wc, es, ec = rt[vel, 0, lb], rt[vel, 0, la], rt[acc, 0, lb], rt[acc, 0, la]
                ddx = rt[vel, 1, lb] - ws * psy - rt[vel, 1, la] + wc * pcy
                ddy = rt[vel, 2, lb] + ws * psx - rt[vel, 2, la] - wc * pcx
                dddx = (rt[acc, 1, lb] - es * psy - ws * ws * psx) - (rt[acc, 1, la] - ec * pcy - wc * wc * pcx)
                dddy = (rt[acc, 2, lb] + es * psx - ws * ws * psy) - (rt[acc, 2, la] + ec * pcx - wc * wc * pcy)
                rows[b, o_rq + j] = wc * pud + ux * ddx + uy * ddy
                rows[b, o_aq + j] = ec * pud - wc * wc * ud + 2 * wc * (-uy * ddx + ux * ddy) + ux * dddx + uy * dddy
    return 0
