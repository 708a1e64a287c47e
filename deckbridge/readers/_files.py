"""File access shared by the readers: one-line errors naming the file."""

from __future__ import annotations

from pathlib import Path

from ..errors import DeckbridgeError


def read_text(path: str | Path) -> str:
    """Text of ``path`` (undecodable bytes replaced); DeckbridgeError naming the file if it cannot be read."""
    try:
        return Path(path).read_text(errors="replace")
    except OSError as exc:
        raise DeckbridgeError(f"{str(path)!r}: cannot read ({exc.strerror})") from None
