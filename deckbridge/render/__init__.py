"""Deck renderers: one module and one ``templates/<dialect>/`` folder per dialect of :mod:`deckbridge.dialects`.

A renderer is ``write(model, mesh, outdir) -> list[Path]``: it renders its jinja2 template(s) and
writes the deck file(s) into ``outdir`` (a staging folder; the caller moves files atomically). The
dialect table names each renderer; nothing registers itself here.
"""

from __future__ import annotations

from pathlib import Path

from ..dialects import DIALECTS
from ..errors import DeckbridgeError
from ..mesh import SkirtMesh, build_mesh
from ..model import Model
from ..outdir import staged


def render_all(model: Model, outdir: str | Path, names: list[str] | None = None,
               mesh: SkirtMesh | None = None) -> list[Path]:
    """Render every dialect's decks (or those of ``names``) of ``model`` into ``outdir`` atomically."""
    mesh = mesh or build_mesh(model)
    chosen = names or sorted(DIALECTS)
    unknown = [n for n in chosen if n not in DIALECTS]
    if unknown:
        raise DeckbridgeError(f"deck dialect {unknown[0]!r}: unknown (known: {', '.join(sorted(DIALECTS))})")
    written: list[Path] = []
    with staged(outdir) as stage:
        for name in chosen:
            written += [Path(outdir) / p.relative_to(stage) for p in DIALECTS[name].write(model, mesh, stage)]
    return written
