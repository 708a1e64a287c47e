"""The reference solver's face-integrated penalty as the partner of CalculiX's face-to-face deck (issue 24).

``run --with-ccx`` compares the ccx series ``ccx/f2f`` (``<name>_ccx_f2f.inp``: ``SURFACE TO SURFACE``,
LINEAR slope from k_c / A, docs/ccx_f2f.md) with ``reference/f2f``: the same condensed system solved with the
face-integrated penalty law (:mod:`reference_solver.face_penalty`: the gap at ccx's integration points of the
base faces, pressure K max(0, -g), the same slope per face), so that the two are one discretisation of one law.
The reference's nodal penalty (``reference/penalty``) stays the partner of the node-to-surface deck.
Rows: the tidy schema of :func:`deckbridge.solve.contact_table`, method ``f2f`` (sigma_N = -F / A on 4-node
faces, as the ccx reader's), with the base-wall sigma_zz table.

On 8-/6-node faces the two series' sigma_N are two different readings of one pressure field (ccx: CPRESS, the
integration-point pressure extrapolated to the nodes; the reference: the hat-basis projection -D^-T r), which
differ by up to a quarter of the peak next to the contact edge while the solutions agree (docs/ccx_f2f.md). What
both give exactly is the contact force on the deck's master ring (``quadratic_master.f2f_ring``: clamped C3D8,
one face per azimuth interval, nodes at the skirt's azimuths 360 j / n_theta): :func:`ring_line_forces` is the
reference's side of it, ``result_files.f2f_master_lines`` ccx's (its printed RF).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from reference_solver.face_penalty import FaceIntegration, face_weighted

from .methods import PENALTY
from .numbering.skirt import mesh_node_ids
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
    lines = table_ring_lines(face.problem, mesh, df) if mesh.quadratic_faces else None
    return SourceResult(df, origin, summary=summary, wall=reference_wall(face, mesh, sol), ring_lines=lines)


def table_ring_lines(problem, mesh, table) -> dict[float, np.ndarray]:
    """{load factor: :func:`ring_line_forces` [N] per azimuth line} of a reference/f2f contact table (its rows'
    gap_m, SI) on ``problem`` (face-weighted contact rows) and ``mesh`` (n_theta lines); step 2's increment 0
    repeats step 1's end (load factor 0) and is left out."""
    rows = dict(zip(zip(mesh_node_ids(mesh, problem.contact_nodes), problem.contact_surface), range(problem.n_contacts)))
    out = {}
    for (step, inc), g in table.groupby(["step", "increment"], sort=True):
        if step == 2 and inc == 0:
            continue
        gap = np.zeros(problem.n_contacts)
        gap[[rows[(n, s)] for n, s in zip(g.node, g.surface)]] = g.gap_m.to_numpy(float)
        out[float(g.load_factor.iloc[0])] = ring_line_forces(problem, gap, mesh.n_theta)[0]
    return out


def ring_lines(xyz: np.ndarray, n_theta: int) -> tuple[np.ndarray, np.ndarray]:
    """(j, s) of points ``xyz`` (n, 3) [m] on the face-to-face deck's master ring of ``n_theta`` faces: the
    point lies on face j (between the ring's azimuth lines j and j + 1, at 360 j / n_theta deg) at natural
    coordinate s in [0, 1] along it. The ring's faces are trapezoids between two radial lines whose chords are
    parallel, so the bilinear map's lines of constant s are rays from the axis: s follows from the azimuth alone,
    tan(phi) = (2 s - 1) tan(pi / n_theta), phi the azimuth from the face's bisector. A force at the point goes
    to the nodes of line j with the weight 1 - s and to those of line j + 1 with s (the C3D8 shape functions)."""
    d = 2.0 * np.pi / n_theta
    th = np.arctan2(xyz[:, 1], xyz[:, 0]) % (2.0 * np.pi)
    j = np.floor(th / d).astype(int) % n_theta
    s = 0.5 * (np.tan(th - (j + 0.5) * d) / np.tan(d / 2) + 1.0)
    return j, np.clip(s, 0.0, 1.0)


def ring_line_forces(problem, gaps: np.ndarray, n_theta: int, k_factor: float = 1.0) -> np.ndarray:
    """The face-integrated penalty's contact force [N] (> 0 pressing the skirt up) on each azimuth line of the
    ccx face-to-face deck's master ring (:func:`ring_lines`): per state (row of ``gaps``, (states, rows) the
    nodal gaps [m] of ``problem``'s contact rows, the reference table's gap_m), sum over the law's integration
    points (:class:`reference_solver.face_penalty.FaceIntegration`) of the point force K_eff w (-g) spread with
    the ring's shape functions; ccx's RF of the ring's top nodes summed per line is the same quantity. Rows off
    the faces (a radial stop) carry none."""
    fi = FaceIntegration(problem)
    j, s = ring_lines(fi.xyz, n_theta)
    gp = np.atleast_2d(gaps) @ fi.G.T                                        # (states, points) [m]
    f = -gp * k_factor * np.where(gp <= 0, 1.0, problem.k_open_ratio) * fi.w  # [N] per point
    out = np.zeros((gp.shape[0], n_theta))
    for k in range(gp.shape[0]):
        np.add.at(out[k], j, f[k] * (1.0 - s))
        np.add.at(out[k], (j + 1) % n_theta, f[k] * s)
    return out
