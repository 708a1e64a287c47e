"""MSC/NX Nastran SOL 106 CGAP penalty deck (``render.py``, cards from :mod:`deckbridge.render.nastran_cards`)
and its OP2 reader (``reader.py``); ids from :mod:`deckbridge.numbering.nastran`. No runner (no Nastran here)."""

from .._record import NASTRAN_MAX_ID, Dialect

RECORD = Dialect(
    name="nastran", package=__name__, renderer=".render:write", templates="nastran", reader="nastran_op2",
    source="nastran", decks=("{name}_penalty.bdf",),
    purpose="MSC/NX Nastran SOL 106, CGAP penalty contact (not run here)",
    max_id=NASTRAN_MAX_ID, largest_id="deckbridge.numbering.nastran:largest_id")
