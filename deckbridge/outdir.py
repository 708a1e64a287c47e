"""Atomic writing of output folders: every file appears whole, or not at all; a command writes only into a
folder it created or marked, and removes only what it created and marked.

Every temporary carries the project's prefix ``.deckbridge-`` (``.deckbridge-tmp-<name>.XXXXXXXX`` files of
:func:`write_text`, ``.deckbridge-staging-XXXXXXXX`` folders of :func:`staged`, ``.deckbridge-old-XXXXXXXX``
folders of :func:`replacing`); :func:`remove_stale` removes those alone, and only in a marked folder.
Every OSError while writing names the path (a full disk says which file or folder).
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import signal
import tempfile
import threading
from pathlib import Path
from typing import IO, Callable, Iterable, Iterator

from .errors import DeckbridgeError, InputError, RunError

_SAFE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")
TMP_PREFIX = ".deckbridge-tmp-"            # + <name>. + 8 random characters (tempfile)
STAGING_PREFIX = ".deckbridge-staging-"
OLD_PREFIX = ".deckbridge-old-"
TEMPORARY_PREFIXES = (TMP_PREFIX, STAGING_PREFIX, OLD_PREFIX)   # every temporary the project makes
_STALE = re.compile(r"\.deckbridge-(?:tmp-.+\.|staging-|old-)[a-z0-9_]{8}")
MARKER = ".deckbridge-output"
LOCK = ".deckbridge-lock"
CONTROL = (MARKER, LOCK)


def safe_filename(name: str) -> str:
    """Return ``name`` if it is a plain file name (no separators, no '..'); raise otherwise."""
    if not _SAFE.match(name) or ".." in name:
        raise DeckbridgeError(f"file name {name!r}: only letters, digits, '_', '-', '.' are allowed")
    return name


def cannot_write(path: str | Path, exc: OSError) -> RunError:
    """The one-line error of an OSError while writing ``path`` (the path named even when the OS did not)."""
    return RunError(f"{str(path)!r}: cannot write ({exc.strerror or type(exc).__name__})")


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
def deferred_signals() -> Iterator[None]:
    """Hold SIGINT and SIGTERM while the block runs (renames that must not be cut half-way), then deliver
    them to the handlers in force before. Outside the main thread the block runs as is."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    got: list[int] = []
    old = {s: signal.signal(s, lambda signum, frame: got.append(signum)) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for s, handler in old.items():
            signal.signal(s, handler)
        for s in dict.fromkeys(got):
            signal.raise_signal(s)


@contextlib.contextmanager
def staged(outdir: str | Path) -> Iterator[Path]:
    """Yield a staging folder inside ``outdir``; on success move its files into ``outdir``.

    On any exception the staging folder is removed and ``outdir`` is left as it was.
    """
    out = prepare(outdir)
    try:
        stage = Path(tempfile.mkdtemp(prefix=STAGING_PREFIX, dir=out))
    except OSError as exc:
        raise DeckbridgeError(f"output folder {str(out)!r}: not writable ({exc.strerror})") from None
    try:
        try:
            yield stage
            with deferred_signals():
                for src in sorted(stage.rglob("*")):
                    if src.is_file():
                        dst = out / src.relative_to(stage)
                        dst.parent.mkdir(parents=True, exist_ok=True)
                        os.replace(src, dst)
        except OSError as exc:
            if exc.filename is not None or exc.strerror is None:
                raise
            raise cannot_write(out, exc) from None
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_file(path: str | Path, write: Callable[[IO], object], **open_kw) -> Path:
    """Write one file atomically: ``write(fh)`` into a temporary file in the same folder (mode of a plain
    open(), not mkstemp's 0600), then rename. ``open_kw``: text-mode options of open() (newline, encoding)."""
    p = Path(path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f"{TMP_PREFIX}{p.name}.", dir=p.parent)
    except OSError as exc:
        raise cannot_write(p, exc) from None
    try:
        with os.fdopen(fd, "w", **open_kw) as fh:
            write(fh)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, p)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise cannot_write(p, exc) from None
        raise
    return p


def write_text(path: str | Path, text: str) -> Path:
    """Write one text file atomically (:func:`write_file`)."""
    return write_file(path, lambda fh: fh.write(text))


# --- output folders of commands: refused targets, ownership marker, stale temporaries, lock -------------
def entries(folder: Path) -> set[str]:
    """Names in ``folder`` other than the marker, the lock and the project's temporaries."""
    with os.scandir(folder) as it:
        return {e.name for e in it if e.name not in CONTROL and not _STALE.fullmatch(e.name)}


def check_target(outdir: str | Path, command: str, force: bool = False, sources: tuple = ()) -> Path:
    """Refuse ``-o outdir`` for ``command`` before anything is written (one line each):

    - an empty path (it would mean the current folder);
    - a folder equal to or inside a source folder (``compare``: the report would overwrite results);
    - a file; unless ``force``: a folder whose marker says another command wrote it, or a non-empty folder
      without a marker (files deckbridge did not write: the user's own ``summary.json``, say).
    Nothing is created here.
    """
    if str(outdir).strip() == "":
        raise InputError("-o = '': give an output folder (use -o . for the current folder)")
    out = Path(outdir)
    real = Path(os.path.realpath(out))
    for src in sources:
        s = Path(os.path.realpath(src))
        if s.is_dir() and (real == s or s in real.parents):
            raise InputError(f"`outdir` = {str(out)!r}: is {'the' if real == s else 'inside the'} source folder "
                             f"{str(src)!r}; the report would overwrite its results: choose another folder")
    if out.exists() and not out.is_dir():
        raise InputError(f"`outdir` = {str(out)!r}: exists and is not a folder")
    owner = owner_of(out)
    if owner is not None and owner != command and not force:
        raise InputError(f"`outdir` = {str(out)!r}: written by 'deckbridge {owner}'; 'deckbridge {command}' would mix "
                         "or overwrite its files: choose another folder, or `force`")
    if owner is None and out.is_dir() and not force:
        try:
            theirs = sorted(entries(out))
        except OSError as exc:
            raise InputError(f"`outdir` = {str(out)!r}: cannot list ({exc.strerror})") from None
        if theirs:
            shown = ", ".join(theirs[:3]) + (", ..." if len(theirs) > 3 else "")
            raise InputError(f"`outdir` = {str(out)!r}: holds files deckbridge did not write ({shown}); 'deckbridge "
                             f"{command}' could overwrite them: choose a new or empty folder, or `force`")
    return out


def _marker_lines(folder: str | Path) -> list[str]:
    try:
        return (Path(folder) / MARKER).read_text(errors="replace")[:100_000].splitlines()
    except OSError:
        return []


def owner_of(folder: str | Path) -> str | None:
    """The command named in ``folder``'s marker file, or None."""
    lines = _marker_lines(folder)
    return lines[0].split()[0] if lines and lines[0].split() else None


def recorded(folder: str | Path) -> list[str]:
    """The top-level entries of ``folder`` its marker records as written by its command (:func:`replacing`)."""
    return [n for n in _marker_lines(folder)[1:] if n and "/" not in n and n not in (".", "..") + CONTROL]


def mark(folder: str | Path, command: str, entries: Iterable[str] | None = None) -> None:
    """Write the marker naming the command that wrote ``folder`` (when it is a folder) and, with ``entries``,
    the top-level entries it wrote (a marker of the same command without entries is kept as it is)."""
    p = Path(folder)
    if p.is_dir() and (entries is not None or owner_of(p) != command):
        write_text(p / MARKER, "".join(f"{line}\n" for line in [command, *sorted(entries or ())]))


def remove_if_empty(folder: str | Path) -> None:
    """Remove ``folder`` and its sub-folders when they hold no file (a command failed before writing)."""
    p = Path(folder)
    if not p.is_dir():
        return
    for root, dirs, files in os.walk(p, topdown=False):
        if set(files) - set(CONTROL):
            return
        with contextlib.suppress(OSError):
            for name in files:
                os.unlink(os.path.join(root, name))
            os.rmdir(root)


def remove_stale(folder: str | Path) -> list[Path]:
    """Remove the project's temporaries a killed run left in ``folder`` and ``folder/cases`` (names of
    :data:`_STALE`), and only in a folder that carries the project's marker: nothing else is touched.
    Only call while holding :func:`lock` on ``folder``."""
    removed: list[Path] = []
    if owner_of(folder) is None:
        return removed
    for d in (Path(folder), Path(folder) / "cases"):
        if not d.is_dir() or d.is_symlink():
            continue
        for p in d.iterdir():
            if not _STALE.fullmatch(p.name):
                continue
            if p.is_dir() and not p.is_symlink():
                shutil.rmtree(p, ignore_errors=True)
            else:
                with contextlib.suppress(OSError):
                    p.unlink()
            removed.append(p)
    return removed


_HELD: set[str] = set()                     # folders locked by this process (POSIX locks are per process)
_HELD_GUARD = threading.Lock()


@contextlib.contextmanager
def lock(folder: str | Path, what: str = "another deckbridge run") -> Iterator[Path]:
    """Hold an exclusive lock on ``folder`` (created if needed) for one writer; refuse at once when
    another process (or another thread of this one) holds it. A POSIX record lock: it dies with its
    process and is not inherited by forked children (a sweep's workers), so a killed run never blocks."""
    import fcntl

    out = prepare(folder)
    key, path = os.path.realpath(out), out / LOCK
    with _HELD_GUARD:
        mine = key in _HELD
        _HELD.add(key)
    if mine:     # opening and closing the file here would release this process's lock: refuse first
        raise RunError(f"{str(out)!r}: {what} (pid {os.getpid()}) is writing here: wait for it to finish, "
                       "or use another folder")
    try:
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
        except OSError as exc:
            raise InputError(f"{str(out)!r}: cannot create the lock file ({exc.strerror})") from None
        try:
            try:
                fcntl.lockf(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                holder = os.pread(fd, 32, 0).decode(errors="replace").strip() or "?"
                raise RunError(f"{str(out)!r}: {what} (pid {holder}) is writing here: wait for it to finish, "
                               "or use another folder") from None
            os.ftruncate(fd, 0)
            os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
            try:
                yield out
            finally:
                with contextlib.suppress(OSError):
                    os.ftruncate(fd, 0)          # released: the file names no holder
        finally:
            os.close(fd)
    finally:
        with _HELD_GUARD:
            _HELD.discard(key)


def _remove(path: Path) -> None:
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path, ignore_errors=True)
    else:
        with contextlib.suppress(FileNotFoundError):
            path.unlink()


@contextlib.contextmanager
def replacing(outdir: str | Path, command: str, layout: Iterable[str]) -> Iterator[Path]:
    """Write ``command``'s outputs into ``outdir`` all or nothing, in place (paths stay those of the folder).

    Under :func:`lock`: the project's stale temporaries are removed, then the entries the previous run of
    ``command`` wrote (its marker's record) and the names of ``layout`` are set aside in a
    ``.deckbridge-old-*`` folder. On success they are deleted (a re-run leaves no stale ``ccx/``) and the new
    entries are recorded in the marker; on any exception or interrupt, the new entries are removed and the
    old ones put back: the folder is left as it was. Other files of the folder are never touched.
    """
    with lock(outdir, f"another 'deckbridge {command}'") as out:
        remove_stale(out)
        before = entries(out)
        old = sorted((set(recorded(out)) | set(layout)) & before)
        try:
            aside = Path(tempfile.mkdtemp(prefix=OLD_PREFIX, dir=out))
        except OSError as exc:
            raise cannot_write(out, exc) from None
        with deferred_signals():
            for name in old:
                os.replace(out / name, aside / name)
        kept = before - set(old)
        try:
            yield out
        except BaseException:
            with deferred_signals():
                for name in entries(out) - kept:
                    _remove(out / name)
                for name in old:
                    os.replace(aside / name, out / name)
                shutil.rmtree(aside, ignore_errors=True)
            raise
        with deferred_signals():
            shutil.rmtree(aside, ignore_errors=True)
            mark(out, command, entries(out) - kept)
