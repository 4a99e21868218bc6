"""The higher pairs as the compiled kernels read them: each pair's law (`_higher`) and each curve it runs
on (`model._curves`) as named tuples of arrays (`HigherTables`, `CurveTables`), built here and only here.

Each holds its numbers in two arrays, one of integers and one of reals, a row per pair (per curve) and a
column per field, the columns named below: a kernel hands a pair's law two arrays rather than a tuple
of a dozen (numba passes every array of a tuple on every call, and a call that LLVM does not inline then
costs more than the law's arithmetic). Flags are 0 or 1 (`H_GEAR`, `H_RACK`, `H_FLAT`; a pair with none
of them is a point on a curve: a cam's knife, roller or circular face, a pin in a slot), so that no
kernel compares against a code. A curve is a circle (or an arc of one) or scipy's interpolating
B-spline, stored as the B-splines of c, c', c'' and c''' (scipy's `BSpline.derivative`, degrees
k … k − 3) so that a kernel evaluates each as scipy does (the knot interval, then the Cox–de Boor
recursion); a roller's path is the profile's offset by a distance along its normal (`Offset`), and a
curve may be carried by a rigid motion (`Placed`: a made design's curve where its link sits).

The reals of a pair and of a curve are a function of its law alone (`pair_reals`, `curve_reals`), so
that a design batch gives every design its own rows (`design_reals`: `engine._tables.DesignTables`) while
the integers (which pair, which curve, which B-spline) are the engine's.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..model import Circle, Offset, Placed, Spline

__all__ = ["HigherTables", "CurveTables", "higher_tables", "curve_tables", "pair_reals", "curve_reals",
           "design_reals", "shared_curves", "HIGHER_CACHE", "CURVE_WORK", "C_PLACED", "C_PLACE",
           "H_GEAR", "H_RACK", "H_FLAT", "H_A", "H_B", "H_CARRIER", "H_CURVE", "H_VAR", "H_ROW", "H_EQUATIONS",
           "H_COLUMN", "H_COEF", "H_CENTRE", "H_AT", "H_AXIS", "H_SIGMA_R", "H_LO", "H_HI", "C_CIRCLE", "C_CLOSED",
           "C_OFFSET", "C_DEGREE", "C_KNOT0", "C_KNOT1", "C_COEF0", "C_CENTRE", "C_RADIUS", "C_LO", "C_HI",
           "C_DISTANCE"]

HIGHER_CACHE = 14   # columns of a pair's cache in the kernels' work arrays (`backends._numba_higher`)
CURVE_WORK = 12     # the Cox–de Boor recursion's work vector: 2·(degree + 1) for the highest degree (5)

# the columns of `HigherTables.ints`: flags (0, 1), link indices, where its curve, unknown and rows are
H_GEAR, H_RACK, H_FLAT = 0, 1, 2  # a gear pair (`Gear`), a rack (`Rack`), a flat face (`FaceOnCurve`)
H_A, H_B, H_CARRIER = 3, 4, 5     # the first link (gear a, the pinion, the curve's), the second, a gear's carrier
H_CURVE, H_VAR = 6, 7             # the curve (`CurveTables` row; −1: none), the contact parameter (global; −1)
H_ROW, H_EQUATIONS, H_COLUMN = 8, 9, 10  # its first residual row in its block, its rows (1, 2), its `higher` place
H_INTS = 11
# the columns of `HigherTables.reals`
H_COEF = 0        # 3: a gear pair's coefficients of θ_a, θ_b, θ_c
H_CENTRE = 3      # 2: a rack's pinion centre (on a)
H_AT = 5          # 2: the point of b: the rack's pitch point, the follower's or the pin's point
H_AXIS = 7        # 2: a rack's line direction, a flat face's normal (on b)
H_SIGMA_R = 9     # a rack's σ·r
H_LO, H_HI = 10, 11  # the contact parameter's range on an open curve (±inf: none)
H_REALS = 12
# the columns of `CurveTables.ints`
C_CIRCLE, C_CLOSED, C_OFFSET, C_DEGREE = 0, 1, 2, 3  # a circle (else a spline); a closed spline; an offset curve; k
C_KNOT0, C_KNOT1, C_COEF0 = 4, 8, 12  # 4 each: c⁽ⁿ⁾'s knots' start and end in `knots`, its first coefficient
C_PLACED = 16                     # carried by a rigid motion (C_PLACE; else not read)
C_INTS = 17
# the columns of `CurveTables.reals`
C_CENTRE, C_RADIUS = 0, 2         # a circle's centre (2) and radius: c(u) = centre + radius·(cos u, sin u)
C_LO, C_HI = 3, 4                 # the parameter's first and last value (a spline's t[k], t[n])
C_DISTANCE = 5                    # the offset along the left normal (a roller's radius, signed; else 0)
C_PLACE = 6                       # 4: the rigid motion's cos, sin and shift (x, y): R·c(u) + r (`Placed`)
C_REALS = 10


class HigherTables(NamedTuple):
    """The H higher pairs of the engine's blocks in solving order (a block's after its lower cuts), each
    giving its `H_EQUATIONS` closure rows from `H_ROW` on in its block's residual."""

    ints: np.ndarray        # (H, H_INTS) int: the columns H_GEAR … H_COLUMN
    reals: np.ndarray       # (H, H_REALS) float: the columns H_COEF … H_HI
    first: np.ndarray       # (K + 1,) int: block k's pairs are first[k] … first[k + 1] − 1


class CurveTables(NamedTuple):
    """The K curves of the higher pairs (in the engine's frame): a circle or a spline, offset or not."""

    ints: np.ndarray        # (K, C_INTS) int: the columns C_CIRCLE … C_COEF0
    reals: np.ndarray       # (K, C_REALS) float: the columns C_CENTRE … C_DISTANCE
    knots: np.ndarray       # (T,) float: every B-spline's knots, concatenated
    coefs: np.ndarray       # (N, 2) float: every B-spline's coefficients, concatenated


def _base(shape):
    """The circle or spline under a shape's rigid motion and offset."""
    if isinstance(shape, Placed):
        shape = shape.base
    return shape.base if isinstance(shape, Offset) else shape


def curve_reals(shape, count: int = 1) -> np.ndarray:
    """The reals (count, C_REALS) of a `Shape` (a circle or a spline, offset or not, placed or not) whose
    numbers hold one value, or one per design (arrays (count,), (2, count))."""
    out = np.zeros((count, C_REALS))
    out[:, C_PLACE] = 1.0                                  # (no rigid motion: the identity)
    if isinstance(shape, Placed):
        out[:, C_PLACE], out[:, C_PLACE + 1] = shape.c, shape.s
        out[:, C_PLACE + 2], out[:, C_PLACE + 3] = shape.r[0], shape.r[1]
        shape = shape.base
    if isinstance(shape, Offset):
        out[:, C_DISTANCE] = shape.distance
        shape = shape.base
    out[:, C_LO], out[:, C_HI] = shape.lo, shape.hi
    if isinstance(shape, Circle):
        out[:, C_CENTRE], out[:, C_CENTRE + 1], out[:, C_RADIUS] = shape.centre[0], shape.centre[1], shape.radius
    return out


def shared_curves(a, b) -> bool:
    """Whether shapes `a` and `b` run on the same B-spline (or both on circles), so that one
    `CurveTables` serves both with their own reals."""
    a, b = _base(a), _base(b)
    if isinstance(a, Circle) or isinstance(b, Circle):
        return isinstance(a, Circle) and isinstance(b, Circle)
    return a is b or all(np.array_equal(x.t, y.t) and np.array_equal(x.c, y.c)
                         for x, y in zip(a.derivatives, b.derivatives))


def curve_tables(shapes: list, numbers: bool = True) -> CurveTables:
    """`CurveTables` of `Shape`s (circles, splines, their offsets, placed or not); without `numbers` the
    reals are left 0 (shapes with one value per design: `design_reals` gives them)."""
    n = len(shapes)
    ints, reals = np.zeros((n, C_INTS), np.int64), np.zeros((n, C_REALS))
    knots, coefs, nk, nc = [], [], 0, 0
    for j, shape in enumerate(shapes):
        if numbers:
            reals[j] = curve_reals(shape)[0]
        ints[j, C_PLACED] = isinstance(shape, Placed)
        ints[j, C_OFFSET] = isinstance(shape.base if isinstance(shape, Placed) else shape, Offset)
        shape = _base(shape)
        if isinstance(shape, Circle):
            ints[j, C_CIRCLE] = 1
            continue
        if not isinstance(shape, Spline):
            raise TypeError(f"no kernel tables for a curve of type {type(shape).__name__}")
        ints[j, C_CLOSED], ints[j, C_DEGREE] = int(shape.closed), shape.spline.k
        for n_, spline in enumerate(shape.derivatives):
            t, c = np.asarray(spline.t, float), np.asarray(spline.c, float).reshape(-1, 2)
            ints[j, C_KNOT0 + n_], ints[j, C_KNOT1 + n_], ints[j, C_COEF0 + n_] = nk, nk + len(t), nc
            knots.append(t)
            coefs.append(c)
            nk, nc = nk + len(t), nc + len(c)
    return CurveTables(ints, reals, np.concatenate(knots) if knots else np.zeros(1),
                       np.ascontiguousarray(np.concatenate(coefs)) if coefs else np.zeros((1, 2)))


def pair_reals(law, count: int = 1) -> np.ndarray:
    """The reals (count, H_REALS) of a higher pair's law whose numbers hold one value, or one per design
    (arrays (count,), (2, count): `mbplanar.accuracy.higher.made_law`)."""
    r = np.zeros((count, H_REALS))
    r[:, H_LO], r[:, H_HI] = law.param_range
    if law.kind == "gear":
        (_, ca), (_, cb), (_, cc) = law.coef
        r[:, H_COEF], r[:, H_COEF + 1], r[:, H_COEF + 2] = ca, cb, cc
    elif law.kind == "rack":
        for col, v in ((H_CENTRE, law.centre), (H_AT, law.at), (H_AXIS, law.line)):
            r[:, col], r[:, col + 1] = v[0], v[1]
        r[:, H_SIGMA_R] = law.sigma_r
    else:
        r[:, H_AT], r[:, H_AT + 1] = law.at[0], law.at[1]
        if law.kind == "face":
            r[:, H_AXIS], r[:, H_AXIS + 1] = law.n0[0], law.n0[1]
    return r


def _higher_cuts(engine):
    """(block, law) of the engine's higher pairs in solving order (a block's after its lower cuts)."""
    return [(bp, law) for bp in engine.blocks for law in bp.cuts if law.kind not in ("R", "P")]


def design_reals(engine, laws: dict, count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per design (count designs) the reals of the engine's higher pairs (count, H, H_REALS) and of their
    curves (count, K, C_REALS), in `higher_tables`' order, from `laws` (name → the pair's law with one
    value or one per design), and every unknown's drawn value (count, M) (the contact parameters'
    `param0`, else 0)."""
    pairs = _higher_cuts(engine)
    hr = np.zeros((count, len(pairs), H_REALS))
    curves = []
    for h, (_, law) in enumerate(pairs):
        hr[:, h] = pair_reals(laws[law.name], count)
        if law.parameters:
            curves.append(curve_reals(laws[law.name].path, count))
    cr = np.stack(curves, axis=1) if curves else np.zeros((count, 0, C_REALS))
    q0 = np.zeros((count, sum(bp.m for bp in engine.blocks)))
    var0 = 0
    for bp in engine.blocks:
        for law, k in bp.params:
            q0[:, var0 + k] = laws[law.name].param0
        var0 += bp.m
    return hr, cr, q0


def higher_tables(engine, laws: dict | None = None) -> tuple[HigherTables, CurveTables]:
    """The engine's higher pairs (its `BlockPlan`s' cuts that are higher laws) and their curves; with
    `laws` (name → law) those laws' curves (a design batch's: `Placed` ones are marked so)."""
    idx = engine.link_index
    names = list(engine.mech.higher)
    ints, reals, shapes, first, var0 = [], [], [], [0], 0
    for bp in engine.blocks:
        row = 2 * sum(1 for law in bp.cuts if law.kind in ("R", "P"))
        params = {law.name: k for law, k in bp.params}
        for law in bp.cuts:
            if law.kind in ("R", "P"):
                continue
            i = np.zeros(H_INTS, np.int64)
            i[H_GEAR], i[H_RACK], i[H_FLAT] = law.kind == "gear", law.kind == "rack", law.kind == "face"
            i[H_A], i[H_B], i[H_CURVE], i[H_VAR] = idx[law.links[0]], idx[law.links[1]], -1, -1
            i[H_ROW], i[H_EQUATIONS], i[H_COLUMN] = row, law.equations, names.index(law.name)
            if law.kind == "gear":
                i[H_CARRIER] = idx[law.carrier]
            elif law.parameters:
                i[H_CURVE], i[H_VAR] = len(shapes), var0 + params[law.name]
                shapes.append((law if laws is None else laws[law.name]).path)
            ints.append(i)
            reals.append(pair_reals(law)[0])
            row += law.equations
        first.append(len(ints))
        var0 += bp.m
    tables = HigherTables(np.array(ints, np.int64).reshape(-1, H_INTS), np.array(reals, float).reshape(-1, H_REALS),
                          np.array(first, np.int64))
    return tables, curve_tables(shapes, laws is None)
