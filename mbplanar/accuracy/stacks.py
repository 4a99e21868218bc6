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
    """Tolerance stacks of Y outputs over N positions for K toleranced dimensions (SI: m, rad).

    Attributes
    ----------
    shift : (N, Y) ndarray
        The outputs' mean shift (from bands not centred on the nominal).
    worst : (N, Y) ndarray
        Worst-case half-width about the shift: Σ_k |∂y/∂x_k|·half-width_k.
    sigma : (N, Y) ndarray
        Statistical (root sum of squares) standard deviation.
    share : (Y, K) ndarray
        Each dimension's share of the output's variance over the cycle (rows sum to 1 where the
        output varies).
    peak : (Y, K) ndarray
        Each dimension's largest worst-case contribution over the cycle.

    Examples
    --------
    The slider-crank's crank and rod ±0.1 mm at 0° and 90°: the rod's share of the slider's variance is
    (1 + 1.06066²)/(1 + 1 + 0.353553² + 1.06066²) = 0.653846:

    >>> import numpy as np
    >>> from mbplanar.accuracy import DesignSpace, Tolerance, resolve_outputs, sensitivities, stack
    >>> from mbplanar.accuracy.run import load
    >>> template, raw, engine = load("models/slider_crank.toml")
    >>> space = DesignSpace(engine, raw, template, ["links.1.length", "links.2.length"])
    >>> s = sensitivities(space, np.radians([0.0, 90.0]), resolve_outputs(engine.mech, ["Bp.x"]))
    >>> band = [Tolerance("links.1.length", -1e-4, 1e-4), Tolerance("links.2.length", -1e-4, 1e-4)]
    >>> st = stack(s, band, space.dimensions)
    >>> st.share.round(6).tolist(), (st.peak * 1e3).round(6).tolist()      # peak in mm
    ([[0.346154, 0.653846]], [[0.1, 0.106066]])
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
    """Worst-case and statistical tolerance stacks from sensitivities.

    Parameters
    ----------
    sens : Sensitivities
        ∂output/∂dimension over the positions.
    tolerances : sequence of Tolerance
        One band per dimension, in the dimensions' units, in the order of `dimensions`.
    dimensions : sequence of Dimension
        The dimensions (their `scale` converts the bands to SI).

    Returns
    -------
    Stack
        Shift, worst case, standard deviation and each dimension's share.

    Raises
    ------
    ValueError
        `tolerances` and `dimensions` of a length other than the sensitivities' K (numpy's matmul
        error).

    Examples
    --------
    Crank and rod of the slider-crank each ±0.1 mm: at 90° the worst case is 0.1 mm·(0.353553 +
    1.06066) and the standard deviation 0.1 mm/√3·√(0.353553² + 1.06066²):

    >>> import numpy as np
    >>> from mbplanar.accuracy import DesignSpace, Tolerance, resolve_outputs, sensitivities, stack
    >>> from mbplanar.accuracy.run import load
    >>> template, raw, engine = load("models/slider_crank.toml")
    >>> space = DesignSpace(engine, raw, template, ["links.1.length", "links.2.length"])
    >>> s = sensitivities(space, np.radians([0.0, 90.0]), resolve_outputs(engine.mech, ["Bp.x"]))
    >>> st = stack(s, [Tolerance("links.1.length", -1e-4, 1e-4), Tolerance("links.2.length", -1e-4, 1e-4)],
    ...            space.dimensions)
    >>> (st.worst[:, 0] * 1e3).round(6).tolist(), round(float(st.sigma[1, 0] * 1e3), 6)     # mm
    ([0.2, 0.141421], 0.06455)
    """
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
