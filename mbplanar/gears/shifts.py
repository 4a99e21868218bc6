"""Choosing the profile shifts: the block contour of admissible (x₁, x₂) and a choice by a stated criterion.

The block contour (the course books' "blocking contour") is the region of the (x₁, x₂) plane where every
check of `pair.margins` is met: no undercut, tips not too thin, no interference with the mate's root,
contact ratio large enough (internal pairs: the ring's tip outside its base circle, no trochoid
interference). It is computed on a grid (every check evaluated for the whole grid at once); its edges
are the zero lines of the margins.

Criteria (`choose_shifts`):

- ``balanced``: equal specific sliding at the root ends of the two active profiles, ζ₁(A) = ζ₂(E); with
  the sum x_Σ free, the point of that curve inside the contour where the (equal) sliding is least;
- ``contact``: the largest transverse contact ratio ε_α inside the contour;
- ``sum``: the given x_Σ (`shift_sum`, or the one a fixed `centre_distance` needs), split to balance the
  sliding (the admissible point of the line x₁ + x₂ = x_Σ nearest to balance when balance lies outside).

A fixed centre distance, or a given sum, restricts every criterion to the line x₁ + x₂ = x_Σ (internal
pairs: x₂ − x₁ = x_Σ). The optimum is located on grids refined around the best point until the step is
below 1e-7 (in shift units).

    >>> from mbplanar.gears import choose_shifts
    >>> c = choose_shifts(10e-3, (12, 30), "balanced")
    >>> c.pair.success, [round(x, 3) for x in c.shifts]
    (True, [0.592, 0.528])
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from .involute import inv
from .pair import (MARGIN_TOLERANCE, MIN_CONTACT, MIN_TIP, GearPair, gear_pair, margins, mesh, shift_sum_for, validate_module,
                   validate_teeth)
from .rack import Rack

__all__ = ["BlockContour", "ShiftChoice", "block_contour", "choose_shifts", "CRITERIA"]

CRITERIA = ("balanced", "contact", "sum")
GRID = 241                 # points per axis of the contour's grid
STEP = 1e-7                # the choice's resolution in x


@dataclass(frozen=True)
class BlockContour:
    """The checks' margins over a grid of (x₁, x₂).

    Attributes
    ----------
    x1, x2 : (N1,), (N2,) the grid's axes
    margins : dict mapping "check gear" (e.g. "undercut 1", "contact ratio") to an (N2, N1) array, ≥ 0 met
    admissible : (N2, N1) bool, every check met
    sliding_gap : (N2, N1) ζ₁(A) − ζ₂(E) (zero on the balanced-sliding curve)
    contact_ratio : (N2, N1) ε_α
    internal : bool
    shift_sum : x_Σ of a fixed centre distance or given sum (None: free)

    Examples
    --------
    >>> from mbplanar.gears import block_contour
    >>> c = block_contour(10e-3, (12, 30), grid=41)
    >>> c.admissible.shape, round(c.area, 2)
    ((41, 41), 0.48)
    """

    x1: np.ndarray
    x2: np.ndarray
    margins: dict
    admissible: np.ndarray
    sliding_gap: np.ndarray
    contact_ratio: np.ndarray
    internal: bool
    shift_sum: float | None = None

    @property
    def area(self) -> float:
        """The admissible area (in x² units), from the grid."""
        return float(self.admissible.sum() * np.diff(self.x1).mean() * np.diff(self.x2).mean())


@dataclass(frozen=True)
class ShiftChoice:
    """The shifts chosen by `criterion`, the pair they give and the contour they were chosen in.

    Attributes
    ----------
    criterion : "balanced", "contact" or "sum"
    shifts : (x₁, x₂)
    pair : GearPair at those shifts
    contour : BlockContour
    shift_sum : the x_Σ the choice was held to (None: free)
    success : the chosen pair meets every check
    message : how the point was found

    Examples
    --------
    >>> from mbplanar.gears import choose_shifts
    >>> c = choose_shifts(10e-3, (12, 30), "sum", centre_distance=0.215)
    >>> round(c.pair.centre_distance, 12), round(sum(c.shifts), 6)
    (0.215, 0.541619)
    """

    criterion: str
    shifts: tuple
    pair: GearPair
    contour: BlockContour
    shift_sum: float | None
    success: bool
    message: str


def _limits(module, z1, z2, internal, rack, min_tip):
    """The grid's box: each gear's shift from below its undercut limit to a little past a pointed tip."""
    boxes = []
    for k, z in ((1, z1), (2, z2)):
        ring = internal and k == 2
        xmin = -1.0 if ring else rack.flank_end - z * math.sin(rack.pressure_angle) ** 2 / 2
        xs = np.linspace(-1.5, 4.0, 2201)                    # the tip alone (no mate: Δy = 0)
        thick = _tip_alone(module, z, xs, rack, ring) >= min_tip * module
        first = int(np.argmax(thick)) if thick.any() else xs.size
        thin = np.flatnonzero(~thick[first:])
        hi = float(xs[first + thin[0]]) + 0.25 if thin.size else 4.0
        boxes.append((min(xmin, 0.0) - 0.5, min(hi, 4.0)))
    return boxes


def _tip_alone(module, z, x, rack, ring=False):
    """s_a of a gear with shift x and no tip shortening (m); a ring's: of its tooth at its tip."""
    al, sign = rack.pressure_angle, -1.0 if ring else 1.0
    d, db = module * z, module * z * math.cos(al)
    da = d + sign * 2 * module * (rack.addendum + sign * x)
    s = module * (math.pi / 2 + sign * 2 * x * math.tan(al))
    with np.errstate(invalid="ignore"):
        alpha_a = np.where(da >= db, np.arccos(np.clip(db / da, -1, 1)), np.nan)
        return da * (s / d + sign * (inv(al) - inv(alpha_a)))


def _evaluate(module, z1, z2, x1, x2, rack, internal, min_tip, min_contact, ring_tip="standard"):
    q = mesh(module, z1, z2, x1, x2, rack, internal, ring_tip)
    mg = margins(q, x1, x2, module, internal, min_tip, min_contact)
    ok = np.ones(np.broadcast(x1, x2).shape, bool)
    for v in mg.values():
        ok &= v >= -MARGIN_TOLERANCE
    return q, mg, ok


def _label(name, gear):
    return name if gear is None else f"{name} {gear}"


def block_contour(module: float, teeth, *, internal: bool = False, rack: Rack | None = None,
                  min_tip: float = MIN_TIP, min_contact: float = MIN_CONTACT, box=None, grid: int = GRID,
                  shift_sum: float | None = None, ring_tip: str = "standard") -> BlockContour:
    """The block contour of a pair: every check's margin over a grid of (x₁, x₂).

    Parameters
    ----------
    module : float
        m, metres.
    teeth : (int, int)
        z₁, z₂ (for an internal pair, z₂ is the ring's).
    internal : bool
        An internal pair (pinion and ring).
    rack : Rack, optional
        The basic rack (default: the standard 20° rack).
    min_tip, min_contact : float
        the limits of the pointed-tip (tip thickness / m) and contact-ratio checks.
    box : ((x1_lo, x1_hi), (x2_lo, x2_hi)), optional
        the grid's extent (default: from below each gear's undercut limit to past its pointed tip).
    grid : int
        points per axis.
    shift_sum : float, optional
        recorded for the picture (the line of a fixed centre distance).
    ring_tip : {"standard", "cut"}
        an internal pair's ring tip (see `pair.mesh`).

    Returns
    -------
    BlockContour
        The grid, each check's margin on it, and where every check passes (`admissible`).

    Raises
    ------
    ModelError
        A module that is not positive, or a tooth number that is not a whole number ≥ 1.
    TypeError, ValueError
        `teeth` not a pair, or a `box` that is not two (low, high) ranges.

    Examples
    --------
    >>> from mbplanar.gears import block_contour
    >>> c = block_contour(10e-3, (12, 30))
    >>> bool(c.admissible.any()), sorted(c.margins)[:2]
    (True, ['contact ratio', 'interference 1'])
    """
    rack = Rack() if rack is None else rack
    m = validate_module(module, "module")
    z1, z2 = validate_teeth(*teeth, internal=internal, where="teeth")
    (a1, b1), (a2, b2) = box if box is not None else _limits(m, z1, z2, internal, rack, min_tip)
    x1 = np.linspace(a1, b1, grid)
    x2 = np.linspace(a2, b2, grid)
    X1, X2 = np.meshgrid(x1, x2)
    q, mg, ok = _evaluate(m, z1, z2, X1, X2, rack, internal, min_tip, min_contact, ring_tip)
    named = {_label(name, gear): v for (name, gear), v in mg.items()}
    with np.errstate(invalid="ignore"):
        gap = q["zeta1_A"] - q["zeta2_E"]
    return BlockContour(x1, x2, named, ok, gap, q["eps"], internal, shift_sum)


def _line(shift_sum, internal):
    """x₂ as a function of x₁ on the line of a fixed sum."""
    return (lambda x1: shift_sum + x1) if internal else (lambda x1: shift_sum - x1)


def _balanced_on_lines(module, z1, z2, sums, lo, hi, rack, internal, ring_tip="standard", iterations=80):
    """x₁ where ζ₁(A) = ζ₂(E) on each line x₁ + x₂ = S (internal: x₂ − x₁ = S), by bisection in x₁ on
    [lo, hi] for all S at once; NaN where the gap does not change sign."""
    sums = np.asarray(sums, float)
    lo, hi = np.full_like(sums, lo), np.full_like(sums, hi)

    def gap(x1):
        x2 = sums + x1 if internal else sums - x1
        q = mesh(module, z1, z2, x1, x2, rack, internal, ring_tip)
        with np.errstate(invalid="ignore"):
            g = q["zeta1_A"] - q["zeta2_E"]
        return np.where(np.isfinite(g), g, np.where(q["zeta1_A"] == -np.inf, -1e300, 1e300))

    g_lo, g_hi = gap(lo), gap(hi)
    valid = np.sign(g_lo) != np.sign(g_hi)
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        g_mid = gap(mid)
        left = np.sign(g_mid) == np.sign(g_lo)
        lo, g_lo = np.where(left, mid, lo), np.where(left, g_mid, g_lo)
        hi = np.where(left, hi, mid)
    return np.where(valid, 0.5 * (lo + hi), np.nan)


def _best(values, admissible):
    """Index of the largest value among the admissible points, or None."""
    if not np.any(admissible):
        return None
    v = np.where(admissible, values, -np.inf)
    return int(np.argmax(v))


def _refine_1d(score, lo, hi, points=401):
    """The argmax of score(x) (vectorised; −inf where not admissible) on [lo, hi], by grids zoomed
    around the best point until the step is below STEP. None when nothing is admissible."""
    best = None
    while True:
        xs = np.linspace(lo, hi, points)
        s = score(xs)
        k = _best(s, np.isfinite(s))
        if k is None:
            return best
        best = float(xs[k])
        step = (hi - lo) / (points - 1)
        if step < STEP:
            return best
        lo, hi = best - 2 * step, best + 2 * step


def _refine_2d(score, box, points=161):
    """The argmax of score(x1, x2) (vectorised over a grid; −inf where not admissible) in `box`."""
    (a1, b1), (a2, b2) = box
    best = None
    while True:
        X1, X2 = np.meshgrid(np.linspace(a1, b1, points), np.linspace(a2, b2, points))
        s = score(X1, X2)
        k = _best(s.ravel(), np.isfinite(s.ravel()))
        if k is None:
            return best
        best = (float(X1.ravel()[k]), float(X2.ravel()[k]))
        h1, h2 = (b1 - a1) / (points - 1), (b2 - a2) / (points - 1)
        if max(h1, h2) < STEP:
            return best
        a1, b1, a2, b2 = best[0] - 2 * h1, best[0] + 2 * h1, best[1] - 2 * h2, best[1] + 2 * h2


def choose_shifts(module: float, teeth, criterion: str = "balanced", *, internal: bool = False,
                  rack: Rack | None = None, centre_distance: float | None = None, shift_sum: float | None = None,
                  min_tip: float = MIN_TIP, min_contact: float = MIN_CONTACT, box=None,
                  ring_tip: str = "standard") -> ShiftChoice:
    """Choose x₁, x₂ inside the block contour by `criterion`.

    Parameters
    ----------
    module : float
        m, metres.
    teeth : (int, int)
    criterion : {"balanced", "contact", "sum"}
    internal : bool
    rack : Rack, optional
    centre_distance : float, optional
        a fixed working centre distance (m): fixes x_Σ.
    shift_sum : float, optional
        a given x_Σ = x₁ + x₂ (internal: x₂ − x₁); needed by "sum" unless `centre_distance` is given.
    min_tip, min_contact : float
        the limits of the checks.
    box : optional
        the contour's grid extent (see `block_contour`).
    ring_tip : {"standard", "cut"}
        an internal pair's ring tip (see `pair.mesh`).

    Returns
    -------
    ShiftChoice

    Raises
    ------
    ModelError
        an unknown criterion, "sum" without a sum, both a sum and a centre distance that disagree, or no
        admissible point (the message names the pair and the line).

    Examples
    --------
    >>> from mbplanar.gears import choose_shifts
    >>> c = choose_shifts(10e-3, (12, 30), "sum", shift_sum=0.5)
    >>> round(sum(c.shifts), 12), round(c.pair.gears[0].root_sliding - c.pair.gears[1].root_sliding, 9)
    (0.5, 0.0)
    """
    rack = Rack() if rack is None else rack
    m = validate_module(module, "module")
    z1, z2 = validate_teeth(*teeth, internal=internal, where="teeth")
    if criterion not in CRITERIA:
        raise ModelError(f"--criterion: unknown criterion {criterion!r} (one of {', '.join(CRITERIA)})")
    if centre_distance is not None:
        if not (isinstance(centre_distance, (int, float)) and math.isfinite(centre_distance) and centre_distance > 0):
            raise ModelError(f"--centre-distance must be > 0, got {centre_distance!r}")
        fixed = shift_sum_for(z1, z2, centre_distance, m, rack, internal)
        if shift_sum is not None and abs(fixed - shift_sum) > 1e-9:
            raise ModelError(f"--shift-sum {shift_sum:g} disagrees with --centre-distance "
                             f"{centre_distance * 1e3:g} mm, which needs x_Σ = {fixed:.6g}")
        shift_sum = fixed
    if shift_sum is not None and not math.isfinite(shift_sum):
        raise ModelError(f"--shift-sum must be finite, got {shift_sum!r}")
    if criterion == "sum" and shift_sum is None:
        raise ModelError("--criterion sum needs --shift-sum or --centre-distance")
    contour = block_contour(m, (z1, z2), internal=internal, rack=rack, min_tip=min_tip, min_contact=min_contact,
                            box=box, shift_sum=shift_sum, ring_tip=ring_tip)
    (a1, b1), (a2, b2) = (contour.x1[0], contour.x1[-1]), (contour.x2[0], contour.x2[-1])

    def evaluate(x1, x2):
        return _evaluate(m, z1, z2, x1, x2, rack, internal, min_tip, min_contact, ring_tip)

    where = f"z = {z1}, {z2}" + (" (internal)" if internal else "")
    if shift_sum is not None:
        line = _line(shift_sum, internal)
        # the part of the line inside the box: x₁ in [a1, b1] and x₂ in [a2, b2]
        ends = sorted(((a2 - shift_sum), (b2 - shift_sum)) if internal else ((shift_sum - b2), (shift_sum - a2)))
        lo, hi = max(a1, ends[0]), min(b1, ends[1])
        xs = np.linspace(lo, hi, 4001) if hi > lo else np.array([])
        if not xs.size or not evaluate(xs, line(xs))[2].any():
            raise ModelError(f"no admissible shifts on the line x_Σ = {shift_sum:.6g} for {where}: every point "
                             f"fails a check (see the block contour)")
        if criterion == "contact":
            def score(x):
                q, _, ok = evaluate(x, line(x))
                return np.where(ok, q["eps"], -np.inf)
            x1 = _refine_1d(score, lo, hi)
            how = f"the largest contact ratio on the line x_Σ = {shift_sum:.6g}"
        else:
            x1 = float(_balanced_on_lines(m, z1, z2, [shift_sum], lo, hi, rack, internal, ring_tip)[0])
            q, _, ok = evaluate(np.array([x1]), line(np.array([x1]))) if math.isfinite(x1) else (None, None, [False])
            if math.isfinite(x1) and ok[0]:
                how = f"balanced specific sliding on the line x_Σ = {shift_sum:.6g}"
            else:
                def nearest(x):
                    q, _, ok = evaluate(x, line(x))
                    return np.where(ok, -np.abs(q["zeta1_A"] - q["zeta2_E"]), -np.inf)
                x1 = _refine_1d(nearest, lo, hi)
                how = (f"the admissible point of the line x_Σ = {shift_sum:.6g} nearest to balanced sliding "
                       f"(balance lies outside the contour)")
        x2 = float(line(x1))
    elif criterion == "contact":
        def score2(x1, x2):
            q, _, ok = evaluate(x1, x2)
            return np.where(ok, q["eps"], -np.inf)
        if not contour.admissible.any():
            raise ModelError(f"no admissible shifts for {where}: every point of the block contour fails a check")
        x1, x2 = _refine_2d(score2, ((a1, b1), (a2, b2)))
        how = "the largest contact ratio inside the block contour"
    else:
        x1, x2, how = _balanced_least_sliding(m, z1, z2, rack, internal, evaluate, contour, where, ring_tip)
    pair = gear_pair(m, (z1, z2), (x1, x2), internal=internal, rack=rack, min_tip=min_tip, min_contact=min_contact,
                     ring_tip=ring_tip)
    return ShiftChoice(criterion, (x1, x2), pair, contour, shift_sum, pair.success,
                       how if pair.success else f"{how}; but {pair.message}")


def _balanced_least_sliding(m, z1, z2, rack, internal, evaluate, contour, where, ring_tip):
    """On the balanced-sliding curve, the admissible point with the least sliding |ζ₁(A)|: the curve is
    followed as x₁(x_Σ) (bisection on each line of constant sum), over grids of x_Σ refined around the
    best."""
    a1, b1 = contour.x1[0], contour.x1[-1]
    a2, b2 = contour.x2[0], contour.x2[-1]
    lo, hi = (a2 - b1, b2 - a1) if internal else (a1 + a2, b1 + b2)

    def score(sums):
        x1 = _balanced_on_lines(m, z1, z2, sums, a1, b1, rack, internal, ring_tip)
        x2 = sums + x1 if internal else sums - x1
        q, _, ok = evaluate(x1, x2)
        ok &= np.isfinite(x1) & (x2 >= a2) & (x2 <= b2)
        return np.where(ok, q["zeta1_A"], -np.inf)           # ζ ≤ 0: the largest is the least sliding

    best = _refine_1d(score, lo, hi, points=201)
    if best is None:
        raise ModelError(f"no admissible shifts with balanced sliding for {where}: the balanced-sliding curve "
                         f"stays outside the block contour (choose --criterion contact, or give --shift-sum)")
    x1 = float(_balanced_on_lines(m, z1, z2, [best], a1, b1, rack, internal, ring_tip)[0])
    x2 = best + x1 if internal else best - x1
    return x1, float(x2), f"balanced specific sliding, least sliding inside the block contour (x_Σ = {best:.6g})"
