"""Errors that end a command with one line and a non-zero exit code."""

from .model import ModelError  # noqa: F401  (re-exported)


class DeckbridgeError(Exception):
    """A user-facing failure; ``str(err)`` is one line naming the file, key or value at fault."""


class DeckUnsupported(DeckbridgeError):
    """A dialect cannot render this model (e.g. friction in a frictionless deck); raised before writing.

    ``dialect``: the dialect name; ``reason``: one line saying why, so a caller can leave that dialect out.
    """

    def __init__(self, dialect: str, reason: str):
        self.dialect, self.reason = dialect, reason
        super().__init__(f"{dialect} deck: {reason}")
