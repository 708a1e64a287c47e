"""CalculiX 2.20: penalty, mortar and face-to-face penalty decks (``render.py``), the ``.frd``/``.dat`` reader (``reader.py``,
files parsed in ``result_files.py``), the ``*EL PRINT`` base-wall stress (``el_stress.py``), the ccx runner
(``runner.py``) and the ParaView series of a run (``paraview.py``); its own ids (``numbering.py``) beyond
the inp family's (:mod:`deckbridge.numbering.inp`)."""

from .._record import Dialect

RECORD = Dialect(
    name="calculix", package=__name__, renderer=".render:write", templates="calculix", reader="calculix",
    source="ccx", decks=("{name}_ccx_penalty.inp", "{name}_ccx_lagrange.inp", "{name}_ccx_f2f.inp"),
    purpose="CalculiX 2.20: penalty deck (node-to-surface LINEAR, or GAPUNI with NLGEOM), mortar (Lagrange) deck "
            "and face-to-face penalty deck (SURFACE TO SURFACE, without NLGEOM), run by ccx",
    runner=".runner:run_result", run_folder="ccx", run_check=".render:check_supported",
    wall_reader=".el_stress:ccx_wall", series_writer=".paraview:write_ccx_series",
    line_reader=".result_files:f2f_ring_lines", version=".runner:version")
