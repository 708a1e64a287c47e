"""Dask worker plugin limiting BLAS / OpenMP thread pools to one thread per worker (threadpoolctl).

In its own module so that importing :mod:`deckbridge.studies` does not import ``distributed``.
"""

from __future__ import annotations

from distributed import WorkerPlugin


class OneBlasThread(WorkerPlugin):
    """One BLAS / OpenMP thread per worker (one worker per core), restored on teardown."""
    name = "deckbridge-one-blas-thread"

    def setup(self, worker=None):
        from threadpoolctl import threadpool_limits
        self._limits = threadpool_limits(limits=1)

    def teardown(self, worker=None):
        limits = getattr(self, "_limits", None)
        if limits is not None:
            limits.restore_original_limits()
