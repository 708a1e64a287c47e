"""Base-wall sigma_zz per state and the whole-section onset of a reference solve.

Wall table columns (one row per state and azimuth): step, increment, load_factor, theta_deg,
szz_inner_pa, szz_outer_pa, szz_mean_pa, szz_bending_pa [Pa], tension > 0 (the definitions of
:mod:`deckbridge.quantities`), and ``area_m2`` [m^2] the base area of the azimuth (every bottom-row face,
on a pad or not: :func:`deckbridge.mesh_data.base_wall_areas`; absent from older tables); on cells with mid-side
nodes (10-, 15-, 20-node) also ``axial_force_n`` [N], the row's share of the base section's axial force
int sigma_zz dA over every base-face node (:func:`deckbridge.base_wall.section_forces`: the rows hold the corners
only, so Sum mean x area is not that integral there). Reference: :func:`deckbridge.base_wall.reference_base_wall` on the
bottom element row (Gauss points -> corners, averaged over the row's elements sharing a node);
CalculiX: ``*EL PRINT`` S of the bottom row (:func:`deckbridge.dialects.calculix.el_stress.ccx_wall`, the
dialect record's ``wall_reader``), used when the deck wrote it (never the ``.frd`` nodal stresses). Read back
from a folder by :func:`deckbridge.readers.reference.read_wall`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

import reference_solver as rs
from reference_solver.recover import path_fields
from reference_solver.path import section_onset

from .azimuth import snap_deg
from .base_wall import reference_base_wall
from .mesh_data import base_wall_areas
from .numbering.skirt import bottom_row_index
from .outdir import write_text

WALL_CSV = "wall_stress.csv"
WALL_COLUMNS = ["step", "increment", "load_factor", "theta_deg", "szz_inner_pa", "szz_outer_pa",
                "szz_mean_pa", "szz_bending_pa"]          # required; AREA written when known
AREA = "area_m2"
FORCE = "axial_force_n"                                    # cells with mid-side nodes (BaseWall.force)


def reference_wall(system: rs.CondensedSystem, mesh, sol: rs.Solution, U: np.ndarray | None = None) -> pd.DataFrame:
    """Wall table of every state of a reference solution (one recovery solve for all of them; ``U`` (rows, n, 3)
    [m]: every row's displacements when the caller already recovered them, :func:`path_fields`)."""
    U = path_fields(system, sol) if U is None else U
    bottom = bottom_row_index(mesh)
    frames = []
    for i in range(sol.step.size):
        bw = reference_base_wall(system.problem, U[i], bottom)
        frames.append(pd.DataFrame({"step": int(sol.step[i]), "increment": int(sol.increment[i]),
                                    "load_factor": float(sol.load_factor[i]), "theta_deg": snap_deg(bw.theta_deg),
                                    "szz_inner_pa": bw.inner, "szz_outer_pa": bw.outer,
                                    "szz_mean_pa": bw.mean, "szz_bending_pa": bw.bending,
                                    AREA: base_wall_areas(mesh.nodes, mesh.hexes[bottom], bw.nodes),
                                    **({} if bw.force is None else {FORCE: bw.force})}))
    out = pd.concat(frames, ignore_index=True)
    return out[WALL_COLUMNS + [AREA] + ([FORCE] if FORCE in out else [])]


def write_wall(folder: Path, table: pd.DataFrame) -> Path:
    """Write ``folder``/wall_stress.csv atomically (:func:`deckbridge.outdir.write_text`: mode from the umask)."""
    return write_text(Path(folder) / WALL_CSV, table.to_csv(index=False))


def azimuth_groups(system: rs.CondensedSystem, mesh, surface: str = "table") -> tuple[list[np.ndarray], np.ndarray]:
    """Contact-row indices of ``surface`` grouped by azimuth (the through-wall nodes), and the azimuths [deg]."""
    rows = np.flatnonzero(system.problem.contact_surface == surface)
    th = snap_deg(mesh.contact_rows.theta[rows])
    keys = np.unique(th)
    return [rows[th == k] for k in keys], keys


def reference_section_onset(system: rs.CondensedSystem, mesh, sol: rs.Solution) -> tuple[float | None, float | None]:
    """Exact whole-section onset (lambda, theta [deg]): every table node of one azimuth open (to 1e-9)."""
    groups, keys = azimuth_groups(system, mesh)
    lam, g = section_onset(system, sol, groups, base={"N": 1.0}, ramp={"T": 1.0, "M": 1.0})
    return lam, (None if g is None else float(keys[g]))
