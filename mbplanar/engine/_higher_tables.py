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
recursion); a roller's path is the profile's offset by a distance along its normal (`Offset`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..model import Circle, Offset, Spline

__all__ = ["HigherTables", "CurveTables", "higher_tables", "curve_tables", "HIGHER_CACHE", "CURVE_WORK",
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
C_INTS = 16
# the columns of `CurveTables.reals`
C_CENTRE, C_RADIUS = 0, 2         # a circle's centre (2) and radius: c(u) = centre + radius·(cos u, sin u)
C_LO, C_HI = 3, 4                 # the parameter's first and last value (a spline's t[k], t[n])
C_DISTANCE = 5                    # the offset along the left normal (a roller's radius, signed; else 0)
C_REALS = 6


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


def curve_tables(shapes: list) -> CurveTables:
    """`CurveTables` of `Shape`s (circles, splines, their offsets)."""
    n = len(shapes)
    ints, reals = np.zeros((n, C_INTS), np.int64), np.zeros((n, C_REALS))
    knots, coefs, nk, nc = [], [], 0, 0
    for j, shape in enumerate(shapes):
        if isinstance(shape, Offset):
            ints[j, C_OFFSET], reals[j, C_DISTANCE] = 1, shape.distance
            shape = shape.base
        reals[j, C_LO], reals[j, C_HI] = shape.lo, shape.hi
        if isinstance(shape, Circle):
            ints[j, C_CIRCLE] = 1
            reals[j, C_CENTRE:C_CENTRE + 2], reals[j, C_RADIUS] = shape.centre, shape.radius
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


def higher_tables(engine) -> tuple[HigherTables, CurveTables]:
    """The engine's higher pairs (its `BlockPlan`s' cuts that are higher laws) and their curves."""
    idx = engine.link_index
    names = list(engine.mech.higher)
    ints, reals, shapes, first, var0 = [], [], [], [0], 0
    for bp in engine.blocks:
        row = 2 * sum(1 for law in bp.cuts if law.kind in ("R", "P"))
        params = {law.name: k for law, k in bp.params}
        for law in bp.cuts:
            if law.kind in ("R", "P"):
                continue
            i, r = np.zeros(H_INTS, np.int64), np.zeros(H_REALS)
            i[H_GEAR], i[H_RACK], i[H_FLAT] = law.kind == "gear", law.kind == "rack", law.kind == "face"
            i[H_A], i[H_B], i[H_CURVE], i[H_VAR] = idx[law.links[0]], idx[law.links[1]], -1, -1
            i[H_ROW], i[H_EQUATIONS], i[H_COLUMN] = row, law.equations, names.index(law.name)
            r[H_LO], r[H_HI] = -np.inf, np.inf
            if law.kind == "gear":
                (_, ca), (_, cb), (carrier, cc) = law.coef
                i[H_CARRIER], r[H_COEF:H_COEF + 3] = idx[carrier], (ca, cb, cc)
            elif law.kind == "rack":
                r[H_CENTRE:H_CENTRE + 2], r[H_AT:H_AT + 2] = law.centre, law.at
                r[H_AXIS:H_AXIS + 2], r[H_SIGMA_R] = law.line, law.sigma_r
            else:
                i[H_CURVE], i[H_VAR] = len(shapes), var0 + params[law.name]
                r[H_AT:H_AT + 2], (r[H_LO], r[H_HI]) = law.at, law.param_range
                if law.kind == "face":
                    r[H_AXIS:H_AXIS + 2] = law.n0
                shapes.append(law.path)
            ints.append(i)
            reals.append(r)
            row += law.equations
        first.append(len(ints))
        var0 += bp.m
    tables = HigherTables(np.array(ints, np.int64).reshape(-1, H_INTS), np.array(reals, float).reshape(-1, H_REALS),
                          np.array(first, np.int64))
    return tables, curve_tables(shapes)
