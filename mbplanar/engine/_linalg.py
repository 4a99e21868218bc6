"""Batched small dense linear algebra: one factorisation per batch element, reused for several
right-hand sides (Newton step, velocities, accelerations).

Shapes, batch last (every elementwise operation then runs over a contiguous batch): A is (n, n, B),
right-hand sides (n, B). numpy's own batched solve pays a LAPACK call per matrix; for the 1×1 … 4×4
blocks of a mechanism, elimination written over the batch axis is several times faster and lets one
factorisation serve every right-hand side. 1×1 and 2×2 matrices (every dyad) use their explicit
inverse (Cramer), a handful of array operations.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["LU", "Cramer", "factor", "lu_factor"]


@dataclass
class LU:
    """Packed LU factors (n, n, B) of a batch of matrices with row permutation `perm` (n, B)."""

    lu: np.ndarray
    perm: np.ndarray
    sign: np.ndarray

    def _pivots(self) -> np.ndarray:
        n = self.lu.shape[0]
        return self.lu[np.arange(n), np.arange(n)]

    @property
    def det(self) -> np.ndarray:
        """Determinant of every matrix, (B,)."""
        return self.sign * np.prod(self._pivots(), axis=0)

    @property
    def pivot_ratio(self) -> np.ndarray:
        """min |pivot| / max |pivot| (B,): near 0 where the matrix is (nearly) singular."""
        d = np.abs(self._pivots())
        return d.min(axis=0) / np.maximum(d.max(axis=0), 1e-300)

    def solve(self, b: np.ndarray) -> np.ndarray:
        """x with A x = b; b (n, B)."""
        lu, n = self.lu, self.lu.shape[0]
        x = np.take_along_axis(b, self.perm, axis=0)
        for i in range(1, n):  # forward: unit lower triangle
            x[i] -= np.einsum("jb,jb->b", lu[i, :i], x[:i])
        for i in range(n - 1, -1, -1):  # backward: upper triangle
            if i < n - 1:
                x[i] -= np.einsum("jb,jb->b", lu[i, i + 1:], x[i + 1:])
            x[i] /= lu[i, i]
        return x


@dataclass
class Cramer:
    """Explicit inverse (n, n, B) of a batch of 1×1 or 2×2 matrices; same interface as `LU`. The pivots
    are those partial pivoting would choose (the larger entry of the first column, then det / that
    entry), so `pivot_ratio` means the same for every size."""

    inv: np.ndarray
    det: np.ndarray
    pivots: tuple

    @property
    def pivot_ratio(self) -> np.ndarray:
        p = np.abs(np.stack(self.pivots))
        return p.min(axis=0) / np.maximum(p.max(axis=0), 1e-300)

    def solve(self, b: np.ndarray) -> np.ndarray:
        inv = self.inv
        if inv.shape[0] == 1:
            return inv[0] * b
        out = np.empty_like(b)
        out[0] = inv[0, 0] * b[0] + inv[0, 1] * b[1]
        out[1] = inv[1, 0] * b[0] + inv[1, 1] * b[1]
        return out


def _cramer(a: np.ndarray) -> Cramer:
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        if a.shape[0] == 1:
            det = a[0, 0].copy()
            return Cramer((1.0 / det)[None, None], det, (det,))
        a00, a01, a10, a11 = a[0, 0], a[0, 1], a[1, 0], a[1, 1]
        det = a00 * a11 - a01 * a10
        inv = np.empty(a.shape)
        inv[0, 0] = a11 / det
        inv[0, 1] = -a01 / det
        inv[1, 0] = -a10 / det
        inv[1, 1] = a00 / det
        first = np.maximum(np.abs(a00), np.abs(a10))
        return Cramer(inv, det, (first, det / first))


def factor(a: np.ndarray):
    """Factor a batch of small matrices once, to solve several right-hand sides with each.

    Parameters
    ----------
    a : numpy.ndarray
        The matrices (n, n, B), batch last.

    Returns
    -------
    LU or Cramer
        The explicit inverse for n ≤ 2 (`Cramer`), else the LU factors with partial pivoting (`LU`);
        both give ``solve(b)`` for b (n, B), ``det`` (B,) and ``pivot_ratio`` (B,), the smallest pivot's
        size over the largest's, near 0 where a matrix is (nearly) singular.

    Raises
    ------
    Nothing: singular matrices give zero pivots and non-finite solutions, so one bad element never
    stops a batch (check `pivot_ratio`).

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.engine import factor
    >>> a = np.stack([[[2.0, 1.0], [1.0, 3.0]], [[1.0, 2.0], [2.0, 4.0]]], axis=-1)   # 2 matrices (2, 2, 2)
    >>> f = factor(a)
    >>> f.det.tolist(), f.pivot_ratio.round(3).tolist()          # pivots 2, 5/2 and 2, 0: the second is singular
    ([5.0, 0.0], [0.8, 0.0])
    >>> factor(a[:, :, :1]).solve(np.array([[3.0], [4.0]])).round(12).ravel().tolist()   # 2x + y = 3, x + 3y = 4
    [1.0, 1.0]
    """
    if 1 <= a.shape[0] <= 2:
        return _cramer(a)
    return lu_factor(a)


def _swap_pivot_rows(lu, perm, sign, k, p):
    """Bring row p[b] (B,) to row k in every matrix b: whole rows when the batch shares one pivot row
    (the usual case, a few contiguous copies), else row by row where p != k."""
    i = p[0]
    if (p == i).all():
        if i != k:
            lu[[k, i]] = lu[[i, k]]
            perm[[k, i]] = perm[[i, k]]
            sign *= -1.0
        return
    r = np.flatnonzero(p != k)
    pk = p[r]
    row = lu[k][:, r]
    lu[k][:, r] = lu[pk, :, r].T
    lu[pk, :, r] = row.T
    perm[k, r], perm[pk, r] = perm[pk, r], perm[k, r].copy()
    sign[r] = -sign[r]


def lu_factor(a: np.ndarray) -> LU:
    """LU factors of every matrix of `a` (n, n, B) with partial pivoting."""
    lu = np.array(a, dtype=float, copy=True)
    n, _, batch = lu.shape
    perm = np.tile(np.arange(n)[:, None], (1, batch))
    sign = np.ones(batch)
    with np.errstate(divide="ignore", invalid="ignore"):
        for k in range(n - 1):
            _swap_pivot_rows(lu, perm, sign, k, k + np.argmax(np.abs(lu[k:, k]), axis=0))
            lu[k + 1:, k] /= lu[k, k]
            lu[k + 1:, k + 1:] -= lu[k + 1:, k, None] * lu[k, None, k + 1:]
    return LU(lu, perm, sign)
