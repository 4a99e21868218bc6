"""The kinematics kernel of a one-input sweep: the engine's corrector, checks and rate passes run position
by position as scalar loops, and the outputs the caller asked for are written in the same pass, straight
into the arrays the `Motion` holds (batch first, no copies). numba compiles it (`backends._numba`); the
same function runs as plain Python for a single position on numpy (`backends._python`).

It is the same engine, not a second one: the branch atlas, its nodes and interpolant, the joint laws'
formulas, the tolerances (the engine's `KernelTol`, an argument), the scaled block Jacobians (explicit
inverse up to 2 × 2, else LU with partial pivoting, as `engine._linalg.factor`) and the acceptance checks
are the engine's; only the loop order differs (per position instead of per operation over the batch).
It takes the common case only: every position between two atlas nodes or past a located limit,
corrected on the branch at the first try. Anything else (a position the batch corrector would hand to
`_repair`, an atlas of one node) returns 1 and the numpy path does the whole batch. Tests hold both
paths equal to rounding on every model.

Per position the kernel writes what `SweepOut` holds and the call asked for (an output array with no
rows is not written): the link angles; the points' positions; with rates the real and the analogue
velocities and accelerations of links and points, the instantaneous centres, the joints' values and
rates; and the record of the link frames and joints (`engine._tables.FIELDS`) that the `Motion`'s
frames, joint values and link analogues are views of and the compiled kinetostatics reads.
"""

from __future__ import annotations

import math

from . import _threads
from ._jit import njit
from ._numba_blocks import (_closure, _hermite_value, _interval, _lu, _lu_solve,  # (LLVM inlines these)
                            _pivot_ratio_2, _place)
from ._numba_higher import _gear_closure, _gear_rates, _higher_closure, _higher_rates
from ..engine import higher_layout as ht  # (the tables' column names)
from ..engine import SweepOut, SweepWork, work_sizes

__all__ = ["run"]


def run(job) -> int:
    """Solve and write every position of a `SweepJob` (its outputs in ``job.out``), split over
    ``job.threads`` threads; returns 0, or 1 when the numpy path must take the batch."""
    inp, out, store = job.inp, job.out, job.store
    if len(inp.x) < 2 * _threads.MIN_CHUNK:  # (one thread: no slicing)
        work = store.get("sweep work")
        if not work:
            work = store["sweep work"] = [SweepWork.new(work_sizes(job.tables))]
        return _call(store, (job.tables, job.atlas, job.tol, inp, out, work[0]))
    parts = _threads.chunks(len(inp.x), job.threads)
    work = _threads.work_arrays(store.setdefault("sweep work", []), lambda: SweepWork.new(work_sizes(job.tables)),
                                len(parts))
    fixed = (job.tables, job.atlas, job.tol)
    if len(parts) == 1:
        return _call(store, (*fixed, inp, out, work[0]))
    status = _threads.run([lambda p=p, wk=wk: _call(job.store, (*fixed, _part_in(inp, p), _part_out(out, p), wk))
                           for p, wk in zip(parts, work)])
    return max(status)


def _part_in(inp, part: slice):
    return inp._replace(x=inp.x[part], om=inp.om[part], ep=inp.ep[part])


def _part_out(out, part: slice):
    """The outputs of the positions `part` (the arrays not written, with no rows, as they are)."""
    return SweepOut(*(a[part] if len(a) else a for a in out))


def _call(store: dict, args: tuple) -> int:
    """`_sweep(*args)`. The first call on an engine looks the compiled function up for the arguments'
    types (the ahead-of-time build's, else numba's, compiled or loaded now: `_jit.Kernel.entry`); later
    calls pass the same types (the engine's tables, and arrays made by `kinematics` as C-contiguous
    float64, int64 and bool arrays of fixed dimensions), so they call it directly."""
    entry = store.get("numba entry")
    if entry is None:
        entry = store["numba entry"] = _sweep.entry(args)
    return entry(*args)


# -- kernel -----------------------------------------------------------------------------------------
# One function, each piece of the engine written once (the placement, the closure and LU of
# `_numba_blocks` are compiled on their own and inlined by LLVM, not by numba): per position
# the atlas' predictor, then per block a loop in three phases: Newton (place, closure, the Jacobian's
# columns by rate passes with unit unknown rates, factor, step), the velocity pass and the acceleration
# pass (a rate pass, the closure's rates, the solve, the correction by the sensitivities).
# Scalar loops over whole arrays indexed in place, compiled without numba's reference counting (its
# atomic increments on every array passed or aliased would cost more than the arithmetic): nothing is
# allocated here, the caller passes every work array (`SweepWork`). Only element access, len() and
# .shape are used on arrays, so that the same function runs as plain Python on memoryviews.
_jit = njit(cache=True, error_model="numpy", nogil=True, _nrt=False, lean=True)


@_jit
def _sweep(tables, atlas, tol, inp, out, work):
    """Solve and write every position of `inp` into `out` (`SweepTables`, `AtlasTables`, `KernelTol`,
    `SweepIn`, `SweepOut`, `SweepWork`); returns 0, or 1 when a position needs the numpy path."""
    steps, cuts, blocks, joints, alpha = tables.steps, tables.cuts, tables.blocks, tables.joints, tables.alpha
    sense, phi_drawn = tables.sense, tables.phi_drawn
    grid, coef, signs, limits = atlas.grid, atlas.coef, atlas.signs, atlas.limits
    x, om, ep, ep_any, rates, p_link, p_at, offsets = inp
    ps, rt, sc, cc, q, guess, jac, perm, res, col, sol, qd_u, hc, wk = work
    hp, cv = tables.higher, tables.curves
    h_ints, h_reals = hp.ints, hp.reals
    angle, xy, w_out, e_out, v_out, a_out = out.angle, out.xy, out.w, out.e, out.v, out.a
    wq_out, eq_out, vq_out, aq_out = out.wq, out.eq, out.vq, out.aq
    value_out, rate_out, accel_out, rate_q_out, accel_q_out = out.value, out.rate, out.accel, out.rate_q, out.accel_q
    ic_out, rows, valid = out.ic, out.rows, out.valid
    closure, max_newton, pivot_polish, pivot_cross = tol.closure, tol.max_newton, tol.pivot_polish, tol.pivot_cross
    max_correction = tol.max_correction
    n_blocks, n_grid, m_all, n_l = len(blocks.m), len(grid), coef.shape[2], ps.shape[1]
    row_scale, var_scale = blocks.row_scale, blocks.var_scale
    vel, acc = len(rt) - 2, len(rt) - 1
    # the outputs asked for (an array with no rows is not written)
    want_w, want_wq, want_v, want_vq = len(w_out) > 0, len(wq_out) > 0, len(v_out) > 0, len(vq_out) > 0
    want_ic, want_rows = len(ic_out) > 0, rows.shape[1] > 0
    want_value, want_rate, want_rate_q = len(value_out) > 0, len(rate_out) > 0, len(rate_q_out) > 0
    want_joints = want_rows or want_value or want_rate or want_rate_q
    cx0, cy0 = tables.centre[0], tables.centre[1]  # (the engine's frame's origin, `Engine.centre`)
    far = cx0 != 0.0 or cy0 != 0.0  # (else the frame is the world's: ρ = 0, no product to form)
    rhx, rhy = 0.0, 0.0
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
            value = _hermite_value(coef[lo, 0, i], coef[lo, 1, i], coef[lo, 2, i], coef[lo, 3, i], coef[lo, 4, i],
                                   coef[lo, 5, i], t)
            q[i] = value
            guess[i] = value
        q_in = sense * (xb - phi_drawn)
        for bk in range(n_blocks):
            k0, k1, c0, c1 = blocks.step0[bk], blocks.step1[bk], blocks.cut0[bk], blocks.cut1[bk]
            var0, m = blocks.var0[bk], blocks.m[bk]
            h0, h1 = hp.first[bk], hp.first[bk + 1]  # (the block's higher pairs: their rows follow the cuts')
            lin = blocks.linear[bk]
            if lin != 0.0:
                # one revolute unknown closed by one gear pair (`engine._tables.linear_block`): linear in it,
                # its Jacobian the constant lin, so a Newton step from the prediction is exact and the
                # rates need no sensitivities (the unknown's rate solves the gear row's rate directly)
                var = var0
                err = 0.0
                for it in range(max_newton + 1):
                    _place(k0, steps, q, q_in, ps, sc)
                    _gear_closure(h0, hp, ps, res)
                    err = abs(res[0]) * row_scale[var]
                    if not err >= closure:  # (converged, or not finite: checked below)
                        break
                    q[var] -= res[0] / lin
                if not (err < closure and (lin > 0) == (signs[near, bk] > 0)
                        and abs(q[var] - guess[var]) * var_scale[var] <= max_correction):
                    return 1
                if rates:
                    parent, child, relative = steps.parent[k0], steps.child[k0], steps.relative[k0]
                    rpx, rpy, rcx, rcy = sc[k0, 0], sc[k0, 1], sc[k0, 2], sc[k0, 3]
                    for slot in range(vel, acc + 1):  # the velocities, then the accelerations
                        wp, vpx, vpy = rt[slot, 0, parent], rt[slot, 1, parent], rt[slot, 2, parent]
                        rt[slot, 0, child] = wp if relative else 0.0  # (the unknown's rate 0: the row's rate)
                        qd = -_gear_rates(h0, hp, rt, slot) / lin
                        wc = qd + wp if relative else qd
                        cx = vpx + wp * -rpy - wc * -rcy
                        cy = vpy + wp * rpx - wc * rcx
                        if slot == acc:
                            wvp, wvc = rt[vel, 0, parent], rt[vel, 0, child]
                            cx = cx - (wvp * wvp) * rpx + (wvc * wvc) * rcx
                            cy = cy - (wvp * wvp) * rpy + (wvc * wvc) * rcy
                        rt[slot, 0, child], rt[slot, 1, child], rt[slot, 2, child] = wc, cx, cy
                continue
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
                        for h in range(h0, h1):  # (Gear, Rack, PointOnCurve, FaceOnCurve.closure)
                            if h_ints[h, ht.H_GEAR]:
                                _gear_closure(h, hp, ps, res)
                            else:
                                _higher_closure(h, hp, cv, ps, q, hc, wk, res)
                        for i in range(m):
                            r = abs(res[i]) * row_scale[var0 + i]
                            finite = finite and math.isfinite(r)
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
                    # (selects, not branches: whether a step's variable is an unknown changes along the tree,
                    # and a mispredicted test here was what made some loaded copies slower, docs/speed.md)
                    own, sg = var >= 0, steps.sign[k]
                    u = qd_u[var - var0 if own else 0]
                    qd = 0.0 if own else sg * (sense if phase == 1 else 0.0)
                    qv = (u if phase == 2 else 0.0) if own else sg * sense
                    sign, rpx, rpy, rcx, rcy = steps.carrier[k], sc[k, 0], sc[k, 1], sc[k, 2], sc[k, 3]
                    qq = sc[k, 4]  # (prismatic: the guide's direction in rpx, rpy, the displacement in qq)
                    prismatic, relative = steps.prismatic[k], steps.relative[k]
                    wvp = rt[vel, 0, parent]
                    wvc = rt[vel, 0, child]
                    for sl in range(s_lo, s_hi):
                        qd = (1.0 if var - var0 == sl else 0.0) if phase == 0 and own else qd
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
                for h in range(h0, h1):  # the higher pairs' rates (their closure_rates): the contact parameter's
                    row, par = h_ints[h, ht.H_ROW], h_ints[h, ht.H_VAR] - var0  # unit rate in its column, its velocity
                    big_u = qd_u[par] if phase == 2 and par >= 0 else 0.0
                    for sl in range(s_lo, s_hi):
                        pu = 1.0 if phase == 0 and par == sl else 0.0
                        if h_ints[h, ht.H_GEAR]:  # (the small gear law called on its own: LLVM inlines it)
                            ox, oy = _gear_rates(h, hp, rt, sl), 0.0
                        else:
                            ox, oy = _higher_rates(h, hp, hc, rt, sl, pu, vel if phase == 2 else -1, big_u)
                        if phase == 0:
                            jac[row, sl] = ox
                            if h_ints[h, ht.H_EQUATIONS] == 2:
                                jac[row + 1, sl] = oy
                        else:
                            col[row] = ox
                            if h_ints[h, ht.H_EQUATIONS] == 2:
                                col[row + 1] = oy
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
                        ratio = _pivot_ratio_2(max(abs(jac[0, 0]), abs(jac[1, 0])), det, pivot_polish)
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
                        if not (det != 0.0 and math.isfinite(det)) or (det > 0) != (signs[near, bk] > 0):
                            return 1
                        for i in range(m):
                            if not abs(q[var0 + i] - guess[var0 + i]) * var_scale[var0 + i] <= max_correction:
                                return 1
                        for h in range(h0, h1):  # a contact past an open curve's end: numpy's (a limit there)
                            var = h_ints[h, ht.H_VAR]
                            if var >= 0 and not (h_reals[h, ht.H_LO] <= q[var] <= h_reals[h, ht.H_HI]):
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
                        if math.isfinite(sol[i]):
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
                wl = wq * omb
                if want_w:
                    w_out[b, l] = wl
                    e_out[b, l] = eq * om2 + wq * epb if ep_any else eq * om2
                if want_wq:
                    wq_out[b, l], eq_out[b, l] = wq, eq
                if want_ic:  # r + perp(v)/ω of the link's frame (kinematics._instant_centres); NaN where ω = 0
                    icx, icy = math.nan, math.nan
                    if wl != 0.0:  # (a test, not a division by 0: the kernel also runs as plain Python)
                        if far:
                            rhx, rhy = ps[2, l] * cy0 - ps[1, l] * cx0, -(ps[2, l] * cx0 + ps[1, l] * cy0)
                        icx = ((ps[3, l] + rhx) + cx0) + -((rt[vel, 2, l] + wq * rhx) * omb) / wl
                        icy = ((ps[4, l] + rhy) + cy0) + ((rt[vel, 1, l] - wq * rhy) * omb) / wl
                    ic_out[b, l, 0] = icx if math.isfinite(icx) else math.nan
                    ic_out[b, l, 1] = icy if math.isfinite(icy) else math.nan
        # the points from the link frames in the world convention (as the records hold them, see below):
        # the frame's origin ρ = −R(θ)·c from the engine's, c the engine's frame's origin (`world_frames`)
        for p in range(len(p_link)):
            k = p_link[p]
            c, s, atx, aty = ps[1, k], ps[2, k], p_at[p, 0], p_at[p, 1]
            if far:
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
                if want_vq:
                    vq_out[b, p, 0], vq_out[b, p, 1], aq_out[b, p, 0], aq_out[b, p, 1] = vx, vy, ax, ay
                if want_v:
                    v_out[b, p, 0], v_out[b, p, 1] = vx * omb, vy * omb
                    if ep_any:
                        a_out[b, p, 0], a_out[b, p, 1] = ax * om2 + vx * epb, ay * om2 + vy * epb
                    else:
                        a_out[b, p, 0], a_out[b, p, 1] = ax * om2, ay * om2
        if want_rows:  # the record: frames (in the world convention, as `world_frames`) and joints
            o_th, o_cos, o_sin, o_r = offsets[0], offsets[1], offsets[2], offsets[3]  # (offsets in RECORD_ORDER)
            o_wq, o_eq, o_fv, o_fa = offsets[5], offsets[6], offsets[7], offsets[8]
            for l in range(n_l):  # noqa: E741
                rows[b, o_th + l], rows[b, o_cos + l], rows[b, o_sin + l] = ps[0, l], ps[1, l], ps[2, l]
                if far:
                    rhx, rhy = ps[2, l] * cy0 - ps[1, l] * cx0, -(ps[2, l] * cx0 + ps[1, l] * cy0)
                rows[b, o_r + 2 * l], rows[b, o_r + 2 * l + 1] = (ps[3, l] + rhx) + cx0, (ps[4, l] + rhy) + cy0
                if rates:
                    wl, el = rt[vel, 0, l], rt[acc, 0, l]
                    rows[b, o_wq + l], rows[b, o_eq + l] = wl, el
                    rows[b, o_fv + 2 * l] = rt[vel, 1, l] - wl * rhy
                    rows[b, o_fv + 2 * l + 1] = rt[vel, 2, l] + wl * rhx
                    rows[b, o_fa + 2 * l] = rt[acc, 1, l] - (el * rhy + wl * wl * rhx)
                    rows[b, o_fa + 2 * l + 1] = rt[acc, 2, l] + (el * rhx - wl * wl * rhy)
            o_contact = offsets[11]  # the contact parameters (0 for a gear or a rack: none)
            for h in range(len(h_ints)):
                var = h_ints[h, ht.H_VAR]
                rows[b, o_contact + h_ints[h, ht.H_COLUMN]] = q[var] if var >= 0 else 0.0
        if not want_joints:
            continue
        o_val, o_rq, o_aq = offsets[4], offsets[9], offsets[10]
        for j in range(len(joints.a)):
            la, lb = joints.a[j], joints.b[j]
            rq, acq = 0.0, 0.0
            if not joints.prismatic[j]:
                val = ps[0, lb] - ps[0, la] + joints.drawn[j]
                if rates:
                    rq = rt[vel, 0, lb] - rt[vel, 0, la]
                    acq = rt[acc, 0, lb] - rt[acc, 0, la]
            else:  # slider point minus carrier point, along the carrier's guide (kinematics._joint_values)
                atx, aty = joints.at[j, 0], joints.at[j, 1]
                psx, psy = ps[1, lb] * atx - ps[2, lb] * aty, ps[2, lb] * atx + ps[1, lb] * aty
                pcx, pcy = ps[1, la] * atx - ps[2, la] * aty, ps[2, la] * atx + ps[1, la] * aty
                dx, dy = ps[3, lb] + psx - ps[3, la] - pcx, ps[4, lb] + psy - ps[4, la] - pcy
                ux = ps[1, la] * joints.u0[j, 0] - ps[2, la] * joints.u0[j, 1]
                uy = ps[2, la] * joints.u0[j, 0] + ps[1, la] * joints.u0[j, 1]
                pud, ud = -uy * dx + ux * dy, ux * dx + uy * dy
                val = joints.drawn[j] + ud
                if rates:
                    ws, wc, es, ec = rt[vel, 0, lb], rt[vel, 0, la], rt[acc, 0, lb], rt[acc, 0, la]
                    ddx = rt[vel, 1, lb] - ws * psy - rt[vel, 1, la] + wc * pcy
                    ddy = rt[vel, 2, lb] + ws * psx - rt[vel, 2, la] - wc * pcx
                    dddx = (rt[acc, 1, lb] - es * psy - ws * ws * psx) - (rt[acc, 1, la] - ec * pcy - wc * wc * pcx)
                    dddy = (rt[acc, 2, lb] + es * psx - ws * ws * psy) - (rt[acc, 2, la] + ec * pcx - wc * wc * pcy)
                    rq = wc * pud + ux * ddx + uy * ddy
                    acq = ec * pud - wc * wc * ud + 2 * wc * (-uy * ddx + ux * ddy) + ux * dddx + uy * dddy
            if want_rows:
                rows[b, o_val + j] = val
                if rates:
                    rows[b, o_rq + j], rows[b, o_aq + j] = rq, acq
            if want_value:
                value_out[b, j] = val
            if rates:
                if want_rate_q:
                    rate_q_out[b, j], accel_q_out[b, j] = rq, acq
                if want_rate:
                    rate_out[b, j] = rq * omb
                    accel_out[b, j] = acq * om2 + rq * epb if ep_any else acq * om2
    return 0
