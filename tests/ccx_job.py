"""Test helper: the project's CalculiX node-to-surface penalty deck of a model, run by ccx."""

import shutil
from pathlib import Path

from deckbridge.dialects import DIALECTS
from deckbridge.render import render_all


def ccx_penalty_job(model, folder: Path) -> Path:
    """Render ``model``'s CalculiX decks into ``folder``/decks, copy its penalty deck into ``folder``/ccx (a
    folder of that job's results only) and run ccx there; returns the job's ``.inp`` (``.frd``, ``.dat``
    beside it)."""
    render_all(model, folder / "decks", names=["calculix"])
    deck = folder / "ccx" / f"{model.name}_ccx_penalty.inp"
    deck.parent.mkdir(parents=True)
    shutil.copyfile(folder / "decks" / deck.name, deck)
    DIALECTS["calculix"].run_module().run(deck, timeout_s=300)
    return deck
