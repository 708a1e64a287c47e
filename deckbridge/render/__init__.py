"""Rendering every dialect's decks (:func:`render_all`) and what the renderers share.

A dialect's renderer is ``deckbridge/dialects/<name>/render.py``: ``write(model, mesh, outdir) -> list[Path]``
renders its jinja2 template(s) (``templates/<name>/``, its record's ``templates``) and writes the deck
file(s) into ``outdir`` (a staging folder; the caller moves files atomically). Shared here: the jinja2
environment and deck paths (:mod:`._env`), the inp-family cards (:mod:`.inp_cards`: Abaqus, CalculiX),
the Nastran-family cards and notes (:mod:`.nastran_cards`, :mod:`.nastran_notes`: Nastran, MYSTRAN), and
the dialect-free model VTU (:mod:`.model_vtu`) that :func:`render_all` writes once beside the decks.
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

from ..deck_elements import element_problem
from ..dialects import DIALECTS
from ..errors import DeckbridgeError, DeckUnsupported
from ..mesh import SkirtMesh, build_mesh
from ..model import Model
from ..outdir import staged


def render_all(model: Model, outdir: str | Path, names: list[str] | None = None,
               mesh: SkirtMesh | None = None, model_vtu: bool | None = None,
               on_unsupported: Callable[[DeckUnsupported], None] | None = None) -> list[Path]:
    """Render every dialect's decks (or those of ``names``) of ``model`` into ``outdir`` atomically.

    ``model_vtu``: also write ``<name>_model.vtu`` (mesh, ids, sets); default: when every dialect is
    rendered (``names`` None), so a chosen subset of decks stays just those decks.
    ``on_unsupported``: called with the :class:`DeckUnsupported` of a dialect that cannot carry the model
    (checked before it writes anything), which is then left out; default: the error propagates.
    """
    mesh = mesh or build_mesh(model)
    chosen = names or sorted(DIALECTS)
    unknown = [n for n in chosen if n not in DIALECTS]
    if unknown:
        raise DeckbridgeError(f"deck dialect {unknown[0]!r}: unknown (known: {', '.join(sorted(DIALECTS))})")
    written: list[Path] = []
    with staged(outdir) as stage:
        for name in chosen:
            try:
                why = element_problem(name, model, mesh) or DIALECTS[name].id_problem(mesh)
                if why:
                    raise DeckUnsupported(name, why)
                files = DIALECTS[name].write(model, mesh, stage)
            except DeckUnsupported as err:
                if on_unsupported is None:
                    raise
                on_unsupported(err)
                continue
            written += [Path(outdir) / p.relative_to(stage) for p in files]
        if names is None if model_vtu is None else model_vtu:
            from .model_vtu import write as write_model_vtu
            written.append(Path(outdir) / write_model_vtu(model, mesh, stage).relative_to(stage))
    return written
