"""The ``deckbridge`` command line. Each command lives in its own module and registers on ``main``."""

from . import _common
from ._common import main  # noqa: F401

# Command modules: importing one registers its command(s) on ``main``.
from . import compare_cmd, decks_cmd, import_cmd, init_cmd, run_cmd, solve_cmd, studies_cmd  # noqa: F401,E402

for _cmd in main.commands.values():          # -o checks, --force, ownership marker (see _common)
    _common.guard_outputs(_cmd)
