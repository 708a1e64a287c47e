"""Readers of contact results into the one tidy table of :mod:`deckbridge.results`.

Each reader module registers ``read(path, model=None) -> DataFrame`` under a format name with a
``detect(path) -> bool`` function. :func:`read` picks the format (or takes ``fmt``) and conforms the
table to the schema. Readers raise :class:`deckbridge.errors.DeckbridgeError` with a one-line message
naming the file when it cannot be read.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import pandas as pd

from ..errors import DeckbridgeError
from ..results import conform


@dataclass(frozen=True)
class Reader:
    name: str
    read: Callable[..., pd.DataFrame]
    detect: Callable[[Path], bool]


READERS: dict[str, Reader] = {}


def register(name: str, detect: Callable[[Path], bool]):
    """Decorator: register ``read(path, model=None)`` under ``name``."""
    def deco(func):
        READERS[name] = Reader(name, func, detect)
        return func
    return deco


def _load_all() -> None:
    """Import every reader module (importing one registers it)."""
    from . import abaqus_dat, calculix, mystran_f06, nastran_op2, plain_csv, reference  # noqa: F401


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
