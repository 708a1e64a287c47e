"""The one registry of solver dialects and result formats.

A dialect is one folder ``deckbridge/dialects/<name>/`` whose ``__init__`` holds its ONE record
``RECORD`` (:class:`Dialect`: renderer, template folder, reader, runner, ...; the parts live beside it:
``render.py``, ``reader.py``, ``runner.py``). :data:`NAMES` lists the folders; the records are loaded by
name (no import edge: the records stay leaves, their parts are imported on use). Result formats that are
no dialect (plain CSV, the reference folder) are :data:`OTHER_FORMATS`, the same :class:`Format` record;
:func:`formats` is every format. The CLI (``decks --dialect``, ``run --with``, ``compare --format``),
:func:`deckbridge.render.render_all`, :func:`deckbridge.readers.read` and the job read only these.
"""

from __future__ import annotations

import importlib

from ._record import INP_MAX_ID, NASTRAN_MAX_ID, Dialect, Format  # noqa: F401  (the record types)

NAMES = ("abaqus", "calculix", "mystran", "nastran", "nastran_surface")        # one folder each under deckbridge/dialects/

DIALECTS: dict[str, Dialect] = {n: importlib.import_module(f"{__name__}.{n}").RECORD for n in NAMES}

OTHER_FORMATS: dict[str, Format] = {f.name: f for f in (
    Format("plain_csv", "deckbridge.readers.plain_csv"),      # a post-processor's CSV export
    Format("reference", "deckbridge.readers.reference", source_reader="read_source"),   # a job's reference_<method>/
)}


def formats() -> dict[str, Format]:
    """Every result format by name: each dialect's reader and :data:`OTHER_FORMATS`, sorted by name."""
    every = {d.reader: d.format() for d in DIALECTS.values()} | OTHER_FORMATS
    return dict(sorted(every.items()))


def dialect(name: str) -> Dialect:
    """The record of dialect ``name``; KeyError naming the known ones otherwise."""
    try:
        return DIALECTS[name]
    except KeyError:
        raise KeyError(f"dialect {name!r}: unknown (known: {', '.join(sorted(DIALECTS))})") from None


def names() -> list[str]:
    """Dialect names, sorted."""
    return sorted(DIALECTS)


def runnable() -> list[str]:
    """Names of the dialects whose solver deckbridge runs (``run --with``), sorted."""
    return sorted(n for n, d in DIALECTS.items() if d.runner)


def solver_versions(sources) -> dict[str, str | None]:
    """{source label: version} of the dialects with a ``version`` whose source label is in ``sources``."""
    return {d.source: d.part(d.version)() for d in DIALECTS.values() if d.version and d.source in sources}
