"""MYSTRAN linear SOL 101 deck (``render.py``, Nastran-family cards from :mod:`deckbridge.render.nastran_cards`),
its F06 reader (``reader.py``) and runner (``runner.py``); ids from :mod:`deckbridge.numbering.nastran`."""

from .._record import NASTRAN_MAX_ID, Dialect

RECORD = Dialect(
    name="mystran", package=__name__, renderer=".render:write", templates="mystran", reader="mystran_f06",
    source="mystran", decks=("{name}_mystran.bdf",),
    purpose="MYSTRAN linear SOL 101, every gap closed (below liftoff)",
    runner=".runner:run", version=".runner:version", max_id=NASTRAN_MAX_ID, largest_id="deckbridge.numbering.nastran:largest_id")
