"""The local executor of a sweep: cases on worker processes forked from this one, without a Dask cluster.

A sweep whose cases share one condensation (one mesh, any k-factors) spends a few tenths of a second
per case; a Dask LocalCluster costs more than that to import and start (scheduler, nannies, workers,
TCP), and then moves the condensed system to every worker. Here the client condenses in process and
forks ``workers`` processes afterwards: they inherit the condensed system (fork: no copy sent), solve
the cases and send back each case's table, summary and provenance; the client stores each as it comes,
as with Dask (only the client writes: resumability and the folder's lock are those of any sweep).
Measured on the 2-core development box (default JAR, 6 k-factors + Lagrange): see bench/README.md.

Strategy ``'split'`` (default) condenses without keeping the sparse factor for the cases, as Dask's
split (only contact sigma_N judged: the files are those of a Dask split sweep); ``'mesh'`` keeps it,
so the forked workers also recover the base-wall sigma_zz (as Dask's ``'mesh'``). Several condense keys
are condensed in turn, each followed by its cases; a study with several meshes is left to Dask by
``executor='auto'`` (its condensations then run in parallel).

With one worker (or one case) everything runs in this process. Elsewhere than Linux the workers are
spawned and the condensed system is sent to each once (pickled).
"""

from __future__ import annotations

import contextlib
import gc
import multiprocessing
import os
import signal
import sys
import threading
import warnings
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Callable, Iterable, Iterator, NamedTuple

from ..errors import RunError
from ..limits import check_workers

_INHERITED = {}                      # in a worker: the condensed system it solves cases on
_LIFELINE: dict[int, tuple[int, int]] = {}   # client pid -> (read, write) ends of the pipe its workers watch


def _lifeline() -> None:
    """Before forking workers: the client's pipe (made once per process). The client alone keeps its write
    end open; a worker sees end-of-file when the client is gone, however it ended (SIGKILL included)."""
    if os.getpid() not in _LIFELINE:
        _LIFELINE.clear()                       # a forked copy of another client: not its pipe
        _LIFELINE[os.getpid()] = os.pipe()      # not inheritable across exec (ccx never holds it)
    _INHERITED["client"] = os.getpid()


def _die_with_client() -> None:
    """In a worker: end this process as soon as the client has ended (end-of-file on the lifeline, or this
    process re-parented), so no orphan keeps computing or holds the study folder. A thread rather than
    prctl(PR_SET_PDEATHSIG): that signal follows the client's *thread* that forked, and the workers are
    forked from a short-lived thread (:func:`_in_fresh_thread`)."""
    import select

    client = _INHERITED.get("client") or os.getppid()
    ends = _LIFELINE.get(client)
    if ends is not None:
        os.close(ends[1])                       # this worker's copy of the write end
    read_end = None if ends is None else ends[0]

    def watch():
        while True:
            if read_end is not None:
                ready = select.select([read_end], [], [], 0.5)[0]
                if ready and not os.read(read_end, 1):
                    os._exit(1)
            else:
                threading.Event().wait(0.5)
            if os.getppid() != client:
                os._exit(1)

    threading.Thread(target=watch, name="deckbridge-lifeline", daemon=True).start()


def _worker_init() -> None:
    """Every worker: one BLAS / OpenMP thread (one worker per core); Ctrl-C left to the client (which
    stops the workers), SIGTERM ends a worker plainly (not the client's handler, inherited by fork); the
    worker ends with the client (:func:`_die_with_client`)."""
    from .tasks import one_blas_thread
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    _die_with_client()
    _INHERITED["blas"] = one_blas_thread()


def _adopt(cond) -> None:
    """Worker initialiser of the cases: :func:`_worker_init`, and keep the condensed system."""
    _worker_init()
    _INHERITED["cond"] = cond


def _solve(i: int, job: tuple, label: str):
    """Job ``i`` solved on the inherited condensation, with its table prepared for the client (:func:`prepared`)."""
    from .tasks import solve_or_error
    res = solve_or_error(_INHERITED["cond"], *job)
    return i, res if isinstance(res, Exception) else (*res, prepared(res[0], label))


class Prepared(NamedTuple):
    """A case table as the store will hold it: ``text`` (written as is by the client), ``table`` (that text
    read back as :meth:`.store.CaseStore.table` reads the file) and its sigma_N ``series`` (None when it
    cannot be built: the client's metrics then report the error)."""
    text: str
    table: object
    series: object


def prepared(df, label: str) -> Prepared:
    """Serialise, read back and build the series of one case on the worker, off the client's path: the
    client writes ``text`` and uses ``table`` and ``series`` instead of reading the file it wrote back."""
    import io

    from ..compare.series import series_of
    from .store import csv_text, table_of

    text = csv_text(df)
    table = table_of(io.StringIO(text))
    try:
        series = series_of(table, label)
    except Exception:          # noqa: BLE001  (left to the metrics, which raise where they always did)
        series = None
    return Prepared(text, table, series)


def _in_fresh_thread(fn: Callable[[], object]) -> None:
    """Run ``fn`` (which forks) in a new thread and wait for it.

    GNU OpenMP (CHOLMOD's threads) is not fork-safe: a child forked from a thread that has run a parallel
    region hangs in its next one (the team's threads are gone). A new thread has no OpenMP team, so its
    children start a fresh one: this process may have factorised before (a library user, the tests)."""
    box: list[BaseException] = []

    def run():
        try:
            fn()
        except BaseException as exc:  # noqa: BLE001  (re-raised in the caller)
            box.append(exc)

    t = threading.Thread(target=run, name="deckbridge-fork")
    t.start()
    t.join()
    if box:
        raise box[0]


class LocalExecutor:
    """``workers`` processes of this machine (default: its cores), forked when there is work for them.

    Use as a context manager (:func:`.cluster.open_executor`): the last pool of workers is kept for the
    report's figures and stopped on exit (at once when the sweep failed or was interrupted)."""

    def __init__(self, workers: int | None = None, start_method: str | None = None):
        check_workers(workers)
        self.workers = workers or max(1, os.cpu_count() or 1)
        self.start_method = start_method or ("fork" if sys.platform.startswith("linux") else "spawn")
        self._kept: ProcessPoolExecutor | None = None

    def __enter__(self) -> "LocalExecutor":
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        self.close(stop=exc_type is not None)

    def name(self, strategy: str) -> str:
        return f"local ({self.workers} process{'es' if self.workers > 1 else ''}, strategy {strategy})"

    def _fork(self, n: int, initializer=_worker_init, initargs=()) -> ProcessPoolExecutor:
        ctx = multiprocessing.get_context(self.start_method)
        _lifeline()
        pool = ProcessPoolExecutor(n, mp_context=ctx, initializer=initializer, initargs=initargs)
        with warnings.catch_warnings():
            # Python 3.12 warns on fork() from a process with threads (the progress bar's monitor): the
            # workers run the solver and the figures only, never the code of those threads
            warnings.filterwarnings("ignore", message=r".*use of fork\(\) may lead to deadlocks", category=DeprecationWarning)
            gc.freeze()             # the workers' collections leave the client's objects (and their pages) alone
            try:
                _in_fresh_thread(lambda: pool.submit(int).result())   # the processes start now (fork: all at once)
            except BaseException:
                pool.shutdown(wait=False, cancel_futures=True)
                raise
            finally:
                gc.unfreeze()
        return pool

    @staticmethod
    def _stop(pool: ProcessPoolExecutor, now: bool) -> None:
        if now:                      # an error or Ctrl-C in the client: stop the workers at once
            procs = list((getattr(pool, "_processes", None) or {}).values())
            for p in procs:
                with contextlib.suppress(Exception):
                    p.terminate()
            for p in procs:          # reap them here: shutdown(wait=True) on a pool whose workers were
                with contextlib.suppress(Exception):    # terminated can wait forever on its manager thread
                    p.join(timeout=10)
                    if p.is_alive():
                        p.kill()
                        p.join(timeout=10)
            pool.shutdown(wait=False, cancel_futures=True)
            return
        pool.shutdown(wait=True, cancel_futures=True)

    def close(self, stop: bool = False) -> None:
        if self._kept is not None:
            pool, self._kept = self._kept, None
            self._stop(pool, stop)

    def condense(self, model_dict: dict, light: bool, meanwhile: Callable[[], object] | None = None):
        """:func:`.tasks.condense_variant` of ``model_dict``; with ``light`` (no sparse factor: it cannot
        leave its process) on a forked process while this one runs ``meanwhile`` (the report's imports)."""
        from .tasks import condense_or_error, condense_variant

        if not light or self.workers < 2 or meanwhile is None:
            cond = condense_variant(model_dict, light=light)
            if meanwhile is not None:
                meanwhile()
            return cond
        pool = self._fork(1)
        try:
            fut = pool.submit(condense_or_error, model_dict)
            meanwhile()
            cond = fut.result()
        except BaseException:
            self._stop(pool, True)
            raise
        self._stop(pool, False)
        if isinstance(cond, Exception):
            raise cond
        return cond

    def solve(self, cond, jobs: list[tuple], labels: list[str]) -> Iterator[tuple[int, object]]:
        """(index, result) of every job in the order they finish: the :class:`DeckbridgeError` of
        :func:`.tasks.solve_or_error`, or its (table, summary, provenance) and the :class:`Prepared` table."""
        n = min(self.workers, len(jobs))
        if n <= 1:
            _INHERITED["cond"] = cond
            try:
                for i, (job, label) in enumerate(zip(jobs, labels)):
                    yield _solve(i, job, label)
            finally:
                _INHERITED.pop("cond", None)
            return
        self.close()
        self._kept = pool = self._fork(n, _adopt, (cond,))
        pending = {pool.submit(_solve, i, job, label) for i, (job, label) in enumerate(zip(jobs, labels))}
        while pending:
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for f in done:
                try:
                    out = f.result()
                except BrokenProcessPool:
                    raise RunError("a local worker process ended abruptly (out of memory? killed?); the finished "
                                   "cases are stored: run the same command again to resume") from None
                yield out

    def mapper(self) -> Callable[[Callable, Iterable], list]:
        """``mapper(fn, jobs)`` for the report's figures: drawn on the workers of the cases (forked after
        the client imported the report's modules: they import nothing), or on new ones."""
        def run(fn, jobs):
            jobs = list(jobs)
            n = min(self.workers, len(jobs))
            if n <= 1:
                return [fn(j) for j in jobs]
            if self._kept is None:
                self._kept = self._fork(n)
            return list(self._kept.map(fn, jobs))
        return run
