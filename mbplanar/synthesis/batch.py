"""Batches of candidate four-bars scored at once: coupler curves (D, P, 2) in closed form and the
distance of target points from them. This is the seam for a path-generation search over design batches
(a global stage scoring thousands of designs per call); a chosen design is then written as a model and
checked by mbplanar (`designs_toml`, `defects.check_defects`).

A design row holds 10 numbers: the fixed pivots A0 (x, y) and B0 (x, y), the crank a, coupler b and
rocker c lengths, the coupler point (u, v) in the coupler's frame (u along A→B, v to its left) and the
assembly mode (+1: B to the left of A→B0, −1 to the right).
"""

from __future__ import annotations

import numpy as np

from ._models import fourbar_toml

__all__ = ["DESIGN_COLUMNS", "fourbar_coupler_paths", "path_errors", "design_toml"]

DESIGN_COLUMNS = ("a0x", "a0y", "b0x", "b0y", "crank", "coupler", "rocker", "u", "v", "mode")


def fourbar_coupler_paths(designs, phi) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Joints A, B and the coupler point of D four-bar designs at P crank angles, in closed form.

    Parameters
    ----------
    designs : (D, 10) array_like
        Rows of `DESIGN_COLUMNS`: fixed pivots A0 and B0 (x, y, m), crank, coupler and rocker lengths
        (m), the coupler point (u along A→B, v to its left, m) and the assembly mode (+1: B to the left
        of A→B0, -1 to the right).
    phi : (P,) or (D, P) array_like
        Crank angles (rad, direction of A0→A): the same for every design, or one row each.

    Returns
    -------
    a, b, p : (D, P, 2) ndarray
        Joints A, B and the coupler point, m (meaningless where `ok` is False).
    ok : (D, P) ndarray of bool
        False where the loop cannot close.

    Raises
    ------
    ValueError
        Rows of another width or shapes of `phi` that do not broadcast (numpy's errors); no design
        check here: a zero-length link gives NaN, reported as not `ok`.

    Examples
    --------
    models/fourbar.toml as a design row: its coupler point M at 60°, 100° and 140°:

    >>> import numpy as np
    >>> from mbplanar.synthesis import fourbar_coupler_paths
    >>> design = [0.0, 0.0, 0.3, 0.0, 0.1, 0.3, 0.25, 0.15, 0.05, 1]
    >>> a, b, p, ok = fourbar_coupler_paths([design], np.radians([60, 100, 140]))
    >>> p[0].round(4).tolist(), bool(ok.all())
    ([[0.1486, 0.2102], [0.0896, 0.2149], [0.0259, 0.1846]], True)
    """
    d = np.atleast_2d(np.asarray(designs, float))
    phi = np.asarray(phi, float)
    phi = phi[None, :] if phi.ndim == 1 else phi
    a0, b0 = d[:, None, 0:2], d[:, None, 2:4]
    crank, coupler, rocker = d[:, 4:5], d[:, 5:6], d[:, 6:7]
    a = a0 + crank[..., None] * np.stack([np.cos(phi), np.sin(phi)], -1)
    delta = b0 - a
    dist = np.hypot(delta[..., 0], delta[..., 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        along = (coupler ** 2 - rocker ** 2 + dist ** 2) / (2 * dist)
        h2 = coupler ** 2 - along ** 2
        ok = (h2 >= 0) & (dist > 0)
        h = d[:, 9:10] * np.sqrt(np.where(ok, h2, 0.0))
        unit = delta / dist[..., None]
    normal = np.stack([-unit[..., 1], unit[..., 0]], -1)
    b = a + along[..., None] * unit + h[..., None] * normal
    e = (b - a) / coupler[..., None]
    left = np.stack([-e[..., 1], e[..., 0]], -1)
    p = a + d[:, None, 7:8] * e + d[:, None, 8:9] * left
    return a, b, p, ok


def path_errors(paths, ok, targets) -> tuple[np.ndarray, np.ndarray]:
    """How far target points are from each of D sampled coupler curves: RMS and largest distance.

    Parameters
    ----------
    paths : (D, P, 2) ndarray
        The curves, sampled (as `fourbar_coupler_paths` gives them), m.
    ok : (D, P) ndarray of bool
        Where each curve closes.
    targets : (T, 2) array_like
        Target points, m.

    Returns
    -------
    rms, largest : (D,) ndarray
        RMS and largest distance of the targets from the nearest sampled point of each curve, m; inf
        for a curve that does not close at every sample.

    Raises
    ------
    ValueError
        Shapes that do not match (numpy's broadcasting error).

    Examples
    --------
    A crank-rocker whose curve passes through the targets, and one with a 0.5 m crank that cannot turn:

    >>> import numpy as np
    >>> from mbplanar.synthesis import fourbar_coupler_paths, path_errors
    >>> designs = [[0.0, 0.0, 0.3, 0.0, 0.1, 0.3, 0.25, 0.15, 0.05, 1],
    ...            [0.0, 0.0, 0.3, 0.0, 0.5, 0.3, 0.25, 0.15, 0.05, 1]]
    >>> a, b, p, ok = fourbar_coupler_paths(designs, np.linspace(0, 2 * np.pi, 360, endpoint=False))
    >>> targets = [[0.1486, 0.2102], [0.0896, 0.2149], [0.0259, 0.1846]]
    >>> rms, largest = path_errors(p, ok, targets)
    >>> bool(largest[0] < 1e-4), float(largest[1])
    (True, inf)
    """
    t = np.asarray(targets, float)
    gap = np.hypot(paths[:, :, None, 0] - t[None, None, :, 0], paths[:, :, None, 1] - t[None, None, :, 1])
    near = np.where(ok[..., None], gap, np.inf).min(axis=1)          # (D, T)
    full = ok.all(axis=1)
    rms = np.where(full, np.sqrt(np.mean(near ** 2, axis=1)), np.inf)
    return rms, np.where(full, near.max(axis=1), np.inf)


def design_toml(design, phi0: float = 0.0) -> str:
    """One design row as a model drawn at crank angle `phi0` (rad); the coupler point is 'P'."""
    a, b, p, ok = fourbar_coupler_paths(np.asarray(design, float)[None], [phi0])
    if not ok[0, 0]:
        from ..errors import ModelError
        raise ModelError("the design cannot be assembled at the drawn crank angle")
    d = np.asarray(design, float)
    return fourbar_toml(d[0:2], a[0, 0], b[0, 0], d[2:4], {"P": p[0, 0]}, name="path_generator",
                        title="Four-bar (design batch)")
