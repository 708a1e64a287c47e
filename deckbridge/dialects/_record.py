"""The record of a solver dialect (:class:`Dialect`) and of a result format (:class:`Format`).

A leaf module (imports nothing of deckbridge). A record names its parts as ``"module:attr"`` strings,
relative (``".render:write"``) to the dialect's own folder ``deckbridge/dialects/<name>/`` (its
``package``), imported on use: registering a dialect never imports its renderer, reader or runner.
A part may also be given as the callable itself (a dialect registered from outside the package, e.g.
a test). The one list of records is :mod:`deckbridge.dialects`.

Names: the dialect name (``calculix``) is what a user types (``decks --dialect``, ``run --with``).
``ccx`` is the CalculiX *program*: the ``source`` label of its results, its ``run_folder`` and the
``_ccx_`` infix of its deck files (kept: they are in result tables and file names users already have).
"""

from __future__ import annotations

import importlib
import inspect
from dataclasses import dataclass
from pathlib import Path


NASTRAN_MAX_ID = 99_999_999      # an 8-character small field (GRID, CHEXA, CGAP, CELAS2 ids)
INP_MAX_ID = 2_147_483_647        # CalculiX reads ids as 10-character integers into 32-bit integers


def attr(ref, package: str | None = None):
    """The object named by ``ref`` (``"module:attr"``, module relative to ``package``), or ``ref`` if callable."""
    if callable(ref):
        return ref
    module, _, name = ref.partition(":")
    return getattr(importlib.import_module(module, package), name)


@dataclass(frozen=True)
class Format:
    """A result format: ``read(path, model=None[, mesh=None]) -> tidy table`` and ``detect(path) -> bool`` of
    ``module``; ``source_reader``: the name in ``module`` of f(path, model) -> SourceResult when a source of
    this format carries more than its table (a reference folder)."""
    name: str                  # what a user types (compare --format)
    module: str                # module holding read and detect (relative to package)
    package: str | None = None
    source_reader: str | None = None

    def read(self, path: Path, model=None, mesh=None):
        """The format's table of ``path``; ``mesh`` (the model's, when built) goes to readers that take it."""
        return self._call("read", path, model, mesh)

    def read_source(self, path: Path, model=None, mesh=None):
        """The source's SourceResult (``source_reader``, given ``mesh`` as :meth:`read`); None when the format has none."""
        if not self.source_reader:
            return None
        return self._call(self.source_reader, path, model, mesh)

    def _call(self, name: str, path: Path, model, mesh):
        fn = attr(f"{self.module}:{name}", self.package)
        takes_mesh = mesh is not None and "mesh" in inspect.signature(fn).parameters
        return fn(path, model=model, **({"mesh": mesh} if takes_mesh else {}))

    def detect(self, path: Path) -> bool:
        return bool(attr(f"{self.module}:detect", self.package)(path))


@dataclass(frozen=True)
class Dialect:
    """A solver dialect, one folder ``deckbridge/dialects/<name>/``. ``decks``: file-name patterns of its
    decks, ``{name}`` = the model's name. Optional parts (None: the dialect has none):

    ``runner``: f(deck, timeout_s, progress) -> Path of the result file its ``reader`` reads (a solver run
    here: ``run --with <name>``; decks run in ``DIR/<run_folder>/``); ``run_check``: f(model) raising
    :class:`deckbridge.errors.DeckUnsupported` before a run; ``wall_reader``: f(result_file, model, mesh) ->
    base-wall table (:mod:`deckbridge.wall_stress` columns) or None; ``series_writer``: f(job, model, outdir,
    mesh, table) -> ParaView series paths, given the contact table already read; ``version``: f() -> its
    solver's version (the report's provenance).
    """
    name: str                  # canonical dialect name (CLI, registry key)
    package: str               # the dialect's folder as a package (parts are relative to it)
    renderer: str              # write(model, mesh, outdir) -> list[Path]
    templates: str             # folder under templates/ (package deckbridge.templates)
    reader: str                # format name of its results (compare --format)
    source: str                # 'source' label of its results in the tidy table
    decks: tuple[str, ...]     # deck file-name patterns
    purpose: str               # what it is for, one line
    reader_module: str = ".reader"
    runner: str | None = None
    run_folder: str | None = None          # default: the dialect name
    run_check: str | None = None
    wall_reader: str | None = None
    series_writer: str | None = None
    line_reader: str | None = None         # f(result, model, mesh) -> {load factor: ring_line_force_n} or None
    version: str | None = None             # f() -> its solver's version line (provenance), None if absent
    # the largest node / element id its fields carry, and f(mesh) -> largest id its decks write
    max_id: int = INP_MAX_ID
    largest_id: str = "deckbridge.numbering.inp:largest_id"

    def part(self, ref):
        """The object a part names (imported now)."""
        return attr(ref, self.package)

    def format(self) -> Format:
        """Its results' format record."""
        return Format(self.reader, self.reader_module, self.package)

    def deck_names(self, model_name: str) -> list[str]:
        """File names of the decks of a model called ``model_name`` (in the order of ``decks``)."""
        return [p.format(name=model_name) for p in self.decks]

    def decks_in(self, folder: str | Path, model_name: str) -> list[Path]:
        """This dialect's decks of ``model_name`` present in ``folder``, sorted by file name."""
        return sorted(p for p in (Path(folder) / n for n in self.deck_names(model_name)) if p.is_file())

    def write(self, model, mesh, outdir: Path) -> list[Path]:
        """Render this dialect's decks of ``model`` into ``outdir`` (imports the renderer now)."""
        return self.part(self.renderer)(model, mesh, outdir)

    def id_problem(self, mesh) -> str | None:
        """Why this dialect's decks cannot carry ``mesh``'s ids (one line), None when they can."""
        n = int(self.part(self.largest_id)(mesh))
        if n <= self.max_id:
            return None
        return (f"its decks would use ids up to {n} (the mesh's own ids and the deck's added nodes and elements), "
                f"above its largest id {self.max_id}: renumber the mesh below {self.max_id // 10} or leave this "
                "dialect out")

    @property
    def folder(self) -> str:
        """Its folder under a job's output DIR when run there."""
        return self.run_folder or self.name

    def check_run(self, model) -> None:
        """Raise DeckUnsupported when its decks of ``model`` cannot be run (nothing written yet)."""
        if self.run_check:
            self.part(self.run_check)(model)

    def run(self, deck: Path, timeout_s: float, progress=None) -> Path:
        """Run its solver on ``deck``; the result file its reader reads."""
        if not self.runner:
            raise ValueError(f"dialect {self.name!r} has no runner")
        return Path(self.part(self.runner)(deck, timeout_s=timeout_s, progress=progress))

    def wall(self, result_file: Path, model, mesh):
        """Base-wall table of a run's result, None without a wall reader or when the run printed none."""
        return self.part(self.wall_reader)(result_file, model, mesh) if self.wall_reader else None

    def ring_lines(self, result_file: Path, model, mesh) -> dict | None:
        """{load factor: contact force [N] per azimuth line of the deck's master ring} of a run's result
        (:data:`deckbridge.quantities.DEFINITIONS` ring_line_force_n); None without a line reader or where the job
        has no such ring."""
        return self.part(self.line_reader)(result_file, model, mesh) if self.line_reader else None

    def write_series(self, job: Path, model, outdir: Path, mesh, table) -> list[Path]:
        """ParaView series of a run (none without a series writer)."""
        return self.part(self.series_writer)(job, model, outdir, mesh, table) if self.series_writer else []
