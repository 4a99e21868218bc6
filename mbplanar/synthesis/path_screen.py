"""The global stage of four-bar path generation: a screen of coupler-curve shapes against the targets.

Where the crank turns fully, a four-bar's coupler curve is a closed curve whose *shape* depends on five
numbers only: the crank, coupler and rocker over the ground, and the coupler point in the coupler's
frame (and the assembly mode). Where the curve lies, how it is turned and how large it is are a
similarity of the plane, z → s·z + τ (s complex): those four numbers are fitted in closed form for each
shape, so the search samples a five-dimensional space instead of a nine-dimensional one. The
transmission angle, the link ratio and the full turn are properties of the shape alone, so every sampled
shape is a crank-rocker by construction and the designer's bounds are judged before anything is traced.

For each shape the targets are matched to points of its curve by their fraction of the way along:

* untimed targets: the curve is resampled uniformly in arc length (`arc_resample`) and target k is
  put at the fraction of the targets' own polyline it lies at, mapped onto a part ρ of the curve's
  length (the whole loop, or less when the targets cover part of it), in either sense, from any start;
* timed targets: target k is put at its crank advance from the first target, from any start.

For every start at once, the best similarity and its residual follow from three circular
cross-correlations of the curve with the targets (`procrustes_screen`, by FFT): the residual is that of
the complex least-squares fit t ≈ s·w + τ. The screen only ranks shapes; the designs it proposes are
measured afterwards by the true nearest-point distances and polished by least squares (`path`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .batch import fourbar_coupler_paths

__all__ = ["ShapeSample", "sample_shapes", "shape_designs", "shape_bounds", "arc_resample", "target_offsets",
           "procrustes_screen", "placed_designs"]

TWO_PI = 2.0 * math.pi
CHANGE_POINT_MARGIN = 0.01
"""Sampled crank-rockers stay this far (as a fraction of the slack) from the change-point four-bars."""

# The sampled ranges, ground = 1: crank a (log), the coupler + rocker sum's excess over 1 + a (log), the
# coupler − rocker difference (a fraction of its range), the coupler point (fractions of the coupler)
A_RANGE = (0.03, 0.95)
EXCESS_RANGE = (0.01, 10.0)
POINT_ALONG = (-1.0, 2.0)
POINT_ACROSS = (-1.5, 1.5)
COVERAGE = (0.9, 0.7, 0.5, 0.35, 0.2)
"""Parts of the curve's length an open run of untimed targets is tried on (besides the whole loop)."""


@dataclass(frozen=True)
class ShapeSample:
    """Sampled shapes: `designs` (S, 10) normalised four-bars (ground A0 = (0, 0), B0 = (1, 0)), and
    their smallest transmission angle `transmission_deg` (S,) and longest over shortest link `ratio` (S,)."""

    designs: np.ndarray
    transmission_deg: np.ndarray
    ratio: np.ndarray


def shape_bounds(designs) -> tuple[np.ndarray, np.ndarray]:
    """Smallest transmission angle (degrees) and link ratio (S,) of crank-rockers (S, 10), in closed form:
    the angle at B between coupler and rocker is extreme where the crank lies along the ground line."""
    d = np.atleast_2d(np.asarray(designs, float))
    a, b, c = np.abs(d[:, 4]), np.abs(d[:, 5]), np.abs(d[:, 6])
    g = np.hypot(d[:, 2] - d[:, 0], d[:, 3] - d[:, 1])
    mu = np.full(len(d), np.inf)
    for diagonal in (g - a, g + a):
        gamma = np.arccos(np.clip((b * b + c * c - diagonal * diagonal) / (2.0 * b * c), -1.0, 1.0))
        mu = np.minimum(mu, np.minimum(gamma, np.pi - gamma))
    links = np.stack([a, b, c, g], axis=1)
    return np.degrees(mu), links.max(axis=1) / links.min(axis=1)


def sample_shapes(count: int, rng: np.random.Generator) -> ShapeSample:
    """`count` crank-rockers (a power of two is best) from a scrambled Sobol sequence drawn from `rng`.

    With the ground 1, the crank a is the shortest link and turns fully exactly when
    |b − c| ≤ 1 − a and b + c ≥ 1 + a; b + c and b − c are sampled inside that region (clear of its
    edges, the change-point four-bars, by `CHANGE_POINT_MARGIN`), so every shape turns fully.
    """
    from scipy.stats import qmc
    x = qmc.Sobol(6, scramble=True, seed=rng).random(count)
    a = np.exp(np.log(A_RANGE[0]) + x[:, 0] * math.log(A_RANGE[1] / A_RANGE[0]))
    slack = 1.0 - a
    excess = np.exp(np.log(EXCESS_RANGE[0]) + x[:, 1] * math.log(EXCESS_RANGE[1] / EXCESS_RANGE[0]))
    total = 1.0 + a + slack * CHANGE_POINT_MARGIN + excess
    diff = (1.0 - CHANGE_POINT_MARGIN) * slack * (2.0 * x[:, 2] - 1.0)
    b, c = 0.5 * (total + diff), 0.5 * (total - diff)
    u = b * (POINT_ALONG[0] + x[:, 3] * (POINT_ALONG[1] - POINT_ALONG[0]))
    v = b * (POINT_ACROSS[0] + x[:, 4] * (POINT_ACROSS[1] - POINT_ACROSS[0]))
    mode = np.where(x[:, 5] < 0.5, -1.0, 1.0)
    zeros, ones = np.zeros(count), np.ones(count)
    d = np.column_stack([zeros, zeros, ones, zeros, a, b, c, u, v, mode])
    mu, ratio = shape_bounds(d)
    return ShapeSample(d, mu, ratio)


def shape_designs(sample: ShapeSample, keep) -> ShapeSample:
    """The shapes where `keep` (S,) is True."""
    keep = np.asarray(keep, bool)
    return ShapeSample(sample.designs[keep], sample.transmission_deg[keep], sample.ratio[keep])


def arc_resample(points, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Closed curves `points` (S, P) complex, resampled at `count` points uniformly in arc length
    (linearly between the samples) from their first point: (S, count) complex, and their lengths (S,)."""
    p = np.asarray(points, complex)
    rows, n = p.shape
    seg = np.abs(np.roll(p, -1, axis=1) - p)
    cum = np.concatenate([np.zeros((rows, 1)), np.cumsum(seg, axis=1)], axis=1)        # (S, P + 1)
    length = cum[:, -1]
    frac = cum / np.where(length > 0, length, 1.0)[:, None]
    want = np.arange(count) / count
    shift = 2.0 * np.arange(rows)[:, None]                                             # rows kept apart
    at = np.searchsorted((frac + shift).ravel(), (want[None, :] + shift).ravel(), side="right")
    at = np.clip(at.reshape(rows, count) - 1 - (n + 1) * np.arange(rows)[:, None], 0, n - 1)
    f0, f1 = np.take_along_axis(frac, at, axis=1), np.take_along_axis(frac, at + 1, axis=1)
    w = (want[None, :] - f0) / np.maximum(f1 - f0, 1e-300)
    loop = np.concatenate([p, p[:, :1]], axis=1)
    z0, z1 = np.take_along_axis(loop, at, axis=1), np.take_along_axis(loop, at + 1, axis=1)
    return z0 + w * (z1 - z0), length


def target_offsets(targets, count: int, timing=None) -> list[np.ndarray]:
    """Candidate correspondences: for each, the offsets (T,) of the targets (T, 2) from the first one
    on a curve of `count` points (arc-length points untimed, crank positions timed).

    Untimed: the targets' fractions along their closed polyline mapped on the whole loop, and along
    their open polyline mapped on each part of `COVERAGE`, in both senses. Timed: the crank's advance.
    """
    if timing is not None:
        return [np.round(np.asarray(timing, float) / TWO_PI * count).astype(int)]
    t = np.asarray(targets, float)
    run = np.r_[0.0, np.cumsum(np.hypot(*np.diff(t, axis=0).T))]
    closed = run[-1] + float(np.hypot(*(t[0] - t[-1])))
    out = []
    for sense in (1, -1):
        out.append(np.round(sense * run / closed * count).astype(int))
        out += [np.round(sense * part * run / run[-1] * count).astype(int) for part in COVERAGE]
    return out


def procrustes_screen(curves, targets, offsets) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Best similarity fit of the targets on each curve, over every start and correspondence.

    Parameters
    ----------
    curves : (S, N) complex
        The curves' points (closed: index N follows N − 1).
    targets : (T,) complex
    offsets : list of (T,) int arrays
        Correspondences (`target_offsets`): target k on curve point (j + offsets[k]) mod N for start j.

    Returns
    -------
    rms : (S,)
        RMS distance of the targets from their matched points after the best fit t ≈ s·w + τ.
    which, start : (S,) int
        The correspondence and the start j of the best fit.
    scale : (S,) complex
        The fitted s (its modulus the size, its argument the turn).
    """
    w = np.asarray(curves, complex)
    t = np.asarray(targets, complex)
    rows, n = w.shape
    k = len(t)
    fw, fw2, fwc = np.fft.fft(w, axis=1), np.fft.fft(np.abs(w) ** 2, axis=1), np.fft.fft(np.conj(w), axis=1)
    t1 = t.sum()
    stt = float(np.sum(np.abs(t) ** 2) - abs(t1) ** 2 / k)
    best = np.full(rows, np.inf)
    which, start = np.zeros(rows, int), np.zeros(rows, int)
    scale = np.zeros(rows, complex)
    index = np.arange(rows)
    for q, off in enumerate(offsets):
        count = np.bincount(off % n, minlength=n).astype(complex)        # sparse signals of the targets
        value = np.zeros(n, complex)
        np.add.at(value, off % n, t)
        g1, gt = np.conj(np.fft.fft(np.conj(count))), np.conj(np.fft.fft(np.conj(value)))
        sw = np.fft.ifft(fw * g1, axis=1)                                 # Σ w over the matched points
        sww = np.fft.ifft(fw2 * g1, axis=1).real - np.abs(sw) ** 2 / k
        swt = np.fft.ifft(fwc * gt, axis=1) - np.conj(sw) * t1 / k
        with np.errstate(divide="ignore", invalid="ignore"):
            resid = np.where(sww > 1e-300, stt - np.abs(swt) ** 2 / sww, np.inf)
        j = np.argmin(resid, axis=1)
        r = resid[index, j]
        better = r < best
        best[better], which[better], start[better] = r[better], q, j[better]
        scale[better] = (swt[index, j] / sww[index, j])[better]
    return np.sqrt(np.maximum(best, 0.0) / k), which, start, scale


def placed_designs(shapes, curves, targets, offsets, which, start, scale) -> np.ndarray:
    """The designs (S, 10) of normalised shapes (S, 10) placed by their fitted similarity: s, and τ from
    the matched points' centroid (`procrustes_screen`'s outputs), in the targets' coordinates."""
    d = np.array(shapes, float)
    w = np.asarray(curves, complex)
    t = np.asarray(targets, complex)
    n = w.shape[1]
    idx = (start[:, None] + np.stack([offsets[q] for q in which])) % n                # (S, T)
    matched = np.take_along_axis(w, idx, axis=1)
    tau = (t.sum() - scale * matched.sum(axis=1)) / len(t)
    a0 = scale * (d[:, 0] + 1j * d[:, 1]) + tau
    b0 = scale * (d[:, 2] + 1j * d[:, 3]) + tau
    d[:, 0], d[:, 1], d[:, 2], d[:, 3] = a0.real, a0.imag, b0.real, b0.imag
    d[:, 4:9] *= np.abs(scale)[:, None]
    return d


def traced(designs, count: int) -> np.ndarray:
    """Coupler curves (S, count) complex of designs (S, 10) over a full crank turn from 0."""
    _, _, p, _ = fourbar_coupler_paths(designs, np.linspace(0.0, TWO_PI, count, endpoint=False))
    return p[..., 0] + 1j * p[..., 1]
