"""The kinetostatics of a compiled one-input `Motion` written as a program of elementary ops, for a
backend's kernel to run over the positions (`backends._numba_kinetostatics`): the loads, the d'Alembert
loads, the assembled system and the virtual-power check, reading the records the compiled kinematics
wrote (`Motion.records`).

It is the same computation as `kinetostatics`, not a second formulation: the layout, the features, the
blocks (one per Assur group, last attached first), their constant pivots and fill-in (`_Block.fill`)
come from `kinetostatics._plan`; the loads' constant parts, guide-force sizes (the diagrams'
interpolated by `loads.guide_force_size`) and heavy links from `loads`. Once per engine (and record
layout), `program_for` writes numpy's formulas, in numpy's order, as a list of elementary ops on the
rows of a work matrix, one row per value and one column per position of a chunk of positions (the
kernel's `chunk_of`); the kernel runs the ops one after the other, each over the whole chunk in an
inner loop (SIMD lanes), so the tables are read once per chunk, not once per position. The time goes
with the rows the ops read and write, so `_Tape` reads constants from the op (not from a row of them),
moves negations into the ops that read them, and drops what nothing reads, all without changing a
rounding. The kernel is one small function of 27 kinds of op whatever the model.

Two things differ from numpy by rounding only: the moments are divided by the model size as a product
with its reciprocal, and the dense part of a class III or higher group (LU with partial pivoting, each
position its own pivot rows) substitutes forward while it eliminates. It takes the model's loads with or
without the inertia loads, and no input inertia; anything else stays with numpy.

The backend gets the `Program` and the records, nothing of the engine (`KinetostaticsJob`).
"""

from __future__ import annotations

import math
from collections import defaultdict
from dataclasses import dataclass
from dataclasses import field as _field
from typing import NamedTuple

import numpy as np

from ..kinematics import point_table
from ._kinetostatics import pivot_orders
from ._loads import constant_parts, heavy_links

__all__ = ["Program", "program_for", "pair_inputs", "PAIR_INPUTS", "LoadTables", "load_tables", "LOAD_FIXED", "LOAD_GUIDE", "LOAD_INERTIA"]

# the record fields (`engine._tables.record_layout`) the program reads
_READS = ("cos", "sin", "r", "fv", "fa", "wq", "eq", "rate_q")

LOAD_FIXED, LOAD_GUIDE, LOAD_INERTIA = "fixed", "guide", "inertia"   # the three kinds of load


class LoadTables(NamedTuple):
    """The N loads the program adds at every position, in numpy's order."""

    link: np.ndarray               # (N,) int: the link loaded
    guide: np.ndarray              # (N,) int: a force along a guide: its row of guide-force sizes; else −1
    inertia: np.ndarray            # (N,) bool: a d'Alembert load (−m·a at the centre, −I·ε)
    carrier: np.ndarray            # (N,) int: the guide's carrier (guide loads; else 0)
    at: np.ndarray                 # (N, 2) float: the point of application, drawn
    force: np.ndarray              # (N, 2) float: a fixed force (else 0)
    moment: np.ndarray             # (N,) float: a fixed moment
    u0: np.ndarray                 # (N, 2) float: the guide's direction, drawn (guide loads; else 0)
    mass: np.ndarray               # (N,) float: inertia loads: the link's mass (else 0)
    moment_of_inertia: np.ndarray  # (N,) float: inertia loads: the link's I_S (else 0)


def load_tables(rows: list) -> LoadTables:
    """`LoadTables` from rows (kind, link, guide row, carrier, at, force or (mass, I_S), moment, u0), kind
    `LOAD_FIXED`, `LOAD_GUIDE` or `LOAD_INERTIA`."""
    n = len(rows)
    out = LoadTables(np.zeros(n, np.int64), np.full(n, -1, np.int64), np.zeros(n, np.bool_), np.zeros(n, np.int64),
                     np.zeros((n, 2)), np.zeros((n, 2)), np.zeros(n), np.zeros((n, 2)), np.zeros(n), np.zeros(n))
    for i, (kind, link, guide, carrier, at, force, moment, u0) in enumerate(rows):
        out.link[i], out.carrier[i], out.at[i], out.moment[i] = link, carrier, at, moment
        if kind == LOAD_INERTIA:
            out.inertia[i], out.mass[i], out.moment_of_inertia[i] = True, force[0], force[1]
        elif kind == LOAD_GUIDE:
            out.guide[i], out.u0[i] = guide, u0
        else:
            out.force[i] = force
    return out


@dataclass(frozen=True, eq=False)
class Program:
    """The kinetostatics of an engine, a record layout and `inertia` as a program (`program_for`).

    Attributes
    ----------
    names, links : list
        The loads' names and links, in the order numpy lists them.
    guide_loads : list
        The loads whose size `guide_force_size` gives: the kernel's inputs 2, 3, ... (after ω, ε).
    sources : list of (int, int, int)
        Per load, the first output rows of its force (fx, fy), point (x, y) and moment.
    outputs_rows : int
        Rows of the outputs (O): the unknowns (`size` of them) first, then the loads' values, the
        virtual-power residual and the singular flag last.
    ops : ndarray (T, 7) int
        The ops (code, d, a, b, e, f, k), codes below.
    consts : ndarray (C,)
        The constants the ops read (K).
    aux : ndarray (X,) int
        The row lists of GATHER and PIVOT.
    rows : int
        Rows of the work matrix.
    size : int
        Unknowns of the system.
    store : dict
        Where a backend keeps what it makes for the program (work arrays, output blocks, its compiled
        entry); left behind when pickled.
    """

    names: list
    links: list
    guide_loads: list
    sources: list
    outputs_rows: int
    ops: np.ndarray
    consts: np.ndarray
    aux: np.ndarray
    rows: int
    size: int
    store: dict = _field(default_factory=dict)

    def __getstate__(self) -> dict:
        return dict(self.__dict__, store={})


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


class _Tape:
    """The kernel's program under construction: ops (code, d, a, b, e, f, k) on rows of a work matrix
    (one row per value, one column per position of a chunk), constants, and the dense groups' row lists.
    A value is computed once (`val` remembers it until a row it reads is written again); rows are
    virtual until `finish` maps them onto as few rows as their lifetimes allow."""

    def __init__(self):
        self.ops, self.consts, self.aux, self.rows = [], [], [], 0
        self._const, self._memo, self._uses, self._shared, self._known = {}, {}, {}, set(), {}
        self._neg = {}  # row → the row it is the negative of (x·(−1) is −x exactly)

    def const(self, value) -> int:
        value = float(value)
        key = (value, bool(np.signbit(value)))
        if key not in self._const:
            self._const[key] = len(self.consts)
            self.consts.append(value)
        return self._const[key]

    def consts2(self, u, v) -> int:
        """Two constants next to each other (read as K[k], K[k + 1])."""
        key = (float(u), float(v), bool(np.signbit(u)), bool(np.signbit(v)))
        if key not in self._const:
            self._const[key] = len(self.consts)
            self.consts += [float(u), float(v)]
        return self._const[key]

    def fresh(self, code, a=0, b=0, e=0, f=0, k=0) -> int:
        """A new row computed by op `code` (one that later ops may write again)."""
        self.rows += 1
        self.ops.append((code, self.rows - 1, a, b, e, f, k))
        return self.rows - 1

    def val(self, code, a=0, b=0, e=0, f=0, k=0) -> int:
        """The row of a value, computed by op `code` unless it already was (or, when what it reads is
        constant, here, with the same floating-point operations)."""
        folded = self._fold(code, a, b, e, f, k)
        if folded is not None:
            return self.value(folded)
        key = (code, a, b, e, f, k)
        if key not in self._memo:
            op = self._with_constants(code, a, b, e, f, k)
            if len(op) == 1:  # x·1, x/1: x itself
                return op[0]
            self._memo[key] = d = self.fresh(*op)
            self._shared.add(d)
            if op[0] == MULK and self.consts[op[5]] == -1.0:
                self._neg[d] = op[1]
            for r in (a, b, e, f) if code != GATHER and code != INPUT else ():
                self._uses.setdefault(r, []).append(key)
        return self._memo[key]

    def _fold(self, code, a, b, e, f, k):
        """The value of op `code` if the rows it reads hold constants (None if not, or if Python's
        arithmetic would raise where the kernel's gives an infinity or a NaN)."""
        if code not in _FOLD:
            return None
        known = self._known
        try:
            v = [known[r] for r in (a, b, e, f)[:len(_W_FIELDS[code]) - 1]]
        except KeyError:
            return None
        if any(math.isnan(u) for u in v) or (code == DIV and v[1] == 0.0) or (code == SQRT and v[0] < 0.0):
            return None
        if code == LEVER:
            return ((v[0] + v[1]) + self.consts[k]) * self.consts[k + 1]
        return _FOLD[code](*v)

    def _with_constants(self, code, a, b, e, f, k) -> tuple:
        """Op `code` with the constants it reads taken from K, not from rows of W (one row fewer to
        read, and no row to fill): (code, a, b, e, f, k), or (row,) where the op gives row `row`
        itself (x·1 = x and x/1 = x exactly). The same floating-point operations, in the same order."""
        code, a, b, e, f = self._without_negations(code, a, b, e, f)
        known = self._known
        if code == MUL and (a in known or b in known):
            x, c = (b, known[a]) if a in known else (a, known[b])
            return (x,) if c == 1.0 and x in self._shared else (MULK, x, 0, 0, 0, self.const(c))
        if code == DIV and known.get(b) == 1.0 and a in self._shared:
            return (a,)
        if code in (MADD, MSUB) and b in known and e in known and a not in known:  # a ± p, p = b·e
            p = known[b] * known[e]
            return ADDK, a, 0, 0, 0, self.const(p if code == MADD else -p)  # (a − p is a + (−p) exactly)
        if code in (MADD, MSUB) and (b in known or e in known):
            y, c = (e, known[b]) if b in known else (b, known[e])  # a ± c·y
            if c == 1.0:
                if a in known and code == MSUB:
                    return KSUB, y, 0, 0, 0, self.const(known[a])
                if a in known:  # (c + y, as y + c)
                    return ADDK, y, 0, 0, 0, self.const(known[a])
                if y in known and code == MADD:
                    return ADDK, a, 0, 0, 0, self.const(known[y])
                return (ADD if code == MADD else SUB), a, y
            if a not in known and y not in known:
                return (MADDK if code == MADD else MSUBK), a, y, 0, 0, self.const(c)
        if code == DOT and (a in known or b in known) and (e in known or f in known):
            x, c = (b, known[a]) if a in known else (a, known[b])
            y, g = (f, known[e]) if e in known else (e, known[f])
            if x not in known and y not in known:
                return DOTK, x, y, 0, 0, self.consts2(c, g)
        return code, a, b, e, f, k

    def _without_negations(self, code, a, b, e, f) -> tuple:
        """Op `code` reading x where it read −x (`_neg`), the sign moved into the op: a ± (−x)·y is
        a ∓ x·y, p + (−x)·y is p − x·y, (−x)·(−y) is x·y; the same numbers, one op fewer to read
        (the negation is dropped when nothing else reads it)."""
        neg = self._neg
        if code in (MADD, MSUB, MUL, DOT) and (b in neg or e in neg or a in neg or f in neg):
            def product(x, y):  # (x, y, negated) of x·y
                flip = (x in neg) != (y in neg)
                return neg.get(x, x), neg.get(y, y), flip
            if code == MUL:
                x, y, flip = product(a, b)
                if not flip:
                    return MUL, x, y, e, f
            elif code in (MADD, MSUB):
                x, y, flip = product(b, e)
                if flip or x != b or y != e:
                    return (MSUB if (code == MADD) == flip else MADD), a, x, y, f
            else:
                x, y, flip = product(a, b)
                u, v, flip2 = product(e, f)
                if flip2 and not flip:
                    return CROSS, x, y, u, v
                if flip and not flip2:
                    return CROSS, u, v, x, y
                if not flip and not flip2:
                    return DOT, x, y, u, v
        return code, a, b, e, f

    def into(self, code, d, a=0, b=0, e=0, f=0, k=0) -> int:
        """Op `code` writing row d again: the values read from d are forgotten."""
        self.ops.append((code, d, a, b, e, f, k))
        self.written(d)
        return d

    def written(self, d):
        self._neg = {r: x for r, x in self._neg.items() if d not in (r, x)}
        for key in self._uses.pop(d, []):
            self._memo.pop(key, None)
        for key in [key for key, row in self._memo.items() if row == d]:
            del self._memo[key]

    def out(self, code, to, a=0, b=0, k=0):
        self.ops.append((code, to, a, b, 0, 0, k))

    def private(self, row) -> int:
        """`row`, or a copy of it where other values may be the same row (an op writing it again
        would change them too)."""
        if row in self._shared:
            return self.fresh(MUL, row, self.value(1.0))
        self._shared.add(row)  # (a second request copies)
        return row

    def set(self, value) -> int:
        return self.fresh(SET, k=self.const(value))

    def value(self, value) -> int:
        key = (SET, 0, 0, 0, 0, self.const(value))
        if key not in self._memo:
            self._memo[key] = d = self.fresh(*key[:1], k=key[5])
            self._shared.add(d)
            self._known[d] = float(value)
        return self._memo[key]

    def add(self, a, b):
        return self.val(MADD, a, b, self.value(1.0))

    def sub(self, a, b):
        return self.val(MSUB, a, b, self.value(1.0))

    def mul(self, a, b):
        return self.val(MUL, a, b)

    def div(self, a, b):
        return self.val(DIV, a, b)

    def mulk(self, a, value):
        return self.val(MUL, a, self.value(value))

    def finish(self) -> tuple:
        """(ops (T, 7) int, constants, aux, rows): the virtual rows mapped onto physical ones, a row
        taken again once the last op touching it has run."""
        needed = _needed(self.ops, self.aux)
        gathered = sorted((op[2], op[1]) for op in needed if op[0] == GATHER)  # (column, row)
        gathered += gathered[-1:] * (len(gathered) % 2)  # (the kernel reads them two at a time)
        ops = [(GATHER, 0, len(self.aux), len(gathered), 0, 0, 0)] + [op for op in needed if op[0] != GATHER]
        ops = np.array(ops, np.int64).reshape(-1, 7)
        aux = np.array(self.aux + [v for pair in gathered for v in pair], np.int64)
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
        mapped = aux.copy()
        for op in ops:
            for field in _W_FIELDS[op[0]]:
                op[field] = phys[op[field]]
            for i in _aux_rows(op):
                mapped[i] = phys[aux[i]]
        return ops, np.array(self.consts + [0.0]), np.concatenate([mapped, np.zeros(1, np.int64)]), max(top, 1)


def _needed(ops, aux) -> list:
    """The ops whose value something reads (an output, or an op that is needed): a constant's row
    that `_Tape._with_constants` took into K, for one, is not filled."""
    live, kept = set(), []
    for op in reversed(ops):
        code, d = op[0], op[1]
        reads = [op[f] for f in _W_FIELDS[code] if f != 1] + [aux[i] for i in _aux_rows(op)]
        if code in (FLAG, PIVOT):  # (they change row d)
            reads.append(d)
        elif code != OUT and code != OUTK:  # an op that only writes row d
            if d not in live:
                continue
            live.discard(d)
        live.update(reads)
        kept.append(op)
    return kept[::-1]


def _touches(op, aux) -> list:
    """The virtual rows an op reads or writes."""
    return [op[f] for f in _W_FIELDS[op[0]]] + [aux[i] for i in _aux_rows(op)]


def _aux_rows(op) -> range:
    """Where `aux` names the rows of W an op reads or writes."""
    if op[0] == PIVOT:
        return range(op[2], op[2] + op[3] * (op[3] + 1))
    if op[0] == GATHER:
        return range(op[2] + 1, op[2] + 2 * op[3], 2)
    return range(0)


# op codes of `_kernel` (code, d, a, b, e, f, k): W is the work matrix (rows, chunk), c a position of the
# chunk, b = b0 + c its position in the batch, K the constants. Sums and differences are MADD and MSUB
# with a row of ones, products by a constant MUL with a row of it, x·y − u·v is x·y + u·(−v): the same
# numbers (x·1 = x, x − y = x + (−y) exactly).
GATHER = 0   # W[d] = row[b, a]            (a: a column of the records; `finish` makes all of them one op,
#              W[aux[a + 2i + 1]] = row[b, aux[a + 2i]] for i < b, two fields a pass over the chunk's
#              records: field by field, not record by record, the writes run along W's rows)
INPUT = 1    # W[d] = inputs[a, b]         (ω, ε, then the guide-force sizes)
SET = 2      # W[d] = K[k]
MUL = 3      # W[d] = W[a] · W[b]
DIV = 4      # W[d] = W[a] / W[b]
MAX = 5      # W[d] = max(W[a], W[b])
SQRT = 6     # W[d] = √W[a]
ABS = 7      # W[d] = |W[a]|
MSUB = 8     # W[d] = W[a] − W[b] · W[e]
MADD = 9     # W[d] = W[a] + W[b] · W[e]
DOT = 10     # W[d] = W[a] · W[b] + W[e] · W[f]
LEVER = 11   # W[d] = ((W[a] + W[b]) + K[k]) · K[k + 1]
OUT = 12     # out[d, b] = W[a]
FLAG = 13    # W[d] = 1 where not K[k] < W[a] <= K[k + 1] (a NaN too)
PIVOT = 14   # the rows aux[a …] of a dense system (b of them, each its entries from the pivot column on and
#              its right side): the first largest |entry| of the column brought first, W[d] negated if moved
# the same with constants from K (`_Tape._with_constants`)
ADD = 15     # W[d] = W[a] + W[b]
SUB = 16     # W[d] = W[a] − W[b]
ADDK = 17    # W[d] = W[a] + K[k]
KSUB = 18    # W[d] = K[k] − W[a]
MULK = 19    # W[d] = W[a] · K[k]
MADDK = 20   # W[d] = W[a] + K[k] · W[b]
MSUBK = 21   # W[d] = W[a] − K[k] · W[b]
DOTK = 22    # W[d] = W[a] · K[k] + W[b] · K[k + 1]
CROSS = 23   # W[d] = W[a] · W[b] − W[e] · W[f]   (DOT of a negated factor, `_Tape._without_negations`)
GUIDE = 24   # W[d] = K[k] · (the unit against the motion: `_WHEN`[K[k + 1]]) of the joint rate W[a] turned
#              round where ω = W[b] < 0 (`guide_force_size` of a load without a table)
RESIDUAL = 25  # W[d] = |W[a]| / W[b], by 1 where W[b] <= 0 (the virtual-power residual, its bound)
OUTK = 26    # out[d, b] = K[k]               (a constant output: a store, no row of W read)
_WHEN = ("forward", "backward", "always")
_ONE, _TWO, _THREE, _FOUR = (1, 2), (1, 2, 3), (1, 2, 3, 4), (1, 2, 3, 4, 5)
# the ops `_Tape` computes itself on constants, as the kernel would
_FOLD = {MUL: lambda a, b: a * b, DIV: lambda a, b: a / b, MAX: lambda a, b: max(a, b), SQRT: math.sqrt, ABS: abs,
         MSUB: lambda a, b, e: a - b * e, MADD: lambda a, b, e: a + b * e, DOT: lambda a, b, e, f: a * b + e * f,
         LEVER: None}
# the fields of each op that name rows of W
_W_FIELDS = {GATHER: (), INPUT: (1,), SET: (1,), MUL: _TWO, DIV: _TWO, MAX: _TWO, SQRT: _ONE, ABS: _ONE,
             MSUB: _THREE, MADD: _THREE, DOT: _FOUR, LEVER: _TWO, OUT: (2,), FLAG: _ONE, PIVOT: (1,),
             ADD: _TWO, SUB: _TWO, ADDK: _ONE, KSUB: _ONE, MULK: _ONE, MADDK: _TWO, MSUBK: _TWO, DOTK: _TWO,
             CROSS: _FOUR, GUIDE: _TWO, RESIDUAL: _TWO, OUTK: ()}


def _program(engine, ks_plan, row_dtype, inertia, orders=None) -> tuple:
    """The program for an engine, its record layout and `inertia`: (names, links and guide
    loads of the loads, the `_Tape`), numpy's formulas in numpy's order, op by op."""
    mech, lay, T = engine.mech, ks_plan.lay, _Tape()
    names, links, guides, loads = _load_table(engine, inertia)
    field = {name: row_dtype.fields[name][1] // 8 for name in _READS}
    per_link = {"cos": ("cos", 1, 0), "sin": ("sin", 1, 0), "rx": ("r", 2, 0), "ry": ("r", 2, 1),
                "fvx": ("fv", 2, 0), "fvy": ("fv", 2, 1), "fax": ("fa", 2, 0), "fay": ("fa", 2, 1),
                "wq": ("wq", 1, 0), "eq": ("eq", 1, 0)}

    ground = engine.link_index[mech.ground]

    def fr(k, name):  # a field of link k's frame (the ground's: the world's, at rest, as the kinematics writes it)
        if k == ground:
            return T.value(1.0 if name == "cos" else 0.0)
        base, width, part = per_link[name]
        return T.val(GATHER, field[base] + width * k + part)

    def turn(k, at):  # the drawn vector `at` turned with link k: (c·x − s·y, s·x + c·y)
        co, si = fr(k, "cos"), fr(k, "sin")
        ax, ay = T.value(at[0]), T.value(at[1])
        return T.val(DOT, co, ax, si, T.value(-at[1])), T.val(DOT, si, ax, co, ay)

    def point(k, at):  # the point drawn at `at` on link k
        ux, uy = turn(k, at)
        return T.add(fr(k, "rx"), ux), T.add(fr(k, "ry"), uy)

    cx, cy = ks_plan.centre
    inv_size = 1.0 / engine.size
    # the entries' features (kinetostatics._features)
    p_names, p_link, p_at = point_table(engine)
    point_of = {name: k for k, name in enumerate(p_names)}
    feat = [T.value(1.0)]
    for name in ks_plan.joints:
        p = point_of[name]
        k = int(p_link[p])
        ux, uy = turn(k, p_at[p])
        feat += [T.val(LEVER, fr(k, "rx"), ux, k=T.consts2(-cx, inv_size)),
                 T.val(LEVER, fr(k, "ry"), uy, k=T.consts2(-cy, inv_size))]
    for name in ks_plan.guides:
        feat += turn(engine.link_index[mech.joints[name].carrier], engine.laws[name].u0)
    base = 1 + 2 * len(ks_plan.joints)
    for g, j in ks_plan.p_inputs:
        ux, uy = feat[base + 2 * g], feat[base + 2 * g + 1]
        feat.append(T.val(DOT, feat[1 + 2 * j], uy, feat[2 + 2 * j], T.mulk(ux, -1.0)))
    tabled = [load for load in guides if load.table]  # (their sizes `solve` interpolates: inputs 2, 3, ...)
    pairs = [[T.val(INPUT, 2 + len(tabled) + PAIR_INPUTS * h + i) for i in range(PAIR_INPUTS)]
             for h in range(len(ks_plan.higher))]  # (the higher pairs' geometry: `pair_inputs`)
    for d_x, d_y, lever, *_ in pairs:
        feat += [d_x, d_y, lever]
    # the loads (loads._evaluate, inertia_loads) and the right-hand side (kinetostatics._right_side)
    n = lay.size
    bvec = [T.value(0.0)] * n
    values = []
    om, ep = T.val(INPUT, 0), T.val(INPUT, 1)
    joint_index = {name: i for i, name in enumerate(mech.joints)}

    def guide_size(load):  # loads.guide_force_size: against the joint's rate, signed by ω's direction
        if load.table:
            return T.val(INPUT, 2 + tabled.index(load))
        size = load.magnitude if load.link != mech.joints[load.joint].carrier else -load.magnitude
        rate = T.val(GATHER, field["rate_q"] + joint_index[load.joint])
        return T.val(GUIDE, rate, om, k=T.consts2(size, _WHEN.index(load.when)))

    om2 = T.mul(om, om)
    outputs, sources = _LoadOutputs(T, n), []
    for ld in range(len(loads.link)):
        k = int(loads.link[ld])
        rx, ry = turn(k, loads.at[ld])
        px, py = point(k, loads.at[ld])
        if loads.inertia[ld]:  # d'Alembert: −m·a at the centre, −I·ε
            wq = fr(k, "wq")
            wr, er = T.mul(wq, om), T.val(DOT, fr(k, "eq"), om2, wq, ep)  # real ω, ε (Motion.w, Motion.e)
            ax = T.val(DOT, fr(k, "fax"), om2, fr(k, "fvx"), ep)
            ay = T.val(DOT, fr(k, "fay"), om2, fr(k, "fvy"), ep)
            ax, ay = T.val(MSUB, ax, er, ry), T.val(MADD, ay, er, rx)
            w2 = T.mul(wr, wr)
            ax, ay = T.val(MSUB, ax, w2, rx), T.val(MSUB, ay, w2, ry)
            fx, fy = T.mulk(ax, -loads.mass[ld]), T.mulk(ay, -loads.mass[ld])
            mz = T.mulk(er, -loads.moment_of_inertia[ld])
        elif loads.guide[ld] >= 0:  # along the guide of the carrier
            ux, uy = turn(int(loads.carrier[ld]), loads.u0[ld])
            size = guide_size(guides[int(loads.guide[ld])])
            fx, fy, mz = T.mul(size, ux), T.mul(size, uy), T.value(loads.moment[ld])
        else:
            fx, fy, mz = T.value(loads.force[ld, 0]), T.value(loads.force[ld, 1]), T.value(loads.moment[ld])
        sources.append((outputs.of((fx, fy)), outputs.of((px, py)), outputs.of((mz,))))
        values.append((k, fx, fy, px, py, mz))
        r = lay.rows.get(k)
        if r is not None:
            bvec[r] = T.val(MSUB, bvec[r], fx, T.value(1.0))
            bvec[r + 1] = T.val(MSUB, bvec[r + 1], fy, T.value(1.0))
            lx, ly = T.add(px, T.value(-cx)), T.add(py, T.value(-cy))
            m = T.add(T.val(DOT, lx, fy, ly, T.mulk(fx, -1.0)), mz)
            bvec[r + 2] = T.val(MSUB, bvec[r + 2], T.mulk(m, inv_size), T.value(1.0))
    # the blocks, last group first (kinetostatics.solve_blocks)
    x = [None] * n
    bad = T.set(0.0)
    for index, blk in enumerate(ks_plan.blocks):
        _program_block(T, blk, feat, bvec, x, bad, float(engine.tol.singular), (orders or {}).get(index))
    radial = _radial_right_side(T, engine, ks_plan, x, pairs)
    if radial:  # (the tangential forces stay as they are: the radial pairs pass through the centres)
        bvec = [T.add(v, radial[r]) if r in radial else v for r, v in enumerate(bvec)]
        x = [None] * n
        for index, blk in enumerate(ks_plan.blocks):
            _program_block(T, blk, feat, bvec, x, bad, float(engine.tol.singular), (orders or {}).get(index))
    out_bad = outputs.top + 1  # the row of `bad`, the residual's before it
    for i in range(n):
        if lay.scale[i] != 1.0:  # (x·1 = x)
            x[i] = T.mulk(x[i], lay.scale[i])
    T.into(FLAG, bad, _nonfinite(T, x), k=T.consts2(-np.inf, np.finfo(float).max))  # not finite
    for i in range(n):
        T.out(OUT, i, x[i])  # (`solve` writes NaN where singular)
    T.out(OUT, out_bad, bad)
    # virtual power with the analogues (kinetostatics._virtual_power)
    speed = T.value(0.0)
    for p in range(len(p_link)):  # the points' velocity analogues (Motion.vq)
        k = int(p_link[p])
        (ux, uy), wq = turn(k, p_at[p]), fr(k, "wq")
        vx, vy = T.val(MSUB, fr(k, "fvx"), wq, uy), T.val(MADD, fr(k, "fvy"), wq, ux)
        speed = T.val(MAX, speed, T.val(DOT, vx, vx, vy, vy))
    for h, pair in zip(mech.higher.values(), pairs):  # and the contacts' on both their links
        px, py = pair[3], pair[4]
        for link in h.links:
            k = engine.link_index[link]
            wq = fr(k, "wq")
            dx, dy = T.sub(px, fr(k, "rx")), T.sub(py, fr(k, "ry"))
            vx, vy = T.val(MSUB, fr(k, "fvx"), wq, dy), T.val(MADD, fr(k, "fvy"), wq, dx)
            speed = T.val(MAX, speed, T.val(DOT, vx, vx, vy, vy))
    speed = T.val(SQRT, speed)  # the largest point speed (one root: the root keeps the order)
    turning = T.value(0.0)
    for k in range(len(engine.links)):
        turning = T.val(MAX, turning, T.val(ABS, fr(k, "wq")))
    total = bound = T.value(0.0)
    for k, fx, fy, px, py, mz in values:
        wq = fr(k, "wq")
        dx, dy = T.sub(px, fr(k, "rx")), T.sub(py, fr(k, "ry"))
        vx, vy = T.val(MSUB, fr(k, "fvx"), wq, dy), T.val(MADD, fr(k, "fvy"), wq, dx)
        total = T.val(MADD, total, T.val(MADD, T.val(DOT, fx, vx, fy, vy), mz, wq), T.value(1.0))
        force = T.val(SQRT, T.val(DOT, fx, fx, fy, fy))
        bound = T.val(MADD, bound, T.val(DOT, force, speed, T.val(ABS, mz), turning), T.value(1.0))
    for inp, col in zip(engine.inputs, lay.in_cols):
        term = T.mul(x[col], T.val(GATHER, field["rate_q"] + list(mech.joints).index(inp.joint)))
        total = T.val(MADD, total, term, T.value(1.0))
        bound = T.val(MADD, bound, T.val(ABS, term), T.value(1.0))
    T.out(OUT, out_bad - 1, T.val(RESIDUAL, total, bound))  # (relative to what the loads could do)
    return names, links, tabled, sources, T


def _radial_right_side(T, engine, ks_plan, x, pairs) -> dict:
    """The right-hand side (row → value) of the gears' and racks' radial forces from the tangential
    unknowns x (`kinetostatics._radial_loads` and `_right_side`: tan α·|F_t| along the normal at the
    pitch point, on the second link, its opposite on the first); empty without gears or racks."""
    mech, lay = engine.mech, ks_plan.lay
    cx, cy = ks_plan.centre
    inv_size = 1.0 / engine.size
    zero, one = T.value(0.0), T.value(1.0)
    out = {}
    for h, pair in zip(mech.higher.values(), pairs):
        if h.kind not in ("gear", "rack"):
            continue
        px, py, nx, ny = pair[3:]
        size = T.mulk(T.val(ABS, x[lay.cols[h.name]]), math.tan(h.pressure_angle))
        fx, fy = T.mul(size, nx), T.mul(size, ny)
        for link, sign in ((h.links[1], 1.0), (h.links[0], -1.0)):
            r = lay.rows.get(engine.link_index[link])
            if r is None:
                continue
            gx, gy = (fx, fy) if sign > 0 else (T.mulk(fx, -1.0), T.mulk(fy, -1.0))
            out[r] = T.val(MSUB, out.get(r, zero), gx, one)
            out[r + 1] = T.val(MSUB, out.get(r + 1, zero), gy, one)
            lx, ly = T.add(px, T.value(-cx)), T.add(py, T.value(-cy))
            m = T.add(T.val(DOT, lx, gy, ly, T.mulk(gx, -1.0)), zero)
            out[r + 2] = T.val(MSUB, out.get(r + 2, zero), T.mulk(m, inv_size), one)
    return out


#: the inputs per higher pair after ω, ε and the guide loads (`pair_inputs`): the direction (x, y) of
#: the force its unknown stands for, its lever about the system's centre / size (the entries' features),
#: the contact point (x, y) and the normal (x, y) (a gear's or a rack's radial force)
PAIR_INPUTS = 7


def pair_inputs(engine, ks_plan, directions: dict, geometry: dict, batch: int) -> np.ndarray:
    """The higher pairs' inputs (`PAIR_INPUTS` × H, B) from their force directions
    (`kinetostatics.pair_directions`) and contact geometry (`kinematics.contact_geometry`), with numpy's
    formulas (`kinetostatics._features`)."""
    out = np.empty((PAIR_INPUTS * len(ks_plan.higher), batch))
    cx, cy = ks_plan.centre
    size = engine.size
    for h, name in enumerate(ks_plan.higher):
        point, d = directions[name]
        rows = out[PAIR_INPUTS * h:PAIR_INPUTS * (h + 1)]
        rows[0], rows[1] = d[:, 0], d[:, 1]
        rows[2] = ((point[:, 0] - cx) * d[:, 1] - (point[:, 1] - cy) * d[:, 0]) / size
        rows[3], rows[4] = geometry[name].point[:, 0], geometry[name].point[:, 1]
        rows[5], rows[6] = geometry[name].normal[:, 0], geometry[name].normal[:, 1]
    return out


class _LoadOutputs:
    """The rows of the kernel's outputs that hold the loads' values, from row `top` on. A pair (x, y)
    or a moment is written once: a link's centre, the point of its gravity and of its d'Alembert load,
    is one pair of rows, every zero moment one row (their arrays are views of the same rows). A value
    the program knows as a constant (gravity's force, a zero moment) is stored by `OUTK`, without a
    row of the work matrix to read."""

    def __init__(self, T, top):
        self.T, self.top, self.start = T, top, {}

    def of(self, values) -> int:
        """The first of the output rows of `values` (a pair or one), next to each other."""
        known = self.T._known
        key = tuple(("k", float(known[v]), bool(np.signbit(known[v]))) if v in known else v for v in values)
        if key not in self.start:
            self.start[key] = self.top
            for v in values:
                if v in known:
                    self.T.out(OUTK, self.top, k=self.T.const(known[v]))
                else:
                    self.T.out(OUT, self.top, v)
                self.top += 1
        return self.start[key]


def _nonfinite(T, values) -> int:
    """A row that is 0 where every one of `values` is finite and NaN where one is not: the sum of
    x·0 (±0 for a finite x, NaN for an infinity or a NaN). One multiply-add per value, where a FLAG per
    value (a select, read and written again) cost about twice as much."""
    acc = T.mulk(values[0], 0.0)
    for v in values[1:]:
        acc = T.val(MADD, acc, v, T.value(0.0))
    return acc


def _program_block(T, blk, feat, bvec, x, bad, min_measure, order=None):
    """One block of `kinetostatics._solve_block`: its entries, the constant pivots eliminated, the rest
    solved densely, the back-substitution into x (rows of the unknowns), and `bad` marked where its
    measure |det| / Π‖row‖ is not above `min_measure`. `order`: the order the dense part's rows start
    in for its LU (`kinetostatics.pivot_orders`; only |det| is read, so a reordering's sign is not)."""
    rows = [bvec[r] for r in blk.rows]  # the right side
    slot, norm = defaultdict(lambda: T.value(0.0)), [None] * len(blk.rows)  # (fill-in starts at 0)
    for i, j, f, coef in blk.entries:
        v = slot[i, j] = T.value(coef) if f == 0 else T.mul(feat[f], T.value(coef))
        norm[i] = T.mul(v, v) if norm[i] is None else T.val(MADD, norm[i], v, v)
    prod = norm[0]
    for v in norm[1:]:
        prod = T.mul(prod, v)
    measure_of = T.val(SQRT, prod)
    for i, c, f, coef in blk.later:
        rows[i] = T.val(MSUB, rows[i], T.value(coef) if f == 0 else T.mulk(feat[f], coef), x[c])
    det = T.value(1.0)
    for (i, j), (affected, columns) in zip(blk.pivots, blk.fill):
        for k in affected:
            m = T.div(slot[k, j], slot[i, j])
            for u in columns:
                slot[k, u] = T.val(MSUB, slot[k, u], m, slot[i, u])
            rows[k] = T.val(MSUB, rows[k], m, rows[i])
        det = T.val(MUL, det, slot[i, j])
    own = blk.own
    nr = len(blk.rest_rows)
    a = [[slot[i, j] for j in blk.rest_cols] for i in blk.rest_rows]
    r = [rows[i] for i in blk.rest_rows]
    if nr == 1:  # the explicit inverse (_linalg.factor)
        x[own[blk.rest_cols[0]]] = T.mul(T.div(T.value(1.0), a[0][0]), r[0])
        det = T.val(MUL, det, a[0][0])
    elif nr == 2:
        d = T.val(DOT, a[0][0], a[1][1], a[0][1], T.mulk(a[1][0], -1.0))
        i00, i01 = T.div(a[1][1], d), T.div(T.mulk(a[0][1], -1.0), d)
        i10, i11 = T.div(T.mulk(a[1][0], -1.0), d), T.div(a[0][0], d)
        x[own[blk.rest_cols[0]]] = T.val(DOT, i00, r[0], i01, r[1])
        x[own[blk.rest_cols[1]]] = T.val(DOT, i10, r[0], i11, r[1])
        det = T.val(MUL, det, d)
    elif nr:  # LU with partial pivoting (_linalg.lu_factor), each position its own pivot rows
        if order is not None:
            a, r = [a[i] for i in order], [r[i] for i in order]
        a = [[T.private(v) for v in row] for row in a]  # (the pivots swap them in place)
        r, det = [T.private(v) for v in r], T.private(det)
        for k in range(nr):
            if k < nr - 1:
                start = len(T.aux)
                for i in range(k, nr):
                    T.aux += a[i][k:] + [r[i]]
                T.into(PIVOT, det, start, nr - k)
                for v in T.aux[start:]:
                    T.written(v)
                for i in range(k + 1, nr):
                    m = T.div(a[i][k], a[k][k])
                    for j in range(k + 1, nr):
                        a[i][j] = T.val(MSUB, a[i][j], m, a[k][j])
                    r[i] = T.val(MSUB, r[i], m, r[k])
            det = T.val(MUL, det, a[k][k])
        sol = [None] * nr
        for i in range(nr - 1, -1, -1):
            acc = r[i]
            for j in range(i + 1, nr):
                acc = T.val(MSUB, acc, a[i][j], sol[j])
            sol[i] = T.div(acc, a[i][i])
        for q, j in enumerate(blk.rest_cols):
            x[own[j]] = sol[q]
    for (i, j), (_, columns) in reversed(list(zip(blk.pivots, blk.fill))):
        acc = rows[i]
        for u in columns:
            acc = T.val(MSUB, acc, slot[i, u], x[own[u]])
        x[own[j]] = T.div(acc, slot[i, j])
    measure = T.div(T.val(ABS, det), measure_of)
    T.into(FLAG, bad, measure, k=T.consts2(min_measure, np.inf))


def program_for(engine, ks_plan, motion, inertia: bool) -> Program:
    """The program of the engine's system (`ks_plan`) for the record layout of `motion` and `inertia`,
    written once per engine, layout and `inertia`."""
    row_dtype = motion.records.dtype
    key = (row_dtype, inertia)
    cache = engine.prepare("kinetostatics programs", dict)  # per row layout and inertia
    if key not in cache:
        dense = any(len(blk.rest_rows) >= 3 for blk in ks_plan.blocks)
        orders = pivot_orders(engine, _sample(engine, motion)) if dense else {}
        names, links, guides, sources, tape = _program(engine, ks_plan, row_dtype, inertia, orders)
        ops, consts, aux, rows = tape.finish()
        top = max(int(op[1]) for op in ops if op[0] in (OUT, OUTK)) + 1  # (the output rows)
        cache[key] = Program(names, links, guides, sources, top, ops, consts, aux, rows, ks_plan.lay.size)
    return cache[key]


def _sample(engine, motion, size=32):
    """The positions of up to `size` of the motion's input values, evenly spread (to learn the dense
    parts' pivot orders from: `pivot_orders`)."""
    from ..kinematics import analyse
    phi = motion.phi[np.unique(np.linspace(0, len(motion.phi) - 1, size).astype(int))]
    return analyse(engine, phi)
