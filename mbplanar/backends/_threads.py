"""Running a compiled kernel over a long batch on several cores: the batch is cut into contiguous
chunks, one per thread, and the kernels (compiled with `nogil`) run at once. Positions are independent,
so the answers do not depend on the cut. Each thread needs its own work arrays; the caller passes them.
"""

from __future__ import annotations

import os

from ..errors import MbplanarError

__all__ = ["MIN_CHUNK", "available", "chunks", "run", "work_arrays"]

MIN_CHUNK = 400  # positions per thread below which another thread costs more than it saves
_pool = None  # the other threads (a ThreadPoolExecutor), made on first use
_pool_size = 0
_CORES = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


def available() -> int:
    """Threads to use by default: `MBPLANAR_THREADS` if set, else the cores this process may run on."""
    value = os.environ.get("MBPLANAR_THREADS")
    if not value:
        return _CORES
    if not value.strip().isdigit() or int(value) < 1:
        raise MbplanarError(f"MBPLANAR_THREADS must be a positive integer, not {value!r}")
    return int(value)


def chunks(batch: int, threads: int | None = None) -> list[slice]:
    """Contiguous slices of a batch, at most `threads` of them (default `available()`) and none
    shorter than MIN_CHUNK."""
    if batch < 2 * MIN_CHUNK:
        return [slice(0, batch)]
    k = max(1, min(threads or available(), batch // MIN_CHUNK))
    cuts = [batch * i // k for i in range(k + 1)]
    return [slice(a, b) for a, b in zip(cuts[:-1], cuts[1:])]


def run(calls: list) -> list:
    """Results of the zero-argument callables `calls`: the first in this thread, the others at once in
    a pool of threads."""
    global _pool, _pool_size
    if len(calls) == 1:
        return [calls[0]()]
    if _pool is None or _pool_size < len(calls) - 1:
        from concurrent.futures import ThreadPoolExecutor  # (imported here: one-thread runs skip it, ~10 ms)
        if _pool is not None:
            _pool.shutdown(wait=False)
        _pool, _pool_size = ThreadPoolExecutor(len(calls) - 1, thread_name_prefix="mbplanar"), len(calls) - 1
    futures = [_pool.submit(call) for call in calls[1:]]
    first = calls[0]()
    return [first] + [f.result() for f in futures]


def work_arrays(store: list, make, threads: int) -> list:
    """The first `threads` sets of work arrays kept in `store`, adding sets made by `make()` as needed."""
    while len(store) < threads:
        store.append(make())
    return store[:threads]
