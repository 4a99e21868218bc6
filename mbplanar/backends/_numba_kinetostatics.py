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
from ._tables import LOAD_FIXED, LOAD_GUIDE, LOAD_INERTIA, load_tables
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


def _zeros(blk) -> list:
    """The places of a block's matrix that are read but hold no entry: fill-in, and the rest of the
    square solved densely."""
    entries = {(i, j) for i, j, _, _ in blk.entries}
    read = {(k, jj) for (i, j), (affected, columns) in zip(blk.pivots, blk.fill) for k in affected for jj in columns}
    read |= {(i, j) for i in blk.rest_rows for j in blk.rest_cols}
    return sorted(read - entries)


class _Tape:
    """The kernel's program under construction: ops (code, d, a, b, k) on rows of a work matrix (one
    row per value, one column per position of a chunk), constants, and the LU groups' row lists. Rows
    are virtual (one per value, `new`) until `_Tape.finish` maps them onto as few rows as their
    lifetimes allow."""

    def __init__(self):
        self.ops, self.consts, self.aux, self.rows = [], [], [], 0
        self._const, self._gathered, self._inputs = {}, {}, {}

    def new(self) -> int:
        self.rows += 1
        return self.rows - 1

    def const(self, value) -> int:
        value = float(value)
        key = (value, np.signbit(value))
        if key not in self._const:
            self._const[key] = len(self.consts)
            self.consts.append(value)
        return self._const[key]

    def op(self, code, d=0, a=0, b=0, k=0) -> int:
        self.ops.append((code, d, a, b, k))
        return d

    # values: each returns the row it wrote
    def gather(self, column) -> int:
        if column not in self._gathered:
            self._gathered[column] = self.op(GATHER, self.new(), column)
        return self._gathered[column]

    def input(self, i) -> int:
        if i not in self._inputs:
            self._inputs[i] = self.op(INPUT, self.new(), i)
        return self._inputs[i]

    def set(self, value, d=None) -> int:
        return self.op(SET, self.new() if d is None else d, k=self.const(value))

    def mulk(self, a, value) -> int:
        return self.op(MULK, self.new(), a, k=self.const(value))

    def addk(self, a, value) -> int:
        return self.op(ADDK, self.new(), a, k=self.const(value))

    def add(self, a, b, d=None) -> int:
        return self.op(ADD, self.new() if d is None else d, a, b)

    def sub(self, a, b, d=None) -> int:
        return self.op(SUB, self.new() if d is None else d, a, b)

    def mul(self, a, b, d=None) -> int:
        return self.op(MUL, self.new() if d is None else d, a, b)

    def div(self, a, b) -> int:
        return self.op(DIV, self.new(), a, b)

    def finish(self) -> tuple:
        """(ops (T, 5) int, constants, aux, rows): the virtual rows mapped onto physical ones, a row
        taken again once the last op reading it has run."""
        ops = np.array(self.ops, np.int64).reshape(-1, 5)
        aux = np.array(self.aux, np.int64)
        touched = [_touches(op, aux) for op in ops]
        last = {}
        for t, rows in enumerate(touched):
            for r in rows:
                last[r] = t
        phys, free, top = {}, [], 0
        for t, rows in enumerate(touched):
            for r in rows:
                if r not in phys:
                    if free:
                        phys[r] = free.pop()
                    else:
                        phys[r], top = top, top + 1
            for r in set(rows):
                if last[r] == t:
                    free.append(phys[r])
        for t, op in enumerate(ops):
            for field in _W_FIELDS[op[0]]:
                op[field] = phys[op[field]]
        for t, op in enumerate(ops):
            if op[0] == LU:
                nr = op[3]
                for i in range(op[2], op[2] + nr * nr + 2 * nr):
                    aux[i] = phys[self.aux[i]]
        return ops, np.array(self.consts + [0.0]), np.concatenate([aux, np.zeros(1, np.int64)]), max(top, 1)


def _touches(op, aux) -> list:
    """The virtual rows an op reads or writes."""
    rows = [op[f] for f in _W_FIELDS[op[0]]]
    if op[0] == LU:
        nr = op[3]
        rows += list(aux[op[2]:op[2] + nr * nr + 2 * nr])
    return rows


# op codes of `_kernel`: W is the work matrix (rows, chunk), c a position of the chunk, b = b0 + c
GATHER = 0   # W[d] = row[b, a]            (a: a column of the records)
INPUT = 1    # W[d] = inputs[a, b]         (ω, ε, then the guide-force sizes)
SET = 2      # W[d] = K[k]
MULK = 3     # W[d] = K[k] · W[a]
ADDK = 4     # W[d] = W[a] + K[k]
ADD = 5      # W[d] = W[a] + W[b]
SUB = 6      # W[d] = W[a] − W[b]
MUL = 7      # W[d] = W[a] · W[b]
DIV = 8      # W[d] = W[a] / W[b]
MAX = 9      # W[d] = max(W[a], W[b])
SQRT = 10    # W[d] = √W[a]
ABS = 11     # W[d] = |W[a]|
OUT = 12     # out[d, b] = W[a]
FLAG = 13    # W[d] = 1 where not W[a] > K[k]
FINITE = 14  # W[d] = 1 where W[a] is not finite
MASK = 15    # W[a] = NaN where W[b] ≠ 0; out[d, b] = W[a]
RESID = 16   # out[d, b] = |W[a]| / (W[b] if W[b] > 0 else 1)
LU = 17      # the dense system of aux[a …] (n = b): LU with partial pivoting, each position its own pivots
# the fields of an op that name rows of W
_W_FIELDS = {GATHER: (1,), INPUT: (1,), SET: (1,), MULK: (1, 2), ADDK: (1, 2), ADD: (1, 2, 3), SUB: (1, 2, 3),
             MUL: (1, 2, 3), DIV: (1, 2, 3), MAX: (1, 2, 3), SQRT: (1, 2), ABS: (1, 2), OUT: (2,), FLAG: (1, 2),
             FINITE: (1, 2), MASK: (2, 3), RESID: (2, 3), LU: (1,)}


def _program(engine, ks_plan, row_dtype, inertia) -> tuple:
    """The kernel's program for an engine, its record layout and `inertia`: (names, links and guide
    loads of the loads, the `_Tape`), numpy's formulas in numpy's order, op by op."""
    mech, lay, T = engine.mech, ks_plan.lay, _Tape()
    names, links, guides, loads = _load_table(engine, inertia)
    field = {name: row_dtype.fields[name][1] // 8 for name in _READS}
    per_link = {"cos": ("cos", 1, 0), "sin": ("sin", 1, 0), "rx": ("r", 2, 0), "ry": ("r", 2, 1),
                "fvx": ("fv", 2, 0), "fvy": ("fv", 2, 1), "fax": ("fa", 2, 0), "fay": ("fa", 2, 1),
                "wq": ("wq", 1, 0), "eq": ("eq", 1, 0)}

    def fr(k, name):  # a field of link k's frame
        base, width, part = per_link[name]
        return T.gather(field[base] + width * k + part)

    def turn(k, ax, ay):  # the drawn vector (ax, ay) turned with link k: (c·ax − s·ay, s·ax + c·ay)
        co, si = fr(k, "cos"), fr(k, "sin")
        return T.sub(T.mulk(co, ax), T.mulk(si, ay)), T.add(T.mulk(si, ax), T.mulk(co, ay))

    cx, cy = ks_plan.centre
    inv_size = 1.0 / engine.size
    # the entries' features (kinetostatics._features)
    p_names, p_link, p_at = _tables(engine)[0]
    point_of = {name: k for k, name in enumerate(p_names)}
    feat = [T.set(1.0)]
    for name in ks_plan.joints:
        p = point_of[name]
        k = int(p_link[p])
        rx, ry = turn(k, *p_at[p])
        feat += [T.mulk(T.addk(T.add(fr(k, "rx"), rx), -cx), inv_size),
                 T.mulk(T.addk(T.add(fr(k, "ry"), ry), -cy), inv_size)]
    n_j = len(ks_plan.joints)
    for name in ks_plan.guides:
        feat += turn(engine.link_index[mech.joints[name].carrier], *engine.laws[name].u0)
    base = 1 + 2 * n_j
    for g, j in ks_plan.p_inputs:
        ux, uy = feat[base + 2 * g], feat[base + 2 * g + 1]
        feat.append(T.sub(T.mul(feat[1 + 2 * j], uy), T.mul(feat[2 + 2 * j], ux)))
    # the loads (loads._evaluate, inertia_loads) and the right-hand side (kinetostatics._right_side)
    n = lay.size
    bvec = [T.set(0.0) for _ in range(n)]
    values = []
    om, ep = T.input(0), T.input(1)
    om2 = T.mul(om, om)
    for ld in range(len(loads.link)):
        k = int(loads.link[ld])
        rx, ry = turn(k, *loads.at[ld])
        px, py = T.add(fr(k, "rx"), rx), T.add(fr(k, "ry"), ry)
        if loads.inertia[ld]:  # d'Alembert: −m·a at the centre, −I·ε
            wq = fr(k, "wq")
            wr, er = T.mul(wq, om), T.add(T.mul(fr(k, "eq"), om2), T.mul(wq, ep))  # real ω, ε
            ax = T.add(T.mul(fr(k, "fax"), om2), T.mul(fr(k, "fvx"), ep))
            ay = T.add(T.mul(fr(k, "fay"), om2), T.mul(fr(k, "fvy"), ep))
            ax, ay = T.sub(ax, T.mul(er, ry)), T.add(ay, T.mul(er, rx))
            w2 = T.mul(wr, wr)
            ax, ay = T.sub(ax, T.mul(w2, rx)), T.sub(ay, T.mul(w2, ry))
            fx, fy, mz = T.mulk(ax, -loads.mass[ld]), T.mulk(ay, -loads.mass[ld]), T.mulk(er, -loads.moment_of_inertia[ld])
        elif loads.guide[ld] >= 0:  # along the guide of the carrier
            ux, uy = turn(int(loads.carrier[ld]), *loads.u0[ld])
            size = T.input(2 + int(loads.guide[ld]))
            fx, fy, mz = T.mul(size, ux), T.mul(size, uy), T.set(loads.moment[ld])
        else:
            fx, fy, mz = T.set(loads.force[ld, 0]), T.set(loads.force[ld, 1]), T.set(loads.moment[ld])
        for i, v in enumerate((fx, fy, px, py, mz)):
            T.op(OUT, n + 5 * ld + i, v)
        values.append((k, fx, fy, px, py, mz))
        r = lay.rows.get(k)
        if r is not None:
            T.sub(bvec[r], fx, d=bvec[r])
            T.sub(bvec[r + 1], fy, d=bvec[r + 1])
            m = T.sub(T.mul(T.addk(px, -cx), fy), T.mul(T.addk(py, -cy), fx))
            T.sub(bvec[r + 2], T.mulk(T.add(m, mz), inv_size), d=bvec[r + 2])
    # the blocks, last group first (kinetostatics._solve_blocks)
    x = [None] * n
    bad = T.set(0.0)
    for blk in ks_plan.blocks:
        _program_block(T, blk, feat, bvec, x, bad, float(engine.tol.singular))
    out_bad = n + 5 * len(loads.link) + 1
    for i in range(n):
        x[i] = T.mulk(x[i], lay.scale[i])
        T.op(FINITE, bad, x[i])
    for i in range(n):
        T.op(MASK, i, x[i], bad)
    T.op(OUT, out_bad, bad)
    # virtual power with the analogues (kinetostatics._virtual_power)
    speed = T.set(0.0)
    for p in range(len(p_link)):  # the points' velocity analogues (Motion.vq)
        k = int(p_link[p])
        (ux, uy), wq = turn(k, *p_at[p]), fr(k, "wq")
        vx, vy = T.sub(fr(k, "fvx"), T.mul(wq, uy)), T.add(fr(k, "fvy"), T.mul(wq, ux))
        T.op(MAX, speed, speed, T.add(T.mul(vx, vx), T.mul(vy, vy)))
    T.op(SQRT, speed, speed)  # the largest point speed (one root: the root keeps the order)
    turning = T.set(0.0)
    for k in range(len(engine.links)):
        T.op(MAX, turning, turning, T.op(ABS, T.new(), fr(k, "wq")))
    total, bound = T.set(0.0), T.set(0.0)
    for k, fx, fy, px, py, mz in values:
        wq = fr(k, "wq")
        dx, dy = T.sub(px, fr(k, "rx")), T.sub(py, fr(k, "ry"))
        term = T.add(T.add(T.mul(fx, T.sub(fr(k, "fvx"), T.mul(wq, dy))), T.mul(fy, T.add(fr(k, "fvy"), T.mul(wq, dx)))),
                     T.mul(mz, wq))
        T.add(total, term, d=total)
        force = T.op(SQRT, T.new(), T.add(T.mul(fx, fx), T.mul(fy, fy)))
        T.add(bound, T.add(T.mul(force, speed), T.mul(T.op(ABS, T.new(), mz), turning)), d=bound)
    for inp, col in zip(engine.inputs, lay.in_cols):
        term = T.mul(x[col], T.gather(field["rate_q"] + list(mech.joints).index(inp.joint)))
        T.add(total, term, d=total)
        T.add(bound, T.op(ABS, T.new(), term), d=bound)
    T.op(RESID, out_bad - 1, total, bound)
    return names, links, guides, T


def _program_block(T, blk, feat, bvec, x, bad, min_measure):
    """One block of `kinetostatics._solve_block`: its entries, the constant pivots eliminated, the rest
    solved densely, the back-substitution into x (rows of the unknowns), and `bad` marked where its
    measure |det| / Π‖row‖ is not above `min_measure`."""
    rows = [bvec[r] for r in blk.rows]  # the right side, in place
    slot, norm = {}, [None] * len(blk.rows)
    for i, j, f, coef in blk.entries:
        v = slot[i, j] = T.set(coef) if f == 0 else T.mulk(feat[f], coef)
        norm[i] = T.mul(v, v) if norm[i] is None else T.add(norm[i], T.mul(v, v))
    for i, j in _zeros(blk):
        slot[i, j] = T.set(0.0)
    prod = norm[0]
    for v in norm[1:]:
        prod = T.mul(prod, v)
    for i, c, f, coef in blk.later:
        T.sub(rows[i], T.mul(T.set(coef) if f == 0 else T.mulk(feat[f], coef), x[c]), d=rows[i])
    det = T.set(1.0)
    for (i, j), (affected, columns) in zip(blk.pivots, blk.fill):
        for k in affected:
            m = T.div(slot[k, j], slot[i, j])
            for u in columns:
                T.sub(slot[k, u], T.mul(m, slot[i, u]), d=slot[k, u])
            T.sub(rows[k], T.mul(m, rows[i]), d=rows[k])
        T.mul(det, slot[i, j], d=det)
    own = blk.own
    nr = len(blk.rest_rows)
    a = [[slot[i, j] for j in blk.rest_cols] for i in blk.rest_rows]
    r = [rows[i] for i in blk.rest_rows]
    if nr == 1:  # the explicit inverse (_linalg.factor)
        x[own[blk.rest_cols[0]]] = T.mul(T.div(T.set(1.0), a[0][0]), r[0])
        T.mul(det, a[0][0], d=det)
    elif nr == 2:
        d = T.sub(T.mul(a[0][0], a[1][1]), T.mul(a[0][1], a[1][0]))
        i00, i01 = T.div(a[1][1], d), T.div(T.mulk(a[0][1], -1.0), d)
        i10, i11 = T.div(T.mulk(a[1][0], -1.0), d), T.div(a[0][0], d)
        x[own[blk.rest_cols[0]]] = T.add(T.mul(i00, r[0]), T.mul(i01, r[1]))
        x[own[blk.rest_cols[1]]] = T.add(T.mul(i10, r[0]), T.mul(i11, r[1]))
        T.mul(det, d, d=det)
    elif nr:
        sol = [T.set(0.0) for _ in range(nr)]
        start = len(T.aux)
        T.aux += [v for row in a for v in row] + r + sol
        T.op(LU, det, start, nr)
        for q, j in enumerate(blk.rest_cols):
            x[own[j]] = sol[q]
    for (i, j), (_, columns) in reversed(list(zip(blk.pivots, blk.fill))):
        acc = rows[i]
        for u in columns:
            acc = T.sub(acc, T.mul(slot[i, u], x[own[u]]))
        x[own[j]] = T.div(acc, slot[i, j])
    measure = T.div(T.op(ABS, T.new(), det), T.op(SQRT, T.new(), prod))
    T.op(FLAG, bad, measure, k=T.const(min_measure))


def _plan(engine, ks_plan, motion, inertia) -> _KernelPlan:
    """The kernel's plan for the engine, the record layout of `motion` and `inertia`, made once."""
    row_dtype = motion.rows.dtype
    key = (row_dtype, inertia)
    cache = engine.prepare("numba kinetostatics", dict)  # per row layout and inertia
    if key not in cache:
        names, links, guides, tape = _program(engine, ks_plan, row_dtype, inertia)
        ops, consts, aux, rows = tape.finish()
        cache[key] = _KernelPlan(names, links, guides, (ops, consts, aux), rows, [])
    return cache[key]


#: positions the kernel takes at once: each op of the program runs over them in an inner loop
CHUNK = 64


def _scratch(rows: int) -> tuple:
    """Work arrays of `_kernel`: the work matrix (rows, CHUNK) and the pivot rows of a dense solve."""
    return np.zeros((rows, CHUNK)), np.zeros(CHUNK, np.int64)


def solve(engine, motion, ks_plan, inertia=True):
    """x (n, B) (the unknowns, NaN where singular), singular (B,), the virtual-power residual (B,) and
    the loads (`LoadValue`s, numpy's order) over the positions of a compiled `motion`."""
    rows = motion.rows
    plan = _plan(engine, ks_plan, motion, inertia)
    batch, n, n_loads = len(rows), ks_plan.lay.size, len(plan.names)
    inputs = np.empty((2 + len(plan.guide_loads), batch))
    inputs[0], inputs[1] = motion.omega[:, 0], motion.epsilon[:, 0]
    for g, load in enumerate(plan.guide_loads):
        inputs[2 + g] = guide_force_size(engine, motion, load)
    out = np.empty((n + 5 * n_loads + 2, batch))  # x, the loads (fx, fy, x, y, moment), residual, singular
    row = rows.view(np.float64).reshape(batch, -1)
    parts = _threads.chunks(batch, engine.threads)
    work = _threads.work_arrays(plan.scratch, lambda: _scratch(plan.sizes), len(parts))
    _threads.run([lambda p=p, w=w: _kernel(p.start, p.stop, *plan.args, row, inputs, out, *w)
                  for p, w in zip(parts, work)])
    loads = out[n:n + 5 * n_loads].reshape(n_loads, 5, batch)
    values = [LoadValue(name, k, loads[i, 0:2].T, loads[i, 2:4].T, loads[i, 4])
              for i, (name, k) in enumerate(zip(plan.names, plan.links))]
    return out[:n], out[-1] != 0.0, out[-2], values


# -- kernel -------------------------------------------------------------------------------------------
_jit = numba.njit(cache=True, error_model="numpy", nogil=True, _nrt=False)


@_jit
def _lu(W, aux, a, nr, det, nc, piv):
    """The dense system aux[a …] (its matrix row by row, right side, solution: rows of W) of each
    position of the chunk solved as `_linalg.lu_factor` does, with its own row pivots (the first
    largest of the column); the determinant multiplied into W[det]."""
    rhs, sol = a + nr * nr, a + nr * nr + nr
    for k in range(nr):
        kk = aux[a + k * nr + k]
        if k < nr - 1:
            for c in range(nc):
                piv[c] = k
            for i in range(k + 1, nr):
                ik = aux[a + i * nr + k]
                for c in range(nc):
                    if abs(W[ik, c]) > abs(W[aux[a + piv[c] * nr + k], c]):
                        piv[c] = i
            for c in range(nc):
                p = piv[c]
                if p != k:
                    for j in range(k, nr):
                        s, t = aux[a + k * nr + j], aux[a + p * nr + j]
                        W[s, c], W[t, c] = W[t, c], W[s, c]
                    s, t = aux[rhs + k], aux[rhs + p]
                    W[s, c], W[t, c] = W[t, c], W[s, c]
                    W[det, c] = -W[det, c]
            rk = aux[rhs + k]
            for i in range(k + 1, nr):
                ik, ri = aux[a + i * nr + k], aux[rhs + i]
                for c in range(nc):
                    W[ik, c] = W[ik, c] / W[kk, c]
                    W[ri, c] -= W[ik, c] * W[rk, c]
                for j in range(k + 1, nr):
                    ij, kj = aux[a + i * nr + j], aux[a + k * nr + j]
                    for c in range(nc):
                        W[ij, c] -= W[ik, c] * W[kj, c]
        for c in range(nc):
            W[det, c] *= W[kk, c]
    for i in range(nr - 1, -1, -1):
        ri, xi, ii = aux[rhs + i], aux[sol + i], aux[a + i * nr + i]
        for c in range(nc):
            W[xi, c] = W[ri, c]
        for j in range(i + 1, nr):
            ij, xj = aux[a + i * nr + j], aux[sol + j]
            for c in range(nc):
                W[xi, c] -= W[ij, c] * W[xj, c]
        for c in range(nc):
            W[xi, c] /= W[ii, c]


@_jit
def _kernel(start, stop, ops, K, aux, row, inputs, out, W, piv):
    """Positions start … stop − 1, a chunk at a time: every op of the program (`_program`; codes above)
    over the chunk, from the records `row` (B, fields) and `inputs` into `out`."""
    chunk = W.shape[1]
    for b0 in range(start, stop, chunk):
        nc = min(chunk, stop - b0)
        for t in range(len(ops)):
            code, d, a, b, k = ops[t, 0], ops[t, 1], ops[t, 2], ops[t, 3], ops[t, 4]
            if code == 0:  # GATHER
                for c in range(nc):
                    W[d, c] = row[b0 + c, a]
            elif code == 1:  # INPUT
                for c in range(nc):
                    W[d, c] = inputs[a, b0 + c]
            elif code == 2:  # SET
                for c in range(nc):
                    W[d, c] = K[k]
            elif code == 3:  # MULK
                for c in range(nc):
                    W[d, c] = K[k] * W[a, c]
            elif code == 4:  # ADDK
                for c in range(nc):
                    W[d, c] = W[a, c] + K[k]
            elif code == 5:  # ADD
                for c in range(nc):
                    W[d, c] = W[a, c] + W[b, c]
            elif code == 6:  # SUB
                for c in range(nc):
                    W[d, c] = W[a, c] - W[b, c]
            elif code == 7:  # MUL
                for c in range(nc):
                    W[d, c] = W[a, c] * W[b, c]
            elif code == 8:  # DIV
                for c in range(nc):
                    W[d, c] = W[a, c] / W[b, c]
            elif code == 9:  # MAX
                for c in range(nc):
                    W[d, c] = max(W[a, c], W[b, c])
            elif code == 10:  # SQRT
                for c in range(nc):
                    W[d, c] = np.sqrt(W[a, c])
            elif code == 11:  # ABS
                for c in range(nc):
                    W[d, c] = abs(W[a, c])
            elif code == 12:  # OUT
                for c in range(nc):
                    out[d, b0 + c] = W[a, c]
            elif code == 13:  # FLAG
                for c in range(nc):
                    if not W[a, c] > K[k]:
                        W[d, c] = 1.0
            elif code == 14:  # FINITE
                for c in range(nc):
                    if not np.isfinite(W[a, c]):
                        W[d, c] = 1.0
            elif code == 15:  # MASK
                for c in range(nc):
                    if W[b, c] != 0.0:
                        W[a, c] = np.nan
                    out[d, b0 + c] = W[a, c]
            elif code == 16:  # RESID
                for c in range(nc):
                    out[d, b0 + c] = abs(W[a, c]) / (W[b, c] if W[b, c] > 0 else 1.0)
            else:  # LU
                _lu(W, aux, a, b, d, nc, piv)
