"""``deckbridge.read_contact``: the tidy contact table of a Nastran surface-contact OP2, for any model.

A light module (the reader, pandas and pyNastran are imported on the first call, so ``import deckbridge``
stays fast); the reader is :mod:`deckbridge.dialects.nastran_surface.reader`.
"""

from __future__ import annotations

from pathlib import Path


def read_contact(path: str | Path, deck: str | Path | None = None, model=None):
    """The tidy contact table (:data:`deckbridge.results.COLUMNS`) of a Nastran surface-contact OP2.

    OP2 tables OQGCF1 (force), OBC1 (pressure, tractions; read by our own record reader), OSPDS1/OSPDSI1
    (separation). Any model: node ids as in the file, one row per (source region, source grid, subcase);
    sigma_n_pa = -pressure [Pa] (< 0 compression), gap_m = the grid's separation [m], status from the
    separations of the faces around the grid. ``deck`` (default: the .bdf/.dat/.nas with the OP2's stem beside
    it) gives the source faces and positions; ``model`` (a deckbridge model) the load factor of subcase 2 and
    the units when the deck has no ``deckbridge-units`` line. One-line :class:`deckbridge.errors.DeckbridgeError`
    on an OP2 without contact tables, a truncated or garbled file, or non-finite values.
    """
    from .dialects.nastran_surface.reader import read_contact as read
    return read(path, deck=deck, model=model)
