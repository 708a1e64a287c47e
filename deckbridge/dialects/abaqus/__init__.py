"""Abaqus/Standard: master/slave Lagrange and augmented-Lagrange decks (``render.py``, docs/abaqus.md) and the
``.dat`` contact-print reader (``reader.py``); inp-family ids from :mod:`deckbridge.numbering.inp`. No runner: no Abaqus here."""

from .._record import Dialect

RECORD = Dialect(
    name="abaqus", package=__name__, renderer=".render:write", templates="abaqus", reader="abaqus_dat",
    source="abaqus", decks=("{name}_lagrange.inp", "{name}_augmented.inp"),
    purpose="Abaqus/Standard, master/slave Lagrange and augmented-Lagrange contact (not run here: no Abaqus)")
