"""Errors that end a command with one line and a non-zero exit code."""

from .model import ModelError  # noqa: F401  (re-exported)


class DeckbridgeError(Exception):
    """A user-facing failure; ``str(err)`` is one line naming the file, key or value at fault."""
