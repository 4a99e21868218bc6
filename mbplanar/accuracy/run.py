"""`accuracy(model)`: a model's `[tolerances]` analysed over its cycle — exact sensitivities, the worst-case
and statistical stacks, the Monte Carlo and the clearances under load — as one `Accuracy` record."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from .clearance import ClearanceErrors, clearance_errors
from .geometry import DesignSpace
from .montecarlo import MonteCarlo, monte_carlo
from .sensitivity import Sensitivities, resolve_outputs, sensitivities
from .spec import ToleranceSpec, read_tolerances
from .stacks import Stack, stack

__all__ = ["Accuracy", "accuracy", "load", "cycle", "MARGIN"]

MARGIN = 0.01   # a cycle between motion limits keeps this fraction of its range clear of each limit


@dataclass(frozen=True)
class Accuracy:
    """The accuracy of a model over its cycle (SI inside: m, rad).

    model, source: the model's name and file; input, unit: the input's name and unit; phi (N,): the
    positions (SI); full_turn: the input turns fully (the positions close a turn); spec: the
    `ToleranceSpec`; dimensions (K,): the toleranced `Dimension`s; outputs (Y,): the `Output`s;
    sensitivities, stack; monte_carlo (None when not asked for or no dimension is toleranced);
    clearances (None without clearances); length_unit: the model's length unit (for ``units="model"``).

    Examples
    --------
    >>> import mbplanar.accuracy as acc
    >>> result = acc.accuracy("models/fourbar.toml", samples=2000, positions=36)
    >>> result.outputs[0].name, result.success
    ('M.x', True)
    """

    model: str
    source: str
    input: str
    unit: str
    phi: np.ndarray
    full_turn: bool
    spec: ToleranceSpec
    dimensions: tuple
    outputs: tuple
    sensitivities: Sensitivities
    stack: Stack
    monte_carlo: MonteCarlo | None
    clearances: ClearanceErrors | None
    length_unit: str = "m"

    @property
    def success(self) -> bool:
        return self.sensitivities.success and (self.monte_carlo is None or self.monte_carlo.success)

    @property
    def message(self) -> str:
        parts = [self.sensitivities.message]
        if self.monte_carlo is not None:
            parts.append(self.monte_carlo.message)
        return "; ".join(parts)

    def as_dict(self) -> dict:
        """The JSON-ready document (SI), as ``mbplanar accuracy --json`` prints it (docs/accuracy.md)."""
        return self.document()

    def document(self, units: str | None = None) -> dict:
        """The JSON-ready document, in SI or (``units="model"``) with lengths in the model's unit."""
        from .report import document
        return document(self, units)

    def table(self, units: str | None = None):
        """(header, columns (N, k)): the CSV of ``mbplanar accuracy -o FILE.csv``, one row per position."""
        from .report import table
        return table(self, units)


def load(model, backend: str = "numpy"):
    """(template, raw mechanism, engine) of a model file, TOML text, dict or `Template`."""
    from ..engine import Engine
    from ..model import parse_model
    from ..study.run import load_template

    template = load_template(model)
    raw = parse_model(template.bind(), source=template.source)
    return template, raw, Engine(raw, backend=backend)


def cycle(engine, positions: int) -> tuple[np.ndarray, bool]:
    """The positions an accuracy study runs over, and whether they close a full turn.

    The input's declared `sweep` (both ends), else a whole turn from the sweep's start for an input
    that turns fully (its end left out), else the range between the motion limits, `MARGIN` of it
    clear of each.

    Parameters
    ----------
    engine : Engine
        The model (one input).
    positions : int
        How many positions.

    Returns
    -------
    phi : (positions,) ndarray
        Input values, SI.
    full_turn : bool
        Whether they close a turn.

    Raises
    ------
    ValueError
        A negative `positions` (numpy's `linspace`); a model that reads gives no error here (a
        model locked at its drawn pose gives a range of one value).

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> from mbplanar.accuracy import cycle
    >>> phi, full = cycle(mbplanar.Engine(mbplanar.read_model("models/slider_crank.toml")), 4)
    >>> np.degrees(phi).round(6).tolist(), full
    ([0.0, 90.0, 180.0, 270.0], True)
    """
    inp = engine.inputs[0]
    if inp.sweep is not None:
        lo, hi = (inp.to_si(v) for v in inp.sweep)
        return np.linspace(lo, hi, positions), False
    lo, hi = engine.reach()
    phi0 = float(engine.phi_drawn[0])
    turns = engine.mech.joints[inp.joint].kind == "R" and lo <= phi0 - 2 * math.pi and hi >= phi0 + 2 * math.pi
    if turns:
        start = inp.to_si(inp.default_sweep()[0])
        return start + 2 * math.pi * np.arange(positions) / positions, True
    if not (math.isfinite(lo) and math.isfinite(hi)) or hi - lo > 4 * math.pi:
        lo, hi = (inp.to_si(v) for v in inp.default_sweep())
        return np.linspace(lo, hi, positions), False
    margin = MARGIN * (hi - lo)
    return np.linspace(lo + margin, hi - margin, positions), False


def accuracy(model, samples: int | None = None, seed: int | None = None, positions: int | None = None,
             outputs=None, backend: str = "numpy", client=None, progress=None, monte_carlo_run: bool = True,
             spec: ToleranceSpec | None = None) -> Accuracy:
    """The accuracy of `model` over its cycle, from its `[tolerances]` section (or `spec`).

    Parameters
    ----------
    model : str, Path, dict or Template
        The model (a file with a `[tolerances]` section).
    samples, seed, positions : int, optional
        Override the section's Monte Carlo size, seed and number of positions.
    outputs : sequence of str, optional
        Override the section's outputs (names as `[tolerances] outputs` takes them).
    backend : {"numpy", "numba"}
        The design batch's loops for the Monte Carlo.
    client : dask.distributed.Client, optional
        Run the Monte Carlo's chunks on a Dask cluster.
    progress : callable, optional
        progress(done, total) as the Monte Carlo's chunks finish.
    monte_carlo_run : bool
        False: the sensitivities, stacks and clearances only.
    spec : ToleranceSpec, optional
        The tolerances, instead of the model's section (names checked against the model).

    Returns
    -------
    Accuracy
        The sensitivities, stacks, Monte Carlo and clearance errors of the model's outputs.

    Raises
    ------
    ModelError
        No `[tolerances]` section, a row naming what the model lacks, a bad band, a count below 1, a model
        with several inputs.
    Interrupted
        Ctrl-C during the Monte Carlo.

    Examples
    --------
    The coupler point M and the rocker 3 of models/fourbar.toml, its seven toleranced dimensions:

    >>> import numpy as np
    >>> import mbplanar.accuracy as acc
    >>> result = acc.accuracy("models/fourbar.toml", samples=500, positions=36)
    >>> [o.name for o in result.outputs], len(result.dimensions), result.monte_carlo.count
    (['M.x', 'M.y', '3.angle'], 7, 500)
    >>> np.round(result.stack.worst.max(axis=0) * [1e3, 1e3, 180 / np.pi], 4).tolist()   # mm, mm, deg
    [0.4446, 0.2575, 0.1295]
    """
    template, raw, engine = load(model, backend)
    source = engine.mech.source
    if len(engine.inputs) != 1:
        raise ModelError(f"accuracy drives one input; this model has {len(engine.inputs)}", source=source)
    from .geometry import catalogue
    every = catalogue(engine, raw, template)
    if spec is None:
        section = template.data.get("tolerances")
        if section is None:
            raise ModelError("the model has no [tolerances] section (docs/format.md, [tolerances])", source=source)
        spec = read_tolerances(section, source, every, engine.mech.joints, engine.mech.units.length_scale,
                               engine.mech.higher)
    else:
        from .spec import closest
        for t in spec.dimensions:
            if t.name not in every:
                raise ModelError(f"'{t.name}' is not a dimension of the model{closest(t.name, every)}",
                                 source=source, where="[tolerances]")
        for c in spec.clearances:
            if c.joint not in engine.mech.joints:
                kind = engine.mech.higher[c.joint].kind if c.joint in engine.mech.higher else None
                raise ModelError((f"'{c.joint}' is a {kind} pair: clearances are for revolute and prismatic pairs"
                                  if kind else f"'{c.joint}' is not a joint of the model"
                                  f"{closest(c.joint, engine.mech.joints)}"), source=source, where="[tolerances]")
    for name, value in (("samples", samples), ("seed", seed), ("positions", positions)):
        low = 0 if name == "seed" else (2 if name == "positions" else 1)
        if value is not None and (isinstance(value, bool) or not isinstance(value, int) or value < low):
            raise ModelError(f"{name} must be a whole number >= {low}, got {value!r}", source=source)
    samples = spec.samples if samples is None else samples
    seed = spec.seed if seed is None else seed
    positions = spec.positions if positions is None else positions
    space = DesignSpace(engine, raw, template, [t.name for t in spec.dimensions])
    outs = resolve_outputs(engine.mech, outputs if outputs is not None else spec.outputs, source)
    phi, full_turn = cycle(engine, positions)
    sens = sensitivities(space, phi, outs)
    stacks = stack(sens, spec.dimensions, space.dimensions)
    mc = None
    if monte_carlo_run and spec.dimensions:
        mc = monte_carlo(space, spec.dimensions, phi, outs, samples, seed, client=client, progress=progress)
    clear = clearance_errors(engine, phi, spec.clearances, outs, full_turn) if spec.clearances else None
    inp = engine.inputs[0]
    return Accuracy(engine.mech.name, str(source), inp.name, inp.unit, phi, full_turn,
                    ToleranceSpec(spec.dimensions, spec.clearances, spec.outputs, samples, seed, positions),
                    space.dimensions, outs, sens, stacks, mc, clear, engine.mech.units.length)

