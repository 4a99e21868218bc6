"""Design studies on a Dask cluster (the optional extra `dask`): each chunk of designs is one task.

`local_client(workers)` starts a LocalCluster of `workers` single-threaded worker processes on this
machine; `connect(address)` joins an existing scheduler. `run_on_client` submits the chunks and gathers
them in table order; every task runs the same function on the same data as the serial run, so the
results are equal bit for bit.
"""

from __future__ import annotations

from ..errors import MbplanarError

__all__ = ["local_client", "connect", "run_on_client"]


def _distributed():
    try:
        import distributed
    except ImportError:
        raise MbplanarError("Dask is not installed: pip install 'mbplanar[dask]'") from None
    return distributed


def local_client(workers: int):
    """A Client of a new LocalCluster with `workers` worker processes of one thread each (closing the
    client closes the cluster)."""
    distributed = _distributed()
    cluster = distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
    client = distributed.Client(cluster)
    client._mbplanar_cluster = cluster  # closed with the client by `close`
    return client


def connect(address: str):
    """A Client of the running scheduler at `address` (e.g. tcp://host:8786)."""
    distributed = _distributed()
    try:
        return distributed.Client(address, timeout="20s")
    except (OSError, TimeoutError) as exc:
        raise MbplanarError(f"cannot reach the Dask scheduler at {address}: {exc}") from None


def close(client):
    """Close a client (and the LocalCluster `local_client` started for it)."""
    cluster = getattr(client, "_mbplanar_cluster", None)
    client.close()
    if cluster is not None:
        cluster.close()


def run_on_client(client, func, data, source, parts, args, progress=None) -> list:
    """func(data, source, part, *args) for every part, one task each on `client`; the results in the
    order of `parts`. progress(done, total) is called as chunks finish (designs done so far)."""
    distributed = _distributed()
    # the table travels with each task (a few kB): no scattered future whose release could race a
    # later study of the same table
    futures = [client.submit(func, data, source, part, *args, pure=False) for part in parts]
    order = {f.key: k for k, f in enumerate(futures)}
    results, done, total = [None] * len(parts), 0, sum(_size(p) for p in parts)
    for future in distributed.as_completed(futures):
        k = order[future.key]
        results[k] = future.result()
        done += _size(parts[k])
        if progress is not None:
            progress(done, total)
    return results


def _size(part) -> int:
    """Designs in a task's part (a Variants, or a (Variants, φ) pair)."""
    return len(part[0]) if isinstance(part, tuple) else len(part)
