"""Deck units: factors that turn an SI value of the model into the value written in a deck.

The model is always SI (N, m, Pa, kg). A deck is written either in SI or in the mm system
(N, mm, MPa, t). Multiply an SI value by the factor to get the deck value; divide a deck value
by it to get SI back. A leaf module (imports nothing of deckbridge).
"""

from __future__ import annotations

from dataclasses import dataclass

UNIT_LABEL = {"SI": "N, m, Pa", "mm": "N, mm, MPa"}


@dataclass(frozen=True)
class Units:
    """Factors SI -> deck: length [m -> mm], stress/pressure [Pa -> MPa], force [N -> N],
    moment [N m -> N mm], spring stiffness [N/m -> N/mm]."""
    name: str
    length: float
    stress: float
    force: float
    moment: float
    stiffness: float


_UNITS = {
    "SI": Units("SI", length=1.0, stress=1.0, force=1.0, moment=1.0, stiffness=1.0),
    "mm": Units("mm", length=1.0e3, stress=1.0e-6, force=1.0, moment=1.0e3, stiffness=1.0e-3),
}


def scale(units: str) -> Units:
    """The factors of the deck unit system ``units`` ('SI' or 'mm'); ValueError otherwise."""
    try:
        return _UNITS[units]
    except KeyError:
        raise ValueError(f"units {units!r}: unknown (known: {', '.join(_UNITS)})") from None
