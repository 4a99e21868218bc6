"""Plausibility of a model's numbers against the size of its drawing: one rule for every reader.

A length typed in another unit than the file's (metres in a millimetre file, millimetres where metres
are meant) is off the drawing by a factor of 1000 or more; a length that is really meant is rarely a
hundredth of the machine it belongs to, or a hundred times larger. So a length whose ratio to the
drawing's size is `SCALE_FACTOR` (100) or more, or 1/`SCALE_FACTOR` or less, is flagged with a
`ModelWarning` that gives the value, the drawing's size, their ratio and the unit the file is read in.
Both boundaries belong to the flagged side (a ratio of exactly 100 warns), to the rounding of the
ratio (`SLACK`).

The drawing's size (`drawing_size`) is the largest distance between two joints of the drawn pose. The
readers that use this rule: the resistance diagram (`s × stroke`), a spring's free length and tension
table, a link's extent and dimensions, the points a load acts at, a cam's stroke and lengths, a
counterweight's radius, a variant table's lengths (against the parameter's declared value), the target
points of path synthesis (against the model's drawing).
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from ..errors import ModelError, ModelWarning, PrecisionWarning

__all__ = ["SCALE_FACTOR", "SLACK", "drawing_size", "out_of_scale", "scale_ratio", "scale_message",
           "warn_scale", "FRAME_GRID", "frame_origin", "FAR_GUARANTEED", "FAR_REFUSED", "far_ratio",
           "check_far"]

SCALE_FACTOR = 100.0   # a length this many times larger or smaller than the drawing is flagged
SLACK = 1e-9           # relative rounding allowed at a boundary: a ratio of 100 (or 1/100) to rounding warns


def drawing_size(mech) -> float:
    """The largest distance (m) between two joints of `mech`'s drawn pose (0 when there is one place)."""
    spots = [j.at for j in mech.joints.values()]
    return max((math.dist(a, b) for a in spots for b in spots), default=0.0)


def scale_ratio(value: float, size: float) -> float:
    """|value| / size (inf for a size of 0 and a nonzero value; 1 when both are 0)."""
    value, size = abs(float(value)), abs(float(size))
    if size == 0:
        return 1.0 if value == 0 else math.inf
    return value / size


def out_of_scale(value: float, size: float, factor: float = SCALE_FACTOR) -> bool:
    """Whether a nonzero length `value` is `factor` times the reference `size` or more, or 1/`factor` of it
    or less (both boundaries included, to a relative `SLACK`). A zero value or a zero size is not judged."""
    if value == 0 or size == 0 or not (math.isfinite(value) and math.isfinite(size)):
        return False
    ratio = scale_ratio(value, size)
    return ratio >= factor * (1.0 - SLACK) or ratio <= (1.0 + SLACK) / factor


def scale_message(what: str, value: float, size: float, unit: str, unit_scale: float,
                  reference: str = "the drawing spans") -> str:
    """'`what` V u while `reference` S u (ratio×): is it in another unit? ...' with V and S in the unit
    `unit` (of `unit_scale` metres) the file is read in; `what` ends in its verb ("free_length =",
    "the s diagram spans")."""
    ratio = scale_ratio(value, size)
    times = f"{ratio:.3g} times" if ratio >= 1 else f"1/{1 / ratio:.3g} of"
    return (f"{what} {value / unit_scale:.6g} {unit} while {reference} {size / unit_scale:.6g} {unit} "
            f"({times} that): is it in another unit? (lengths here are read in {unit})")


def warn_scale(what: str, value: float, size: float, unit: str, unit_scale: float, *, source=None, where=None,
               reference: str = "the drawing spans", stacklevel: int = 3) -> bool:
    """A `ModelWarning` naming `source` and `where` when `value` is out of scale with `size` (see
    `out_of_scale`); whether it warned."""
    if not out_of_scale(value, size):
        return False
    message = scale_message(what, value, size, unit, unit_scale, reference)
    warnings.warn(ModelWarning(str(ModelError(message, source=source, where=where))), stacklevel=stacklevel)
    return True


# -- where the engine measures from ------------------------------------------------------------------
FRAME_GRID = 16.0  # the origin of a mechanism's own frame lies on a grid of at least this many sizes


def frame_origin(points, size: float) -> np.ndarray:
    """The origin of the frame a mechanism is solved in: the mean of its drawn joints `points` ((N, 2),
    or (N, 2, D) for D designs) rounded to a grid whose spacing is the power of two at or above
    `FRAME_GRID` × `size` ((2,), or (2, D)).

    Positions measured from it are vectors within the mechanism (a few sizes long), so that closure
    residuals and their tolerances mean the same wherever the mechanism is drawn. On that grid it is 0
    for a mechanism drawn within a few sizes of the world's origin (the world frame itself, exactly),
    and moving a drawn coordinate into the frame (p − origin) is exact (Sterbenz: the two are within a
    factor 2 of each other, or the origin's component is 0)."""
    mean = np.mean(np.asarray(points, float), axis=0)
    if not (size > 0 and math.isfinite(size)):
        return np.zeros_like(mean)
    grid = 2.0 ** math.ceil(math.log2(FRAME_GRID * size))
    return np.round(mean / grid) * grid + 0.0  # (+ 0.0: no −0)


FAR_GUARANTEED = 1e8   # drawn up to this many sizes from the origin, the answers are the origin's (see docs/units.md)
FAR_REFUSED = 1e11     # beyond, the drawing's coordinates hold its shape to fewer than 5 digits: refused
ROUNDING = 2.0 ** -53  # relative rounding of a coordinate


def far_ratio(mech, size: float | None = None) -> tuple[float, float, float]:
    """(distance, size, ratio): how far the farthest drawn joint of `mech` lies from the world's
    origin (m), the drawing's size (m, `drawing_size` unless given) and their ratio (0 for a size 0)."""
    size = drawing_size(mech) if size is None else size
    distance = max((math.hypot(*j.at) for j in mech.joints.values()), default=0.0)
    return distance, size, (distance / size if size > 0 else 0.0)


def check_far(mech, size: float | None = None):
    """A `PrecisionWarning` for a mechanism drawn more than `FAR_GUARANTEED` times its size from the
    world's origin, a `ModelError` beyond `FAR_REFUSED`: its drawn coordinates carry rounding of
    ~1e-16 of their own size, ~1e-16 × ratio of the mechanism's, which its answers inherit (the engine
    solves in the mechanism's own frame, `frame_origin`, so that nothing else depends on where it lies)."""
    distance, size, ratio = far_ratio(mech, size)
    if ratio <= FAR_GUARANTEED or not math.isfinite(ratio):
        return
    units = mech.units
    k = units.length_scale
    where = (f"joints are drawn up to {distance / k:.6g} {units.length} from the origin, {ratio:.3g} times the "
             f"mechanism's size ({size / k:.6g} {units.length})")
    if ratio > FAR_REFUSED:
        raise ModelError(f"{where}: its coordinates hold its shape only to ~{ROUNDING * ratio:.1g} of its size "
                         f"(beyond {FAR_REFUSED:g} times the size, fewer than 5 digits); move the drawing nearer "
                         "the origin", source=mech.source)
    warnings.warn(PrecisionWarning(str(ModelError(
        f"{where}: its coordinates hold its shape only to ~{ROUNDING * ratio:.1g} of its size, and the results "
        f"may differ by about as much from the same mechanism drawn near the origin (within {FAR_GUARANTEED:g} "
        "times its size they are the origin's, to ~1e-16 times that ratio); move the drawing nearer the origin",
        source=mech.source))), stacklevel=3)
