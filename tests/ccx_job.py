"""Test helper: one of the project's CalculiX decks of a model (penalty or mortar), run by ccx."""

import shutil
from pathlib import Path

from deckbridge.dialects import DIALECTS
from deckbridge.render import render_all


def ccx_job(model, folder: Path, deck: str = "penalty") -> Path:
    """Render ``model``'s CalculiX decks into ``folder``/decks, copy its ``deck`` (``penalty`` or ``lagrange``:
    ``<name>_ccx_<deck>.inp``) into ``folder``/ccx (a folder of that job's results only) and run ccx there;
    returns the job's ``.inp`` (``.frd``, ``.dat`` beside it)."""
    render_all(model, folder / "decks", names=["calculix"])
    inp = folder / "ccx" / f"{model.name}_ccx_{deck}.inp"
    inp.parent.mkdir(parents=True)
    shutil.copyfile(folder / "decks" / inp.name, inp)
    DIALECTS["calculix"].run_module().run(inp, timeout_s=300)
    return inp


def ccx_penalty_job(model, folder: Path) -> Path:
    """:func:`ccx_job` of the node-to-surface penalty deck."""
    return ccx_job(model, folder, "penalty")
