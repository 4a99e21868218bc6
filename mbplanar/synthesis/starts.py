"""Independent starts of a search, one after the other here or one task each on a Dask cluster.

Each start is a function of the problem and its own seed only, so the results are the same whichever
way they run (bit for bit); they come back in the order of the seeds. The Dask side is the design
studies' (`mbplanar.study.cluster`).
"""

from __future__ import annotations

__all__ = ["run_starts"]


def run_starts(func, setup, seeds, client=None, progress=None) -> list:
    """[func(setup, seed) for seed in seeds], serially or on `client` (one task per seed);
    progress(done, total) is called as starts finish."""
    if client is None:
        out = []
        for seed in seeds:
            out.append(func(setup, seed))
            if progress is not None:
                progress(len(out), len(seeds))
        return out
    from ..study.cluster import run_on_client
    parts = [[s] for s in seeds]
    return [r[0] for r in run_on_client(client, _dask_task, func, setup, parts, (), progress)]


def _dask_task(func, setup, seeds) -> list:
    """A Dask task: func(setup, seed) for the seeds of one part."""
    return [func(setup, s) for s in seeds]
