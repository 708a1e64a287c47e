"""Deck units: factors that multiply an SI value (N, m, Pa) to give the value written in a deck.

``SI``: N, m, Pa, kg (every factor 1). ``mm``: N, mm, MPa, t (length x 1e3, stress x 1e-6, force x 1,
moment [N m -> N mm] x 1e3, stiffness [N/m -> N/mm] x 1e-3). A pressure per length [Pa/m -> MPa/mm] is
``stress / length``. Readers divide by the same factors to come back to SI. A leaf module.
"""

from __future__ import annotations

from dataclasses import dataclass

UNIT_LABEL = {"SI": "N, m, Pa", "mm": "N, mm, MPa"}


@dataclass(frozen=True)
class Units:
    """Multiply an SI value by a factor to get the deck value (divide to read back)."""
    name: str
    length: float
    stress: float
    force: float
    moment: float
    stiffness: float


_UNITS = {"SI": Units("SI", 1.0, 1.0, 1.0, 1.0, 1.0),
          "mm": Units("mm", 1.0e3, 1.0e-6, 1.0, 1.0e3, 1.0e-3)}


def scale(units: str) -> Units:
    """The factors of deck units ``units`` ('SI' or 'mm'); ValueError naming the value otherwise."""
    try:
        return _UNITS[units]
    except KeyError:
        raise ValueError(f"units {units!r}: unknown (known: {', '.join(_UNITS)})") from None
