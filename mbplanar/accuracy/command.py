"""`mbplanar accuracy MODEL [--samples N] [--seed S] [--positions N] [--outputs LIST] [--json | -o FILE.csv]
[--units si|model] [--workers N | --scheduler ADDRESS] [--progress | --no-progress] [--yes]`: the
command-line side of the accuracy analysis (parsing, printing; the work is `accuracy`)."""

from __future__ import annotations

import argparse
import json

from .._progress import Progress, add_long_run_options
from ..model import add_units_option

__all__ = ["add_arguments", "run"]


def _count(low: int):
    def parse(text) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number >= {low}, got {text!r}") from None
        if value < low:
            raise argparse.ArgumentTypeError(f"expected a whole number >= {low}, got {text!r}")
        return value
    return parse


def add_arguments(s):
    """The options of `mbplanar accuracy`."""
    s.add_argument("model", help="a model with a [tolerances] section")
    s.add_argument("--samples", type=_count(1), help="Monte Carlo samples (default: the section's, else 100000)")
    s.add_argument("--seed", type=_count(0), help="the Monte Carlo's seed (default: the section's, else 0)")
    s.add_argument("--positions", type=_count(2), help="positions over the cycle (default: the section's, else 360)")
    s.add_argument("--outputs", help="what to report (comma list of joints, points, links, X.x, L.angle, J.value; "
                                     "default: the section's)")
    s.add_argument("--no-monte-carlo", action="store_true", help="sensitivities, stacks and clearances only")
    g = s.add_mutually_exclusive_group()
    g.add_argument("--json", action="store_true", help="everything as JSON (SI)")
    g.add_argument("-o", "--output", help="CSV file, one row per position")
    add_units_option(s, "the lengths of the JSON and CSV")
    w = s.add_mutually_exclusive_group()
    w.add_argument("--workers", type=_count(1), help="run the Monte Carlo on a Dask LocalCluster of N workers")
    w.add_argument("--scheduler", help="run the Monte Carlo on the Dask cluster of this scheduler")
    add_long_run_options(s, "the Monte Carlo's first chunks")


def run(args) -> int:
    """Run the analysis the arguments describe and print or write it."""
    from ..errors import ModelError
    from ..io import write_csv
    from ..study.cluster import close, connect, local_client
    from .report import document, format_text, table
    from .run import accuracy

    outputs = None
    if args.outputs is not None:
        outputs = [n.strip() for n in args.outputs.split(",") if n.strip()]
        if not outputs:
            raise ModelError("--outputs needs names separated by commas")
    client = local_client(args.workers) if args.workers else connect(args.scheduler) if args.scheduler else None
    bar = _Bar(args.progress, args.yes, args.model)
    try:
        result = accuracy(args.model, samples=args.samples, seed=args.seed, positions=args.positions,
                          outputs=outputs, backend=args.backend, client=client, progress=bar,
                          monte_carlo_run=not args.no_monte_carlo)
    finally:
        bar.close()
        if client is not None:
            close(client)
    if args.json:
        print(json.dumps(document(result, units=args.units), indent=2, ensure_ascii=False))
    elif args.output:
        header, cols = table(result, units=args.units)
        write_csv(args.output, header, cols)
    else:
        from ..model import Units
        unit = result.length_unit
        print(format_text(result, unit, Units(length=unit).length_scale))
    return 0


class _Bar:
    """A progress callback that opens the bar at its first report (the total is known then); it also
    estimates the whole Monte Carlo's time from its first chunks (`mbplanar._progress.Progress`)."""

    def __init__(self, show, yes, source):
        import time
        self.show, self.yes, self.source, self.bar, self.start = show, yes, str(source), None, time.perf_counter()

    def __call__(self, done, total):
        if self.bar is None:
            self.bar = Progress(total, "samples", show=self.show, what=f"a Monte Carlo of {total} samples",
                                yes=self.yes, source=self.source, start=self.start)
        self.bar.update(done)

    def close(self):
        if self.bar is not None:
            self.bar.close()
