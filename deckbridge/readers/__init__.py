"""Readers of contact results into the one tidy table of :mod:`deckbridge.results`.

Formats: the :class:`~deckbridge.dialects.Format` records of :func:`deckbridge.dialects.formats` (each
dialect's reader, ``deckbridge/dialects/<name>/reader.py``, plus plain CSV and the reference folder here);
a format's module holds ``read(path, model=None)`` and ``detect(path)``. :func:`read` picks the format (or
takes ``fmt``) and conforms the table to the schema; :func:`read_result` adds what a source carries beside
its table. Readers raise :class:`deckbridge.errors.DeckbridgeError` with a one-line message naming the file
when it cannot be read. This package also holds what readers share (``_checks``, ``_contact_law``,
``_files``, ``_nodemap``).
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from ..dialects import DIALECTS, formats as _formats
from ..errors import DeckbridgeError
from ..results import SourceResult, conform


def formats() -> list[str]:
    """Every format name, sorted (without importing the readers)."""
    return list(_formats())


def detect(path: str | Path) -> str:
    """Name of the format of ``path``; raise if none or several match."""
    p = Path(path)
    if not p.exists():
        raise DeckbridgeError(f"{str(p)!r}: no such file or folder")
    every = _formats()
    hits = [name for name, f in every.items() if f.detect(p)]
    if not hits:
        raise DeckbridgeError(f"{str(p)!r}: format not recognised (name one; known formats: {', '.join(every)})")
    return hits[0]


def read(path: str | Path, fmt: str | None = None, model=None, mesh=None) -> pd.DataFrame:
    """Read contact results at ``path`` into the tidy table. ``mesh``: ``model``'s mesh when already built
    (readers that need it build it otherwise)."""
    name = fmt or detect(path)
    every = _formats()
    if name not in every:
        raise DeckbridgeError(f"format {name!r}: unknown (known: {', '.join(every)})")
    return conform(every[name].read(Path(path), model=model, mesh=mesh))


def read_result(path: str | Path, fmt: str | None = None, model=None, mesh=None):
    """What a source gives for a comparison: the table of :func:`read`, as a :class:`SourceResult` with its
    companions where the format has them (its ``source_reader``: a reference folder's summary, base wall,
    friction, global figures, :func:`.reference.read_source`; a dialect with a ``wall_reader``: its base-wall table when ``model`` is
    known), else the bare table."""
    name = fmt or detect(path)
    whole = _formats()[name].read_source(Path(path), model=model, mesh=mesh) if name in _formats() else None
    if whole is not None:
        return whole
    table = read(path, fmt=name, model=model, mesh=mesh)
    owner = next((d for d in DIALECTS.values() if d.reader == name), None)
    wall = owner.wall(Path(str(path)), model, mesh) if owner is not None and model is not None else None
    return table if wall is None else SourceResult(table, str(path), wall=wall)
