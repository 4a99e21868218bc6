"""Tolerance stacks from exact sensitivities: the worst case and the statistical (root sum of squares)
error of every output at every position, and which dimension contributes what.

With S = ∂y/∂p (N positions, Y outputs, K dimensions, SI) and each dimension's deviation from nominal
distributed with mean m_k, standard deviation σ_k and half-width h_k (a uniform band [a, b]: m = (a + b)/2,
σ = (b − a)/√12, h = (b − a)/2; a normal row: m = 0, σ, h = 3σ), to first order

- the mean shift  Σ_k S_k m_k  (an asymmetric band moves the output's mean);
- the worst case  Σ_k |S_k| h_k  about that shift (every dimension at the limit that hurts);
- the statistical spread  σ_y = √(Σ_k (S_k σ_k)²)  (independent dimensions), reported as ±3σ.

A dimension's share of an output's variance over the cycle is Σ_n (S_nk σ_k)² / Σ_n σ_y,n²; its
peak is its largest |S_k| h_k over the cycle.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Stack", "stack"]


@dataclass(frozen=True)
class Stack:
    """The stacks of Y outputs over N positions for K toleranced dimensions (SI: m, rad).

    shift, worst, sigma (N, Y): mean shift, worst-case half-width about it, standard deviation;
    share (Y, K): each dimension's share of the output's variance over the cycle (rows sum to 1 where
    the output varies); peak (Y, K): each dimension's largest worst-case contribution over the cycle.
    """

    shift: np.ndarray
    worst: np.ndarray
    sigma: np.ndarray
    share: np.ndarray
    peak: np.ndarray

    def ranked(self, y: int) -> list[int]:
        """The dimensions in the order of their share of output y's variance (largest first)."""
        return [int(k) for k in np.argsort(-self.share[y], kind="stable")]


def stack(sens, tolerances, dimensions) -> Stack:
    """The stacks of `sens` (`Sensitivities`) for `tolerances` (spec.Tolerance rows, in the dimensions'
    units) of `dimensions` (geometry.Dimension, the same order: their `scale` converts to SI)."""
    scale = np.array([d.scale for d in dimensions])
    mean = np.array([t.mean for t in tolerances]) * scale
    std = np.array([t.std for t in tolerances]) * scale
    half = np.array([t.half_width for t in tolerances]) * scale
    d = sens.d
    with np.errstate(invalid="ignore"):
        shift = d @ mean
        worst = np.abs(d) @ half
        parts = (d * std) ** 2                       # (N, Y, K)
        sigma = np.sqrt(parts.sum(axis=2))
        total = np.nansum(parts, axis=(0, 2))        # (Y,)
        share = np.where(total[:, None] > 0, np.nansum(parts, axis=0) / np.where(total > 0, total, 1.0)[:, None], 0.0)
        peak = np.nanmax(np.abs(d) * half, axis=0) if len(d) else np.zeros(d.shape[1:])
    return Stack(shift, worst, sigma, share, np.nan_to_num(peak))
