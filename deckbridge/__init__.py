"""deckbridge: one neutral model of a structure in contact, decks for two contact methods,
an open reference solver and a comparator of local contact stresses.

Data flow: model -> mesh -> (render decks | reference solver | external solver) -> results table
-> comparison -> report.
"""

from .model import Model, ModelError, load  # noqa: F401

__version__ = "0.1.0"
from .contact_results import read_contact  # noqa: F401,E402
