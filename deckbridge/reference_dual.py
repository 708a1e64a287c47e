"""The reference solver's Lagrange law in CalculiX's own multiplier basis, the partner of ccx's mortar deck (issue 23).

``run --with-ccx`` on a skirt with 8-/6-node table faces compares the ccx series ``ccx/mortar``
(``<name>_ccx_lagrange.inp``: ``TYPE=MORTAR``, read as ccx's own multipliers lambda = (T r) / d,
``dialects/calculix/face_rows.py``) with ``reference/mortar``: the same condensed system solved with the
face-weighted Lagrange in that basis (``contact_weighting='face-dual'``,
:func:`reference_solver.face_weights.dual_mortar`: dual functions to the transformed slave functions T N, alpha = 1/5),
so that the two are one discretisation of one law
(docs/mortar_stop.md, last section: 2.4e-4 of the peak node by node on one model). The reference's default Lagrange
(``reference/lagrange``, hat basis: a pressure field >= 0 everywhere) stays as it was.
Rows: the tidy schema of :func:`deckbridge.solve.contact_table`, method ``mortar``, sigma_N = -lambda, the table
rows' ``area_m2`` = d = int T N dA (the multipliers' shares: Sum force_n = Sum of the nodal forces) and ``gap_m`` the
projected gap (D g) / d its law keeps >= 0 (:func:`deckbridge.quantities.law_gaps`), with the base-wall sigma_zz table
of its own solution (:func:`deckbridge.wall_stress.reference_wall`, as ``reference/lagrange``; until round 5 none, and
the report's sigma_zz check had no wall of this series). As rendered the deck and the reference still differ in one
model detail (the deck's springs on corner nodes only; the top weights are ccx's ``*DISTRIBUTING`` ones on both sides
since round 5, ``mesh_order.top_weights``): docs/mortar_stop.md.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from .methods import LAGRANGE
from .results import SourceResult
from .solve import solve_system
from .wall_stress import reference_wall

METHOD = "mortar"               # the ccx mortar reader's method name: the two series pair by it


def wants_mortar_dual(model, mesh, chosen, decks_dir: Path) -> bool:
    """True when a job runs CalculiX, wrote its mortar deck (``chosen``: the job's dialect records) and the table
    faces are 8-/6-node (the reference's face-weighted laws; frictionless there)."""
    return (bool(mesh.quadratic_faces) and any(d.name == "calculix" for d in chosen)
            and (Path(decks_dir) / f"{model.name}_ccx_lagrange.inp").exists())


def dual_system(system):
    """A shallow copy of a condensed ``system`` (same matrices) whose problem takes ccx's multiplier basis
    (``contact_weighting='face-dual'``) and whose table rows' areas are its shares d = the row sums of D."""
    from reference_solver.face_law import weighting_matrix
    p = dataclasses.replace(system.problem, contact_weighting="face-dual")
    d = np.asarray(weighting_matrix(p).sum(axis=1)).ravel()
    area = np.where(p.contact_surface == "table", d, p.contact_area)
    return dataclasses.replace(system, problem=dataclasses.replace(p, contact_area=area))


def dual_lagrange(model, mesh, system) -> tuple:
    """The Lagrange path of ``model`` in ccx's multiplier basis on its condensed ``system`` (no re-condensing):
    (dual system, table, summary, solution). One solve serves the job's onset check (deckbridge/onset_basis.py)
    and ccx/mortar's partner (:func:`mortar_series`)."""
    dual = dual_system(system)
    return (dual, *solve_system(model, mesh, dual, LAGRANGE, recover=False))


def mortar_series(model, mesh, system, origin: str, solved: tuple | None = None) -> SourceResult:
    """The reference Lagrange of ``model`` in ccx's multiplier basis on its condensed ``system`` (no re-condensing)
    as one source of a comparison (``origin``: where the job's reference results live); ``solved``: that path
    already solved by :func:`dual_lagrange` (else solved here)."""
    dual, df, summary, sol = solved if solved is not None else dual_lagrange(model, mesh, system)
    df["method"] = METHOD
    summary["method"] = METHOD
    return SourceResult(df, origin, summary=summary, wall=reference_wall(dual, mesh, sol))
