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
    """The blocks as `ForceBlockTables`: every place of a block's matrix that the solve reads gets a slot
    of the kernel's store (entries first, then fill-in and the rest's zeros), and each step of
    `kinetostatics._solve_block` is listed on slots, in numpy's order."""
    per_block, rows, entry, ent_c, later, lat_c, piv, aff, upd, prow = ([] for _ in range(10))
    rest_r, rest_c, rest_s, zeros = [], [], [], []
    slots = 0
    for blk in blocks:
        slot = {}
        for i, j, _, _ in blk.entries:
            slot[i, j] = slots + len(slot)
        for i, j in _zeros(blk):
            slot[i, j] = slots + len(slot)
            zeros.append(slot[i, j])
        slots += len(slot)
        per_block.append((len(blk.rows), len(rows), len(entry), len(entry) + len(blk.entries), len(later),
                          len(later) + len(blk.later), len(piv), len(piv) + len(blk.pivots), len(rest_r),
                          len(rest_r) + len(blk.rest_rows), len(rest_s)))
        rows += list(blk.rows)
        entry += [(slot[i, j], i, f) for i, j, f, _ in blk.entries]
        ent_c += [coef for *_, coef in blk.entries]
        later += [(i, c, f) for i, c, f, _ in blk.later]
        lat_c += [coef for *_, coef in blk.later]
        for (i, j), (affected, columns) in zip(blk.pivots, blk.fill):
            piv.append((slot[i, j], i, blk.own[j], len(aff), len(aff) + len(affected), len(prow),
                        len(prow) + len(columns)))
            for k in affected:
                aff.append((k, slot[k, j], len(upd), len(upd) + len(columns)))
                upd += [(slot[k, u], slot[i, u]) for u in columns]
            prow += [(slot[i, u], blk.own[u]) for u in columns]
        rest_r += blk.rest_rows
        rest_c += [blk.own[j] for j in blk.rest_cols]
        rest_s += [slot[i, j] for i in blk.rest_rows for j in blk.rest_cols]
    ints = lambda x, w=None: np.array(x, np.int64).reshape((-1, w) if w else -1)  # noqa: E731
    per_block = ints(per_block, 11)
    tables = ForceBlockTables(*(np.ascontiguousarray(per_block[:, c]) for c in range(11)), ints(rows),
                              ints(entry, 3), np.array(ent_c, float), ints(later, 3), np.array(lat_c, float),
                              ints(piv, 7), ints(aff, 4), ints(upd, 2), ints(prow, 2), ints(rest_r), ints(rest_c),
                              ints(rest_s), ints(zeros))
    return tables, slots


def _zeros(blk) -> list:
    """The places of a block's matrix that are read but hold no entry: fill-in, and the rest of the
    square solved densely."""
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
    blocks, slots = _block_tables(ks_plan.blocks)
    args = (offsets, len(engine.links), p_link.astype(np.int64), np.ascontiguousarray(p_at, float), link_row,
            np.asarray(ks_plan.centre, float), float(engine.size), jpoint, guide_i, guide_f, p_inputs, loads,
            blocks, lay.scale.astype(float), np.array(lay.in_cols, np.int64), in_joint, float(engine.tol.singular))
    sizes = (slots, max([1] + [len(b.rows) for b in ks_plan.blocks]), lay.size,
             1 + 2 * len(jpoint) + 2 * len(guide_i) + len(p_inputs))
    plan = cache[key] = _KernelPlan(names, links, guides, args, sizes, [])
    return plan


#: positions a kernel takes at once: each step of the solve runs over them in an inner loop, so that
#: reading the tables costs once per chunk and the arithmetic runs in SIMD lanes
CHUNK = 32


def _scratch(slots: int, n_max: int, n: int, n_features: int) -> tuple:
    """Work arrays of `_kernel`, per position of a chunk (last axis): the slots, a block's right side and
    row norms, the unknowns, the whole right side, the features, and six vectors (the multiplier, the
    determinant, a sum, the bad positions, the largest point speed and angular speed); then a rest's
    dense matrix, right side, permutation and solution for one position."""
    return (np.zeros((max(slots, 1), CHUNK)), np.zeros((n_max, CHUNK)), np.zeros((n_max, CHUNK)),
            np.zeros((max(n, 1), CHUNK)), np.zeros((max(n, 1), CHUNK)), np.zeros((n_features, CHUNK)),
            np.zeros((6, CHUNK)), np.zeros((n_max, n_max)), np.zeros(n_max), np.zeros(n_max, np.int64),
            np.zeros(n_max))


def solve(engine, motion, ks_plan, inertia=True):
    """x (n, B) (the unknowns, NaN where singular), singular (B,), the virtual-power residual (B,) and
    the loads (`LoadValue`s, numpy's order) over the positions of a compiled `motion`."""
    rows = motion.rows
    plan = _plan(engine, ks_plan, motion, inertia)
    batch = len(rows)
    sizes = np.zeros((batch, max(len(plan.guide_loads), 1)))
    for g, load in enumerate(plan.guide_loads):
        sizes[:, g] = guide_force_size(engine, motion, load)
    x = np.empty((ks_plan.lay.size, batch))
    singular = np.empty(batch, np.bool_)
    residual = np.empty(batch)
    loads = np.empty((batch, len(plan.names), 5))
    om = np.ascontiguousarray(motion.omega[:, 0])
    ep = np.ascontiguousarray(motion.epsilon[:, 0])
    row = rows.view(np.float64).reshape(batch, -1)
    parts = _threads.chunks(batch, engine.threads)
    work = _threads.work_arrays(plan.scratch, lambda: _scratch(*plan.sizes), len(parts))
    _threads.run([lambda p=p, w=w: _kernel(p.start, p.stop, row, om, ep, sizes, *plan.args, x, singular, residual,
                                           loads, *w)
                  for p, w in zip(parts, work)])
    values = [LoadValue(name, k, loads[:, i, 0:2], loads[:, i, 2:4], loads[:, i, 4])
              for i, (name, k) in enumerate(zip(plan.names, plan.links))]
    return x, singular, residual, values


# -- kernel -------------------------------------------------------------------------------------------
_jit = numba.njit(cache=True, error_model="numpy", nogil=True, _nrt=False)


@_jit
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


@_jit
def _features(b0, nc, row, o_cos, o_sin, o_r, p_link, p_at, centre, inv_size, jpoint, guide_i, guide_f, p_inputs,
              feat):
    """The entries' features (kinetostatics._features) of positions b0 … b0 + nc − 1 into feat (F, chunk)."""
    cx, cy = centre[0], centre[1]
    n_j, n_g = len(jpoint), len(guide_i)
    base = 1 + 2 * n_j
    for c in range(nc):
        feat[0, c] = 1.0
    for jj in range(n_j):  # the joint's point from its link's frame (kinematics._moving_points)
        p = jpoint[jj]
        k = p_link[p]
        ax, ay = p_at[p, 0], p_at[p, 1]
        for c in range(nc):
            b = b0 + c
            co, si = row[b, o_cos + k], row[b, o_sin + k]
            px = row[b, o_r + 2 * k] + (co * ax - si * ay)
            py = row[b, o_r + 2 * k + 1] + (si * ax + co * ay)
            feat[1 + 2 * jj, c] = (px - cx) * inv_size
            feat[2 + 2 * jj, c] = (py - cy) * inv_size
    for g in range(n_g):
        k, ux, uy = guide_i[g], guide_f[g, 0], guide_f[g, 1]
        for c in range(nc):
            co, si = row[b0 + c, o_cos + k], row[b0 + c, o_sin + k]
            feat[base + 2 * g, c] = co * ux - si * uy
            feat[base + 2 * g + 1, c] = si * ux + co * uy
    for q in range(len(p_inputs)):
        g, j = p_inputs[q, 0], p_inputs[q, 1]
        for c in range(nc):
            feat[base + 2 * n_g + q, c] = (feat[1 + 2 * j, c] * feat[base + 2 * g + 1, c]
                                           - feat[2 + 2 * j, c] * feat[base + 2 * g, c])


@_jit
def _loads(b0, nc, row, omega, epsilon, sizes, offsets, centre, inv_size, link_row, loads, loads_out, bvec):
    """The loads (loads._evaluate, inertia_loads) into loads_out[b] (fx, fy, x, y, moment) and minus
    them into the right side bvec (n, chunk) (kinetostatics._right_side)."""
    o_cos, o_sin, o_r, o_fv, o_fa, o_wq, o_eq = (offsets[0], offsets[1], offsets[2], offsets[3], offsets[4],
                                                 offsets[5], offsets[6])
    cx, cy = centre[0], centre[1]
    for i in range(bvec.shape[0]):
        for c in range(nc):
            bvec[i, c] = 0.0
    for ld in range(len(loads.link)):
        k, g, r = loads.link[ld], loads.guide[ld], link_row[loads.link[ld]]
        atx, aty, mass, mom_i = loads.at[ld, 0], loads.at[ld, 1], loads.mass[ld], loads.moment_of_inertia[ld]
        inertia, carrier, u0x, u0y = loads.inertia[ld], loads.carrier[ld], loads.u0[ld, 0], loads.u0[ld, 1]
        for c in range(nc):
            b = b0 + c
            co, si = row[b, o_cos + k], row[b, o_sin + k]
            rx = co * atx - si * aty
            ry = si * atx + co * aty
            px, py = row[b, o_r + 2 * k] + rx, row[b, o_r + 2 * k + 1] + ry
            if inertia:  # d'Alembert: −m·a at the centre, −I·ε
                om, ep = omega[b], epsilon[b]
                om2 = om * om
                wq = row[b, o_wq + k]
                wr, er = wq * om, row[b, o_eq + k] * om2 + wq * ep  # real ω, ε (Motion.w, Motion.e)
                ax = row[b, o_fa + 2 * k] * om2 + row[b, o_fv + 2 * k] * ep
                ay = row[b, o_fa + 2 * k + 1] * om2 + row[b, o_fv + 2 * k + 1] * ep
                ax -= er * ry
                ay += er * rx
                ax -= (wr * wr) * rx
                ay -= (wr * wr) * ry
                fx, fy, mz = -mass * ax, -mass * ay, -mom_i * er
            elif g >= 0:  # along the guide of the carrier
                co, si = row[b, o_cos + carrier], row[b, o_sin + carrier]
                ux = co * u0x - si * u0y
                uy = si * u0x + co * u0y
                fx, fy, mz = sizes[b, g] * ux, sizes[b, g] * uy, loads.moment[ld]
            else:
                fx, fy, mz = loads.force[ld, 0], loads.force[ld, 1], loads.moment[ld]
            loads_out[b, ld, 0], loads_out[b, ld, 1], loads_out[b, ld, 2] = fx, fy, px
            loads_out[b, ld, 3], loads_out[b, ld, 4] = py, mz
            if r >= 0:
                bvec[r, c] -= fx
                bvec[r + 1, c] -= fy
                bvec[r + 2, c] -= ((px - cx) * fy - (py - cy) * fx + mz) * inv_size


@_jit
def _solve_block(bk, nc, fb, feat, bvec, X, S, rl, norm, vec, M, rr, perm, sol, min_measure):
    """One block of `kinetostatics._solve_block` over a chunk, into X (n, chunk) (scaled unknowns); marks
    vec[3] where its singularity measure |det| / Π‖row‖ is not above min_measure."""
    n, r0 = fb.size[bk], fb.row0[bk]
    mult, det, total, bad = vec[0], vec[1], vec[2], vec[3]
    for i in range(n):
        ri = fb.rows[r0 + i]
        for c in range(nc):
            rl[i, c] = bvec[ri, c]
            norm[i, c] = 0.0  # Σ of the row's squares
    for e in range(fb.entry0[bk], fb.entry1[bk]):
        t, i, f, coef = fb.entry[e, 0], fb.entry[e, 1], fb.entry[e, 2], fb.entry_coef[e]
        for c in range(nc):
            v = coef if f == 0 else coef * feat[f, c]
            S[t, c] = v
            norm[i, c] += v * v
    for c in range(nc):
        total[c] = 1.0  # Π‖row‖²
        det[c] = 1.0
    for i in range(n):
        for c in range(nc):
            total[c] *= norm[i, c]
    for e in range(fb.later0[bk], fb.later1[bk]):
        i, col, f, coef = fb.later[e, 0], fb.later[e, 1], fb.later[e, 2], fb.later_coef[e]
        for c in range(nc):
            rl[i, c] -= (coef if f == 0 else coef * feat[f, c]) * X[col, c]
    for p in range(fb.pivot0[bk], fb.pivot1[bk]):  # the constant pivots
        s, i = fb.pivots[p, 0], fb.pivots[p, 1]
        for a in range(fb.pivots[p, 3], fb.pivots[p, 4]):
            k, skj = fb.affected[a, 0], fb.affected[a, 1]
            for c in range(nc):
                mult[c] = S[skj, c] / S[s, c]
            for u in range(fb.affected[a, 2], fb.affected[a, 3]):
                tu, su = fb.updates[u, 0], fb.updates[u, 1]
                for c in range(nc):
                    S[tu, c] -= mult[c] * S[su, c]
            for c in range(nc):
                rl[k, c] -= mult[c] * rl[i, c]
        for c in range(nc):
            det[c] *= S[s, c]
    s0, s1, q0 = fb.rest0[bk], fb.rest1[bk], fb.rest_slot0[bk]
    nr = s1 - s0
    if nr:  # the rest, densely with pivoting, position by position
        for c in range(nc):
            for p in range(nr):
                for q in range(nr):
                    M[p, q] = S[fb.rest_slots[q0 + p * nr + q], c]
                rr[p] = rl[fb.rest_rows[s0 + p], c]
            det[c] *= _dense_solve(M, nr, perm, rr, sol)
            for q in range(nr):
                X[fb.rest_cols[s0 + q], c] = sol[q]
    for p in range(fb.pivot1[bk] - 1, fb.pivot0[bk] - 1, -1):  # back-substitution
        s, i, j = fb.pivots[p, 0], fb.pivots[p, 1], fb.pivots[p, 2]
        for c in range(nc):
            mult[c] = rl[i, c]
        for u in range(fb.pivots[p, 5], fb.pivots[p, 6]):
            su, col = fb.pivot_row[u, 0], fb.pivot_row[u, 1]
            for c in range(nc):
                mult[c] -= S[su, c] * X[col, c]
        for c in range(nc):
            X[j, c] = mult[c] / S[s, c]
    for c in range(nc):
        if not abs(det[c]) / np.sqrt(total[c]) > min_measure:
            bad[c] = 1.0


@_jit
def _virtual_power(b0, nc, row, offsets, n_l, p_link, p_at, loads, in_cols, in_joint, x_out, loads_out, vec,
                   residual):
    """The relative virtual-power residual with the analogues (kinetostatics._virtual_power) of the chunk."""
    o_cos, o_sin, o_r, o_fv, o_wq, o_rq = offsets[0], offsets[1], offsets[2], offsets[3], offsets[5], offsets[7]
    vscale, wscale, total, bound = vec[4], vec[5], vec[0], vec[2]
    for c in range(nc):
        vscale[c], wscale[c], total[c], bound[c] = 0.0, 0.0, 0.0, 0.0
    for p in range(len(p_link)):  # the points' velocity analogues (Motion.vq)
        k, ax, ay = p_link[p], p_at[p, 0], p_at[p, 1]
        for c in range(nc):
            b = b0 + c
            co, si, wk = row[b, o_cos + k], row[b, o_sin + k], row[b, o_wq + k]
            vx = row[b, o_fv + 2 * k] - wk * (si * ax + co * ay)
            vy = row[b, o_fv + 2 * k + 1] + wk * (co * ax - si * ay)
            vscale[c] = max(vscale[c], vx * vx + vy * vy)
    for c in range(nc):
        vscale[c] = np.sqrt(vscale[c])  # the largest point speed (one root: the root keeps the order)
    for k in range(n_l):
        for c in range(nc):
            wscale[c] = max(wscale[c], abs(row[b0 + c, o_wq + k]))
    for ld in range(len(loads.link)):
        k = loads.link[ld]
        for c in range(nc):
            b = b0 + c
            fx, fy, px, py, mz = (loads_out[b, ld, 0], loads_out[b, ld, 1], loads_out[b, ld, 2],
                                  loads_out[b, ld, 3], loads_out[b, ld, 4])
            wk = row[b, o_wq + k]
            dx, dy = px - row[b, o_r + 2 * k], py - row[b, o_r + 2 * k + 1]
            total[c] += fx * (row[b, o_fv + 2 * k] - wk * dy) + fy * (row[b, o_fv + 2 * k + 1] + wk * dx) + mz * wk
            bound[c] += np.sqrt(fx * fx + fy * fy) * vscale[c] + abs(mz) * wscale[c]
    for q in range(len(in_cols)):
        col, jq = in_cols[q], o_rq + in_joint[q]
        for c in range(nc):
            term = x_out[col, b0 + c] * row[b0 + c, jq]
            total[c] += term
            bound[c] += abs(term)
    for c in range(nc):
        residual[b0 + c] = abs(total[c]) / (bound[c] if bound[c] > 0 else 1.0)


@_jit
def _kernel(start, stop, row, omega, epsilon, sizes, offsets, n_l, p_link, p_at, link_row, centre, size, jpoint,
            guide_i, guide_f, p_inputs, loads, fb, scale, in_cols, in_joint, min_measure, x_out, singular, residual,
            loads_out, S, rl, norm, X, bvec, feat, vec, M, rr, perm, sol):
    """Positions start … stop − 1, a chunk at a time: features, loads (stored in loads_out[b]: fx, fy, x,
    y, moment), the blocks into x_out[:, b] (scaled back, NaN where a block's measure is not above
    min_measure, `Tolerances.singular`), and the relative virtual-power residual."""
    inv_size = 1.0 / size
    n, chunk = len(scale), S.shape[1]
    bad = vec[3]
    for b0 in range(start, stop, chunk):
        nc = min(chunk, stop - b0)
        _features(b0, nc, row, offsets[0], offsets[1], offsets[2], p_link, p_at, centre, inv_size, jpoint, guide_i,
                  guide_f, p_inputs, feat)
        _loads(b0, nc, row, omega, epsilon, sizes, offsets, centre, inv_size, link_row, loads, loads_out, bvec)
        for z in range(len(fb.zeros)):
            for c in range(nc):
                S[fb.zeros[z], c] = 0.0
        for c in range(nc):
            bad[c] = 0.0
        for bk in range(len(fb.size)):  # last group first (kinetostatics._solve_blocks)
            _solve_block(bk, nc, fb, feat, bvec, X, S, rl, norm, vec, M, rr, perm, sol, min_measure)
        for i in range(n):
            for c in range(nc):
                X[i, c] *= scale[i]
                if not np.isfinite(X[i, c]):
                    bad[c] = 1.0
        for c in range(nc):
            singular[b0 + c] = bad[c] != 0.0
        for i in range(n):
            for c in range(nc):
                x_out[i, b0 + c] = np.nan if bad[c] != 0.0 else X[i, c]
        _virtual_power(b0, nc, row, offsets, n_l, p_link, p_at, loads, in_cols, in_joint, x_out, loads_out, vec,
                       residual)
