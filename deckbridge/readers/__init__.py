"""Readers of contact results into the one tidy table of :mod:`deckbridge.results`.

Formats: the reader of each dialect of :mod:`deckbridge.dialects` plus :data:`OTHER_FORMATS`; format
``f`` is the module ``deckbridge.readers.f``, which registers itself in :mod:`._registry` when
imported. :func:`read` picks the format (or takes ``fmt``) and conforms the table to the schema.
Readers raise :class:`deckbridge.errors.DeckbridgeError` with a one-line message naming the file
when it cannot be read.
"""

from __future__ import annotations

import importlib
from pathlib import Path

import pandas as pd

from ..dialects import DIALECTS
from ..errors import DeckbridgeError
from ..results import conform
from ._registry import READERS

OTHER_FORMATS = ("plain_csv", "reference")   # readers of no deck dialect


def formats() -> list[str]:
    """Every format name, sorted (without importing the readers)."""
    return sorted({d.reader for d in DIALECTS.values()} | set(OTHER_FORMATS))


def _load_all() -> None:
    """Import every reader module, in format-name order (importing one registers it)."""
    for name in formats():
        importlib.import_module(f"{__name__}.{name}")


def detect(path: str | Path) -> str:
    """Name of the format of ``path``; raise if none or several match."""
    _load_all()
    p = Path(path)
    if not p.exists():
        raise DeckbridgeError(f"{str(p)!r}: no such file or folder")
    hits = [r.name for r in READERS.values() if r.detect(p)]
    if not hits:
        raise DeckbridgeError(f"{str(p)!r}: format not recognised (use --format; known: {', '.join(sorted(READERS))})")
    return hits[0]


def read(path: str | Path, fmt: str | None = None, model=None) -> pd.DataFrame:
    """Read contact results at ``path`` into the tidy table."""
    _load_all()
    name = fmt or detect(path)
    if name not in READERS:
        raise DeckbridgeError(f"format {name!r}: unknown (known: {', '.join(sorted(READERS))})")
    return conform(READERS[name].read(Path(path), model=model))
