"""Dask for the studies: a LocalCluster of worker processes on this machine, or an existing cluster;
:func:`open_executor` picks it or the forked local workers of :mod:`.local` (``sweep --executor``).

``open_client(scheduler=None, workers=None)`` is a context manager yielding a
``dask.distributed.Client``: with ``scheduler`` (an address such as ``tcp://host:8786``) it connects
to that cluster, whose workers must have deckbridge installed; otherwise it starts a LocalCluster
of ``workers`` processes (default ``os.cpu_count()``), one thread each, on 127.0.0.1, no dashboard
(Dask's ``dashboard_address=None`` still opens :8787; the HTTP server is bound to an ephemeral loopback port).
The connection to ``scheduler`` is made under a wall-clock limit (handshake included).

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

from ..errors import DeckbridgeError, RunError
from ..limits import check_workers
from ..textsafe import one_line


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return one_line(text.splitlines()[0] if text else type(exc).__name__)


def _quiet_client_finalizers() -> None:
    """A half-made Client times out again in its finalizer at exit: keep that off stderr (one line only)."""
    previous = sys.unraisablehook

    def hook(unraisable):
        if "distributed" not in type(unraisable.object).__module__ + repr(unraisable.object)[:200]:
            previous(unraisable)

    sys.unraisablehook = hook


def _connect(scheduler: str, timeout_s: float):
    """``Client(scheduler)`` with the whole handshake under a wall-clock limit of ``timeout_s``.

    Dask's own ``timeout`` covers the TCP connect only: a port that accepts TCP but does not speak
    Dask's protocol hangs in the handshake (or sends bytes read as a frame length of exabytes). The
    client is made in a daemon thread; when it has not answered in time the command ends with one
    line (the thread, blocked on the socket, ends with the process).
    """
    import threading

    from dask.distributed import Client

    box: dict = {}

    def make():
        try:
            box["client"] = Client(scheduler, timeout=timeout_s)
        except BaseException as exc:  # noqa: BLE001  (reported below as one line)
            box["error"] = exc

    t = threading.Thread(target=make, name="deckbridge-dask-connect", daemon=True)
    t.start()
    t.join(timeout_s + 2.0)
    if t.is_alive() or "error" in box:
        _quiet_client_finalizers()
    if t.is_alive():
        raise RunError(f"`scheduler` = {scheduler!r}: no Dask scheduler answered within {timeout_s + 2.0:g} s "
                       "(is it a Dask scheduler address, e.g. tcp://host:8786?)")
    if "error" in box:
        raise RunError(f"`scheduler` = {scheduler!r}: cannot connect ({_first_line(box['error'])})")
    return box["client"]


def default_workers() -> int:
    return max(1, os.cpu_count() or 1)


@contextlib.contextmanager
def open_client(scheduler: str | None = None, workers: int | None = None, processes: bool = True,
                timeout_s: float = 20.0, start_method: str | None = None) -> Iterator["object"]:
    """A Dask client on an existing scheduler or on a fresh LocalCluster (closed on exit)."""
    import dask
    from dask.distributed import Client, LocalCluster

    check_workers(workers)
    if scheduler is not None:
        if workers is not None:
            raise DeckbridgeError(f"`workers` = {workers!r} and `scheduler` = {scheduler!r}: "
                                  "the cluster at `scheduler` has its own workers; give one or the other")
        if not isinstance(scheduler, str) or not scheduler.strip() or len(scheduler) > 300:
            raise DeckbridgeError(f"`scheduler` = {scheduler!r}: give an address such as tcp://host:8786")
        client = _connect(scheduler, timeout_s)
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
            # dashboard_address=None means Dask's default :8787 on every interface: disable the dashboard
            # and bind what HTTP the scheduler keeps (/health) to an ephemeral loopback port
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=processes,
                                   host="127.0.0.1" if processes else None, dashboard_address="127.0.0.1:0",
                                   scheduler_kwargs={"dashboard": False}, silence_logs=logging.ERROR,
                                   timeout=timeout_s)
    except Exception as exc:      # noqa: BLE001  (any start failure ends as one line)
        raise RunError(f"local Dask cluster of {n} workers: cannot start ({_first_line(exc)})") from None
    try:
        client = Client(cluster, timeout=timeout_s)
    except Exception as exc:      # noqa: BLE001
        cluster.close()
        raise RunError(f"local Dask cluster of {n} workers: no client ({_first_line(exc)})") from None
    try:
        if processes:
            from .blas_plugin import OneBlasThread
            client.register_plugin(OneBlasThread())
        yield client
    finally:
        client.close()
        cluster.close()


EXECUTORS = ("auto", "local", "dask")


def executor_kind(executor: str, scheduler: str | None, condensations: int) -> str:
    """'local' or 'dask' for ``--executor`` (auto: Dask for ``--scheduler`` or several condensations, whose
    Dask tasks then run in parallel; else the forked local workers of :mod:`.local`, which skip the
    cluster's start and send no condensed system)."""
    if executor not in EXECUTORS:
        raise DeckbridgeError(f"`executor` = {executor!r}: must be one of {', '.join(EXECUTORS)}")
    if scheduler is not None and executor == "local":
        raise DeckbridgeError(f"`executor` local and `scheduler` = {scheduler!r}: give one or the other")
    if executor == "auto":
        return "dask" if scheduler is not None or condensations > 1 else "local"
    return executor


@contextlib.contextmanager
def open_executor(executor: str = "auto", scheduler: str | None = None, workers: int | None = None,
                  condensations: int = 1) -> Iterator["object"]:
    """A :class:`~deckbridge.studies.local.LocalExecutor` or a Dask client (:func:`open_client`), as
    :func:`executor_kind` chooses."""
    if executor_kind(executor, scheduler, condensations) == "local":
        from .local import LocalExecutor
        with LocalExecutor(workers) as local:
            yield local
        return
    with open_client(scheduler, workers) as client:
        yield client

