"""`mbplanar accuracy MODEL [--samples N] [--seed S] [--positions N] [--outputs LIST] [--json | -o FILE.csv]
[--units si|model] [--workers N | --scheduler ADDRESS] [--progress | --no-progress]`: the command-line
side of the accuracy analysis (parsing, printing; the work is `accuracy`)."""

from __future__ import annotations

import argparse
import json
import sys

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
    s.add_argument("--units", choices=("si", "model"), default="si",
                   help="lengths in the JSON and CSV: si (m) or model (the table's length_unit)")
    w = s.add_mutually_exclusive_group()
    w.add_argument("--workers", type=_count(1), help="run the Monte Carlo on a Dask LocalCluster of N workers")
    w.add_argument("--scheduler", help="run the Monte Carlo on the Dask cluster of this scheduler")
    p = s.add_mutually_exclusive_group()
    p.add_argument("--progress", action="store_true", default=None,
                   help="a progress bar on stderr (default: when stderr is a terminal)")
    p.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bar")


def run(args) -> int:
    """Run the analysis the arguments describe and print or write it."""
    from ..errors import ModelError
    from ..io._export import write_csv
    from ..study.cluster import close, connect, local_client, progress_bar
    from .report import document, format_text, table
    from .run import accuracy

    outputs = None
    if args.outputs is not None:
        outputs = [n.strip() for n in args.outputs.split(",") if n.strip()]
        if not outputs:
            raise ModelError("--outputs needs names separated by commas")
    client = local_client(args.workers) if args.workers else connect(args.scheduler) if args.scheduler else None
    show = sys.stderr.isatty() if args.progress is None else args.progress
    bar = _Bar(progress_bar) if show else None
    try:
        result = accuracy(args.model, samples=args.samples, seed=args.seed, positions=args.positions,
                          outputs=outputs, backend=args.backend, client=client, progress=bar,
                          monte_carlo_run=not args.no_monte_carlo)
    except KeyboardInterrupt:
        done = f" after {bar.done} of {bar.total} samples" if bar is not None and bar.total else ""
        print(f"mbplanar: {args.model}: accuracy interrupted{done}", file=sys.stderr)
        return 130
    finally:
        if bar is not None:
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
    """A progress callback that opens the bar at its first report (the total is known then)."""

    def __init__(self, factory):
        self.factory, self.bar, self.done, self.total = factory, None, 0, 0

    def __call__(self, done, total):
        if self.bar is None:
            self.bar = self.factory(total)
        self.done, self.total = done, total
        self.bar[0](done, total)

    def close(self):
        if self.bar is not None:
            self.bar[1]()
