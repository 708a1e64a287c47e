"""Test helper: one of the project's CalculiX decks of a model (penalty, lagrange (mortar) or f2f), run by ccx."""

import shutil
from pathlib import Path

from deckbridge.dialects import DIALECTS
from deckbridge.render import render_all


def ccx_job(model, folder: Path, deck: str = "penalty") -> Path:
    """Render ``model``'s CalculiX decks into ``folder``/decks, copy its ``deck`` (``penalty``, ``lagrange``, ``f2f``:
    ``<name>_ccx_<deck>.inp``) into ``folder``/ccx (a folder of that job's results only) and run ccx there;
    returns the job's ``.inp`` (``.frd``, ``.dat`` beside it)."""
    render_all(model, folder / "decks", names=["calculix"])
    inp = folder / "ccx" / f"{model.name}_ccx_{deck}.inp"
    inp.parent.mkdir(parents=True)
    shutil.copyfile(folder / "decks" / inp.name, inp)
    DIALECTS["calculix"].run(inp, timeout_s=300)
    return inp


def ccx_penalty_job(model, folder: Path) -> Path:
    """:func:`ccx_job` of the node-to-surface penalty deck."""
    return ccx_job(model, folder, "penalty")


def small_strain_pairs(model, system, sol, ref, ccx):
    """Yield ``(step, load_factor, joined)`` at every increment of the reference solution ``sol`` whose table lift
    / (R + t/2) <= 0.01 (the small-strain range): ``joined`` = the reference table ``ref`` merged with the ccx table
    ``ccx`` on node and surface (suffixes ``_r``, ``_c``). ccx's step 2 starts at its first increment (no lambda 0)."""
    import numpy as np
    g = model.geometry
    table = system.problem.contact_surface == "table"
    for k, lam in enumerate(sol.load_factor):
        lift = float(np.max(sol.gap[k, table], initial=0.0)) / (g.radius + g.thickness / 2)
        step = int(sol.step[k])
        if lift > 0.01 or (step == 2 and lam == 0.0):
            continue
        r = ref[(ref.step == step) & np.isclose(ref.load_factor, lam)]
        c = ccx[(ccx.step == step) & np.isclose(ccx.load_factor, lam)]
        yield step, float(lam), r.merge(c, on=["node", "surface"], suffixes=("_r", "_c"))
