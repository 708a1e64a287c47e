"""The readers' registry (a leaf: reader modules import it, it imports none of them).

Each reader module registers ``read(path, model=None) -> DataFrame`` under its format name with a
``detect(path) -> bool`` function; the format name is the module's name under ``deckbridge.readers``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import pandas as pd


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
