"""Nastran penalty deck ``<name>_penalty.bdf``: SOL 106, CGAP contact, two subcases.

Subcase 1 applies N; subcase 2 applies the totals N + lambda_max (T, M) in ``steps.increments``
increments. The template holds the executive and case control and the comments; the bulk cards
come from the pyNastran model of :func:`.nastran_cards.penalty_bulk`.
"""

from __future__ import annotations

from pathlib import Path

from . import RECORD
from ...mesh import SkirtMesh
from ...model import Model
from ...outdir import write_text
from ...render import nastran_cards as nc
from ...render import nastran_notes
from ...render._env import deck_paths, render


def deck_text(model: Model, mesh: SkirtMesh) -> str:
    """The whole penalty deck as text."""
    b = nc.penalty_bulk(model, mesh)
    return render(
        RECORD.templates, "penalty.bdf.j2", **nastran_notes.context(model, mesh),
        name=model.name, title=model.title, lambda_max=f"{model.steps.lambda_max:g}",
        increments=model.steps.increments, load_introduction=model.load_introduction,
        spc_sid=nc.SPC_SID, cid_cyl=nc.CID_CYL, load_step1=nc.LOAD_STEP1, load_step2=nc.LOAD_STEP2,
        nlparm_step1=nc.NLPARM_STEP1, nlparm_step2=nc.NLPARM_STEP2, tangential=nc.tangential(model),
        friction=f"{model.contact.friction:g}", n_grids=mesh.n_nodes, n_hexa=mesh.hexes.shape[0],
        n_contacts=len(b.groups["gaps"]) // 2, cards={g: b.text(g) for g in b.groups},
    )


def write(model: Model, mesh: SkirtMesh, outdir: Path) -> list[Path]:
    """Write ``<name>_penalty.bdf`` into ``outdir``."""
    (path,) = deck_paths(RECORD, model.name, outdir)
    return [write_text(path, deck_text(model, mesh))]
