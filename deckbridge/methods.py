"""The reference solver's contact methods, in one place: the CLI choices, the studies and the reports read them here.

Each :class:`Method` says what the rest of deckbridge needs to know about a method of
``reference_solver`` (its contact law, :data:`reference_solver.METHODS`):

- ``uses_k``: the penalty stiffness k_c = alpha A^2 K / V applies (the k-factor and alpha options);
- ``springs_follow_k``: the tangential springs scale with the k-factor when k_t follows k_n
  (:mod:`deckbridge.tangent_springs`); the exact methods keep them as built;
- ``exact``: the converged answer is the Lagrange answer, whatever k (its sweep curve against k is flat);
- ``algorithms``: the solver's algorithms of the method (first = default);
- ``label``: how figures, tables and the console name it.

Adding a method: register its law in ``reference_solver`` (ARCHITECTURE.md, "Add a contact law") and add
one :class:`Method` line here.
"""

from __future__ import annotations

from dataclasses import dataclass

import reference_solver as rs

from .errors import DeckbridgeError

@dataclass(frozen=True)
class Method:
    name: str
    label: str
    uses_k: bool
    springs_follow_k: bool
    exact: bool
    algorithms: tuple[str, ...]


METHODS: dict[str, Method] = {
    "penalty": Method("penalty", "penalty", uses_k=True, springs_follow_k=True, exact=False,
                      algorithms=rs.LAWS["penalty"].algorithms),
    "lagrange": Method("lagrange", "Lagrange", uses_k=False, springs_follow_k=False, exact=True,
                       algorithms=rs.LAWS["lagrange"].algorithms),
    "augmented": Method("augmented", "augmented Lagrangian", uses_k=True, springs_follow_k=False, exact=True,
                        algorithms=rs.LAWS["augmented"].algorithms),
}
NAMES: tuple[str, ...] = tuple(METHODS)
PENALTY, LAGRANGE, AUGMENTED = "penalty", "lagrange", "augmented"
K_METHODS: tuple[str, ...] = tuple(m for m in NAMES if METHODS[m].uses_k)   # take --k-factor / --alpha


def method(name: str) -> Method:
    """The method ``name``; an unknown name is a one-line DeckbridgeError naming the known ones."""
    if name not in METHODS:
        raise DeckbridgeError(f"method = {name!r}: must be one of {', '.join(NAMES)}")
    return METHODS[name]


def uses_k(name: str) -> bool:
    return method(name).uses_k


def case_label(name: str, k_factor: float | None = None) -> str:
    """'lagrange', 'penalty k=0.01', 'augmented k=10': how a case is named in comparisons."""
    return name if not (METHODS[name].uses_k and k_factor is not None) else f"{name} k={k_factor:.12g}"
