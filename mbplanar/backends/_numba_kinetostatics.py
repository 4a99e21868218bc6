"""Compiled kinetostatics of a compiled one-input `Motion` (optional, needs numba): the loads, the
d'Alembert loads, the assembled system and the virtual-power check, position by position, reading the
rows the compiled kinematics wrote (`Motion.rows`) while they are in the cache.

It is the same computation as `kinetostatics`, not a second formulation: the layout, the features, the
blocks, their pivots and fill-in (`_Block.fill`) come from `kinetostatics._plan`; the loads' constant
parts, guide-force sizes and heavy links from `loads`; the formulas are numpy's written per position,
in the same order (but for one thing: the moments are divided by the model size as a product with its
reciprocal, a division costing several multiplications here). It takes the model's loads with or
without the inertia loads, and no input inertia; anything else stays with numpy. Tests hold both equal
to rounding.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from . import _threads
from ._numba_kinematics import _lu, _lu_solve
from ._tables import LOAD_FIXED, LOAD_GUIDE, LOAD_INERTIA, ForceBlockTables, load_tables
from ..kinematics._motion import _tables
from ..forces._loads import LoadValue, constant_parts, guide_force_size, heavy_links

__all__ = ["solve"]

# row fields the kernel reads, in the order of its `offsets` argument
_READS = ("cos", "sin", "r", "fv", "fa", "wq", "eq", "rate_q")


@dataclass
class _KernelPlan:
    """The model's loads and the system's structure as arrays in `_kernel`'s order, built once per
    engine and row layout: `names`, `links` of the loads in the order numpy lists them; `guide_loads`,
    the rows whose size `guide_force_size` gives; `args`; `sizes` of the kernel's work arrays and
    `scratch`, one set of them per thread."""

    names: list
    links: list
    guide_loads: list
    args: tuple
    sizes: tuple
    scratch: list


def _load_table(engine, inertia):
    """The loads as (names, links, guide loads, `LoadTables`), in the order numpy lists them: the model's
    loads, gravity on the heavy links, and (with `inertia`) their d'Alembert loads."""
    mech = engine.mech
    names, rows, guides = [], [], []
    for load in mech.loads:
        at, force, moment = constant_parts(mech, load)
        k = engine.link_index[load.link]
        if force is None:  # along a guide: the kernel scales its direction by `guide_force_size`
            carrier = engine.link_index[mech.joints[load.joint].carrier]
            rows.append((LOAD_GUIDE, k, len(guides), carrier, at, (0.0, 0.0), moment, engine.laws[load.joint].u0))
            guides.append(load)
        else:
            rows.append((LOAD_FIXED, k, -1, 0, at, force, moment, (0.0, 0.0)))
        names.append(load.name)
    heavy = heavy_links(mech)
    gravity = mech.gravity
    if gravity:
        for name, lk, at in heavy:
            if lk.mass:
                rows.append((LOAD_FIXED, engine.link_index[name], -1, 0, at, lk.mass * gravity.vector, 0.0,
                             (0.0, 0.0)))
                names.append(f"gravity on {name}")
    if inertia:
        for name, lk, at in heavy:
            rows.append((LOAD_INERTIA, engine.link_index[name], -1, 0, at, (lk.mass, lk.inertia), 0.0, (0.0, 0.0)))
            names.append(f"inertia of {name}")
    return names, [r[1] for r in rows], guides, load_tables(rows)


def _block_tables(blocks):
    """The blocks flattened: (K, 12) int per block: size, first row/column, entries, earlier-column
    entries, pivots, rest and zeros (start, end each); then rows, columns, entries (i, j, feature) and
    their coefficients, earlier entries (i, column, feature) and coefficients, pivots (i, j, affected
    start, end, columns start, end), affected rows, pivot-row columns, rest rows, rest columns, zeros
    (i, j)."""
    table, rows, own, ent_i, ent_c, lat_i, lat_c, piv, aff, pcol, rest_r, rest_c, zero = ([] for _ in range(13))
    for blk in blocks:
        zeros = _zeros(blk)
        table.append((len(blk.rows), len(rows), len(ent_i), len(ent_i) + len(blk.entries), len(lat_i),
                      len(lat_i) + len(blk.later), len(piv), len(piv) + len(blk.pivots), len(rest_r),
                      len(rest_r) + len(blk.rest_rows), len(zero), len(zero) + len(zeros)))
        zero += zeros
        rows += list(blk.rows)
        own += list(blk.own)
        ent_i += [(i, j, f) for i, j, f, _ in blk.entries]
        ent_c += [coef for *_, coef in blk.entries]
        lat_i += [(i, c, f) for i, c, f, _ in blk.later]
        lat_c += [coef for *_, coef in blk.later]
        for (i, j), (affected, columns) in zip(blk.pivots, blk.fill):
            piv.append((i, j, len(aff), len(aff) + len(affected), len(pcol), len(pcol) + len(columns)))
            aff += affected
            pcol += columns
        rest_r += blk.rest_rows
        rest_c += blk.rest_cols
    ints = lambda x, w=None: np.array(x, np.int64).reshape((-1, w) if w else -1)  # noqa: E731
    table = ints(table, 12)
    return ForceBlockTables(*(np.ascontiguousarray(table[:, c]) for c in range(12)), ints(rows), ints(own),
                            ints(ent_i, 3), np.array(ent_c, float), ints(lat_i, 3), np.array(lat_c, float),
                            ints(piv, 6), ints(aff), ints(pcol), ints(rest_r), ints(rest_c), ints(zero, 2))


def _zeros(blk) -> list:
    """The positions of a block's dense matrix that are read but hold no entry: fill-in, and the rest
    of the square solved densely."""
    entries = {(i, j) for i, j, _, _ in blk.entries}
    read = {(k, jj) for (i, j), (affected, columns) in zip(blk.pivots, blk.fill) for k in affected for jj in columns}
    read |= {(i, j) for i in blk.rest_rows for j in blk.rest_cols}
    return sorted(read - entries)


def _plan(engine, ks_plan, motion, inertia) -> _KernelPlan:
    row_dtype = motion.rows.dtype
    key = (row_dtype, inertia)
    cache = engine.prepare("numba kinetostatics", dict)  # per row layout and inertia
    if key in cache:
        return cache[key]
    mech, lay = engine.mech, ks_plan.lay
    names, links, guides, loads = _load_table(engine, inertia)
    offsets = np.array([row_dtype.fields[name][1] // 8 for name in _READS], np.int64)
    link_row = np.full(len(engine.links), -1, np.int64)
    for k, row in lay.rows.items():
        link_row[k] = row
    p_names, p_link, p_at = _tables(engine)[0]  # every point: the kernel places them from the frames
    point_of = {name: k for k, name in enumerate(p_names)}
    jpoint = np.array([point_of[name] for name in ks_plan.joints], np.int64)
    guide_i = np.array([engine.link_index[mech.joints[n].carrier] for n in ks_plan.guides], np.int64)
    guide_f = np.array([engine.laws[n].u0 for n in ks_plan.guides], float).reshape(-1, 2)
    p_inputs = np.array(ks_plan.p_inputs, np.int64).reshape(-1, 2)
    in_joint = np.array([list(mech.joints).index(inp.joint) for inp in engine.inputs], np.int64)
    blocks = _block_tables(ks_plan.blocks)
    args = (offsets, len(engine.links), p_link.astype(np.int64), np.ascontiguousarray(p_at, float), link_row,
            np.asarray(ks_plan.centre, float), float(engine.size), jpoint, guide_i, guide_f, p_inputs, loads,
            blocks, lay.scale.astype(float), np.array(lay.in_cols, np.int64), in_joint, float(engine.tol.singular))
    sizes = (max([1] + [len(b.rows) for b in ks_plan.blocks]), lay.size,
             1 + 2 * len(jpoint) + 2 * len(guide_i) + len(p_inputs))
    plan = cache[key] = _KernelPlan(names, links, guides, args, sizes, [])
    return plan


def _scratch(n_max: int, n: int, n_features: int) -> tuple:
    """Work arrays of `_kernel`: a block's dense matrix, its right side, the dense rest with its right
    side, permutation and solution, the whole right side, the features."""
    return (np.zeros((n_max, n_max)), np.zeros(n_max), np.zeros((n_max, n_max)), np.zeros(n_max),
            np.zeros(n_max, np.int64), np.zeros(n_max), np.zeros(max(n, 1)), np.zeros(n_features))


def solve(engine, motion, ks_plan, inertia=True):
    """x (n, B) (the unknowns, NaN where singular), singular (B,), the virtual-power residual (B,) and
    the loads (`LoadValue`s, numpy's order) over the positions of a compiled `motion`."""
    rows = motion.rows
    plan = _plan(engine, ks_plan, motion, inertia)
    batch = len(rows)
    sizes = np.zeros((batch, max(len(plan.guide_loads), 1)))
    for g, load in enumerate(plan.guide_loads):
        sizes[:, g] = guide_force_size(engine, motion, load)
    x = np.empty((batch, ks_plan.lay.size))
    singular = np.empty(batch, np.bool_)
    residual = np.empty(batch)
    loads = np.empty((batch, len(plan.names), 5))
    om = np.ascontiguousarray(motion.omega[:, 0])
    ep = np.ascontiguousarray(motion.epsilon[:, 0])
    row = rows.view(np.float64).reshape(batch, -1)
    parts = _threads.chunks(batch, engine.threads)
    work = _threads.work_arrays(plan.scratch, lambda: _scratch(*plan.sizes), len(parts))
    _threads.run([lambda p=p, w=w: _kernel(row[p], om[p], ep[p], sizes[p], *plan.args, x[p], singular[p], residual[p],
                                           loads[p], *w)
                  for p, w in zip(parts, work)])
    values = [LoadValue(name, k, loads[:, i, 0:2], loads[:, i, 2:4], loads[:, i, 4])
              for i, (name, k) in enumerate(zip(plan.names, plan.links))]
    return x.T, singular, residual, values


# -- kernel -------------------------------------------------------------------------------------------
_jit = numba.njit(cache=True, error_model="numpy", nogil=True, _nrt=False)
_inline = numba.njit(cache=True, error_model="numpy", nogil=True, _nrt=False, inline="always")


@_inline
def _dense_solve(M, n, perm, rhs, sol):
    """Solve M[:n, :n] sol = rhs as `_linalg.factor` does (explicit inverse for n ≤ 2, else the
    kinematics kernel's LU with partial pivoting); returns the determinant. M is overwritten."""
    if n == 1:
        det = M[0, 0]
        sol[0] = (1.0 / det) * rhs[0]
        return det
    if n == 2:
        a00, a01, a10, a11 = M[0, 0], M[0, 1], M[1, 0], M[1, 1]
        det = a00 * a11 - a01 * a10
        i00, i01, i10, i11 = a11 / det, -a01 / det, -a10 / det, a00 / det
        sol[0] = i00 * rhs[0] + i01 * rhs[1]
        sol[1] = i10 * rhs[0] + i11 * rhs[1]
        return det
    det, _ = _lu(M, n, perm)
    _lu_solve(M, n, perm, rhs, sol)
    return det


@_inline
def _solve_block(bk, fb, feat, bvec, x, A, rl, M, rr, perm, sol):
    """One block of `kinetostatics._solve_block` at one position, into x (scaled unknowns); returns
    its singularity measure |det| / Π‖row‖."""
    n, r0 = fb.size[bk], fb.row0[bk]
    for i in range(n):
        rl[i] = bvec[fb.rows[r0 + i]]
        rr[i] = 0.0  # Σ of the row's squares
    for z in range(fb.zero0[bk], fb.zero1[bk]):
        A[fb.zeros[z, 0], fb.zeros[z, 1]] = 0.0
    for e in range(fb.entry0[bk], fb.entry1[bk]):
        f, i = fb.entry[e, 2], fb.entry[e, 0]
        v = fb.entry_coef[e] if f == 0 else fb.entry_coef[e] * feat[f]
        A[i, fb.entry[e, 1]] = v
        rr[i] += v * v
    norm2 = 1.0
    for i in range(n):
        norm2 *= rr[i]
    for e in range(fb.later0[bk], fb.later1[bk]):
        f = fb.later[e, 2]
        rl[fb.later[e, 0]] -= (fb.later_coef[e] if f == 0 else fb.later_coef[e] * feat[f]) * x[fb.later[e, 1]]
    det = 1.0
    for p in range(fb.pivot0[bk], fb.pivot1[bk]):
        i, j = fb.pivots[p, 0], fb.pivots[p, 1]
        pivot = A[i, j]
        for t in range(fb.pivots[p, 2], fb.pivots[p, 3]):
            k = fb.affected[t]
            m = A[k, j] / pivot
            for u in range(fb.pivots[p, 4], fb.pivots[p, 5]):
                A[k, fb.pivot_cols[u]] -= m * A[i, fb.pivot_cols[u]]
            rl[k] -= m * rl[i]
        det *= pivot
    s0, s1 = fb.rest0[bk], fb.rest1[bk]
    if s1 > s0:
        nr = s1 - s0
        for p in range(nr):
            for q in range(nr):
                M[p, q] = A[fb.rest_rows[s0 + p], fb.rest_cols[s0 + q]]
            rr[p] = rl[fb.rest_rows[s0 + p]]  # rr, free again, takes the rest's right side
        det *= _dense_solve(M, nr, perm, rr, sol)
        for q in range(nr):
            x[fb.own[r0 + fb.rest_cols[s0 + q]]] = sol[q]
    for p in range(fb.pivot1[bk] - 1, fb.pivot0[bk] - 1, -1):
        i, j = fb.pivots[p, 0], fb.pivots[p, 1]
        acc = rl[i]
        for u in range(fb.pivots[p, 4], fb.pivots[p, 5]):
            acc -= A[i, fb.pivot_cols[u]] * x[fb.own[r0 + fb.pivot_cols[u]]]
        x[fb.own[r0 + j]] = acc / A[i, j]
    return abs(det) / np.sqrt(norm2)


@_jit
def _kernel(row, omega, epsilon, sizes, offsets, n_l, p_link, p_at, link_row, centre, size, jpoint, guide_i, guide_f,
            p_inputs, loads, fb, scale, in_cols, in_joint, min_measure, x_out, singular, residual, loads_out, A, rl, M,
            rr, perm, sol, bvec, feat):
    """Every position b: features, loads (stored in loads_out[b]: fx, fy, x, y, moment), the blocks into
    x_out[b] (scaled back, NaN where a block's measure is not above min_measure, `Tolerances.singular`),
    and the relative virtual-power residual."""
    o_cos, o_sin, o_r, o_fv, o_fa, o_wq, o_eq, o_rq = (
        offsets[0], offsets[1], offsets[2], offsets[3], offsets[4], offsets[5], offsets[6], offsets[7])
    cx, cy = centre[0], centre[1]
    inv_size = 1.0 / size
    n_j, n_g, n_loads, n = len(jpoint), len(guide_i), len(loads.link), len(scale)
    base = 1 + 2 * n_j
    for b in range(len(row)):
        om, ep = omega[b], epsilon[b]
        om2 = om * om
        # the entries' features (kinetostatics._features)
        feat[0] = 1.0
        for jj in range(n_j):  # the joint's point from its link's frame (kinematics._moving_points)
            p = jpoint[jj]
            k = p_link[p]
            c, s = row[b, o_cos + k], row[b, o_sin + k]
            px = row[b, o_r + 2 * k] + (c * p_at[p, 0] - s * p_at[p, 1])
            py = row[b, o_r + 2 * k + 1] + (s * p_at[p, 0] + c * p_at[p, 1])
            feat[1 + 2 * jj] = (px - cx) * inv_size
            feat[2 + 2 * jj] = (py - cy) * inv_size
        for g in range(n_g):
            c, s = row[b, o_cos + guide_i[g]], row[b, o_sin + guide_i[g]]
            feat[base + 2 * g] = c * guide_f[g, 0] - s * guide_f[g, 1]
            feat[base + 2 * g + 1] = s * guide_f[g, 0] + c * guide_f[g, 1]
        for q in range(len(p_inputs)):
            g, j = p_inputs[q, 0], p_inputs[q, 1]
            feat[base + 2 * n_g + q] = feat[1 + 2 * j] * feat[base + 2 * g + 1] - feat[2 + 2 * j] * feat[base + 2 * g]
        # the loads (loads._evaluate, inertia_loads) and the right-hand side (kinetostatics._right_side)
        for i in range(n):
            bvec[i] = 0.0
        for ld in range(n_loads):
            k, g = loads.link[ld], loads.guide[ld]
            c, s = row[b, o_cos + k], row[b, o_sin + k]
            rx = c * loads.at[ld, 0] - s * loads.at[ld, 1]
            ry = s * loads.at[ld, 0] + c * loads.at[ld, 1]
            px, py = row[b, o_r + 2 * k] + rx, row[b, o_r + 2 * k + 1] + ry
            if loads.inertia[ld]:  # d'Alembert: −m·a at the centre, −I·ε
                wq = row[b, o_wq + k]
                wr, er = wq * om, row[b, o_eq + k] * om2 + wq * ep  # real ω, ε (Motion.w, Motion.e)
                ax = row[b, o_fa + 2 * k] * om2 + row[b, o_fv + 2 * k] * ep
                ay = row[b, o_fa + 2 * k + 1] * om2 + row[b, o_fv + 2 * k + 1] * ep
                ax -= er * ry
                ay += er * rx
                ax -= (wr * wr) * rx
                ay -= (wr * wr) * ry
                fx, fy, mz = -loads.mass[ld] * ax, -loads.mass[ld] * ay, -loads.moment_of_inertia[ld] * er
            elif g >= 0:  # along the guide of the carrier
                c, s = row[b, o_cos + loads.carrier[ld]], row[b, o_sin + loads.carrier[ld]]
                ux = c * loads.u0[ld, 0] - s * loads.u0[ld, 1]
                uy = s * loads.u0[ld, 0] + c * loads.u0[ld, 1]
                fx, fy, mz = sizes[b, g] * ux, sizes[b, g] * uy, loads.moment[ld]
            else:
                fx, fy, mz = loads.force[ld, 0], loads.force[ld, 1], loads.moment[ld]
            loads_out[b, ld, 0], loads_out[b, ld, 1], loads_out[b, ld, 2] = fx, fy, px
            loads_out[b, ld, 3], loads_out[b, ld, 4] = py, mz
            r = link_row[k]
            if r >= 0:
                bvec[r] -= fx
                bvec[r + 1] -= fy
                bvec[r + 2] -= ((px - cx) * fy - (py - cy) * fx + mz) * inv_size
        # the blocks, last group first (kinetostatics._solve_blocks)
        xb = x_out[b]
        bad = False
        for bk in range(len(fb.size)):
            measure = _solve_block(bk, fb, feat, bvec, xb, A, rl, M, rr, perm, sol)
            bad = bad or not measure > min_measure
        for i in range(n):
            xb[i] *= scale[i]
            bad = bad or not np.isfinite(xb[i])
        if bad:
            for i in range(n):
                xb[i] = np.nan
        singular[b] = bad
        # virtual power with the analogues (kinetostatics._virtual_power)
        vscale, wscale = 0.0, 0.0
        for p in range(len(p_link)):  # the points' velocity analogues (Motion.vq)
            k = p_link[p]
            c, s, wk = row[b, o_cos + k], row[b, o_sin + k], row[b, o_wq + k]
            vx = row[b, o_fv + 2 * k] - wk * (s * p_at[p, 0] + c * p_at[p, 1])
            vy = row[b, o_fv + 2 * k + 1] + wk * (c * p_at[p, 0] - s * p_at[p, 1])
            vscale = max(vscale, vx * vx + vy * vy)
        vscale = np.sqrt(vscale)  # the largest point speed (one root: the root keeps the order)
        for k in range(n_l):
            wscale = max(wscale, abs(row[b, o_wq + k]))
        total, bound = 0.0, 0.0
        for ld in range(n_loads):
            k = loads.link[ld]
            fx, fy, px, py, mz = (loads_out[b, ld, 0], loads_out[b, ld, 1], loads_out[b, ld, 2],
                                  loads_out[b, ld, 3], loads_out[b, ld, 4])
            wk = row[b, o_wq + k]
            dx, dy = px - row[b, o_r + 2 * k], py - row[b, o_r + 2 * k + 1]
            total += fx * (row[b, o_fv + 2 * k] - wk * dy) + fy * (row[b, o_fv + 2 * k + 1] + wk * dx) + mz * wk
            bound += np.sqrt(fx * fx + fy * fy) * vscale + abs(mz) * wscale
        for q in range(len(in_cols)):
            term = xb[in_cols[q]] * row[b, o_rq + in_joint[q]]
            total += term
            bound += abs(term)
        residual[b] = abs(total) / (bound if bound > 0 else 1.0)
