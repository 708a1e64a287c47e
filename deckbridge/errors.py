"""Errors that end a command with one line and a non-zero exit code.

One root, :class:`DeckbridgeError`, and two kinds the command line tells apart by exit code:

- :class:`InputError` (exit 2): usage, model values, unreadable or malformed files, output folders;
- :class:`RunError` (exit 1): a run that failed on valid input (solver diverged, the skirt tipped
  over, ccx failed or was stopped, the Dask cluster did not answer).

A plain ``DeckbridgeError`` counts as an input error (exit 2). :class:`ModelError` is an input error
whose message is ``key = value: reason`` with the value shortened and escaped (:mod:`.textsafe`).
This module is a leaf: it imports nothing of deckbridge but :mod:`.textsafe`. :func:`read_text`: a file's
text, or one error line naming it.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from .textsafe import one_line, show

EXIT_INPUT = 2
EXIT_RUN = 1


class DeckbridgeError(Exception):
    """A user-facing failure; ``str(err)`` is one line naming the file, key or value at fault."""

    exit_code = EXIT_INPUT


class InputError(DeckbridgeError):
    """Bad input: usage, model, files, output folder (exit 2)."""

    exit_code = EXIT_INPUT


class RunError(DeckbridgeError):
    """A failure while running on valid input: solver, ccx, cluster (exit 1)."""

    exit_code = EXIT_RUN


class ModelError(InputError, ValueError):
    """Invalid model input; ``str(err)`` is one line: ``[source: ]key = value: reason``.

    ``value`` is kept as given; the message shows it shortened and with control characters escaped.
    ``source`` (the model file) is set by the loader so that value errors name the file.
    """

    def __init__(self, key: str, value: Any, reason: str, source: str | None = None):
        self.key, self.value, self.reason, self.source = key, value, reason, source
        super().__init__(key, reason)

    def __reduce__(self):          # picklable (Dask workers send errors back)
        return (type(self), (self.key, self.value, self.reason, self.source))

    def __str__(self) -> str:
        head = f"{one_line(self.source)}: " if self.source else ""
        return f"{head}{one_line(self.key)} = {show(self.value)}: {one_line(self.reason)}"


class DeckUnsupported(InputError):
    """A dialect cannot render this model (e.g. friction in a frictionless deck); raised before writing.

    ``dialect``: the dialect name; ``reason``: one line saying why, so a caller can leave that dialect out.
    """

    def __init__(self, dialect: str, reason: str):
        self.dialect, self.reason = dialect, reason
        super().__init__(f"{dialect} deck: {reason}")

    def note(self) -> str:
        """The one line printed where the dialect is left out and the other decks are written."""
        return f"note: {self}; that dialect is left out"


def read_text(path: str | Path) -> str:
    """Text of ``path`` (undecodable bytes replaced); DeckbridgeError naming the file if it cannot be read."""
    try:
        return Path(path).read_text(errors="replace")
    except OSError as exc:
        raise DeckbridgeError(f"{str(path)!r}: cannot read ({exc.strerror})") from None
