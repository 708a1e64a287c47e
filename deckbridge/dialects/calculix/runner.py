"""Run CalculiX ``ccx -i <job>`` on a deck in its folder, with a time limit and progress lines.

ccx writes ``<job>.dat``, ``<job>.frd``, ``<job>.sta`` (and scratch files) beside the deck. It reports
input and convergence errors as ``*ERROR ...`` lines on stdout (sometimes with exit status 0, sometimes
201 or 255); success is "Job finished" and no ``*ERROR``. Progress lines ("increment 3 attempt 1",
"iteration 2") are passed to an optional callback as they come.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from ...errors import DeckbridgeError, RunError

_PROGRESS = re.compile(r"^\s*(increment \d+ attempt \d+|iteration \d+|STEP\s+\d+|Job finished)", re.I)
_JOB_SCRATCH = (".12d", ".cvg", ".rout")
_DIR_SCRATCH = ("spooles.out", "contact.fbd", "intpoints.out", "slavintmortar.out", "slavtan.fbd")


@dataclass(frozen=True)
class CcxRun:
    """A finished ccx job: its files and the wall time [s]."""
    deck: Path
    dat: Path
    frd: Path
    sta: Path
    seconds: float
    increments: int        # converged increments listed in the .sta


def binary() -> str:
    """The ccx executable: $DECKBRIDGE_CCX, else ``ccx`` on the PATH."""
    exe = os.environ.get("DECKBRIDGE_CCX") or shutil.which("ccx")
    if not exe or not Path(exe).is_file():
        raise RunError("CalculiX: 'ccx' not found on the PATH (apt-get install calculix-ccx, "
                              "or set DECKBRIDGE_CCX)")
    return exe


THREAD_VARS = ("OMP_NUM_THREADS", "CCX_NPROC_STIFFNESS", "CCX_NPROC_EQUATION_SOLVER", "CCX_NPROC_RESULTS")


def _cpu_times() -> tuple[float, float] | None:
    """(idle, total) jiffies of all CPUs from /proc/stat (idle includes iowait); None where unreadable."""
    try:
        fields = Path("/proc/stat").read_text().split("\n", 1)[0].split()
    except OSError:
        return None
    if not fields or fields[0] != "cpu":
        return None
    t = [float(x) for x in fields[1:]]
    return t[3] + (t[4] if len(t) > 4 else 0.0), sum(t[:8])


def idle_cores(sample_s: float = 0.2, times: Callable[[], tuple[float, float] | None] = _cpu_times,
               n_cpu: int | None = None) -> float | None:
    """Cores idle over the next ``sample_s`` seconds [-] (idle share of all CPUs x their count); None if unknown."""
    n_cpu = n_cpu or os.cpu_count() or 1
    a = times()
    time.sleep(sample_s)
    b = times()
    if a is None or b is None or b[1] <= a[1]:
        return None
    return n_cpu * (b[0] - a[0]) / (b[1] - a[1])


def default_threads(env: dict, idle: Callable[[], float | None] | None = None, n_cpu: int | None = None) -> int | None:
    """ccx's thread count when the caller set none: the idle cores (at least 1), or None (ccx's own default)
    where the environment already sets one of :data:`THREAD_VARS`.

    Without OMP_NUM_THREADS the OpenMP regions of Debian's ccx 2.20 take every CPU (libgomp's default); beside
    one busy core such a job ran 8.6x slower than on one thread (the scenario matrix's mortar case, 566 s
    against 66 s): a loaded machine gets fewer threads, an idle one all of them.
    """
    if any(v in env for v in THREAD_VARS):
        return None
    n_cpu = n_cpu or os.cpu_count() or 1
    free = (idle or idle_cores)()
    if free is None:
        return n_cpu
    return max(1, min(n_cpu, int(free + 0.5)))


def _first_error(lines: list[str]) -> str | None:
    """The first ``*ERROR`` message with its continuation line, as one line."""
    for k, line in enumerate(lines):
        if "*ERROR" in line:
            parts = [line.strip()]
            nxt = lines[k + 1] if k + 1 < len(lines) else ""
            if nxt.strip() and not nxt.lstrip().startswith("*"):
                parts.append(nxt.strip())
            return " ".join(" ".join(parts).split())[:300]
    return None


def _clean(deck: Path, existed: set[str]) -> None:
    """Remove ccx's scratch files of the job, and its fixed-name debug files if this run created them."""
    for suffix in _JOB_SCRATCH:
        deck.with_suffix(suffix).unlink(missing_ok=True)
    for name in _DIR_SCRATCH:
        if name not in existed:
            (deck.parent / name).unlink(missing_ok=True)


def run(deck: str | Path, timeout_s: float = 600.0, progress: Callable[[str], None] | None = None,
        threads: int | None = None) -> CcxRun:
    """Run ccx on ``deck`` (``<job>.inp``) inside its folder; return the job's result files.

    Raise :class:`DeckbridgeError` (one line naming the deck) when ccx cannot start, runs longer than
    ``timeout_s``, or reports an error. ``threads`` sets OMP_NUM_THREADS / CCX_NPROC_* for the run; without it
    (and with none of them in the environment) ccx gets the idle cores (:func:`default_threads`).
    """
    deck = Path(deck).resolve()
    if not deck.is_file() or deck.suffix.lower() != ".inp":
        raise DeckbridgeError(f"{str(deck)!r}: no such .inp deck")
    exe = binary()
    for old in (".dat", ".frd", ".sta"):
        deck.with_suffix(old).unlink(missing_ok=True)
    env = dict(os.environ)
    if threads is None:
        threads = default_threads(env)
    if threads is not None:
        for var in THREAD_VARS:
            env[var] = str(int(threads))
    existed = {name for name in _DIR_SCRATCH if (deck.parent / name).exists()}
    start = time.monotonic()
    try:
        proc = subprocess.Popen([exe, "-i", deck.stem], cwd=deck.parent, stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True, errors="replace", env=env)
    except OSError as exc:
        raise RunError(f"CalculiX: cannot start {exe!r} ({exc.strerror})") from None
    lines: list[str] = []

    def pump():
        for line in proc.stdout:
            lines.append(line.rstrip("\n"))
            if progress is not None and _PROGRESS.match(line):
                progress(line.strip())

    reader = threading.Thread(target=pump, daemon=True)
    reader.start()
    try:
        code = proc.wait(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
        raise RunError(f"{str(deck)!r}: ccx ran longer than {timeout_s:g} s and was stopped") from None
    except BaseException:          # interrupted: do not leave ccx running
        proc.kill()
        proc.wait()
        raise
    finally:
        reader.join(timeout=5)
        proc.stdout.close()
        _clean(deck, existed)
    seconds = time.monotonic() - start
    sta = deck.with_suffix(".sta")
    sta_lines = sta.read_text(errors="replace").splitlines() if sta.is_file() else []
    err = _first_error(lines) or _first_error(sta_lines)
    if err or code != 0 or not any("Job finished" in ln for ln in lines):
        why = err or f"exit {code} without 'Job finished'"
        raise RunError(f"{str(deck)!r}: ccx failed (exit {code}): {why}")
    increments = sum(1 for ln in sta_lines if re.match(r"^\s*\d+\s+\d+\s+\d+\s+\d+\s", ln))
    return CcxRun(deck=deck, dat=deck.with_suffix(".dat"), frd=deck.with_suffix(".frd"), sta=sta,
                  seconds=seconds, increments=increments)


def run_result(deck: str | Path, timeout_s: float = 600.0, progress: Callable[[str], None] | None = None) -> Path:
    """The dialect record's runner: run ccx on ``deck`` (:func:`run`); the job's ``.frd`` (its reader's file)."""
    return run(deck, timeout_s=timeout_s, progress=progress).frd


def version() -> str | None:
    """'ccx -v' line with the version when CalculiX is installed (the dialect record's ``version``)."""
    exe = os.environ.get("DECKBRIDGE_CCX") or shutil.which("ccx")
    if exe is None:
        return None
    try:
        r = subprocess.run([exe, "-v"], capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    return next((ln.strip() for ln in (r.stdout + r.stderr).splitlines() if "ersion" in ln), None)
