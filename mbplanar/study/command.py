"""`mbplanar study MODEL --variants TABLE.csv [--json] [-o SUMMARY.csv] [--workers N | --scheduler ADDR]
[--progress | --no-progress] [--yes] [--units si|model]`:
the command-line side of a design study (parsing, printing; the work is `run_study`)."""

from __future__ import annotations

import argparse
import csv
import json
import math

from .._progress import Interrupted, Progress, add_long_run_options
from ..model import add_units_option, display_units

__all__ = ["add_parser", "cmd_study"]


def _positive(text) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive whole number, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive whole number, got {text!r}")
    return value


def add_parser(sub):
    """Register the `study` command on the CLI's sub-parsers."""
    s = sub.add_parser("study", help="a table of design variants: full turn, motion limits, strokes, "
                                     "transmission angles per variant")
    s.add_argument("model", help="a model with [parameters]")
    s.add_argument("--variants", required=True, help="CSV: one row per variant, columns named after parameters")
    s.add_argument("--points", help="coupler-curve samples of these joints or points (comma list)")
    s.add_argument("--samples", type=_positive, default=36, help="samples per design over its range (default 36)")
    s.add_argument("--json", action="store_true", help="the whole study as JSON")
    s.add_argument("-o", "--output", help="summary CSV file (one row per variant)")
    g = s.add_mutually_exclusive_group()
    g.add_argument("--workers", type=_positive, help="run on a Dask LocalCluster of N worker processes")
    g.add_argument("--scheduler", help="run on the Dask cluster of this scheduler (e.g. tcp://host:8786)")
    s.add_argument("--chunk", type=_positive, default=None, help="designs per task (default 64)")
    add_long_run_options(s, "the first chunks")
    add_units_option(s, "the strokes, extremes, samples and balancing loads")
    s.set_defaults(func=cmd_study)
    return s


def cmd_study(args) -> int:
    """Run the study the arguments describe and print or write its summary."""
    from .cluster import close, connect, local_client
    from .report import format_study, study_document
    from .run import CHUNK, run_study

    points = [p.strip() for p in args.points.split(",") if p.strip()] if args.points else []
    client = local_client(args.workers) if args.workers else connect(args.scheduler) if args.scheduler else None
    bar = _ProgressOnce(args.progress, args.yes, args.variants)
    try:
        study = run_study(args.model, args.variants, points=points, samples=args.samples, client=client,
                          chunk=args.chunk or CHUNK, progress=bar)
    except Interrupted as exc:
        if exc.partial is not None and args.output:
            _write_table(args.output, exc.partial, args.units)
            exc.message += f"; wrote the {len(exc.partial.designs)} designs done to {args.output}"
        raise
    finally:
        bar.close()
        if client is not None:
            close(client)
    if args.output:
        _write_table(args.output, study, args.units)
    if args.json:
        print(json.dumps(_plain(study_document(study, _display(study, args.units))), indent=2, ensure_ascii=False))
    elif not args.output:
        print(format_study(study))
    return 0


def _display(study, system: str):
    """The units the study is shown in (`--units`): SI, or its model's."""
    return display_units(study, system)


def _write_table(path, study, system: str):
    from .report import study_table
    header, rows = study_table(study, _display(study, system))
    with open(path, "w", newline="", encoding="utf-8") as f:
        csv.writer(f).writerows([header] + rows)


def _plain(obj):
    """JSON-safe copy: numpy scalars as floats, non-finite numbers as null."""
    if isinstance(obj, dict):
        return {k: _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, (bool, str, int)) or obj is None:
        return obj
    value = float(obj)
    return value if math.isfinite(value) else None


class _ProgressOnce:
    """A progress callback that opens the bar at its first report (the total is known then); it also
    estimates the whole study's time from its first seconds (`mbplanar._progress.Progress`)."""

    def __init__(self, show, yes, source):
        import time
        self.show, self.yes, self.source, self.bar, self.start = show, yes, str(source), None, time.perf_counter()

    def __call__(self, done, total):
        if self.bar is None:
            self.bar = Progress(total, "designs", show=self.show, what=f"a study of {total} designs", yes=self.yes,
                                source=self.source, start=self.start)
        self.bar.update(done)

    def close(self):
        if self.bar is not None:
            self.bar.close()
