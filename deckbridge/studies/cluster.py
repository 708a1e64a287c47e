"""Dask for the studies: a LocalCluster of worker processes on this machine, or an existing cluster.

``open_client(scheduler=None, workers=None)`` is a context manager yielding a
``dask.distributed.Client``: with ``scheduler`` (an address such as ``tcp://host:8786``) it connects
to that cluster, whose workers must have deckbridge installed; otherwise it starts a LocalCluster
of ``workers`` processes (default ``os.cpu_count()``), one thread each, no dashboard.

On Linux the local workers are forked (``start_method='fork'``) after the solver modules are imported
here: they start in about 0.3 s instead of about 1.5 s for spawned interpreters that import numpy,
scipy, pandas and CHOLMOD again (measured on a 2-core machine). A forked worker inherits BLAS thread
pools sized for the whole machine (the nanny's OMP/OPENBLAS_NUM_THREADS=1 comes too late for
libraries already loaded), so every worker limits its BLAS/OpenMP pools to one thread
(:class:`~deckbridge.studies.blas_plugin.OneBlasThread`, threadpoolctl): without it the cases ran 2-3 times slower, one worker's
BLAS threads competing with the other's. Elsewhere workers are spawned. Python 3.12 warns that
forking a multi-threaded process (Dask's event-loop thread) may deadlock the child; the fork happens
before any case runs, from the loop thread, and never hung in our runs. Set
``DASK_DISTRIBUTED__WORKER__MULTIPROCESSING_METHOD=spawn`` (or ``forkserver``) to avoid it.
"""

from __future__ import annotations

import contextlib
import logging
import os
import sys
import warnings
from typing import Iterator

from ..errors import DeckbridgeError


def default_workers() -> int:
    return max(1, os.cpu_count() or 1)


@contextlib.contextmanager
def open_client(scheduler: str | None = None, workers: int | None = None, processes: bool = True,
                timeout_s: float = 20.0, start_method: str | None = None) -> Iterator["object"]:
    """A Dask client on an existing scheduler or on a fresh LocalCluster (closed on exit)."""
    import dask
    from dask.distributed import Client, LocalCluster

    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise DeckbridgeError(f"--workers = {workers!r}: must be a positive integer")
    if scheduler is not None:
        if workers is not None:
            raise DeckbridgeError(f"--workers = {workers!r} and --scheduler = {scheduler!r}: "
                                  "the cluster at --scheduler has its own workers; give one or the other")
        try:
            client = Client(scheduler, timeout=timeout_s)
        except (OSError, TimeoutError, ValueError, TypeError) as exc:
            msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise DeckbridgeError(f"--scheduler = {scheduler!r}: cannot connect ({msg})") from None
        try:
            yield client
        finally:
            client.close()
        return
    n = workers or default_workers()
    method = (start_method or os.environ.get("DASK_DISTRIBUTED__WORKER__MULTIPROCESSING_METHOD")
              or ("fork" if sys.platform.startswith("linux") else "spawn"))
    from .. import solve  # noqa: F401  (forked workers inherit the solver modules)
    from . import tasks  # noqa: F401
    try:
        with dask.config.set({"distributed.worker.multiprocessing-method": method}), warnings.catch_warnings():
            warnings.filterwarnings("ignore", message=r".*use of fork\(\) may lead to deadlocks", category=DeprecationWarning)
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=processes,
                                   dashboard_address=None, silence_logs=logging.ERROR)
    except Exception as exc:      # noqa: BLE001  (any start failure ends as one line)
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise DeckbridgeError(f"local Dask cluster of {n} workers: cannot start ({msg})") from None
    client = Client(cluster)
    try:
        if processes:
            from .blas_plugin import OneBlasThread
            client.register_plugin(OneBlasThread())
        yield client
    finally:
        client.close()
        cluster.close()
