"""The ``deckbridge`` command line. Each command lives in its own module and registers on ``main``."""

from ._common import main  # noqa: F401

# Command modules: importing one registers its command(s) on ``main``.
from . import decks_cmd, init_cmd  # noqa: F401,E402
