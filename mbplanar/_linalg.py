"""Batched small dense linear algebra: one LU factorisation per batch element, reused for several
right-hand sides (Newton step, velocities, accelerations, reactions).

Shapes: A is (B, n, n), right-hand sides (B, n) or (B, n, k). numpy's own batched solve pays a LAPACK
call per matrix; for the 2×2 … 20×20 blocks of a mechanism, elimination written over the batch axis is
several times faster and lets one factorisation serve every right-hand side.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["LU", "lu_factor"]


@dataclass
class LU:
    """Packed LU factors of a batch of matrices with row permutation `perm` (B, n)."""

    lu: np.ndarray
    perm: np.ndarray
    sign: np.ndarray

    @property
    def det(self) -> np.ndarray:
        """Determinant of every matrix, (B,)."""
        return self.sign * np.prod(np.diagonal(self.lu, axis1=1, axis2=2), axis=1)

    @property
    def pivot_ratio(self) -> np.ndarray:
        """min |pivot| / max |pivot| (B,): near 0 where the matrix is (nearly) singular."""
        d = np.abs(np.diagonal(self.lu, axis1=1, axis2=2))
        return d.min(axis=1) / np.maximum(d.max(axis=1), 1e-300)

    def solve(self, b: np.ndarray) -> np.ndarray:
        """x with A x = b; b (B, n) or (B, n, k)."""
        lu, n = self.lu, self.lu.shape[1]
        vector = b.ndim == 2
        x = np.take_along_axis(b, self.perm if vector else self.perm[:, :, None], axis=1)
        x = x[:, :, None].copy() if vector else x.copy()
        for i in range(1, n):  # forward: unit lower triangle
            x[:, i] -= np.einsum("bj,bjk->bk", lu[:, i, :i], x[:, :i])
        for i in range(n - 1, -1, -1):  # backward: upper triangle
            if i < n - 1:
                x[:, i] -= np.einsum("bj,bjk->bk", lu[:, i, i + 1:], x[:, i + 1:])
            x[:, i] /= lu[:, i, i, None]
        return x[:, :, 0] if vector else x


def lu_factor(a: np.ndarray) -> LU:
    """Factor every matrix of `a` (B, n, n) with partial pivoting. Singular matrices give zero pivots
    (check `pivot_ratio`); nothing is raised, so one bad element never stops a batch."""
    lu = np.array(a, dtype=float, copy=True)
    batch, n, _ = lu.shape
    perm = np.tile(np.arange(n), (batch, 1))
    sign = np.ones(batch)
    rows = np.arange(batch)
    with np.errstate(divide="ignore", invalid="ignore"):
        for k in range(n - 1):
            p = k + np.argmax(np.abs(lu[:, k:, k]), axis=1)
            swap = p != k
            if swap.any():
                r, pk = rows[swap], p[swap]
                lu[r, k], lu[r, pk] = lu[r, pk], lu[r, k].copy()
                perm[r, k], perm[r, pk] = perm[r, pk], perm[r, k].copy()
                sign[swap] = -sign[swap]
            lu[:, k + 1:, k] /= lu[:, k, k, None]
            lu[:, k + 1:, k + 1:] -= lu[:, k + 1:, k, None] * lu[:, k, None, k + 1:]
    return LU(lu, perm, sign)
