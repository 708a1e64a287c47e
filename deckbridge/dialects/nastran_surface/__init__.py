"""Simcenter Nastran SOL 101 surface-contact deck (``render.py``: BSURFS sources, the table and the stop as
clamped solid layers, BCTSET / BCSET / BCRESULTS) and the reader of its OP2 contact tables (``reader.py``
over our own record reader ``op2_tables.py``: OQGCF1, OBC1, OSPDS1/OSPDSI1). No runner (no Nastran here).
See docs/nastran_surface.md for what the deck carries and what could not be verified."""

from .._record import NASTRAN_MAX_ID, Dialect

RECORD = Dialect(
    name="nastran_surface", package=__name__, renderer=".render:write", templates="nastran_surface",
    reader="nastran_contact", source="nastran_surface", decks=("{name}_surface.bdf",),
    purpose="Simcenter Nastran SOL 101 surface contact (BSURFS/BCTSET/BCSET), table and stop as clamped solid "
            "layers (not run here)",
    max_id=NASTRAN_MAX_ID, largest_id="deckbridge.dialects.nastran_surface.render:largest_id")
