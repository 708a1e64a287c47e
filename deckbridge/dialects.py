"""One record per solver dialect: the single table the CLI, the job, the renderers and the readers read.

A leaf module (imports nothing of deckbridge): renderers and runners are named as ``"module:attr"``
strings and imported on use, so registering a dialect never imports it. Adding a dialect is one
``templates/<name>/`` folder, one renderer module, one reader module ``deckbridge.readers.<reader>``
and one :class:`Dialect` line in :data:`DIALECTS` (its reader module registers itself with
:func:`deckbridge.readers._registry.register` under the format name).

Names: the dialect name (``calculix``) is what a user types (``decks --dialect``, ``compare --format``
of its reader) and the template folder. ``ccx`` is the CalculiX *program*: the runner, the
``source`` label of its results and the ``_ccx_`` infix of its deck files (both kept: they are in
result tables and file names users already have).
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path


NASTRAN_MAX_ID = 99_999_999      # an 8-character small field (GRID, CHEXA, CGAP, CELAS2 ids)
INP_MAX_ID = 2_147_483_647        # CalculiX reads ids as 10-character integers into 32-bit integers


@dataclass(frozen=True)
class Dialect:
    """A solver dialect. ``decks``: file-name patterns of its decks, ``{name}`` = the model's name."""
    name: str                  # canonical dialect name (CLI, registry key)
    renderer: str              # "module:function", write(model, mesh, outdir) -> list[Path]
    templates: str             # folder under templates/ (package deckbridge.templates)
    reader: str                # format name of its results = module deckbridge.readers.<reader>
    source: str                # 'source' label of its results in the tidy table
    decks: tuple[str, ...]     # deck file-name patterns
    purpose: str               # what it is for, one line
    runner: str | None = None  # "module" with run(deck, timeout_s, ...) for a solver run here
    # "module:function", f(model) -> {deck file name: why it runs NLGEOM although analysis.nlgeom is false}
    nlgeom_forced_by: str | None = None
    # the largest node / element id its fields carry, and "module:function" f(mesh) -> largest id its decks write
    max_id: int = INP_MAX_ID
    largest_id: str = "deckbridge.numbering.inp:largest_id"

    def deck_names(self, model_name: str) -> list[str]:
        """File names of the decks of a model called ``model_name`` (in the order of ``decks``)."""
        return [p.format(name=model_name) for p in self.decks]

    def decks_in(self, folder: str | Path, model_name: str) -> list[Path]:
        """This dialect's decks of ``model_name`` present in ``folder``, sorted by file name."""
        return sorted(p for p in (Path(folder) / n for n in self.deck_names(model_name)) if p.is_file())

    def write(self, model, mesh, outdir: Path) -> list[Path]:
        """Render this dialect's decks of ``model`` into ``outdir`` (imports the renderer now)."""
        return _attr(self.renderer)(model, mesh, outdir)

    def id_problem(self, mesh) -> str | None:
        """Why this dialect's decks cannot carry ``mesh``'s ids (one line), None when they can."""
        n = int(_attr(self.largest_id)(mesh))
        if n <= self.max_id:
            return None
        return (f"its decks would use ids up to {n} (the mesh's own ids and the deck's added nodes and elements), "
                f"above its largest id {self.max_id}: renumber the mesh below {self.max_id // 10} or leave this "
                "dialect out")

    def nlgeom_forced(self, model) -> dict[str, str]:
        """Decks of ``model`` whose analysis differs from analysis.nlgeom = false (they run NLGEOM), with why."""
        return _attr(self.nlgeom_forced_by)(model) if self.nlgeom_forced_by else {}

    def run_module(self):
        """The runner module (``run(deck, timeout_s=...)``); None when deckbridge runs no solver for it."""
        return importlib.import_module(self.runner) if self.runner else None


def _attr(ref: str):
    module, _, attr = ref.partition(":")
    return getattr(importlib.import_module(module), attr)


DIALECTS: dict[str, Dialect] = {d.name: d for d in (
    Dialect("abaqus", "deckbridge.render.abaqus:write", "abaqus", "abaqus_dat", "abaqus",
            ("{name}_lagrange.inp",),
            "Abaqus/Standard, master/slave Lagrange contact (not run here: no Abaqus)"),
    Dialect("calculix", "deckbridge.render.calculix:write", "calculix", "calculix", "ccx",
            ("{name}_ccx_penalty.inp", "{name}_ccx_lagrange.inp"),
            "CalculiX 2.20: penalty deck (node-to-surface LINEAR, or GAPUNI with NLGEOM) and mortar (Lagrange) "
            "deck, run by ccx",
            runner="deckbridge.external.ccx_run", nlgeom_forced_by="deckbridge.render.calculix:nlgeom_forced"),
    Dialect("mystran", "deckbridge.render.mystran:write", "mystran", "mystran_f06", "mystran",
            ("{name}_mystran.bdf",),
            "MYSTRAN linear SOL 101, every gap closed (below liftoff)",
            runner="deckbridge.external.mystran_run", max_id=NASTRAN_MAX_ID,
            largest_id="deckbridge.numbering.nastran:largest_id"),
    Dialect("nastran", "deckbridge.render.nastran:write", "nastran", "nastran_op2", "nastran",
            ("{name}_penalty.bdf",),
            "MSC/NX Nastran SOL 106, CGAP penalty contact (not run here)", max_id=NASTRAN_MAX_ID,
            largest_id="deckbridge.numbering.nastran:largest_id"),
    Dialect("nastran_surface", "deckbridge.render.nastran_surface:write", "nastran_surface", "nastran_contact",
            "nastran_surface", ("{name}_surface.bdf",),
            "Simcenter Nastran SOL 101 surface contact (BSURFS/BCTSET/BCTPARM), table and stop as clamped solid "
            "layers (not run here)", max_id=NASTRAN_MAX_ID,
            largest_id="deckbridge.render.nastran_surface:largest_id"),
)}


def dialect(name: str) -> Dialect:
    """The record of dialect ``name``; KeyError naming the known ones otherwise."""
    try:
        return DIALECTS[name]
    except KeyError:
        raise KeyError(f"dialect {name!r}: unknown (known: {', '.join(sorted(DIALECTS))})") from None


def names() -> list[str]:
    """Dialect names, sorted."""
    return sorted(DIALECTS)
