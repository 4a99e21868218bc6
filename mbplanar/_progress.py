"""Long runs: a progress bar with the time left on a terminal, and a time estimate before a long request.

`Progress` shows tqdm's bar on stderr when tqdm is installed (a plain line with the count, the elapsed
time and the time left otherwise), and only when asked or when stderr is a terminal. It also guards
against requests that would run for long: once a short part of the run (the probe: `PROBE_SECONDS` after
its first report, so that one-off costs such as a compile before it do not count) tells its pace, a run whose estimated total time exceeds `LONG_RUN` (10
minutes) says so on stderr with the estimate, and goes on only when the user agreed (`--yes` on the
command line, or "y" to the question when stdin and stderr are terminals); otherwise it stops with
`LongRun` (exit status 2), before any output is written. Ctrl-C is the user's (`KeyboardInterrupt`);
the commands turn it into exit status 130 and write what they have where their format allows.
"""

from __future__ import annotations

import math
import sys
import time

from .errors import Interrupted, LongRun

__all__ = ["Progress", "LongRun", "Interrupted", "LONG_RUN", "PROBE_SECONDS", "duration", "confirm_long_run",
           "shown", "add_long_run_options"]

LONG_RUN = 600.0       # s: a request estimated to take longer asks before it runs on
PROBE_SECONDS = 2.0    # s of a run after which its pace is taken as known


def duration(seconds: float) -> str:
    """'42 s', '12 min', '3.4 h', '2.1 days'."""
    if not math.isfinite(seconds):
        return "forever"
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    if seconds < 172800:
        return f"{seconds / 3600:.1f} h"
    return f"{seconds / 86400:.1f} days"


def shown(flag: bool | None) -> bool:
    """Whether to show a progress bar: `flag` when given, else whether stderr is a terminal."""
    if flag is not None:
        return bool(flag)
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


def add_long_run_options(parser, counted: str = "the first seconds"):
    """--progress / --no-progress and --yes of a command that may run long (`counted`: what its estimate
    is taken from)."""
    g = parser.add_mutually_exclusive_group()
    g.add_argument("--progress", action="store_true", default=None,
                   help="a progress bar with the time left on stderr (default: when stderr is a terminal)")
    g.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bar")
    parser.add_argument("--yes", action="store_true",
                        help=f"run on even when the estimate from {counted} exceeds 10 minutes (else: asked on a "
                             "terminal, refused otherwise)")


def confirm_long_run(estimate: float, what: str, basis: str, yes: bool = False, source: str | None = None):
    """Nothing when `estimate` (s) is within `LONG_RUN`; else say so on stderr and go on when `yes` or
    when the user answers "y" on a terminal; otherwise raise `LongRun`."""
    if estimate <= LONG_RUN:
        return
    head = f"{source}: " if source else ""
    line = f"{what} would take about {duration(estimate)} ({basis})"
    if yes:
        print(f"mbplanar: {head}note: {line}; going on (--yes)", file=sys.stderr, flush=True)
        return
    if _interactive():
        print(f"mbplanar: {head}{line}.", file=sys.stderr, flush=True)
        print("Go on? [y/N] ", end="", file=sys.stderr, flush=True)
        answer = sys.stdin.readline().strip().lower()
        if answer in ("y", "yes"):
            return
    raise LongRun(f"{line}, more than {duration(LONG_RUN)}: add --yes to run it anyway, or ask for less",
                  source=source)


def _interactive() -> bool:
    try:
        return sys.stdin.isatty() and sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


class Progress:
    """Progress of a run of `total` units (`unit`, e.g. "positions", "s of motion").

    Parameters
    ----------
    total : float
        The amount of work (a count, or simulated seconds).
    unit : str
        What is counted, for the plain line.
    show : bool or None
        Draw a bar (None: when stderr is a terminal).
    what : str
        The request in words ("sweep of 10000001 positions"), for the estimate's message.
    yes : bool
        The user agreed beforehand to a long run (`--yes`).
    source : str, optional
        The file the run is about, for the messages.
    guard : bool
        Estimate the total time from the pace over `PROBE_SECONDS` after the first report and ask before
        a run longer than `LONG_RUN` goes on (`confirm_long_run`).
    start : float, optional
        When the run started (`time.perf_counter()`; default: now).
    """

    def __init__(self, total: float, unit: str = "", show: bool | None = None, what: str = "", yes: bool = False,
                 source: str | None = None, guard: bool = True, start: float | None = None):
        self.total, self.unit, self.what, self.yes, self.source = total, unit, what, yes, source
        self.guard, self.done = guard, 0.0
        self.start = time.perf_counter() if start is None else start   # (a perf_counter time)
        self.bar, self._plain, self._last, self._first = None, False, 0.0, None
        if shown(show):
            try:
                from tqdm import tqdm
            except ImportError:
                self._plain = True
            else:
                whole = float(total).is_integer()
                fmt = None if whole else ("{percentage:3.0f}%|{bar}| {n:.4g}/{total:.4g} " + unit
                                          + " [{elapsed}<{remaining}]")   # (a share of simulated time)
                self.bar = tqdm(total=int(total) if whole else float(total), unit=f" {unit}" if unit else "it",
                                leave=False, file=sys.stderr, dynamic_ncols=True, bar_format=fmt)

    def update(self, done: float):
        """The run has done `done` of its total."""
        self.done = done
        now = time.perf_counter()
        elapsed = now - self.start
        if self._first is None:   # the pace is timed from the first report on: one-off costs (a compile) before
            self._first = (now, done)
        t0, d0 = self._first
        if self.guard and d0 < done < self.total and now - t0 >= PROBE_SECONDS:
            self.guard = False
            estimate = elapsed + (now - t0) * (self.total - done) / (done - d0)
            confirm_long_run(estimate, self.what or f"this run of {self.total:g} {self.unit}",
                             f"{_amount(float(f'{done - d0:.4g}'), self.unit)} took {duration(now - t0)}", self.yes,
                             self.source)
        if self.bar is not None:
            self.bar.update(done - self.bar.n)
            if done >= self.total:
                self.bar.refresh()  # tqdm draws at most every 0.1 s: the last count would depend on timing
        elif self._plain and (elapsed - self._last >= 0.5 or done >= self.total):
            self._last = elapsed
            left = elapsed * (self.total - done) / done if done else math.inf
            print(f"\r{_amount(done, '')}/{_amount(self.total, self.unit)} ({100 * done / self.total:.0f} %), "
                  f"{duration(elapsed)} elapsed, about {duration(left)} left ", end="", file=sys.stderr, flush=True)

    def __call__(self, done, total=None):
        """A progress(done, total) callback."""
        self.update(done)

    def close(self):
        if self.bar is not None:
            self.bar.close()
            self.bar = None
        elif self._plain:
            print(file=sys.stderr, flush=True)
            self._plain = False

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False


def _amount(value: float, unit: str) -> str:
    text = f"{value:g}" if not float(value).is_integer() else f"{int(value)}"
    return f"{text} {unit}".strip()
