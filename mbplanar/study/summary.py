"""The per-design summary a designer filters on, and its serial reference: one engine per design
through the public API (`check`, `analyse`, `kinetostatics`).

`summarise(engine, ...)` gives a `DesignSummary`: whether the drawn pose assembles, whether the input
turns fully, the motion limits (lock or dead points) with their kind and input value, the extreme
positions and stroke of every output link and slider with the quick-return ratio, the smallest
transmission angle, coupler-curve samples of chosen points and, where the model has loads or masses,
the largest reaction and the mean balancing moment over the samples. Angles inside are radians; the
`_deg` fields are degrees.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace

import numpy as np

from ..analysis import LimitReport, check
from ..errors import MbplanarError, ModelError
from ..kinematics import analyse
from ..forces import kinetostatics
from ..forces import has_force_data
from ..model import parse_model
from .dimensions import with_dimensions

__all__ = ["DesignSummary", "SummaryLimit", "SummaryChangePoint", "SummaryExtreme", "summarise", "summarise_design",
           "failed_design", "with_forces", "SAMPLES"]

SAMPLES = 36  # coupler-curve (and force) samples over the range the input moves through


@dataclass(frozen=True)
class SummaryLimit(LimitReport):
    """A design's motion limit: `check`'s (`LimitReport`: the input value in the model's unit, the
    direction it is met in, the links and joints in line, its kind and the sentence) and the input value
    in degrees."""

    phi_deg: float


@dataclass(frozen=True)
class SummaryChangePoint:
    """A change point a design passes: the input value (model unit, and in degrees), the links and
    joints in line, its kind."""

    phi: float
    links: list
    joints: list
    kind: str
    phi_deg: float


@dataclass(frozen=True)
class SummaryExtreme:
    """An output's extremes: a link's angle (rad) or a slider's displacement (m), at input values (model
    unit); `stroke` (None for a link that turns) and `quick_return` (the input's travel over the slower
    stroke divided by its travel over the faster one, ≥ 1; full turn only, else None)."""

    name: str
    kind: str
    minimum: float | None
    at_min: float | None
    maximum: float | None
    at_max: float | None
    turns: bool
    stroke: float | None
    quick_return: float | None


@dataclass(frozen=True, eq=False)
class DesignSummary:
    """The numbers one design is judged by in a study.

    Attributes
    ----------
    name, parameters : str, dict
        The variant's name and its parameter values (each in its parameter's unit).
    assembles : bool
        The drawn pose closes and is not singular; `reason` says why not.
    reason : str or None
        Why the design does not assemble.
    full_turn : bool or None
        The input turns a whole revolution without a motion limit (None: not assembled).
    range : (2,) tuple or None
        The input values (model unit) the input moves through from the drawn pose.
    limits : list of SummaryLimit
        Motion limits.
    change_points : list of SummaryChangePoint
        Branch crossings passed.
    extremes : list of SummaryExtreme
        Link angles (rad) and slider displacements (m) at their extremes, at input values (model
        unit), strokes and quick-return ratios.
    transmission_min_deg, transmission_at, transmission_pair : float, float, str
        The smallest transmission angle (degrees), where, and at which pair.
    samples_phi : (S,) ndarray or None
        Input values of the samples (model unit).
    samples : dict
        {point: (S, 2) ndarray} of the sampled points, m.
    max_reaction, max_reaction_joint, mean_balancing : float, str, float
        The largest reaction (N) and its joint, the mean balancing moment (N·m) or force (N): with
        loads or masses only.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.study import summarise
    >>> s = summarise(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), samples=12)
    >>> s.assembles, s.full_turn, s.limits, round(s.transmission_min_deg, 2)
    (True, True, [], 41.41)
    """

    name: str
    parameters: dict
    assembles: bool
    reason: str | None = None
    full_turn: bool | None = None
    range: tuple | None = None
    limits: list = field(default_factory=list)
    change_points: list = field(default_factory=list)
    extremes: list = field(default_factory=list)
    transmission_min_deg: float | None = None
    transmission_at: float | None = None
    transmission_pair: str | None = None
    samples_phi: np.ndarray | None = None
    samples: dict = field(default_factory=dict)
    max_reaction: float | None = None
    max_reaction_joint: str | None = None
    mean_balancing: float | None = None

    def as_dict(self) -> dict:
        """JSON-ready document (arrays as lists)."""
        doc = asdict(self)
        doc["samples_phi"] = None if self.samples_phi is None else [float(x) for x in self.samples_phi]
        doc["samples"] = {k: np.asarray(v).tolist() for k, v in self.samples.items()}
        doc["range"] = None if self.range is None else list(self.range)
        return doc


def failed_design(name: str, parameters: dict, reason: str) -> DesignSummary:
    """The summary of a design that cannot be assembled (or is refused), with its reason."""
    return DesignSummary(name, parameters, False, reason)


def _to_deg(inp, value: float) -> float:
    """An input value in the model's unit, in degrees (revolute inputs only)."""
    return math.degrees(inp.to_si(value)) if inp.unit in ("deg", "rad") else float("nan")


def _limits(inp, report) -> tuple[list, list]:
    limits = [SummaryLimit(**asdict(lim), phi_deg=_to_deg(inp, lim.phi)) for lim in report.limits]
    crossings = [SummaryChangePoint(c.phi, c.links, c.joints, c.kind, _to_deg(inp, c.phi))
                 for c in report.change_points]
    return limits, crossings


def _extremes(inp, report) -> list:
    out = []
    for e in report.extremes:
        quick = None
        if report.full_turn and not e.turns:
            turn = inp.from_si(2 * math.pi)
            forward = (e.at_max - e.at_min) % turn
            if 0 < forward < turn:
                quick = max(forward, turn - forward) / min(forward, turn - forward)
        out.append(SummaryExtreme(e.name, e.kind, e.minimum, e.at_min, e.maximum, e.at_max, e.turns,
                                  None if e.turns else e.maximum - e.minimum, quick))
    return out


def _transmission(report) -> tuple:
    if not report.transmission:
        return None, None, None
    worst = min(report.transmission, key=lambda a: a.minimum)
    return math.degrees(worst.minimum), worst.at_min, worst.name


def _samples(engine, lo: float, hi: float, points, count: int, full_turn: bool):
    """Input values (model unit) and the kinematics at `count` samples over [lo, hi] (SI); a full turn
    leaves out its end (the start again)."""
    inp = engine.inputs[0]
    grid = np.linspace(lo, hi, count + 1 if full_turn else count)[:count] if count else np.zeros(0)
    motion = analyse(engine, grid)
    xy = {p: motion.xy[:, motion.point(p)] for p in points}
    return inp.from_si(motion.phi[:, 0]), xy, motion


def _forces(engine, motion) -> tuple:
    result = kinetostatics(engine, motion)
    magnitudes = {name: r.magnitude for name, r in result.reactions.items()}
    joint = max(magnitudes, key=lambda n: np.nanmax(magnitudes[n], initial=-np.inf))
    balancing = next(iter(result.balancing.values()))
    return float(np.nanmax(magnitudes[joint])), joint, float(np.nanmean(balancing))


def summarise(engine, name: str = "", parameters: dict | None = None, points=(), samples: int = SAMPLES,
              forces: bool | None = None) -> DesignSummary:
    """The summary of one design: assembly, full turn or limits, extremes, transmission angle, forces.

    Parameters
    ----------
    engine : Engine
        A one-input mechanism.
    name, parameters : str, dict
        The variant's name and parameter values, copied into the summary.
    points : sequence of str
        Points (joints or points of interest) whose coupler curves are sampled.
    samples : int
        Samples over the range the input moves through.
    forces : bool, optional
        Reactions and balancing moment over the samples; default: when the model has loads or masses.

    Returns
    -------
    DesignSummary
        The design's numbers (a design that does not assemble gets `assembles` False and its reason).

    Raises
    ------
    ModelError
        A model with more than one input.

    Examples
    --------
    The rocker of models/fourbar.toml (OA 0.1, AB 0.3, BC 0.25, OC 0.3 m) swings between the dead
    centres OB = 0.4 and 0.2 m: arccos(−0.05) − arccos(0.75) = 0.898083 rad, with the crank 197.146°
    apart going one way and 162.854° the other:

    >>> import mbplanar
    >>> from mbplanar.study import summarise
    >>> s = summarise(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), samples=12, points=["M"])
    >>> rocker = next(e for e in s.extremes if e.name == "3")
    >>> rocker.turns, round(rocker.stroke, 6), round(rocker.quick_return, 5), s.samples["M"].shape
    (False, 0.898083, 1.21057, (12, 2))
    """
    if len(engine.inputs) != 1:
        raise ModelError(f"{engine.mech.source}: a design study drives one input; this model has "
                         f"{len(engine.inputs)}")
    inp = engine.inputs[0]
    report = check(engine)
    limits, crossings = _limits(inp, report)
    t_min, t_at, t_pair = _transmission(report)
    lo, hi = (inp.to_si(x) for x in report.range)
    phi, xy, motion = _samples(engine, lo, hi, points, samples, report.full_turn)
    out = DesignSummary(name, dict(parameters or {}), True, None, report.full_turn, tuple(report.range), limits,
                        crossings, _extremes(inp, report), t_min, t_at, t_pair, phi, xy)
    if (has_force_data(engine.mech) if forces is None else forces) and len(motion.phi):
        out = with_forces(out, *_forces(engine, motion))
    return out


def with_forces(summary: DesignSummary, max_reaction, joint, mean_balancing) -> DesignSummary:
    """The summary with its largest reaction (N), where it acts, and its mean balancing load."""
    return replace(summary, max_reaction=max_reaction, max_reaction_joint=joint, mean_balancing=mean_balancing)


def summarise_design(base, template, name: str, values: dict, points=(), samples: int = SAMPLES,
                     forces: bool | None = None) -> DesignSummary:
    """One design of a study, by itself: bind its parameters, re-dimension the reference engine `base`
    (`with_dimensions`) and summarise it; a design that cannot be built or assembled gets its reason."""
    try:
        mech = parse_model(template.bind(values), source=f"{template.source} [variant {name}]")
        engine = with_dimensions(base, mech)
        return summarise(engine, name, values, points, samples, forces)
    except MbplanarError as exc:
        return failed_design(name, values, str(exc))
