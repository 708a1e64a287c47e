"""The reference solver's face-integrated penalty as the partner of CalculiX's face-to-face deck (issue 24).

``run --with-ccx`` compares the ccx series ``ccx/f2f`` (``<name>_ccx_f2f.inp``: ``SURFACE TO SURFACE``,
LINEAR slope from k_c / A, docs/ccx_f2f.md) with ``reference/f2f``: the same condensed system solved with the
face-integrated penalty law (:mod:`reference_solver.face_penalty`: the gap at ccx's integration points of the
base faces, pressure K max(0, -g), the same slope per face), so that the two are one discretisation of one law.
The reference's nodal penalty (``reference/penalty``) stays the partner of the node-to-surface deck.
Rows: the tidy schema of :func:`deckbridge.solve.contact_table`, method ``f2f`` (sigma_N = -F / A on 4-node
faces, as the ccx reader's), with the base-wall sigma_zz table.
"""

from __future__ import annotations

from pathlib import Path

from reference_solver.face_penalty import face_weighted

from .methods import PENALTY
from .results import SourceResult
from .solve import solve_system
from .wall_stress import reference_wall

METHOD = "f2f"


def wants_f2f(model, chosen, decks_dir: Path) -> bool:
    """True when a job runs CalculiX, wrote its face-to-face deck (``chosen``: the job's dialect records) and the
    model is frictionless (``contact.tangential: springs``: the face-integrated law has no friction; with friction
    ``ccx/f2f`` stays compared with every other series)."""
    return (model.contact.tangential != "friction" and any(d.name == "calculix" for d in chosen)
            and (Path(decks_dir) / f"{model.name}_ccx_f2f.inp").exists())


def f2f_series(model, mesh, system, origin: str) -> SourceResult:
    """The face-integrated reference penalty of ``model`` on its condensed ``system`` (no re-condensing) as one
    source of a comparison (``origin``: where the job's reference results live)."""
    face = face_weighted(system)
    df, summary, sol = solve_system(model, mesh, face, PENALTY, recover=True)
    df["method"] = METHOD
    summary["method"] = METHOD
    return SourceResult(df, origin, summary=summary, wall=reference_wall(face, mesh, sol))
