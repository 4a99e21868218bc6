"""Running a design study: every variant of a table summarised, in chunks of designs that run one
after the other here, or one task each on a Dask cluster (`client`). The chunks are the same either
way, and each is computed by the same function from the same data, so a study on a cluster equals the
serial run bit for bit."""

from __future__ import annotations

import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

from ..errors import ModelError
from ..parameters import Template
from ..table import parse_model
from .summary import SAMPLES, DesignSummary, summarise_design
from .variants import Variants, read_variants

__all__ = ["Study", "run_study", "load_template", "CHUNK"]

CHUNK = 64  # designs per task


@dataclass
class Study:
    """The summaries of a study's designs (in table order) and what they were computed for."""

    model: str
    source: str
    input: str
    unit: str
    parameters: tuple
    designs: list[DesignSummary]

    @property
    def counts(self) -> dict:
        """How many designs: in all, assembled, turning fully, stopping at a motion limit."""
        ok = [d for d in self.designs if d.assembles]
        return {"designs": len(self.designs), "assembled": len(ok),
                "full_turn": sum(bool(d.full_turn) for d in ok),
                "locking": sum(bool(d.limits) and not d.full_turn for d in ok)}


def load_template(model) -> Template:
    """A `Template` from a model file path, TOML text or a parsed dict (or a Template as it is)."""
    if isinstance(model, Template):
        return model
    if isinstance(model, dict):
        return Template(model)
    path = Path(model)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ModelError(f"{path}: cannot read the model file ({exc})") from None
    try:
        return Template(tomllib.loads(text), str(path))
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"{path}: TOML syntax error: {exc}") from None


def _base_engine(template: Template):
    from ..solver import Engine

    return Engine(parse_model(template.bind(), source=template.source))


def run_chunk(data: dict, source: str, variants: Variants, points=(), samples: int = SAMPLES,
              forces=None) -> list[DesignSummary]:
    """Summaries of a chunk of designs (one Dask task): the reference engine is compiled once, then
    re-dimensioned per design."""
    template = Template(data, source)
    base = _base_engine(template)
    return [summarise_design(base, template, variants.names[k], variants.row(k), points, samples, forces)
            for k in range(len(variants))]


def _chunks(count: int, size: int) -> list[slice]:
    return [slice(start, min(start + size, count)) for start in range(0, count, size)]


def run_study(model, variants, *, points=(), samples: int = SAMPLES, forces=None, client=None,
              chunk: int = CHUNK, progress=None) -> Study:
    """Summarise every design of a variant table.

    Parameters
    ----------
    model : str, Path, dict or Template
        The model with its `[parameters]`.
    variants : Variants or str or Path
        The designs (a `Variants`, or the path of a CSV variant table).
    points : sequence of str
        Points whose coupler curves are sampled.
    samples : int
        Samples per design over its range of motion.
    forces : bool, optional
        Reactions and balancing moment (default: when the model has loads or masses).
    client : dask.distributed.Client, optional
        Run the chunks as tasks on this client's cluster; default: here, one after the other.
    chunk : int
        Designs per chunk (per task).
    progress : callable, optional
        Called as progress(done, total) after each chunk (designs done so far).

    Returns
    -------
    Study
    """
    template = load_template(model)
    if not isinstance(variants, Variants):
        variants = read_variants(variants, template)
    if chunk < 1:
        raise ValueError(f"chunk must be a positive number of designs, not {chunk}")
    base = _base_engine(template)
    if len(base.inputs) != 1:
        raise ModelError(f"{template.source}: a design study drives one input; this model has {len(base.inputs)}")
    for p in points:
        if p not in base.mech.joints and p not in base.mech.points:
            raise ModelError(f"{template.source}: point '{p}' is neither a joint nor a point of the model")
    parts = [variants.take(s) for s in _chunks(len(variants), chunk)]
    args = (tuple(points), samples, forces)
    if client is None:
        results, done = [], 0
        for part in parts:
            results.append(run_chunk(template.raw, template.source, part, *args))
            done += len(part)
            if progress is not None:
                progress(done, len(variants))
    else:
        from .cluster import run_on_client

        results = run_on_client(client, run_chunk, template.raw, template.source, parts, args, progress)
    inp = base.inputs[0]
    designs = [d for part in results for d in part]
    return Study(base.mech.name, template.source, inp.name, inp.unit, template.names, designs)


def stderr_progress(done: int, total: int):
    """A plain progress counter on stderr."""
    print(f"\r{done}/{total} designs", end="\n" if done == total else "", file=sys.stderr, flush=True)
