"""BLAS threads for the sparse factorisation and the dense contact work (threadpoolctl).

Measured on the 2-core development box (bench/README.md): CHOLMOD with Debian's OpenBLAS is not
faster with more BLAS threads than cores and much slower when they oversubscribe a busy machine,
and the small dense contact solves are fastest on one thread. The default is therefore one thread
unless ``REFERENCE_SOLVER_THREADS`` says otherwise; ``threads`` arguments override both.
"""

from __future__ import annotations

import contextlib
import functools
import os

from .errors import ReferenceSolverError

try:
    from threadpoolctl import ThreadpoolController, threadpool_info
except ImportError:  # pragma: no cover - threadpoolctl is a dependency
    ThreadpoolController = threadpool_info = None


@functools.lru_cache(maxsize=1)
def _controller():
    """One threadpoolctl controller over every BLAS this package calls (NumPy, SciPy, CHOLMOD's).

    Built once: a fresh ``threadpool_limits`` scans the loaded libraries each time (about 1 ms, a dozen
    times per load path). The libraries the solver uses are imported first so that the snapshot holds them.
    """
    import scipy.linalg  # noqa: F401  (SciPy's BLAS)
    try:
        import sksparse.cholmod  # noqa: F401  (CHOLMOD's BLAS)
    except ImportError:
        pass
    return ThreadpoolController()


def default_threads() -> int:
    """Threads used when none are given: ``REFERENCE_SOLVER_THREADS`` or 1."""
    v = os.environ.get("REFERENCE_SOLVER_THREADS", "1")
    try:
        n = int(v)
    except ValueError:
        raise ReferenceSolverError(f"REFERENCE_SOLVER_THREADS = {v!r}: must be a positive integer") from None
    if n < 1:
        raise ReferenceSolverError(f"REFERENCE_SOLVER_THREADS = {v!r}: must be a positive integer")
    return n


def blas_threads(threads: int | None):
    """Context limiting the BLAS thread pools to ``threads`` (None: :func:`default_threads`)."""
    n = default_threads() if threads is None else threads
    if not (isinstance(n, int) and n >= 1):
        raise ReferenceSolverError(f"threads = {threads!r}: must be a positive integer")
    if ThreadpoolController is None:
        return contextlib.nullcontext()
    return _controller().limit(limits=n, user_api="blas")


def blas_info() -> list[dict]:
    """BLAS libraries loaded, with kernel (architecture) and thread count (threadpoolctl)."""
    if threadpool_info is None:
        return []
    return [{k: d.get(k) for k in ("internal_api", "version", "architecture", "num_threads", "filepath")}
            for d in threadpool_info() if d.get("user_api") == "blas"]


def with_blas_threads(fn):
    """Decorator: run ``fn`` under :func:`blas_threads`, taking an optional ``threads=`` keyword."""
    @functools.wraps(fn)
    def wrapper(*args, threads: int | None = None, **kw):
        with blas_threads(threads):
            return fn(*args, **kw)
    return wrapper
