"""Nastran penalty deck ``<name>_penalty.bdf``: SOL 106, CGAP contact, two subcases.

Subcase 1 applies N; subcase 2 applies the totals N + lambda_max (T, M) in ``steps.increments``
increments. Card conventions (ids, gap axis, PGAP fields) are in :mod:`.nastran_cards`.
"""

from __future__ import annotations

from pathlib import Path

from ..mesh import SkirtMesh
from ..model import Model
from ..outdir import write_text
from . import nastran_cards as nc
from ._env import deck_paths, render


def deck_text(model: Model, mesh: SkirtMesh) -> str:
    """The whole penalty deck as text."""
    return render(
        "nastran", "penalty.bdf.j2", **nc.model_context(model, mesh),
        increments=model.steps.increments, load_introduction=model.load_introduction,
        load_step1=nc.LOAD_STEP1, load_step2=nc.LOAD_STEP2,
        nlparm_step1=nc.NLPARM_STEP1, nlparm_step2=nc.NLPARM_STEP2,
        gaps=nc.gap_cards(mesh, model), springs=nc.circumferential_spring_cards(mesh),
        nlparm=nc.nlparm_cards(model),
    )


def write(model: Model, mesh: SkirtMesh, outdir: Path) -> list[Path]:
    """Write ``<name>_penalty.bdf`` into ``outdir``."""
    (path,) = deck_paths("nastran", model.name, outdir)
    return [write_text(path, deck_text(model, mesh))]
