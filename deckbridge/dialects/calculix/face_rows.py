"""Table rows of the CalculiX decks on quadratic faces (issue 23): sigma_N as a pressure, not a nodal force.

On 8- and 6-node faces a uniform pressure p gives the corner nodes -1/12 (8-node) or 0 (6-node) of p x face
area and the mid-side nodes +1/3: the nodal force of a face-weighted contact is not a pressure, so the nodal
reading sigma_N = -F / A (4-node faces) would call every corner of a pressed quadratic face "in tension". On
these faces the ccx reader reports, as the reference solver does for its face-weighted law
(``reference_solver/face_law.py``, ``deckbridge/solve.py``), the pressure field's nodal values:

- mortar deck (``*_ccx_lagrange.inp``): ccx's own multipliers, sigma_N = -D^-T r [Pa] over the table surface,
  r_i = RF_i . n [N] the slave node's consistent contact force (RF of the ``.dat`` ``*NODE PRINT`` of the table
  slave nodes, > 0 pressing the skirt onto the table) and D_ab = int psi_a N_b dA = diag(d) T^-T the mortar
  matrix of ccx's TYPE=MORTAR basis (:func:`reference_solver.face_weights.dual_mortar`: dual functions psi to
  the transformed Nt = T N, alpha = 1/5, d = int Nt dA): lambda = (T r) / d >= 0, the quantity ccx's law puts
  its sign condition on, and node by node what the reference's ``contact_weighting='face-dual'`` reports
  (``reference/mortar``, :mod:`deckbridge.reference_dual`; docs/mortar_stop.md). Exact (-p) for a uniform
  pressure p. The rows' areas are then d (:attr:`TableProjection.areas`), their gaps the projected gap (D g) / d
  that ccx's law keeps >= 0 (:meth:`TableProjection.gaps`, :func:`deckbridge.quantities.projected_gap`; the
  reference's ``gap_m`` of the same rows). (Until round 4 the hat basis of the
  reference's default law, -D_hat^-T r on hat areas: tensile next to the contact edge.) Without a model (no
  faces to build D from) the reader takes ccx's own nodal pressure -CPRESS instead.
- face-to-face deck (``*_ccx_f2f.inp``, master a wide C3D8 ring, no master node under each slave node):
  sigma_N = -CPRESS of the ``.frd`` CONTACT block (see :func:`f2f_table_sigma`).

The rows' ``area_m2`` is int Phi_a dA of the multiplier basis (d for the mortar rows, the hat areas
:func:`deckbridge.face_areas.contact_areas` elsewhere), so Sum sigma_N x area = -Sum r; the through-wall sigma_N
(:func:`deckbridge.quantities.sigma_n_wall`) = Sum sigma_N x area / Sum area per azimuth. The table's force_n is the
row's nodal force as ccx applies it (:data:`deckbridge.quantities.DEFINITIONS`): r = RF . n of the mortar rows;
NaN on the face-to-face rows and the mortar rows read without a model, where ccx prints a pressure only (CPRESS x
area is no nodal force there: past liftoff its sum missed N by -0.69 / +0.49 / +0.67 %). The f2f deck's exact
contact resultant is its clamped master ring's reaction (:func:`.result_files.f2f_master_resultant`). The contact-law check
(:mod:`deckbridge.readers._contact_law`) judges these rows by the pressure.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.sparse.linalg as spla

from ...errors import DeckbridgeError
from ...numbering.skirt import mesh_node_ids
from ...quantities import projected_gap

QUADRATIC_TYPES = ("C3D20", "C3D20R", "C3D10", "C3D15")     # ccx element types with 8- or 6-node faces
MORTAR_BASIS = "dual"           # the multipliers the reader reports for a mortar job's table: ccx's own


class TableProjection:
    """-D^-T r of the table rows of a slave table ``node_ids`` / ``table`` (bool per row) on ``mesh``'s table
    faces (D: the reference's mortar matrix, module doc): :meth:`sigma` maps the rows' normal forces r [N]
    (> 0 compressive) to sigma_N [Pa] (< 0 compression). D is factorised once per job. ``basis``: the multiplier
    basis of D, 'hat' (the reference's default law) or 'dual' (ccx's own TYPE=MORTAR multipliers, D = diag(d) T^-T
    of :func:`reference_solver.face_weights.dual_mortar`: -D^-T r = -(T r) / d, what the reference's
    ``contact_weighting='face-dual'`` reports; the reader's, :data:`MORTAR_BASIS`; tests/test_dual_mortar.py).
    :attr:`areas` [m^2]: the rows' multiplier shares, the row sums of D (d, or the hat areas), so that
    Sum sigma_N x area = -Sum r."""

    def __init__(self, mesh, node_ids: np.ndarray, table: np.ndarray, basis: str = "hat"):
        from reference_solver.face_weights import face_matrix
        surf, M = face_matrix(mesh.nodes, mesh.table_faces, mortar=True, basis=basis)
        pos = {int(n): k for k, n in enumerate(mesh_node_ids(mesh, surf))}
        rows = np.flatnonzero(table)
        missing = [int(node_ids[i]) for i in rows if int(node_ids[i]) not in pos]
        if missing or rows.size != surf.size:
            raise DeckbridgeError(f"table slave node {missing[0] if missing else '?'}: not on the model's table "
                                  f"faces ({rows.size} table rows, {surf.size} face nodes): deck of another model?")
        self.rows = rows
        self.order = np.array([pos[int(node_ids[i])] for i in rows])
        self.lu = spla.splu(M.tocsc())
        self.D = M.tocsr()
        self.areas = np.asarray(M.sum(axis=1)).ravel()[self.order]

    def forces(self, sigma_rows: np.ndarray) -> np.ndarray:
        """The rows' normal forces r = -D^T sigma_N [N] (> 0 compressive) of their sigma_N [Pa] (row order): the
        inverse of :meth:`sigma`, e.g. to read one table in another basis."""
        s = np.zeros(self.order.size)
        s[self.order] = sigma_rows
        return -(self.D.T @ s)[self.order]

    def gaps(self, gap_rows: np.ndarray) -> np.ndarray:
        """The rows' gaps [m] as ccx's mortar law constrains them, (D g) / d
        (:func:`deckbridge.quantities.projected_gap`), from their nodal gaps ``gap_rows`` [m] (row order)."""
        g = np.zeros(self.order.size)
        g[self.order] = gap_rows
        return projected_gap(self.D, g)[self.order]

    def slaves(self, sl):
        """The reader's slave rows ``sl`` (result_files.Slaves) with :attr:`areas` on the projected rows."""
        area = np.array(sl.area, float)
        area[self.rows] = self.areas
        return dataclasses.replace(sl, area=area)

    def sigma(self, r_rows: np.ndarray) -> np.ndarray:
        """sigma_N [Pa] of the table rows (in row order) from their normal forces ``r_rows`` [N]."""
        r = np.zeros(self.order.size)
        r[self.order] = r_rows
        return -self.lu.solve(r, trans="T")[self.order]


def f2f_table_sigma(cpress: dict[int, float], node_ids: np.ndarray) -> np.ndarray:
    """sigma_N [Pa] of table slave nodes ``node_ids`` of a face-to-face (SURFACE TO SURFACE) job from one ``.frd``
    CONTACT block: sigma_N = -CPRESS.

    CPRESS is ccx's contact pressure [Pa] at the slave node: the penalty pressure K x penetration of the
    surface-to-surface contact at the slave face's integration points, extrapolated to the face's nodes and
    averaged over the faces that share the node; > 0 compressive (ccx's sign), hence sigma_N = -CPRESS < 0 in
    compression. ccx prints a row only for nodes of faces in contact: a node without one carries no pressure
    (0, open). ``cpress``: node id -> CPRESS in SI."""
    return np.array([-float(cpress.get(int(n), 0.0)) for n in node_ids]) + 0.0


def face_neighbours(mesh, node_ids: np.ndarray, table: np.ndarray) -> list[np.ndarray]:
    """Per slave row: the rows of every node on the table faces that hold it (itself included; empty for a
    row not on a table face, e.g. the stop)."""
    row_of = {int(n): i for i, n in enumerate(node_ids) if table[i]}
    near: list[set] = [set() for _ in range(node_ids.size)]
    for _, conn in mesh.table_faces:
        for face in mesh_node_ids(mesh, conn.ravel()).reshape(conn.shape):
            rows = [row_of[int(n)] for n in face if int(n) in row_of]
            for i in rows:
                near[i].update(rows)
    return [np.array(sorted(s), np.int64) for s in near]


def law_gaps(sigma: np.ndarray, gap: np.ndarray, near: list[np.ndarray]) -> np.ndarray:
    """The gap [m] the contact-law check judges a face-weighted row on (``law_gap_m``): for a pressed row
    (sigma_N < 0) the smallest gap of the nodes of its faces (the face's law carries pressure to every node of a
    face that is closed anywhere: a quadratic face spans three azimuths), NaN (its own gap_m) elsewhere. ``gap``: the
    table's gap_m, on mortar rows already the projected gap (D g) / d (:meth:`TableProjection.gaps`), 0 at a
    pressed row by ccx's law; on face-to-face rows the nodal gap."""
    out = np.full(sigma.size, np.nan)
    for i, rows in enumerate(near):
        if rows.size and sigma[i] < 0:
            out[i] = np.nanmin(gap[rows]) if np.isfinite(gap[rows]).any() else np.nan
    return out


def column_neighbours(theta_deg: np.ndarray, table: np.ndarray, reach: int = 2) -> list[np.ndarray]:
    """:func:`face_neighbours` without the mesh (a deck's slave lines only): per table row the table rows whose
    azimuth column lies within ``reach`` columns of its own, periodic (a quadratic face spans three azimuth
    columns, corner - mid-side - corner, so its nodes are within 2 of each other); empty for other rows."""
    rows = np.flatnonzero(table)
    cols, idx = np.unique(np.round(theta_deg[rows], 6), return_inverse=True)
    n = cols.size
    near = [np.zeros(0, np.int64) for _ in range(theta_deg.size)]
    for k, i in enumerate(rows):
        d = np.abs(idx - idx[k])
        near[i] = rows[np.minimum(d, n - d) <= reach]
    return near
