"""Atomic writing of output folders: every file appears whole, or not at all."""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import tempfile
from pathlib import Path
from typing import Iterator

from .errors import DeckbridgeError, InputError, RunError

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


# --- output folders of commands: refused targets, ownership marker, stale temporaries, lock -------------
MARKER = ".deckbridge-output"
LOCK = ".deckbridge-lock"
_TEMP_PREFIXES = (".staging-",)


def check_target(outdir: str | Path, command: str, force: bool = False, sources: tuple = ()) -> Path:
    """Refuse ``-o outdir`` for ``command`` before anything is written (one line each):

    - an empty path (it would mean the current folder);
    - a folder equal to or inside a source folder (``compare``: the report would overwrite results);
    - a file, or a folder whose marker says another command wrote it, unless ``force``.
    Nothing is created here.
    """
    if str(outdir).strip() == "":
        raise InputError("-o = '': give an output folder (use -o . for the current folder)")
    out = Path(outdir)
    real = Path(os.path.realpath(out))
    for src in sources:
        s = Path(os.path.realpath(src))
        if s.is_dir() and (real == s or s in real.parents):
            raise InputError(f"-o = {str(out)!r}: is {'the' if real == s else 'inside the'} source folder "
                             f"{str(src)!r}; the report would overwrite its results: choose another folder")
    if out.exists() and not out.is_dir():
        raise InputError(f"-o = {str(out)!r}: exists and is not a folder")
    owner = owner_of(out)
    if owner is not None and owner != command and not force:
        raise InputError(f"-o = {str(out)!r}: written by 'deckbridge {owner}'; 'deckbridge {command}' would mix "
                         "or overwrite its files: choose another folder, or --force")
    return out


def owner_of(folder: str | Path) -> str | None:
    """The command named in ``folder``'s marker file, or None."""
    try:
        text = (Path(folder) / MARKER).read_text(errors="replace")[:200]
    except OSError:
        return None
    return text.strip().split()[0] if text.strip() else None


def mark(folder: str | Path, command: str) -> None:
    """Write the marker naming the command that wrote ``folder`` (when it is a folder)."""
    p = Path(folder)
    if p.is_dir() and owner_of(p) != command:
        with contextlib.suppress(OSError):
            write_text(p / MARKER, f"{command}\n")


def remove_if_empty(folder: str | Path) -> None:
    """Remove ``folder`` and its sub-folders when they hold no file (a command failed before writing)."""
    p = Path(folder)
    if not p.is_dir():
        return
    for root, dirs, files in os.walk(p, topdown=False):
        if set(files) - {LOCK, MARKER}:
            return
        with contextlib.suppress(OSError):
            for name in files:
                os.unlink(os.path.join(root, name))
            os.rmdir(root)


def remove_stale(folder: str | Path) -> list[Path]:
    """Remove temporaries a killed run left in ``folder`` and ``folder/cases`` (staging folders, ``.name.xxxx``
    temp files of :func:`write_text`). Only call while holding :func:`lock` on ``folder``."""
    removed = []
    for d in (Path(folder), Path(folder) / "cases"):
        if not d.is_dir():
            continue
        for p in d.iterdir():
            name = p.name
            if name in (MARKER, LOCK) or not name.startswith("."):
                continue
            if p.is_dir() and name.startswith(_TEMP_PREFIXES):
                shutil.rmtree(p, ignore_errors=True)
                removed.append(p)
            elif p.is_file() and re.fullmatch(r"\.[^/]+\.[A-Za-z0-9_]{6,}", name):
                with contextlib.suppress(OSError):
                    p.unlink()
                    removed.append(p)
    return removed


@contextlib.contextmanager
def lock(folder: str | Path, what: str = "another deckbridge run") -> Iterator[Path]:
    """Hold an exclusive lock on ``folder`` (created if needed) for one writer; refuse at once when
    another process holds it. The lock dies with its process (flock), so a killed run never blocks."""
    import fcntl

    out = prepare(folder)
    path = out / LOCK
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    except OSError as exc:
        raise InputError(f"{str(out)!r}: cannot create the lock file ({exc.strerror})") from None
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            holder = os.pread(fd, 32, 0).decode(errors="replace").strip() or "?"
            raise RunError(f"{str(out)!r}: {what} (pid {holder}) is writing here: wait for it to finish, "
                           "or use another folder") from None
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        yield out
    finally:
        os.close(fd)
