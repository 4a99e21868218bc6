"""The order in which a curve meets untimed targets, judged with a tolerance.

Targets are given in their order along the wanted curve. On a design's coupler curve each target has a
position: the arc length, along the curve traced by the input, of its nearest point. The curve meets
the targets in order when, in one sense, each target's position follows the previous one's (and the
whole run goes round a closed curve at most once). Two targets that lie almost on top of each other,
or a little noise on dense targets, can put a target a hair *behind* its predecessor: that is not a
defect a designer cares about, so a step back is accepted up to a tolerance that scales with the
targets' spacing (half their median spacing), and never more than a small part of the curve
(`CURVE_SHARE` of its length). Every step back is still reported, with its length, so that the
result can say which targets it takes out of order and by how much.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["OrderReport", "order_tolerance", "order_report", "curve_positions"]

SPACING_SHARE = 0.5
"""A step back is accepted up to this share of the targets' median spacing ..."""
CURVE_SHARE = 0.02
"""... and never more than this share of the curve's length."""


@dataclass(frozen=True)
class OrderReport:
    """How a curve meets the targets: `sense` (+1 along the traced direction, −1 against it); `back`
    (T − 1,) the length each step k → k + 1 goes back along the curve (0 for a step forward);
    `tolerance` the step back accepted; `length` the curve's length; `ok` no step back beyond it."""

    sense: int
    back: np.ndarray
    tolerance: float
    length: float

    @property
    def ok(self) -> bool:
        return bool(np.all(self.back <= self.tolerance))

    @property
    def excess(self) -> float:
        """Total length of the steps back beyond the tolerance (0 when in order)."""
        return float(np.sum(np.maximum(self.back - self.tolerance, 0.0)))

    def steps_back(self) -> list[tuple[int, int, float]]:
        """[(k, k + 1, length back)] (1-based targets) of every step that goes back."""
        return [(k + 1, k + 2, float(b)) for k, b in enumerate(self.back) if b > 0.0]


def order_tolerance(targets, length: float) -> float:
    """The step back accepted: half the median spacing of consecutive targets (T, 2), at most
    `CURVE_SHARE` of the curve's `length`."""
    t = np.asarray(targets, float)
    spacing = float(np.median(np.hypot(*np.diff(t, axis=0).T))) if len(t) > 1 else 0.0
    return min(SPACING_SHARE * spacing, CURVE_SHARE * float(length))


def order_report(positions, length: float, targets, closed: bool = True) -> OrderReport:
    """How positions (T,) along a curve of `length` (closed: positions modulo the length) meet the
    targets in their order, in the better of the two senses."""
    s = np.asarray(positions, float)
    tol = order_tolerance(targets, length)
    best = None
    for sense in (1, -1):
        u = sense * (s - s[0])
        if closed:   # positions from the first target, a step back across the start allowed up to tol
            u = np.mod(u + tol, length) - tol
        back = np.maximum(u[:-1] - u[1:], 0.0)
        excess = float(np.sum(np.maximum(back - tol, 0.0)))
        key = (excess, float(np.sum(back)))
        if best is None or key < best[0]:
            best = (key, OrderReport(sense, back, tol, float(length)))
    return best[1]


def curve_positions(points, closed: bool = True) -> np.ndarray:
    """Arc length (P + 1,) at each of the curve's points (P, 2) from the first, the last entry the
    whole length (closed: back to the first point)."""
    p = np.asarray(points, float)
    if closed:
        p = np.vstack([p, p[:1]])
    return np.r_[0.0, np.cumsum(np.hypot(*np.diff(p, axis=0).T))]
