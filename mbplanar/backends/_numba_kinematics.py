"""Compiled kinematics of a one-input sweep (optional, needs numba): the engine's corrector, checks and
rate passes run position by position as scalar loops, and every output of `Motion` is written in the
same pass.

It is the same engine, not a second one: the branch atlas, its nodes and interpolant, the joint laws'
formulas, the tolerances (the engine's `Tolerances`, passed as an argument) and the acceptance checks
are the engine's; only the loop order differs (per position instead of per operation over the batch).
It takes the common case only: every position between two atlas nodes or past a located limit,
corrected on the branch at the first try. Anything
else (a change point's bracket, a position the batch corrector would hand to `_repair`, an atlas of
one node) returns None and the numpy path does the whole batch. Tests hold both paths equal to
rounding on every model.

The plan is the engine's `BlockPlan`s as named tables of arrays (`_tables`), built once per engine.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from . import _threads
from ._tables import kinematics_tables
from ..engine._atlas import _in_brackets

__all__ = ["FIELDS", "sweep"]

# what the kernel writes per position, in this order: (name, per link / point / joint, components)
# (the link frames and the joints only: `Motion` derives the points, the real rates, the angles and the
# instantaneous centres from them when first read, so that the memory written per position, which
# bounds the speed, is smaller)
FIELDS = (("wq", "L", 1), ("eq", "L", 1), ("th", "L", 1), ("cos", "L", 1), ("sin", "L", 1),
          ("r", "L", 2), ("fv", "L", 2), ("fa", "L", 2), ("value", "J", 1), ("rate_q", "J", 1), ("accel_q", "J", 1))


_LIMITS = {(lo, hi): np.array([lo, hi], np.bool_) for lo in (False, True) for hi in (False, True)}


@dataclass
class _KernelPlan:
    """An engine compiled for the kernel, built once: `args`, the engine's blocks and output tables as
    arrays in `_sweep`'s order; `row`, the structured dtype of one position's output (FIELDS);
    `sizes` of the kernel's work arrays, `scratch` one set of them per thread (so that an engine is
    not for several callers at once)."""

    args: tuple
    row: np.dtype
    sizes: tuple
    scratch: list


def _plan(engine, joint_table) -> _KernelPlan:
    return engine.prepare("numba kinematics", lambda: _make_plan(engine, joint_table))


def _make_plan(engine, joint_table) -> _KernelPlan:
    """The engine's blocks and output tables as the kernel's arguments (`_tables.kinematics_tables`)."""
    steps, cuts, blocks, joints = kinematics_tables(engine, joint_table)
    args = (steps, cuts, blocks, joints, float(engine.inputs[0].sense), float(engine.phi_drawn[0]),
            engine.link_index[engine.mech.ground], engine.tol.as_array())
    per = {"L": len(engine.links), "J": len(joints.drawn)}
    row = np.dtype([(name, float, (per[kind], comp) if comp > 1 else (per[kind],))
                    for name, kind, comp in FIELDS])
    m_max = max([1] + [bp.m for bp in engine.blocks])
    sizes = (len(steps.parent), len(cuts.a), per["L"], len(blocks.var_scale), m_max)
    return _KernelPlan(args, row, sizes, [])


def _scratch(n_steps: int, n_cuts: int, n_links: int, m_all: int, m_max: int) -> tuple:
    """Work arrays of `_sweep`: pose (5, L), rates (slots, 3, L), step and cut caches, unknowns and
    their guesses, a block's Jacobian with its row permutation, and four vectors of a block's size."""
    vec = lambda n: np.zeros(max(n, 1))  # noqa: E731
    return (np.zeros((5, n_links)), np.zeros((m_max + 2, 3, n_links)), np.zeros((max(n_steps, 1), 5)),
            np.zeros((max(n_cuts, 1), 9)), vec(m_all), vec(m_all), np.zeros((m_max, m_max)),
            np.zeros(m_max, np.int64), vec(m_max), vec(m_max), vec(m_max), vec(m_max))


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


def sweep(engine, x, lo, hi, joint_table):
    """Kinematics of the one-input positions x (B,) (SI, contiguous, between lo and hi): one structured
    row per position (FIELDS) and `valid` (B,) (False past a located limit); None where the numpy path
    must take the batch."""
    atlas = engine.atlas()
    atlas.cover(lo, hi)
    grid, coef, signs = _atlas_tables(engine, atlas)
    if len(grid) < 2:
        return None
    if atlas.crossings and _in_brackets(atlas.crossings, x).any():
        return None
    plan = _plan(engine, joint_table)
    rows = np.empty(len(x), plan.row)
    valid = np.empty(len(x), np.bool_)
    limits = _LIMITS[atlas.limits[-1] is not None, atlas.limits[+1] is not None]
    out = rows.view(np.float64).reshape(len(x), -1)
    parts = _threads.chunks(len(x), engine.threads)
    work = _threads.work_arrays(plan.scratch, lambda: _scratch(*plan.sizes), len(parts))
    status = _threads.run([lambda p=p, w=w: _sweep(*plan.args, grid, coef, signs, limits, x[p], out[p], valid[p], *w)
                           for p, w in zip(parts, work)])
    return None if any(status) else (rows, valid)


# -- kernels ----------------------------------------------------------------------------------------
# Scalar loops over whole arrays indexed in place, compiled without numba's reference counting (its
# atomic increments on every array passed or aliased would cost more than the arithmetic): so nothing
# is allocated here, the caller passes every work array (`_scratch`).
# Pose ps (5, L): θ, cos θ, sin θ, r_x, r_y per link. Rates rt (slots, 3, L): ω, v_x, v_y per link;
# slots 0 … m−1 hold a block's sensitivities to its unknowns, then the velocities, then the accelerations.
_jit = numba.njit(cache=True, error_model="numpy", nogil=True, _nrt=False)
_inline = numba.njit(cache=True, error_model="numpy", nogil=True, _nrt=False, inline="always")


@_inline
def _place(k, steps, q, q_in, ps, sc):
    """Place the child of tree step k; caches rho_parent, rho_child (R) or u, q (P) in sc[k]."""
    parent, child, rel, var = steps.parent[k], steps.child[k], steps.relative[k], steps.var[k]
    value = q[var] if var >= 0 else steps.sign[k] * q_in
    cp, sp = ps[1, parent], ps[2, parent]
    if not steps.prismatic[k]:
        s0x, s0y = steps.s0[k, 0], steps.s0[k, 1]
        rpx, rpy = cp * s0x - sp * s0y, sp * s0x + cp * s0y
        t = ps[0, parent] + value if rel else value
        cc, ss = np.cos(t), np.sin(t)
        ps[0, child], ps[1, child], ps[2, child] = t, cc, ss
        rcx, rcy = cc * s0x - ss * s0y, ss * s0x + cc * s0y
        ps[3, child] = ps[3, parent] + rpx - rcx
        ps[4, child] = ps[4, parent] + rpy - rcy
        sc[k, 0], sc[k, 1], sc[k, 2], sc[k, 3] = rpx, rpy, rcx, rcy
    else:
        sign = steps.carrier[k]
        ux, uy = cp * steps.u0[k, 0] - sp * steps.u0[k, 1], sp * steps.u0[k, 0] + cp * steps.u0[k, 1]
        ps[0, child], ps[1, child], ps[2, child] = ps[0, parent], cp, sp
        ps[3, child] = ps[3, parent] + (sign * value) * ux
        ps[4, child] = ps[4, parent] + (sign * value) * uy
        sc[k, 0], sc[k, 1], sc[k, 4] = ux, uy, value


@_inline
def _closure(k, cuts, ps, cc, res, row):
    """Residual rows row, row + 1 of cut k; caches what its rates need in cc[k]."""
    a, b = cuts.a[k], cuts.b[k]
    s0x, s0y = cuts.s0[k, 0], cuts.s0[k, 1]
    rax, ray = ps[1, a] * s0x - ps[2, a] * s0y, ps[2, a] * s0x + ps[1, a] * s0y
    rbx, rby = ps[1, b] * s0x - ps[2, b] * s0y, ps[2, b] * s0x + ps[1, b] * s0y
    if not cuts.prismatic[k]:
        res[row] = ps[3, a] + rax - ps[3, b] - rbx
        res[row + 1] = ps[4, a] + ray - ps[4, b] - rby
    else:  # a carrier, b slider
        nx = ps[1, a] * cuts.n0[k, 0] - ps[2, a] * cuts.n0[k, 1]
        ny = ps[2, a] * cuts.n0[k, 0] + ps[1, a] * cuts.n0[k, 1]
        dx = ps[3, b] + rbx - ps[3, a] - rax
        dy = ps[4, b] + rby - ps[4, a] - ray
        res[row] = ps[0, b] - ps[0, a]
        res[row + 1] = nx * dx + ny * dy
        cc[k, 4], cc[k, 5], cc[k, 6], cc[k, 7], cc[k, 8] = nx, ny, dx, dy, -ny * dx + nx * dy
    cc[k, 0], cc[k, 1], cc[k, 2], cc[k, 3] = rax, ray, rbx, rby


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
def _lu(a, m, perm):
    """LU with partial pivoting of a[:m, :m] in place (first largest pivot, as numpy's argmax);
    returns (det, min |pivot| / max |pivot|)."""
    sign = 1.0
    for i in range(m):
        perm[i] = i
    for k in range(m - 1):
        p, big = k, abs(a[k, k])
        for i in range(k + 1, m):
            if abs(a[i, k]) > big:
                p, big = i, abs(a[i, k])
        if p != k:
            for j in range(m):
                a[k, j], a[p, j] = a[p, j], a[k, j]
            perm[k], perm[p] = perm[p], perm[k]
            sign = -sign
        for i in range(k + 1, m):
            a[i, k] /= a[k, k]
            for j in range(k + 1, m):
                a[i, j] -= a[i, k] * a[k, j]
    det, lo, hi = sign, np.inf, 0.0
    for i in range(m):
        det *= a[i, i]
        lo, hi = min(lo, abs(a[i, i])), max(hi, abs(a[i, i]))
    return det, lo / max(hi, 1e-300)


@_inline
def _lu_solve(a, m, perm, b, x):
    """x = A⁻¹ b from the factors of `_lu` (b is left as it was)."""
    for i in range(m):
        x[i] = b[perm[i]]
    for i in range(1, m):
        for j in range(i):
            x[i] -= a[i, j] * x[j]
    for i in range(m - 1, -1, -1):
        for j in range(i + 1, m):
            x[i] -= a[i, j] * x[j]
        x[i] /= a[i, i]


@_inline
def _jacobian(k0, k1, c0, c1, a0, a1, m, var0, steps, cuts, anchors, sc, cc, rt, jac, col):
    """Closure Jacobian (m, m) of a block, and in rt[0 … m − 1] the sensitivities of its links' rates to
    each unknown (the links outside the block stay at 0)."""
    for j in range(m):
        for t in range(a0, a1):  # the links the block reads but does not place are at rest
            for comp in range(3):
                rt[j, comp, anchors[t]] = 0.0
        for k in range(k0, k1):
            _step_rates(k, steps, sc, rt, j, 1.0 if steps.var[k] - var0 == j and steps.var[k] >= 0 else 0.0, -1,
                        0.0)
        for k in range(c0, c1):
            _closure_rates(k, cuts, cc, rt, j, -1, col, 2 * (k - c0))
        for i in range(m):
            jac[i, j] = col[i]


@_inline
def _block_rates(k0, k1, c0, c1, m, var0, steps, cuts, sc, cc, rt, slot, vel, lu, perm, q_in_rate, qd_vel,
                 q_in_vel, rhs, out):
    """A block's link rates into rt[slot] (accelerations with vel >= 0), its unknowns' rates into
    out[:m]; qd_vel, q_in_vel: the unknowns' and the input's velocities (for the Coriolis terms)."""
    for k in range(k0, k1):
        var, sign = steps.var[k], steps.sign[k]
        qd = 0.0 if var >= 0 else sign * q_in_rate
        qv = qd_vel[var - var0] if var >= 0 else sign * q_in_vel
        _step_rates(k, steps, sc, rt, slot, qd, vel, qv)
    if m == 0:
        return
    for k in range(c0, c1):
        _closure_rates(k, cuts, cc, rt, slot, vel, rhs, 2 * (k - c0))
    for i in range(m):
        rhs[i] = -rhs[i]
    _lu_solve(lu, m, perm, rhs, out)
    for k in range(k0, k1):
        link = steps.child[k]
        for j in range(m):
            for comp in range(3):
                rt[slot, comp, link] += rt[j, comp, link] * out[j]


@_inline
def _interval(grid, x):
    """i with grid[i] <= x <= grid[i + 1] (bisection), clipped to the grid's intervals."""
    lo, hi = 0, len(grid) - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if grid[mid] < x:
            lo = mid
        else:
            hi = mid
    return lo


@_jit
def _sweep(steps, cuts, blocks, joints, sense, phi_drawn, ground, tol, grid, coef, signs, limits, x, out, valid,
           ps, rt, sc, cc, q, guess, jac, perm, res, step, qd_u, qdd_u):
    """Solve and write every position; returns 0, or 1 when a position needs the numpy path. tol: the
    engine's `Tolerances.as_array()` (an argument, so that no tolerance is frozen into numba's cache)."""
    closure, max_newton, pivot_polish, pivot_cross, max_correction = (  # Tolerances.KERNEL_FIELDS
        tol[0], int(tol[1]), tol[2], tol[3], tol[4])
    n_blocks, n_grid, m_all = len(blocks.m), len(grid), coef.shape[2]
    row_scale, var_scale = blocks.row_scale, blocks.var_scale
    vel, acc = len(rt) - 2, len(rt) - 1
    ps[:, :] = 0.0
    ps[1, :] = 1.0
    for b in range(len(x)):
        xb = x[b]
        if (limits[0] and xb < grid[0]) or (limits[1] and xb > grid[n_grid - 1]):
            valid[b] = False  # past a located limit: no solution on the branch
            continue
        if xb < grid[0] or xb > grid[n_grid - 1]:
            return 1
        valid[b] = True
        # the quintic Hermite interpolant between the two nodes around x, and the nearest node
        lo = _interval(grid, xb)
        t = (xb - grid[lo]) / (grid[lo + 1] - grid[lo])
        near = lo if abs(xb - grid[lo]) <= abs(xb - grid[lo + 1]) else lo + 1
        for i in range(m_all):
            value = coef[lo, 5, i]
            for p in range(4, -1, -1):
                value = value * t + coef[lo, p, i]
            q[i] = value
            guess[i] = value
        ps[0, ground], ps[1, ground], ps[2, ground], ps[3, ground], ps[4, ground] = 0.0, 1.0, 0.0, 0.0, 0.0
        rt[vel, :, :] = 0.0
        rt[acc, :, :] = 0.0
        q_in = sense * (xb - phi_drawn)
        for bk in range(n_blocks):
            k0, k1, c0, c1 = blocks.step0[bk], blocks.step1[bk], blocks.cut0[bk], blocks.cut1[bk]
            var0, m = blocks.var0[bk], blocks.m[bk]
            polished, ok, det, ratio, err = False, False, 1.0, 1.0, 0.0
            for it in range(max_newton + 1):
                for k in range(k0, k1):
                    _place(k, steps, q, q_in, ps, sc)
                err = 0.0
                for k in range(c0, c1):
                    _closure(k, cuts, ps, cc, res, 2 * (k - c0))
                for i in range(m):
                    err = max(err, abs(res[i]) * row_scale[var0 + i])
                if m == 0:
                    ok = True
                    break
                _jacobian(k0, k1, c0, c1, blocks.anchor0[bk], blocks.anchor1[bk], m, var0, steps, cuts, blocks.anchors,
                          sc, cc, rt, jac, step)
                det, ratio = _lu(jac, m, perm)
                ok = err < closure
                if ok and not polished:
                    # near a singular position one more step, as solver.Engine._newton does
                    polished = True
                    if ratio >= pivot_polish or ratio < pivot_cross * 1e3:
                        break
                elif ok or it == max_newton:
                    break
                for i in range(m):
                    res[i] = -res[i]
                _lu_solve(jac, m, perm, res, step)
                for i in range(m):
                    if np.isfinite(step[i]):
                        q[var0 + i] += step[i]
            if not (ok and np.isfinite(err)):
                return 1
            if m:
                if det == 0.0 or (det > 0) != (signs[near, bk] > 0):
                    return 1
                for i in range(m):
                    if abs(q[var0 + i] - guess[var0 + i]) * var_scale[var0 + i] > max_correction:
                        return 1
            # velocity analogues, then acceleration analogues (input rate sense·1, acceleration 0)
            _block_rates(k0, k1, c0, c1, m, var0, steps, cuts, sc, cc, rt, vel, -1, jac, perm, sense, qd_u,
                         0.0, res, qd_u)
            _block_rates(k0, k1, c0, c1, m, var0, steps, cuts, sc, cc, rt, acc, vel, jac, perm, 0.0, qd_u,
                         sense, res, qdd_u)
        _write(b, out, ps, rt, vel, acc, joints)
    return 0


@_jit
def _write(b, out, ps, rt, vel, acc, joints):
    """Every output of position b (in the order of FIELDS) from its link states (analogue rates)."""
    n_l, n_j = ps.shape[1], len(joints.a)
    o_eq, o_th, o_cos, o_sin, o_r = n_l, 2 * n_l, 3 * n_l, 4 * n_l, 5 * n_l
    o_fv, o_fa, o_val = 7 * n_l, 9 * n_l, 11 * n_l
    o_rq, o_accq = o_val + n_j, o_val + 2 * n_j
    for l in range(n_l):  # noqa: E741
        out[b, l], out[b, o_eq + l], out[b, o_th + l] = rt[vel, 0, l], rt[acc, 0, l], ps[0, l]
        out[b, o_cos + l], out[b, o_sin + l] = ps[1, l], ps[2, l]
        out[b, o_r + 2 * l], out[b, o_r + 2 * l + 1] = ps[3, l], ps[4, l]
        out[b, o_fv + 2 * l], out[b, o_fv + 2 * l + 1] = rt[vel, 1, l], rt[vel, 2, l]
        out[b, o_fa + 2 * l], out[b, o_fa + 2 * l + 1] = rt[acc, 1, l], rt[acc, 2, l]
    for j in range(n_j):
        la, lb = joints.a[j], joints.b[j]
        ws, wc, es, ec = rt[vel, 0, lb], rt[vel, 0, la], rt[acc, 0, lb], rt[acc, 0, la]
        if not joints.prismatic[j]:
            value, rq, aq = ps[0, lb] - ps[0, la] + joints.drawn[j], ws - wc, es - ec
        else:  # slider point minus carrier point, along the carrier's guide
            atx, aty = joints.at[j, 0], joints.at[j, 1]
            psx, psy = ps[1, lb] * atx - ps[2, lb] * aty, ps[2, lb] * atx + ps[1, lb] * aty
            pcx, pcy = ps[1, la] * atx - ps[2, la] * aty, ps[2, la] * atx + ps[1, la] * aty
            dx, dy = ps[3, lb] + psx - ps[3, la] - pcx, ps[4, lb] + psy - ps[4, la] - pcy
            ddx = rt[vel, 1, lb] - ws * psy - rt[vel, 1, la] + wc * pcy
            ddy = rt[vel, 2, lb] + ws * psx - rt[vel, 2, la] - wc * pcx
            dddx = (rt[acc, 1, lb] - es * psy - ws * ws * psx) - (rt[acc, 1, la] - ec * pcy - wc * wc * pcx)
            dddy = (rt[acc, 2, lb] + es * psx - ws * ws * psy) - (rt[acc, 2, la] + ec * pcx - wc * wc * pcy)
            ux = ps[1, la] * joints.u0[j, 0] - ps[2, la] * joints.u0[j, 1]
            uy = ps[2, la] * joints.u0[j, 0] + ps[1, la] * joints.u0[j, 1]
            pud, ud = -uy * dx + ux * dy, ux * dx + uy * dy
            value = joints.drawn[j] + ud
            rq = wc * pud + ux * ddx + uy * ddy
            aq = ec * pud - wc * wc * ud + 2 * wc * (-uy * ddx + ux * ddy) + ux * dddx + uy * dddy
        out[b, o_val + j], out[b, o_rq + j], out[b, o_accq + j] = value, rq, aq
