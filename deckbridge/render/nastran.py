"""Nastran penalty deck ``<name>_penalty.bdf``: SOL 106, CGAP contact, two subcases.

Subcase 1 applies N; subcase 2 applies the totals N + lambda_max (T, M) in ``steps.increments``
increments. Card conventions (ids, gap axis, PGAP fields) are in :mod:`.nastran_cards`.
"""

from __future__ import annotations

from pathlib import Path

from ..dialects import DIALECTS
from ..mesh import SkirtMesh
from ..model import Model
from ..outdir import safe_filename, write_text
from . import nastran_cards as nc
from ._env import render


def deck_text(model: Model, mesh: SkirtMesh) -> str:
    """The whole penalty deck as text."""
    lay = nc.gap_layout(mesh)
    return render(
        "nastran", "penalty.bdf.j2",
        name=model.name, title=model.title, lambda_max=f"{model.steps.lambda_max:g}",
        increments=model.steps.increments, load_introduction=model.load_introduction,
        spc_sid=nc.SPC_SID, cid_cyl=nc.CID_CYL,
        load_step1=nc.LOAD_STEP1, load_step2=nc.LOAD_STEP2,
        nlparm_step1=nc.NLPARM_STEP1, nlparm_step2=nc.NLPARM_STEP2,
        cord=[nc.cord2c_card()], material=nc.material_cards(model),
        grids=nc.grid_cards(mesh), n_grids=mesh.n_nodes, ref_grid=nc.reference_grid_card(mesh),
        hexas=nc.hexa_cards(mesh), n_hexa=mesh.hexes.shape[0],
        ground_grids=nc.ground_grid_cards(mesh), spcs=nc.spc_ground_cards(lay.ground),
        gaps=nc.gap_cards(mesh, model), n_gaps=len(lay),
        springs=nc.circumferential_spring_cards(mesh),
        coupling=nc.coupling_cards(mesh, model), loads=nc.load_cards(mesh, model),
        nlparm=nc.nlparm_cards(model),
    )


def write(model: Model, mesh: SkirtMesh, outdir: Path) -> list[Path]:
    """Write ``<name>_penalty.bdf`` into ``outdir``."""
    (name,) = DIALECTS["nastran"].deck_names(model.name)
    path = Path(outdir) / safe_filename(name)
    write_text(path, deck_text(model, mesh))
    return [path]
