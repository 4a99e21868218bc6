"""A one-line notice on stderr while numba compiles the kernels: the first use after installing
compiles them (several seconds) unless ``mbplanar compile`` compiled them ahead of time (`_aot`); numba
keeps them in its on-disk cache, and later processes load them from there without this notice."""

from __future__ import annotations

import sys
import time

from numba.core import event

__all__ = ["install", "quiet"]


class _Notice(event.Listener):
    """Writes "mbplanar: compiling the numba kernels once" when numba starts compiling a kernel of
    mbplanar, and the wall time it took when the outermost compile ends (with the hint that
    ``mbplanar compile`` does it ahead of time)."""

    def __init__(self):
        self.depth, self.start = 0, 0.0

    def on_start(self, ev):
        if not _ours(ev):
            return
        if self.depth == 0:
            self.start = time.perf_counter()
            sys.stderr.write("mbplanar: compiling the numba kernels once")
            sys.stderr.flush()
        self.depth += 1

    def on_end(self, ev):
        if not _ours(ev):
            return
        self.depth -= 1
        if self.depth == 0:
            sys.stderr.write(f" ({time.perf_counter() - self.start:.1f} s); later runs use the cache "
                             "(`mbplanar compile` builds them ahead of time)\n")
            sys.stderr.flush()


def _ours(ev) -> bool:
    if _quiet:
        return False
    dispatcher = ev.data.get("dispatcher") if isinstance(ev.data, dict) else None
    module = getattr(getattr(dispatcher, "py_func", None), "__module__", "") or ""
    return module.startswith("mbplanar.")


_installed: list = []
_quiet: list = []


class quiet:
    """``with quiet():`` no notice (``mbplanar compile`` says what it does itself)."""

    def __enter__(self):
        _quiet.append(True)

    def __exit__(self, *exc):
        _quiet.pop()


def install():
    """Register the notice once per process."""
    if not _installed:
        _installed.append(_Notice())
        event.register("numba:compile", _installed[0])
