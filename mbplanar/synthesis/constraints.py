"""Design constraints of path generation beyond meeting the targets: a full crank turn, a smallest
transmission angle, a largest ratio of link lengths, and boxes that the fixed pivots must lie in.

`PathConstraints` holds them; `fourbar_violations` measures how far batches of four-bar designs are
from meeting them (a length per constraint, zero when met), which the global stage adds to its
objective as a penalty and the least-squares polish as weighted residuals. A design that does not meet
them on mbplanar's own analysis is never reported as a solution (`path._verified`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError

__all__ = ["PathConstraints", "fourbar_violations", "transmission_angles", "read_constraints"]

PIVOTS = ("A0", "B0")
"""The fixed pivots of the four-bar: crank pivot A0, rocker pivot B0."""


@dataclass(frozen=True)
class PathConstraints:
    """What a path generator must satisfy besides the targets.

    Attributes
    ----------
    full_turn : bool
        The input crank turns fully (Grashof, the crank the shortest link) on one branch; False: the
        targets need only lie on one branch between two motion limits.
    min_transmission_deg : float or None
        Smallest transmission angle μ (deviation of the angle between coupler and rocker from 0 and
        180°) over the travel, degrees, in [0, 90).
    max_ratio : float or None
        Largest ratio longest / shortest of the links (the ground included), above 1.
    pivots : dict
        {"A0" or "B0" (or a generic model's ground joint): ((x_min, y_min), (x_max, y_max))} boxes, m.
    transmission_joints : tuple or None
        (J1, J2, J3) joints of a generic model whose angle at J2 is the transmission angle (the
        four-bar's is at B between A and B0).

    Raises
    ------
    ModelError
        On construction, for a value out of these ranges or a box that is not [[x_min, y_min],
        [x_max, y_max]] with x_min < x_max and y_min < y_max.

    Examples
    --------
    >>> from mbplanar.synthesis import PathConstraints
    >>> c = PathConstraints(min_transmission_deg=30.0, max_ratio=10.0, pivots={"A0": ((-1, -1), (0, 0))})
    >>> c.box("A0")[1].tolist(), c.box("B0")
    ([0.0, 0.0], None)
    >>> PathConstraints(max_ratio=0.5)
    Traceback (most recent call last):
    ...
    mbplanar.errors.ModelError: max_ratio (longest / shortest link) must be a number above 1, got 0.5
    """

    full_turn: bool = True
    min_transmission_deg: float | None = None
    max_ratio: float | None = None
    pivots: dict = field(default_factory=dict)
    transmission_joints: tuple | None = None

    def __post_init__(self):
        mu = self.min_transmission_deg
        if mu is not None and not (isinstance(mu, (int, float)) and 0.0 <= mu < 90.0):
            raise ModelError(f"min_transmission_deg must be a number in [0, 90), got {mu!r}")
        tj = self.transmission_joints
        if tj is not None and not (isinstance(tj, (list, tuple)) and len(tj) == 3 and all(isinstance(n, str) for n in tj)):
            raise ModelError(f"transmission_joints must name three joints [J1, J2, J3], got {tj!r}")
        r = self.max_ratio
        if r is not None and not (isinstance(r, (int, float)) and math.isfinite(r) and r > 1.0):
            raise ModelError(f"max_ratio (longest / shortest link) must be a number above 1, got {r!r}")
        for name, box in self.pivots.items():
            try:
                lo, hi = np.asarray(box, float)
            except (TypeError, ValueError):
                raise ModelError(f"pivot region of {name} must be [[x_min, y_min], [x_max, y_max]], got {box!r}") from None
            if lo.shape != (2,) or not np.all(np.isfinite([lo, hi])) or np.any(hi <= lo):
                raise ModelError(f"pivot region of {name} must be [[x_min, y_min], [x_max, y_max]] with "
                                 f"x_min < x_max and y_min < y_max, got {box!r}")

    def box(self, name: str):
        """(lo (2,), hi (2,)) of pivot `name`'s region, or None."""
        if name not in self.pivots:
            return None
        lo, hi = np.asarray(self.pivots[name], float)
        return lo, hi

    def as_dict(self) -> dict:
        return {"full_turn": self.full_turn, "min_transmission_deg": self.min_transmission_deg,
                "max_ratio": self.max_ratio,
                "pivots": {k: np.asarray(v, float).tolist() for k, v in self.pivots.items()},
                "transmission_joints": list(self.transmission_joints) if self.transmission_joints else None}


def read_constraints(table: dict, where: str, full_turn: bool = True) -> PathConstraints:
    """Constraints from a TOML table {full_turn, min_transmission_deg, max_ratio, pivots = {name: box},
    transmission_joints}."""
    if not isinstance(table, dict):
        raise ModelError(f"{where}: [constraints] must be a table")
    known = ("full_turn", "min_transmission_deg", "max_ratio", "pivots", "transmission_joints")
    unknown = sorted(set(table) - set(known))
    if unknown:
        raise ModelError(f"{where}: unknown constraint(s) {', '.join(unknown)} (known: {', '.join(known)})")
    pivots = table.get("pivots", {})
    if not isinstance(pivots, dict):
        raise ModelError(f"{where}: pivots must be a table {{name = [[x_min, y_min], [x_max, y_max]]}}")
    turn = table.get("full_turn", full_turn)
    if not isinstance(turn, bool):
        raise ModelError(f"{where}: full_turn must be true or false")
    try:
        tj = table.get("transmission_joints")
        return PathConstraints(turn, table.get("min_transmission_deg"), table.get("max_ratio"), dict(pivots),
                               tuple(tj) if isinstance(tj, list) else tj)
    except ModelError as exc:
        raise ModelError(f"{where}: {exc}") from None


def transmission_angles(a, b, b0) -> np.ndarray:
    """Transmission angle μ ∈ [0, π/2] (rad) at joint B between the coupler B→A and the rocker B→B0:
    positions (..., 2) each; 0 at a dead point of the rocker."""
    u, w = a - b, b0 - b
    cross = u[..., 0] * w[..., 1] - u[..., 1] * w[..., 0]
    dot = u[..., 0] * w[..., 0] + u[..., 1] * w[..., 1]
    angle = np.abs(np.arctan2(cross, dot))
    return np.minimum(angle, np.pi - angle)


def _grashof(d, margin: float) -> np.ndarray:
    """(D,) ≥ 0: zero for a crank that turns fully (Grashof, the crank the shortest link) with
    s + l ≤ (1 − margin)(p + q), clear of the change-point four-bars."""
    ground = np.hypot(d[:, 2] - d[:, 0], d[:, 3] - d[:, 1])
    links = np.stack([np.abs(d[:, 4]), np.abs(d[:, 5]), np.abs(d[:, 6]), ground], axis=1)
    s, l = links.min(axis=1), links.max(axis=1)
    pq = links.sum(axis=1) - s - l
    return np.maximum(s + l - (1.0 - margin) * pq, 0.0) + np.maximum(links[:, 0] - links[:, 1:].min(axis=1), 0.0)


def fourbar_violations(c: PathConstraints, d, a, b, ok, size: float, margin: float = 0.01,
                       closure: bool = True) -> np.ndarray:
    """How far designs d (D, 10) are from meeting `c`, in lengths (D, 4) (columns: full turn or
    assembly over the travel, link ratio, transmission angle (rad × size), pivot regions): zero when met.

    a, b (D, P, 2) are the joints A, B over the travel and ok (D, P) where the loop closes (`closure`
    False: a part of the travel may not close, as for untimed targets without a full turn); `margin`
    keeps the penalised designs a little inside the constraints, so that a polished design meets them
    exactly.
    """
    out = np.zeros((len(d), 4))
    if c.full_turn:
        out[:, 0] = _grashof(d, margin)
    if closure:
        out[:, 0] += size * np.mean(~ok, axis=1)
    ground = np.hypot(d[:, 2] - d[:, 0], d[:, 3] - d[:, 1])
    links = np.stack([np.abs(d[:, 4]), np.abs(d[:, 5]), np.abs(d[:, 6]), ground], axis=1)
    if c.max_ratio is not None:
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = links.max(axis=1) / links.min(axis=1)
        out[:, 1] = size * np.nan_to_num(np.maximum(ratio / (c.max_ratio * (1.0 - margin)) - 1.0, 0.0), nan=1e3)
    if c.min_transmission_deg is not None:
        mu = np.where(ok, transmission_angles(a, b, d[:, None, 2:4]), np.pi / 2)
        need = math.radians(c.min_transmission_deg) + margin * math.radians(5.0)
        out[:, 2] = size * np.maximum(need - mu.min(axis=1), 0.0)
    for name, col in zip(PIVOTS, (0, 2)):
        box = c.box(name)
        if box is not None:
            xy = d[:, col:col + 2]
            out[:, 3] += np.hypot(*np.maximum(np.maximum(box[0] - xy, xy - box[1]), 0.0).T)
    return out
