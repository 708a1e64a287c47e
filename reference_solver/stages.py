"""Stage marks for profiling (bench/scale.py): ``mark(name)`` calls the hook set by ``set_hook``.

The solver marks the end of each stage of the condensation (assembly, split, factor, schur,
dense); the hook can read the clock and the peak RSS. No hook, no cost.
"""

from __future__ import annotations

from typing import Callable

_hook: Callable[[str], None] | None = None


def set_hook(fn: Callable[[str], None] | None) -> None:
    """Install (or with None remove) the function called with each stage name."""
    global _hook
    _hook = fn


def mark(name: str) -> None:
    if _hook is not None:
        _hook(name)
