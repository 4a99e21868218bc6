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
    args = (offsets, p_link.astype(np.int64), np.ascontiguousarray(p_at, float), link_row,
            np.asarray(ks_plan.centre, float), float(engine.size), jpoint, guide_i, guide_f, p_inputs, loads,
            blocks, lay.scale.astype(float), np.array(lay.in_cols, np.int64), in_joint, float(engine.tol.singular))
    sizes = (slots, max([1] + [len(b.rows) for b in ks_plan.blocks]), lay.size,
             1 + 2 * len(jpoint) + 2 * len(guide_i) + len(p_inputs))
    plan = cache[key] = _KernelPlan(names, links, guides, args, sizes, [])
    return plan


#: positions a kernel takes at once: each step runs over them in an inner loop, so that reading the
#: tables costs once per chunk and the arithmetic runs in SIMD lanes
CHUNK = 32
#: the frame fields `_gather` copies per link and position, in this order
_FRAME = ("cos", "sin", "rx", "ry", "fvx", "fvy", "fax", "fay", "wq", "eq")


def _scratch(slots: int, n_max: int, n: int, n_features: int, n_links: int) -> tuple:
    """Work arrays of `_kernel`, per position of a chunk (last axis): the slots, a block's right side and
    row norms, the unknowns, the whole right side, the features, seven vectors (`_V_*`), the frames
    (`_FRAME`, per link) and the pivot rows of a dense solve."""
    return (np.zeros((max(slots, 1), CHUNK)), np.zeros((n_max, CHUNK)), np.zeros((n_max, CHUNK)),
            np.zeros((max(n, 1), CHUNK)), np.zeros((max(n, 1), CHUNK)), np.zeros((n_features, CHUNK)),
            np.zeros((7, CHUNK)), np.zeros((len(_FRAME), n_links, CHUNK)), np.zeros(CHUNK, np.int64))


def solve(engine, motion, ks_plan, inertia=True):
    """x (n, B) (the unknowns, NaN where singular), singular (B,), the virtual-power residual (B,) and
    the loads (`LoadValue`s, numpy's order) over the positions of a compiled `motion`."""
    rows = motion.rows
    plan = _plan(engine, ks_plan, motion, inertia)
    batch = len(rows)
    sizes = np.zeros((max(len(plan.guide_loads), 1), batch))
    for g, load in enumerate(plan.guide_loads):
        sizes[g] = guide_force_size(engine, motion, load)
    x = np.empty((ks_plan.lay.size, batch))
    singular = np.empty(batch, np.bool_)
    residual = np.empty(batch)
    loads = np.empty((len(plan.names), 5, batch))  # fx, fy, x, y, moment
    om = np.ascontiguousarray(motion.omega[:, 0])
    ep = np.ascontiguousarray(motion.epsilon[:, 0])
    row = rows.view(np.float64).reshape(batch, -1)
    parts = _threads.chunks(batch, engine.threads)
    work = _threads.work_arrays(plan.scratch, lambda: _scratch(*plan.sizes, len(engine.links)), len(parts))
    _threads.run([lambda p=p, w=w: _kernel(p.start, p.stop, row, om, ep, sizes, *plan.args, x, singular, residual,
                                           loads, *w)
                  for p, w in zip(parts, work)])
    values = [LoadValue(name, k, loads[i, 0:2].T, loads[i, 2:4].T, loads[i, 4])
              for i, (name, k) in enumerate(zip(plan.names, plan.links))]
    return x, singular, residual, values


# -- kernel -------------------------------------------------------------------------------------------
_jit = numba.njit(cache=True, error_model="numpy", nogil=True, _nrt=False)
# the rows of the vectors work array
_V_MULT, _V_DET, _V_PROD, _V_BAD, _V_SPEED, _V_TURN, _V_BIG = 0, 1, 2, 3, 4, 5, 6


@_jit
def _gather(b0, nc, row, offsets, fr):
    """The frames of positions b0 … b0 + nc − 1 from their records into fr (`_FRAME`, L, chunk)."""
    o_cos, o_sin, o_r, o_fv, o_fa, o_wq, o_eq = (offsets[0], offsets[1], offsets[2], offsets[3], offsets[4],
                                                 offsets[5], offsets[6])
    for c in range(nc):
        rec = row[b0 + c]
        for k in range(fr.shape[1]):
            fr[0, k, c], fr[1, k, c] = rec[o_cos + k], rec[o_sin + k]
            fr[2, k, c], fr[3, k, c] = rec[o_r + 2 * k], rec[o_r + 2 * k + 1]
            fr[4, k, c], fr[5, k, c] = rec[o_fv + 2 * k], rec[o_fv + 2 * k + 1]
            fr[6, k, c], fr[7, k, c] = rec[o_fa + 2 * k], rec[o_fa + 2 * k + 1]
            fr[8, k, c], fr[9, k, c] = rec[o_wq + k], rec[o_eq + k]


@_jit
def _features(nc, fr, p_link, p_at, centre, inv_size, jpoint, guide_i, guide_f, p_inputs, feat):
    """The entries' features (kinetostatics._features) of the chunk into feat (F, chunk)."""
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
            co, si = fr[0, k, c], fr[1, k, c]
            px = fr[2, k, c] + (co * ax - si * ay)
            py = fr[3, k, c] + (si * ax + co * ay)
            feat[1 + 2 * jj, c] = (px - cx) * inv_size
            feat[2 + 2 * jj, c] = (py - cy) * inv_size
    for g in range(n_g):
        k, ux, uy = guide_i[g], guide_f[g, 0], guide_f[g, 1]
        for c in range(nc):
            co, si = fr[0, k, c], fr[1, k, c]
            feat[base + 2 * g, c] = co * ux - si * uy
            feat[base + 2 * g + 1, c] = si * ux + co * uy
    for q in range(len(p_inputs)):
        g, j = p_inputs[q, 0], p_inputs[q, 1]
        for c in range(nc):
            feat[base + 2 * n_g + q, c] = (feat[1 + 2 * j, c] * feat[base + 2 * g + 1, c]
                                           - feat[2 + 2 * j, c] * feat[base + 2 * g, c])


@_jit
def _loads(b0, nc, fr, omega, epsilon, sizes, centre, inv_size, link_row, loads, loads_out, bvec):
    """The loads (loads._evaluate, inertia_loads) into loads_out[:, :, b] (fx, fy, x, y, moment) and
    minus them into the right side bvec (n, chunk) (kinetostatics._right_side)."""
    cx, cy = centre[0], centre[1]
    for i in range(bvec.shape[0]):
        for c in range(nc):
            bvec[i, c] = 0.0
    for ld in range(len(loads.link)):
        k, g, r = loads.link[ld], loads.guide[ld], link_row[loads.link[ld]]
        atx, aty, mass, mom_i = loads.at[ld, 0], loads.at[ld, 1], loads.mass[ld], loads.moment_of_inertia[ld]
        out = loads_out[ld]
        for c in range(nc):
            co, si = fr[0, k, c], fr[1, k, c]
            rx = co * atx - si * aty
            ry = si * atx + co * aty
            out[2, b0 + c], out[3, b0 + c] = fr[2, k, c] + rx, fr[3, k, c] + ry
        if loads.inertia[ld]:  # d'Alembert: −m·a at the centre, −I·ε
            for c in range(nc):
                om, ep = omega[b0 + c], epsilon[b0 + c]
                om2 = om * om
                wq = fr[8, k, c]
                wr, er = wq * om, fr[9, k, c] * om2 + wq * ep  # real ω, ε (Motion.w, Motion.e)
                co, si = fr[0, k, c], fr[1, k, c]
                rx = co * atx - si * aty
                ry = si * atx + co * aty
                ax = fr[6, k, c] * om2 + fr[4, k, c] * ep
                ay = fr[7, k, c] * om2 + fr[5, k, c] * ep
                ax -= er * ry
                ay += er * rx
                ax -= (wr * wr) * rx
                ay -= (wr * wr) * ry
                out[0, b0 + c], out[1, b0 + c], out[4, b0 + c] = -mass * ax, -mass * ay, -mom_i * er
        elif g >= 0:  # along the guide of the carrier
            kc, u0x, u0y, mz = loads.carrier[ld], loads.u0[ld, 0], loads.u0[ld, 1], loads.moment[ld]
            for c in range(nc):
                co, si = fr[0, kc, c], fr[1, kc, c]
                size = sizes[g, b0 + c]
                out[0, b0 + c], out[1, b0 + c] = size * (co * u0x - si * u0y), size * (si * u0x + co * u0y)
                out[4, b0 + c] = mz
        else:
            fx, fy, mz = loads.force[ld, 0], loads.force[ld, 1], loads.moment[ld]
            for c in range(nc):
                out[0, b0 + c], out[1, b0 + c], out[4, b0 + c] = fx, fy, mz
        if r >= 0:
            for c in range(nc):
                fx, fy, px, py = out[0, b0 + c], out[1, b0 + c], out[2, b0 + c], out[3, b0 + c]
                bvec[r, c] -= fx
                bvec[r + 1, c] -= fy
                bvec[r + 2, c] -= ((px - cx) * fy - (py - cy) * fx + out[4, b0 + c]) * inv_size


@_jit
def _rest_solve(bk, nc, fb, S, rl, X, vec, ipiv):
    """The rest of a block (`_Block.rest_rows`, `rest_cols`) over the chunk, solved in place on its slots
    as `_linalg.factor` does: the explicit inverse up to 2×2, else LU with partial pivoting, each position
    its own pivots; the unknowns into X, the determinant into vec[_V_DET]."""
    s0, q0 = fb.rest0[bk], fb.rest_slot0[bk]
    nr = fb.rest1[bk] - s0
    rows, cols, slot = fb.rest_rows, fb.rest_cols, fb.rest_slots
    det, mult, big = vec[_V_DET], vec[_V_MULT], vec[_V_BIG]
    if nr == 1:
        a, r = S[slot[q0]], rl[rows[s0]]
        for c in range(nc):
            d = a[c]
            X[cols[s0], c] = (1.0 / d) * r[c]
            det[c] *= d
        return
    if nr == 2:
        a00, a01, a10, a11 = S[slot[q0]], S[slot[q0 + 1]], S[slot[q0 + 2]], S[slot[q0 + 3]]
        r0, r1 = rl[rows[s0]], rl[rows[s0 + 1]]
        x0, x1 = X[cols[s0]], X[cols[s0 + 1]]
        for c in range(nc):
            d = a00[c] * a11[c] - a01[c] * a10[c]
            i00, i01, i10, i11 = a11[c] / d, -a01[c] / d, -a10[c] / d, a00[c] / d
            x0[c] = i00 * r0[c] + i01 * r1[c]
            x1[c] = i10 * r0[c] + i11 * r1[c]
            det[c] *= d
        return
    for k in range(nr):
        akk = S[slot[q0 + k * nr + k]]
        if k < nr - 1:
            for c in range(nc):  # the first largest pivot of the column (numpy's argmax)
                ipiv[c], big[c] = k, abs(akk[c])
            for i in range(k + 1, nr):
                aik = S[slot[q0 + i * nr + k]]
                for c in range(nc):
                    if abs(aik[c]) > big[c]:
                        ipiv[c], big[c] = i, abs(aik[c])
            for c in range(nc):
                p = ipiv[c]
                if p != k:
                    for j in range(k, nr):
                        skj, spj = slot[q0 + k * nr + j], slot[q0 + p * nr + j]
                        S[skj, c], S[spj, c] = S[spj, c], S[skj, c]
                    rk, rp = rows[s0 + k], rows[s0 + p]
                    rl[rk, c], rl[rp, c] = rl[rp, c], rl[rk, c]
                    det[c] = -det[c]
            rk = rl[rows[s0 + k]]
            for i in range(k + 1, nr):
                aik, ri = S[slot[q0 + i * nr + k]], rl[rows[s0 + i]]
                for c in range(nc):
                    mult[c] = aik[c] / akk[c]
                    ri[c] -= mult[c] * rk[c]
                for j in range(k + 1, nr):
                    aij, akj = S[slot[q0 + i * nr + j]], S[slot[q0 + k * nr + j]]
                    for c in range(nc):
                        aij[c] -= mult[c] * akj[c]
        for c in range(nc):
            det[c] *= akk[c]
    for i in range(nr - 1, -1, -1):
        ri, xi, aii = rl[rows[s0 + i]], X[cols[s0 + i]], S[slot[q0 + i * nr + i]]
        for c in range(nc):
            mult[c] = ri[c]
        for j in range(i + 1, nr):
            aij, xj = S[slot[q0 + i * nr + j]], X[cols[s0 + j]]
            for c in range(nc):
                mult[c] -= aij[c] * xj[c]
        for c in range(nc):
            xi[c] = mult[c] / aii[c]


@_jit
def _solve_block(bk, nc, fb, feat, bvec, X, S, rl, norm, vec, ipiv, min_measure):
    """One block of `kinetostatics._solve_block` over a chunk, into X (n, chunk) (scaled unknowns); marks
    vec[_V_BAD] where its singularity measure |det| / Π‖row‖ is not above min_measure."""
    n, r0 = fb.size[bk], fb.row0[bk]
    mult, det, prod, bad = vec[_V_MULT], vec[_V_DET], vec[_V_PROD], vec[_V_BAD]
    for i in range(n):
        ri, bi, ni = rl[i], bvec[fb.rows[r0 + i]], norm[i]
        for c in range(nc):
            ri[c] = bi[c]
            ni[c] = 0.0  # Σ of the row's squares
    for e in range(fb.entry0[bk], fb.entry1[bk]):
        st, ni, fe, coef = S[fb.entry[e, 0]], norm[fb.entry[e, 1]], feat[fb.entry[e, 2]], fb.entry_coef[e]
        for c in range(nc):  # (feature 0 is 1)
            v = coef * fe[c]
            st[c] = v
            ni[c] += v * v
    for c in range(nc):
        prod[c] = 1.0  # Π‖row‖²
        det[c] = 1.0
    for i in range(n):
        ni = norm[i]
        for c in range(nc):
            prod[c] *= ni[c]
    for e in range(fb.later0[bk], fb.later1[bk]):
        ri, xc, fe, coef = rl[fb.later[e, 0]], X[fb.later[e, 1]], feat[fb.later[e, 2]], fb.later_coef[e]
        for c in range(nc):
            ri[c] -= (coef * fe[c]) * xc[c]
    for p in range(fb.pivot0[bk], fb.pivot1[bk]):  # the constant pivots
        sp, ri = S[fb.pivots[p, 0]], rl[fb.pivots[p, 1]]
        for a in range(fb.pivots[p, 3], fb.pivots[p, 4]):
            rk, skj = rl[fb.affected[a, 0]], S[fb.affected[a, 1]]
            for c in range(nc):
                mult[c] = skj[c] / sp[c]
            for u in range(fb.affected[a, 2], fb.affected[a, 3]):
                tu, su = S[fb.updates[u, 0]], S[fb.updates[u, 1]]
                for c in range(nc):
                    tu[c] -= mult[c] * su[c]
            for c in range(nc):
                rk[c] -= mult[c] * ri[c]
        for c in range(nc):
            det[c] *= sp[c]
    if fb.rest1[bk] > fb.rest0[bk]:
        _rest_solve(bk, nc, fb, S, rl, X, vec, ipiv)
    for p in range(fb.pivot1[bk] - 1, fb.pivot0[bk] - 1, -1):  # back-substitution
        sp, ri, xj = S[fb.pivots[p, 0]], rl[fb.pivots[p, 1]], X[fb.pivots[p, 2]]
        for c in range(nc):
            mult[c] = ri[c]
        for u in range(fb.pivots[p, 5], fb.pivots[p, 6]):
            su, xu = S[fb.pivot_row[u, 0]], X[fb.pivot_row[u, 1]]
            for c in range(nc):
                mult[c] -= su[c] * xu[c]
        for c in range(nc):
            xj[c] = mult[c] / sp[c]
    for c in range(nc):
        if not abs(det[c]) / np.sqrt(prod[c]) > min_measure:
            bad[c] = 1.0


@_jit
def _virtual_power(b0, nc, fr, row, o_rq, p_link, p_at, loads, in_cols, in_joint, x_out, loads_out, vec,
                   residual):
    """The relative virtual-power residual with the analogues (kinetostatics._virtual_power) of the chunk."""
    vscale, wscale, total, bound = vec[_V_SPEED], vec[_V_TURN], vec[_V_MULT], vec[_V_PROD]
    for c in range(nc):
        vscale[c], wscale[c], total[c], bound[c] = 0.0, 0.0, 0.0, 0.0
    for p in range(len(p_link)):  # the points' velocity analogues (Motion.vq)
        k, ax, ay = p_link[p], p_at[p, 0], p_at[p, 1]
        for c in range(nc):
            co, si, wk = fr[0, k, c], fr[1, k, c], fr[8, k, c]
            vx = fr[4, k, c] - wk * (si * ax + co * ay)
            vy = fr[5, k, c] + wk * (co * ax - si * ay)
            vscale[c] = max(vscale[c], vx * vx + vy * vy)
    for c in range(nc):
        vscale[c] = np.sqrt(vscale[c])  # the largest point speed (one root: the root keeps the order)
    for k in range(fr.shape[1]):
        for c in range(nc):
            wscale[c] = max(wscale[c], abs(fr[8, k, c]))
    for ld in range(len(loads.link)):
        k, out = loads.link[ld], loads_out[ld]
        for c in range(nc):
            fx, fy, px, py, mz = out[0, b0 + c], out[1, b0 + c], out[2, b0 + c], out[3, b0 + c], out[4, b0 + c]
            wk = fr[8, k, c]
            dx, dy = px - fr[2, k, c], py - fr[3, k, c]
            total[c] += fx * (fr[4, k, c] - wk * dy) + fy * (fr[5, k, c] + wk * dx) + mz * wk
            bound[c] += np.sqrt(fx * fx + fy * fy) * vscale[c] + abs(mz) * wscale[c]
    for q in range(len(in_cols)):
        xq, jq = x_out[in_cols[q]], o_rq + in_joint[q]
        for c in range(nc):
            term = xq[b0 + c] * row[b0 + c, jq]
            total[c] += term
            bound[c] += abs(term)
    for c in range(nc):
        residual[b0 + c] = abs(total[c]) / (bound[c] if bound[c] > 0 else 1.0)


@_jit
def _kernel(start, stop, row, omega, epsilon, sizes, offsets, p_link, p_at, link_row, centre, size, jpoint,
            guide_i, guide_f, p_inputs, loads, fb, scale, in_cols, in_joint, min_measure, x_out, singular, residual,
            loads_out, S, rl, norm, X, bvec, feat, vec, fr, ipiv):
    """Positions start … stop − 1, a chunk at a time: the frames, features, loads (into loads_out[:, :, b]:
    fx, fy, x, y, moment), the blocks into x_out[:, b] (scaled back, NaN where a block's measure is not
    above min_measure, `Tolerances.singular`), and the relative virtual-power residual."""
    inv_size = 1.0 / size
    n, chunk = len(scale), S.shape[1]
    bad = vec[_V_BAD]
    for b0 in range(start, stop, chunk):
        nc = min(chunk, stop - b0)
        _gather(b0, nc, row, offsets, fr)
        _features(nc, fr, p_link, p_at, centre, inv_size, jpoint, guide_i, guide_f, p_inputs, feat)
        _loads(b0, nc, fr, omega, epsilon, sizes, centre, inv_size, link_row, loads, loads_out, bvec)
        for z in range(len(fb.zeros)):
            sz = S[fb.zeros[z]]
            for c in range(nc):
                sz[c] = 0.0
        for c in range(nc):
            bad[c] = 0.0
        for bk in range(len(fb.size)):  # last group first (kinetostatics._solve_blocks)
            _solve_block(bk, nc, fb, feat, bvec, X, S, rl, norm, vec, ipiv, min_measure)
        for i in range(n):
            xi, si = X[i], scale[i]
            for c in range(nc):
                xi[c] *= si
                if not np.isfinite(xi[c]):
                    bad[c] = 1.0
        for c in range(nc):
            singular[b0 + c] = bad[c] != 0.0
        for i in range(n):
            xi, oi = X[i], x_out[i]
            for c in range(nc):
                oi[b0 + c] = np.nan if bad[c] != 0.0 else xi[c]
        _virtual_power(b0, nc, fr, row, offsets[7], p_link, p_at, loads, in_cols, in_joint, x_out, loads_out, vec,
                       residual)
