"""Atomic writing of output folders: every file appears whole, or not at all."""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import tempfile
from pathlib import Path
from typing import Iterator

from .errors import DeckbridgeError

_SAFE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")


def safe_filename(name: str) -> str:
    """Return ``name`` if it is a plain file name (no separators, no '..'); raise otherwise."""
    if not _SAFE.match(name) or ".." in name:
        raise DeckbridgeError(f"file name {name!r}: only letters, digits, '_', '-', '.' are allowed")
    return name


def prepare(outdir: str | Path) -> Path:
    """Create ``outdir`` if needed and check that it is a writable folder."""
    out = Path(outdir)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise DeckbridgeError(f"output folder {str(out)!r}: cannot create ({exc.strerror})") from None
    if not out.is_dir():
        raise DeckbridgeError(f"output folder {str(out)!r}: not a folder")
    if not os.access(out, os.W_OK | os.X_OK):
        raise DeckbridgeError(f"output folder {str(out)!r}: not writable")
    return out


@contextlib.contextmanager
def staged(outdir: str | Path) -> Iterator[Path]:
    """Yield a staging folder inside ``outdir``; on success move its files into ``outdir``.

    On any exception the staging folder is removed and ``outdir`` is left as it was.
    """
    out = prepare(outdir)
    try:
        stage = Path(tempfile.mkdtemp(prefix=".staging-", dir=out))
    except OSError as exc:
        raise DeckbridgeError(f"output folder {str(out)!r}: not writable ({exc.strerror})") from None
    try:
        yield stage
        for src in sorted(stage.rglob("*")):
            if src.is_file():
                dst = out / src.relative_to(stage)
                dst.parent.mkdir(parents=True, exist_ok=True)
                os.replace(src, dst)
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_text(path: str | Path, text: str) -> Path:
    """Write one file atomically (temporary file in the same folder, then rename)."""
    p = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", dir=p.parent)
    try:
        with os.fdopen(fd, "w") as fh:
            fh.write(text)
        os.chmod(tmp, 0o666 & ~_umask())   # mkstemp makes 0600: give the mode a plain open() would
        os.replace(tmp, p)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    return p
