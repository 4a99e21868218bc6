"""The higher pairs as the compiled kernels read them: each pair's law (`_higher`) and each curve it runs
on (`model._curves`) as named tuples of arrays (`HigherTables`, `CurveTables`), built here and only here.

Like the lower pairs' tables, they store booleans rather than codes (`gear`, `rack`, `flat`; a pair with
none of them is a point on a curve: a cam's knife, roller or circular face, a pin in a slot), so that no
kernel compares against a constant of another file. A curve is a circle (or an arc of one) or scipy's
interpolating B-spline, stored as the B-splines of c, c', c'' and c''' (scipy's `BSpline.derivative`,
degrees k … k − 3) so that a kernel evaluates each as scipy does (the knot interval, then the Cox–de Boor
recursion); a roller's path is the profile's offset by a distance along its normal (`Offset`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..model._curves import Circle, Offset, Spline

__all__ = ["HigherTables", "CurveTables", "higher_tables", "curve_tables", "HIGHER_CACHE", "CURVE_WORK"]

HIGHER_CACHE = 14   # columns of a pair's cache in the kernels' work arrays (`backends._numba_higher`)
CURVE_WORK = 12     # the Cox–de Boor recursion's work vector: 2·(degree + 1) for the highest degree (5)


class CurveTables(NamedTuple):
    """The K curves of the higher pairs (in the engine's frame): a circle or a spline, offset or not."""

    circle: np.ndarray      # (K,) bool: a circle c(u) = centre + radius·(cos u, sin u) (else a spline)
    centre: np.ndarray      # (K, 2) float: the circle's centre
    radius: np.ndarray      # (K,) float: the circle's radius
    closed: np.ndarray      # (K,) bool: a closed spline (its parameter taken into lo … hi, twice as scipy does)
    lo: np.ndarray          # (K,) float: the parameter's first value (a spline's t[k])
    hi: np.ndarray          # (K,) float: its last (a spline's t[n])
    offset: np.ndarray      # (K,) bool: the curve is its base moved by `distance` along the left normal
    distance: np.ndarray    # (K,) float: the offset (a roller's radius, signed; else 0)
    degree: np.ndarray      # (K,) int: the spline's degree k (3 or 5; else 0)
    knot0: np.ndarray       # (K, 4) int: where the knots of c⁽ⁿ⁾'s B-spline start in `knots`, n = 0 … 3
    knot1: np.ndarray       # (K, 4) int: where they end (exclusive)
    coef0: np.ndarray       # (K, 4) int: where its coefficients start in `coefs`
    knots: np.ndarray       # (T,) float: every B-spline's knots, concatenated
    coefs: np.ndarray       # (N, 2) float: every B-spline's coefficients, concatenated


class HigherTables(NamedTuple):
    """The H higher pairs of the engine's blocks in solving order (a block's after its lower cuts), each
    giving `equations` closure rows from `row` on in its block's residual."""

    gear: np.ndarray        # (H,) bool: r_a(θ_a − θ_c) ± r_b(θ_b − θ_c) = 0
    rack: np.ndarray        # (H,) bool: (X_C − X_A)·U + σr·(θ_p − θ_k) = 0
    flat: np.ndarray        # (H,) bool: a flat face on a curve (else, neither gear nor rack: a point on it)
    a: np.ndarray           # (H,) int: the first link (gear a, the pinion, the curve's link)
    b: np.ndarray           # (H,) int: the second link (gear b, the rack, the follower's or pin's link)
    carrier: np.ndarray     # (H,) int: a gear pair's carrier (else 0)
    coef: np.ndarray        # (H, 3) float: a gear pair's coefficients of θ_a, θ_b, θ_c
    centre: np.ndarray      # (H, 2) float: a rack's pinion centre (on a)
    at: np.ndarray          # (H, 2) float: the point of b: the rack's pitch point, the follower's or pin's point
    axis: np.ndarray        # (H, 2) float: a rack's line direction, a flat face's normal (on b)
    sigma_r: np.ndarray     # (H,) float: a rack's σ·r
    curve: np.ndarray       # (H,) int: the curve the contact runs on (`CurveTables`; −1: none)
    var: np.ndarray         # (H,) int: the contact parameter's unknown (global index; −1: none)
    row: np.ndarray         # (H,) int: the pair's first residual row in its block
    equations: np.ndarray   # (H,) int: its residual rows (1 or 2)
    first: np.ndarray       # (K + 1,) int: block k's pairs are first[k] … first[k + 1] − 1
    lo: np.ndarray          # (H,) float: the contact parameter's range on an open curve (−inf: none)
    hi: np.ndarray          # (H,) float
    column: np.ndarray      # (H,) int: the pair's place in the model's `higher` (the records' contact column)


_WIDTH = {"coef": (3,), "centre": (2,), "at": (2,), "axis": (2,)}


def _column(rows: list, name: str, dtype) -> np.ndarray:
    """The field `name` of every row as one contiguous array (H,) or (H, width)."""
    return np.array([r[name] for r in rows], dtype).reshape((len(rows),) + _WIDTH.get(name, ()))


def curve_tables(shapes: list) -> CurveTables:
    """`CurveTables` of `Shape`s (circles, splines, their offsets)."""
    n = len(shapes)
    out = CurveTables(np.zeros(n, np.bool_), np.zeros((n, 2)), np.zeros(n), np.zeros(n, np.bool_), np.zeros(n),
                      np.zeros(n), np.zeros(n, np.bool_), np.zeros(n), np.zeros(n, np.int64),
                      np.zeros((n, 4), np.int64), np.zeros((n, 4), np.int64), np.zeros((n, 4), np.int64),
                      None, None)
    knots, coefs, nk, nc = [], [], 0, 0
    for j, shape in enumerate(shapes):
        if isinstance(shape, Offset):
            out.offset[j], out.distance[j] = True, shape.distance
            shape = shape.base
        out.lo[j], out.hi[j] = shape.lo, shape.hi
        if isinstance(shape, Circle):
            out.circle[j], out.centre[j], out.radius[j] = True, shape.centre, shape.radius
            continue
        if not isinstance(shape, Spline):
            raise TypeError(f"no kernel tables for a curve of type {type(shape).__name__}")
        out.closed[j], out.degree[j] = shape.closed, shape.spline.k
        for n, spline in enumerate(shape.derivatives):
            t, c = np.asarray(spline.t, float), np.asarray(spline.c, float).reshape(-1, 2)
            out.knot0[j, n], out.knot1[j, n], out.coef0[j, n] = nk, nk + len(t), nc
            knots.append(t)
            coefs.append(c)
            nk, nc = nk + len(t), nc + len(c)
    return out._replace(knots=np.concatenate(knots) if knots else np.zeros(1),
                        coefs=np.ascontiguousarray(np.concatenate(coefs)) if coefs else np.zeros((1, 2)))


def higher_tables(engine) -> tuple[HigherTables, CurveTables]:
    """The engine's higher pairs (its `BlockPlan`s' cuts that are higher laws) and their curves."""
    idx = engine.link_index
    rows, shapes, first, var0 = [], [], [0], 0
    names = list(engine.mech.higher)
    for bp in engine.blocks:
        row = 2 * sum(1 for law in bp.cuts if law.kind in ("R", "P"))
        params = {law.name: k for law, k in bp.params}
        for law in bp.cuts:
            if law.kind in ("R", "P"):
                continue
            a, b = law.links[0], law.links[1]
            entry = dict(gear=law.kind == "gear", rack=law.kind == "rack", flat=law.kind == "face", a=idx[a],
                         b=idx[b], carrier=0, coef=(0.0, 0.0, 0.0), centre=(0.0, 0.0), at=(0.0, 0.0),
                         axis=(0.0, 0.0), sigma_r=0.0, curve=-1, var=-1, row=row, equations=law.equations,
                         lo=-np.inf, hi=np.inf, column=names.index(law.name))
            if law.kind == "gear":
                (_, ca), (_, cb), (carrier, cc) = law.coef
                entry.update(carrier=idx[carrier], coef=(ca, cb, cc))
            elif law.kind == "rack":
                entry.update(centre=tuple(law.centre), at=tuple(law.at), axis=tuple(law.line), sigma_r=law.sigma_r)
            else:
                entry.update(at=tuple(law.at), curve=len(shapes), var=var0 + params[law.name],
                             lo=law.param_range[0], hi=law.param_range[1])
                if law.kind == "face":
                    entry.update(axis=tuple(law.n0))
                shapes.append(law.path)
            rows.append(entry)
            row += law.equations
        first.append(len(rows))
        var0 += bp.m
    col = lambda name, dtype=float: _column(rows, name, dtype)  # noqa: E731
    tables = HigherTables(col("gear", np.bool_), col("rack", np.bool_), col("flat", np.bool_), col("a", np.int64),
                          col("b", np.int64), col("carrier", np.int64), col("coef"), col("centre"), col("at"),
                          col("axis"), col("sigma_r"), col("curve", np.int64), col("var", np.int64),
                          col("row", np.int64), col("equations", np.int64), np.array(first, np.int64), col("lo"),
                          col("hi"), col("column", np.int64))
    return tables, curve_tables(shapes)
