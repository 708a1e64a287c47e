"""Deck renderers, registered by name (one module and one ``templates/<dialect>/`` folder each).

A renderer is ``write(model, mesh, outdir) -> list[Path]``: it renders its jinja2 template(s) and
writes the deck file(s) into ``outdir`` (a staging folder; the caller moves files atomically).
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

from ..mesh import SkirtMesh, build_mesh
from ..model import Model
from ..outdir import staged

Renderer = Callable[[Model, SkirtMesh, Path], list[Path]]
RENDERERS: dict[str, Renderer] = {}


def register(name: str):
    """Decorator: register a renderer under ``name``."""
    def deco(func: Renderer) -> Renderer:
        RENDERERS[name] = func
        return func
    return deco


def _load_all() -> None:
    """Import every renderer module (importing one registers it)."""
    from . import abaqus, calculix, mystran, nastran  # noqa: F401


def render_all(model: Model, outdir: str | Path, names: list[str] | None = None,
               mesh: SkirtMesh | None = None) -> list[Path]:
    """Render every registered deck (or ``names``) of ``model`` into ``outdir`` atomically."""
    _load_all()
    mesh = mesh or build_mesh(model)
    chosen = names or sorted(RENDERERS)
    unknown = [n for n in chosen if n not in RENDERERS]
    if unknown:
        from ..errors import DeckbridgeError
        raise DeckbridgeError(f"deck dialect {unknown[0]!r}: unknown (known: {', '.join(sorted(RENDERERS))})")
    written: list[Path] = []
    with staged(outdir) as stage:
        for name in chosen:
            written += [Path(outdir) / p.relative_to(stage) for p in RENDERERS[name](model, mesh, stage)]
    return written
