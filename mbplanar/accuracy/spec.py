"""The `[tolerances]` section: toleranced dimensions with their bands, the pairs' clearances, what is
reported, and the Monte Carlo's size and seed.

    [tolerances]
    outputs = ["M", "3"]                                   # default: every joint, point and moving link
    dimensions = [
      { name = "links.2.length", band = 0.0002 },          # ±0.2 mm (uniform), in the length_unit
      { name = "joints.C.x", band = [-0.0001, 0.0003] },   # asymmetric: the mean moves by +0.1 mm
      { name = "input.zero", sigma = 0.05 },               # normal, σ = 0.05° (the input's unit)
    ]
    clearances = [{ joint = "B", clearance = 0.00005 }]    # R: radial; P: the block's play across its guide

A band is uniform between its limits (σ = (upper − lower)/√12, ±b: σ = b/√3); a `sigma` row is normal
about the nominal value, and its worst case is taken as ±3σ. Every number is in its dimension's unit
(`mbplanar.accuracy.geometry` lists the dimensions a model has and what each means). The keys are
declared in `mbplanar.model._keys` (`TOLERANCES`); `read_tolerances` reads them through those declarations
and names the row of every mistake.
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass

from ..errors import ModelError
from ..model import CLEARANCE, TOLERANCE, TOLERANCES, Row

__all__ = ["Tolerance", "Clearance", "ToleranceSpec", "read_tolerances", "closest", "WORST_SIGMAS"]

WORST_SIGMAS = 3.0   # the worst case of a normal row: ±3σ


@dataclass(frozen=True)
class Tolerance:
    """One toleranced dimension `name`, its deviations from nominal in its own unit: uniform between `lower`
    and `upper`, or (`sigma` not None) normal with that standard deviation about the nominal value.

    Examples
    --------
    >>> t = Tolerance("links.2.length", -0.1, 0.1)
    >>> round(t.std, 6), t.mean, t.half_width
    (0.057735, 0.0, 0.1)
    """

    name: str
    lower: float = 0.0
    upper: float = 0.0
    sigma: float | None = None
    row: str = ""

    @property
    def distribution(self) -> str:
        return "normal" if self.sigma is not None else "uniform"

    @property
    def mean(self) -> float:
        """The mean deviation (a band's middle; 0 for a normal row)."""
        return 0.0 if self.sigma is not None else 0.5 * (self.lower + self.upper)

    @property
    def std(self) -> float:
        """The standard deviation: (upper − lower)/√12 for a band, σ for a normal row."""
        return self.sigma if self.sigma is not None else (self.upper - self.lower) / math.sqrt(12.0)

    @property
    def half_width(self) -> float:
        """Half the worst-case range about the mean: (upper − lower)/2, or 3σ."""
        return WORST_SIGMAS * self.sigma if self.sigma is not None else 0.5 * (self.upper - self.lower)


@dataclass(frozen=True)
class Clearance:
    """The clearance of one pair: how far its two elements may move apart.

    Attributes
    ----------
    joint : str
        The pair's name.
    value : float
        The clearance, m: an R pair's radial clearance (pin and hole's radii apart), a P pair's largest
        offset of the block across its guide.
    row : str
        Where the row was read (for messages).

    Examples
    --------
    >>> from mbplanar.accuracy import Clearance
    >>> Clearance("A", 2e-5).value           # 20 µm of radial clearance in pair A
    2e-05
    """

    joint: str
    value: float
    row: str = ""


@dataclass(frozen=True)
class ToleranceSpec:
    """A model's `[tolerances]` section, read: what is toleranced, what is measured, how it is sampled.

    Attributes
    ----------
    dimensions : tuple of Tolerance
        The toleranced dimensions' bands, in the dimensions' units.
    clearances : tuple of Clearance
        The pairs' clearances, m.
    outputs : tuple of str or None
        The outputs' names as written; None: every joint, point and moving link.
    samples, seed : int
        The Monte Carlo's size and its generator's seed.
    positions : int
        Positions over the cycle.

    Examples
    --------
    >>> from mbplanar.accuracy import Tolerance, ToleranceSpec
    >>> spec = ToleranceSpec((Tolerance("links.2.length", -1e-4, 1e-4),), outputs=("Bp.x",), samples=1000)
    >>> [t.name for t in spec.dimensions], spec.positions, spec.seed
    (['links.2.length'], 360, 0)
    """

    dimensions: tuple[Tolerance, ...] = ()
    clearances: tuple[Clearance, ...] = ()
    outputs: tuple[str, ...] | None = None
    samples: int = 100_000
    seed: int = 0
    positions: int = 360


def closest(name: str, names) -> str:
    """' (closest: a, b, c)' or '' : the names most like `name`, for a message."""
    near = difflib.get_close_matches(str(name), [str(n) for n in names], n=3, cutoff=0.5)
    return f" (closest: {', '.join(near)})" if near else ""


def read_tolerances(raw, source: str, dimensions, joints, length_scale: float = 1.0, higher=None) -> ToleranceSpec:
    """Read a model's `[tolerances]` section into a `ToleranceSpec`, every name checked against the model.

    Parameters
    ----------
    raw : dict
        The section as TOML gives it: "dimensions" (rows {name, band = b or [lower, upper]} or
        {name, sigma}), "clearances" (rows {joint, clearance}), "outputs", "samples", "seed",
        "positions".
    source : str
        The model file, for the messages.
    dimensions : collection of str
        The names of the dimensions the model has (`catalogue`).
    joints : dict
        The model's joints by name (a clearance names one).
    length_scale : float
        Metres per length unit of the table (clearances are returned in metres).
    higher : dict, optional
        The model's higher pairs by name (their kinds), for the message of a clearance naming one.

    Returns
    -------
    ToleranceSpec
        The bands in the dimensions' units, the clearances in metres.

    Raises
    ------
    ModelError
        A name the model does not have (with the closest names), a negative band or clearance, a row with
        both or neither of band and sigma, an unknown key, a pair listed twice, a count below its bound.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.accuracy import catalogue, read_tolerances
    >>> from mbplanar.accuracy.run import load
    >>> template, raw, engine = load("models/fourbar.toml")
    >>> names = catalogue(engine, raw, template)
    >>> section = {"dimensions": [{"name": "links.2.length", "band": 1e-4},
    ...                           {"name": "joints.C.x", "band": [-5e-5, 1e-4]}],
    ...            "clearances": [{"joint": "A", "clearance": 2e-5}], "samples": 1000}
    >>> spec = read_tolerances(section, "models/fourbar.toml", names, engine.mech.joints)
    >>> [(t.name, t.lower, t.upper) for t in spec.dimensions], spec.samples
    ([('links.2.length', -0.0001, 0.0001), ('joints.C.x', -5e-05, 0.0001)], 1000)
    >>> read_tolerances({"dimensions": [{"name": "links.2.lenght", "band": 1e-4}]}, "models/fourbar.toml",
    ...                 names, engine.mech.joints)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    mbplanar.errors.ModelError: ... 'links.2.lenght' is not a dimension of the model (closest: links.2.length, ...)
    """
    where = f"{source}: [tolerances]"
    if not isinstance(raw, dict):
        raise ModelError(f"{where}: must be a table (dimensions = [...], clearances = [...])")
    top = Row(raw, where, section=TOLERANCES)
    rows = _rows(top, "dimensions", where)
    pairs = _rows(top, "clearances", where)
    outputs = top.raw("outputs")
    samples, seed, positions = (top.get(k) for k in ("samples", "seed", "positions"))
    top.check_unknown_keys()
    dims, seen = [], set()
    for k, spec in enumerate(rows):
        name = spec.get("name") if isinstance(spec, dict) else None
        label = f"{where} dimensions[{k}]" + (f" '{name}'" if isinstance(name, str) else "")
        tol = _tolerance(Row(spec, label, section=TOLERANCE), dimensions)
        if tol.name in seen:
            raise ModelError(f"{label}: '{tol.name}' is toleranced twice")
        seen.add(tol.name)
        dims.append(tol)
    found, given = [], set()
    for k, spec in enumerate(pairs):
        joint = spec.get("joint") if isinstance(spec, dict) else None
        label = f"{where} clearances[{k}]" + (f" '{joint}'" if isinstance(joint, (str, int)) else "")
        row = Row(spec, label, section=CLEARANCE)
        joint = row.get("joint")
        if higher and joint in higher:
            row.fail(f"'{joint}' is a {higher[joint].kind} pair: clearances are for revolute and prismatic pairs "
                     "(a higher pair's play, its backlash, is outside its rigid contact law); give the clearance "
                     "of the pairs its links turn or slide in")
        if joint not in joints:
            row.fail(f"'{joint}' is not a joint of the model{closest(joint, joints)}")
        if joint in given:
            row.fail(f"joint '{joint}' is listed twice")
        given.add(joint)
        value = row.get("clearance")
        row.check_unknown_keys()
        found.append(Clearance(joint, value * length_scale, label))
    if outputs is not None:
        if not isinstance(outputs, list) or not all(isinstance(o, (str, int)) and not isinstance(o, bool)
                                                    for o in outputs):
            top.fail(f"'outputs' must be a list of names, got {outputs!r}")
        outputs = tuple(str(o) for o in outputs)
    return ToleranceSpec(tuple(dims), tuple(found), outputs, samples, seed, positions)


def _rows(top: Row, key: str, where: str) -> list:
    rows = top.raw(key, [])
    if not isinstance(rows, list) or not all(isinstance(r, dict) for r in rows):
        raise ModelError(f"{where}: '{key}' must be a list of rows {{ ... }}")
    return rows


def _tolerance(row: Row, dimensions) -> Tolerance:
    name = row.get("name")
    if name not in dimensions:
        row.fail(f"'{name}' is not a dimension of the model{closest(name, dimensions)}")
    band, sigma = row.raw("band"), row.get("sigma")
    row.check_unknown_keys()
    if (band is None) == (sigma is None):
        row.fail("give a band (b or [lower, upper]) or a sigma, not " + ("both" if band is not None else "neither"))
    if sigma is not None:
        return Tolerance(name, sigma=sigma, row=row.where)
    if isinstance(band, list) and len(band) == 2 and all(_finite(b) for b in band):
        lower, upper = float(band[0]), float(band[1])
        if lower > upper:
            row.fail(f"the band's lower deviation {lower:g} is above its upper one {upper:g}: the band's width "
                     "must not be negative")
        return Tolerance(name, lower, upper, row=row.where)
    if not _finite(band):
        row.fail(f"'band' must be a number b (±b) or [lower, upper], got {band!r}")
    if band < 0:
        row.fail(f"the band must not be negative, got {band:g}")
    return Tolerance(name, -float(band), float(band), row=row.where)


def _finite(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)
