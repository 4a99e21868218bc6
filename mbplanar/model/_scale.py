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
    """The size of a mechanism's drawing: the largest distance between two of its drawn joints.

    Parameters
    ----------
    mech : Mechanism
        The model (its joints' drawn places, m).

    Returns
    -------
    float
        The size, m; 0 when every joint is drawn at one place (or there is none).

    Raises
    ------
    Nothing on a `Mechanism`.

    Examples
    --------
    >>> from mbplanar.model import drawing_size, read_model
    >>> round(drawing_size(read_model("models/fourbar.toml")), 4)       # O to B
    0.3917
    """
    spots = [j.at for j in mech.joints.values()]
    return max((math.dist(a, b) for a in spots for b in spots), default=0.0)


def scale_ratio(value: float, size: float) -> float:
    """|value| / size (inf for a size of 0 and a nonzero value; 1 when both are 0)."""
    value, size = abs(float(value)), abs(float(size))
    if size == 0:
        return 1.0 if value == 0 else math.inf
    return value / size


def out_of_scale(value: float, size: float, factor: float = SCALE_FACTOR) -> bool:
    """Whether a length is out of scale with a reference size: the rule that flags a unit typed wrong.

    Parameters
    ----------
    value : float
        The length, m (its sign is ignored).
    size : float
        The reference, m (the drawing's size, `drawing_size`).
    factor : float, optional
        How many times larger or smaller is flagged (`SCALE_FACTOR`, 100).

    Returns
    -------
    bool
        True when |value| / size is `factor` or more, or 1/`factor` or less (both boundaries included, to
        a relative `SLACK`); False for a zero or non-finite value or size, which are not judged.

    Raises
    ------
    Nothing: numbers are judged, anything else is a `TypeError` from the arithmetic.

    Examples
    --------
    >>> from mbplanar.model import out_of_scale
    >>> out_of_scale(250.0, 0.39), out_of_scale(0.25, 0.39), out_of_scale(0.0039, 0.39)
    (True, False, True)
    """
    if value == 0 or size == 0 or not (math.isfinite(value) and math.isfinite(size)):
        return False
    ratio = scale_ratio(value, size)
    return ratio >= factor * (1.0 - SLACK) or ratio <= (1.0 + SLACK) / factor


def scale_message(what: str, value: float, size: float, unit: str, unit_scale: float,
                  reference: str = "the drawing spans") -> str:
    """The words of the scale warning: the value, the size, their ratio and the unit the file is read in.

    Parameters
    ----------
    what : str
        What the value is, ending in its verb ("free_length =", "the s diagram spans").
    value, size : float
        The length and the reference it is out of scale with, m.
    unit : str
        The unit the file is read in ("mm").
    unit_scale : float
        Its size, m.
    reference : str, optional
        What the size is, with its verb.

    Returns
    -------
    str
        '`what` V u while `reference` S u (ratio): is it in another unit? ...', V and S in `unit`.

    Raises
    ------
    ZeroDivisionError
        A `unit_scale` of 0, or a `value` of 0 against a nonzero size (not out of scale: not asked).

    Examples
    --------
    >>> from mbplanar.model import scale_message
    >>> scale_message("free_length =", 0.25, 0.0004, "mm", 1e-3)
    'free_length = 250 mm while the drawing spans 0.4 mm (625 times that): is it in another unit? ...'
    """
    ratio = scale_ratio(value, size)
    times = f"{ratio:.3g} times" if ratio >= 1 else f"1/{1 / ratio:.3g} of"
    return (f"{what} {value / unit_scale:.6g} {unit} while {reference} {size / unit_scale:.6g} {unit} "
            f"({times} that): is it in another unit? (lengths here are read in {unit})")


def warn_scale(what: str, value: float, size: float, unit: str, unit_scale: float, *, source=None, where=None,
               reference: str = "the drawing spans", stacklevel: int = 3) -> bool:
    """Warn when a length is out of scale with the drawing (`out_of_scale`): every reader's one rule.

    Parameters
    ----------
    what, value, size, unit, unit_scale, reference
        As in `scale_message`.
    source : str, optional
        The file the message names.
    where : str, optional
        The row or key the message names.
    stacklevel : int, optional
        As in `warnings.warn`: the caller to point at.

    Returns
    -------
    bool
        Whether it warned.

    Raises
    ------
    Nothing: it warns (`ModelWarning`), which a ``-W error`` filter turns into an exception.

    Examples
    --------
    >>> import warnings
    >>> from mbplanar.model import warn_scale
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     warned = warn_scale("length =", 300.0, 0.39, "m", 1.0, source="arm.toml", where="links[0]")
    >>> warned, str(caught[0].message)[:50]
    (True, 'arm.toml: links[0]: length = 300 m while the drawi')
    """
    if not out_of_scale(value, size):
        return False
    message = scale_message(what, value, size, unit, unit_scale, reference)
    warnings.warn(ModelWarning(str(ModelError(message, source=source, where=where))), stacklevel=stacklevel)
    return True


# -- where the engine measures from ------------------------------------------------------------------
FRAME_GRID = 16.0  # the origin of a mechanism's own frame lies on a grid of at least this many sizes


def frame_origin(points, size: float) -> np.ndarray:
    """The origin of the frame a mechanism is solved in (`Engine.centre`).

    The mean of its drawn joints rounded to a grid whose spacing is the power of two at or above
    `FRAME_GRID` × `size`. Positions measured from it are vectors within the mechanism (a few sizes long),
    so that closure residuals and their tolerances mean the same wherever the mechanism is drawn. On that
    grid it is 0 for a mechanism drawn within a few sizes of the world's origin (the world frame itself,
    exactly), and moving a drawn coordinate into the frame (p − origin) is exact (Sterbenz: the two are
    within a factor 2 of each other, or the origin's component is 0).

    Parameters
    ----------
    points : array_like
        The drawn joints (N, 2), or (N, 2, D) for D designs, m.
    size : float
        The mechanism's size, m (`drawing_size`).

    Returns
    -------
    numpy.ndarray
        The origin (2,), or (2, D), m; zeros for a size that is not positive and finite.

    Raises
    ------
    Nothing on numbers; an empty `points` gives a NaN origin (numpy's mean of nothing).

    Examples
    --------
    >>> from mbplanar.model import frame_origin
    >>> frame_origin([[0.0, 0.0], [0.3, 0.0]], 0.39)                   # near the origin: the world's
    array([0., 0.])
    >>> frame_origin([[1000.0, 5.0], [1000.3, 5.0]], 0.39)             # far: on a grid of 8 m
    array([1000.,    8.])
    """
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
    """Refuse or warn about a mechanism drawn too far from the world's origin for its size.

    Its drawn coordinates carry rounding of ~1e-16 of their own size, ~1e-16 × ratio of the mechanism's,
    which its answers inherit (the engine solves in the mechanism's own frame, `frame_origin`, so that
    nothing else depends on where it lies).

    Parameters
    ----------
    mech : Mechanism
        The model.
    size : float, optional
        Its size, m (`drawing_size` unless given).

    Returns
    -------
    None

    Raises
    ------
    ModelError
        The farthest joint is more than `FAR_REFUSED` (1e11) times the size from the origin.

    Warns
    -----
    PrecisionWarning
        More than `FAR_GUARANTEED` (1e8) times the size.

    Examples
    --------
    >>> from mbplanar.model import check_far, read_model, translated
    >>> mech = read_model("models/fourbar.toml")
    >>> check_far(mech) is None                                         # near: silent
    True
    >>> check_far(translated(mech, (1e11, 0.0)))
    Traceback (most recent call last):
    mbplanar.errors.ModelError: models/fourbar.toml: joints are drawn up to ... from the origin, ...
    """
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
