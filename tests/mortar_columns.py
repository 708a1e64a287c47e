"""Test and bench helper (issue 23): the table of a quadratic skirt read through the wall, azimuth by azimuth, for
the reference solver's face-weighted Lagrange and a CalculiX job on the same mesh.

Through-wall sigma_N of an azimuth column = -sum F / sum a over the column's table nodes [Pa] (< 0 compression),
F the consistent node force [N] (> 0 pressing the skirt onto the table; ccx mortar: RF_z of the slave node;
reference: ``Solution.force`` = D^T lambda) and a = int N_i dA [m^2] the consistent share of the table faces
(``face_weights.face_shares``; the same for both sides, so a pressure constant through the wall is read exactly
on 8- and 6-node faces). Used by tests/test_ccx_quadratic_mortar.py and bench/mortar_convergence.py."""

from __future__ import annotations

import numpy as np

import reference_solver as rs
from reference_solver.elements import element_type
from reference_solver.face_weights import face_shares, surface_faces


class TableColumns:
    """The table's azimuth columns of ``mesh`` / ``system`` (deckbridge's condensed system): ``nodes`` (mesh
    indices of the table rows, in the problem's contact order), ``rows`` (bool mask of those rows in the problem's
    contact arrays), ``column`` (column index per table node), ``theta`` [deg] per column, ``area`` [m^2] per
    column (sum of a = int N_i dA), ``faces`` (face type, connectivity) of the table surface."""

    def __init__(self, mesh, system):
        p = system.problem
        self.rows = p.contact_surface == "table"
        self.nodes = p.contact_nodes[self.rows]
        on = np.zeros(mesh.n_nodes, bool)
        on[self.nodes] = True
        self.faces = surface_faces((rs.ElementBlock(element_type(mesh.element), mesh.hexes),), on)
        share = np.zeros(mesh.n_nodes)
        for ftype, conn in self.faces:
            np.add.at(share, conn.ravel(), face_shares(ftype, mesh.nodes[conn]).ravel())
        theta = np.round(np.degrees(np.arctan2(mesh.nodes[self.nodes, 1], mesh.nodes[self.nodes, 0])) % 360.0, 6)
        self.theta, self.column = np.unique(theta, return_inverse=True)
        self.area = np.bincount(self.column, share[self.nodes])

    def sigma(self, force: np.ndarray) -> np.ndarray:
        """Through-wall sigma_N [Pa] per column from the table nodes' forces ``force`` [N] (> 0 compressive)."""
        return -np.bincount(self.column, force, minlength=self.theta.size) / self.area


def reference_lagrange(model):
    """(mesh, system, solution) of the reference face-weighted Lagrange on ``model``."""
    from deckbridge.solve import condense_model, solve_system
    mesh, system = condense_model(model)
    _, _, sol = solve_system(model, mesh, system, "lagrange")
    return mesh, system, sol


def state_index(sol, step: int, lam: float) -> int | None:
    """Index of the reference solution's last state of ``step`` at load factor ``lam`` (None: no such state)."""
    k = [i for i in range(sol.load_factor.size) if sol.step[i] == step and abs(sol.load_factor[i] - lam) < 1e-9]
    return k[-1] if k else None


def mortar_states(model, mesh, system, sol, inp) -> list[dict]:
    """Per printed state of the ccx mortar job ``inp`` (its ``.dat`` NTABLE forces) at a load factor the
    reference also reached: lambda, lift / (R + t/2) of
    the reference, whether every reference table node is closed, the reference peak |sigma_N| [Pa], ccx's
    RF_z per table node (``rf``, :class:`TableColumns` order) and their sum [N], the through-wall sigma_N per column [Pa] of both (``ref``, ``ccx``), ``theta`` [deg], ``area``
    [m^2] and ``pressed`` (the column holds a closed reference node) per column."""
    from deckbridge.dialects.calculix.result_files import _dat_blocks
    from deckbridge.numbering.skirt import mesh_node_ids
    cols = TableColumns(mesh, system)
    ids = mesh_node_ids(mesh, cols.nodes)
    printed = [b for b in _dat_blocks(inp.with_suffix(".dat")) if b["kind"] == "forces" and b["set"] == "NTABLE"]
    radius = model.geometry.radius + model.geometry.thickness / 2
    states = []
    for n, b in enumerate(printed):
        step, lam = (1, 0.0) if n == 0 else (2, round((b["time"] - 1.0) * model.steps.lambda_max, 9))
        k = state_index(sol, step, lam)
        if k is None:                                            # a ccx cutback's state: no reference twin
            continue
        fc = np.array([b["values"][int(i)][2] for i in ids])     # RF_z: the table's push, > 0 compressive
        states.append({"lam": lam, "lift": max(float(sol.gap[k, cols.rows].max()), 0.0) / radius,
                       "closed": bool(sol.closed[k, cols.rows].all()),
                       "peak": float(np.abs(sol.sigma_n[k, cols.rows]).max()), "rz": float(fc.sum()),
                       "theta": cols.theta, "ref": cols.sigma(sol.force[k, cols.rows]), "ccx": cols.sigma(fc),
                       "rf": fc, "area": cols.area, "pressed": np.bincount(cols.column, sol.closed[k, cols.rows], cols.theta.size) > 0})
    return states


def edge_columns(theta: np.ndarray, pressed: np.ndarray, cell_deg: float) -> np.ndarray:
    """Mask of the columns within one cell (``cell_deg``) of a contact edge, periodic; an edge lies midway
    between a ``pressed`` column (one holding a closed node) and a neighbour that is not."""
    n = theta.size
    edges = [0.5 * (theta[i] + theta[(i + 1) % n] + (360.0 if i + 1 == n else 0.0))
             for i in range(n) if pressed[i] != pressed[(i + 1) % n]]
    mask = np.zeros(n, bool)
    for e in edges:
        mask |= np.abs((theta - e + 180.0) % 360.0 - 180.0) <= cell_deg + 1e-9
    return mask


def edge_windows(s: dict, cell_deg: float) -> float:
    """The contact edges of state ``s`` (:func:`mortar_states`) compared by their force: per edge (midway between a
    pressed column and an unpressed neighbour) the table force [N] of the columns within one cell (``cell_deg``)
    of it, reference against ccx; the largest |difference| / the window's area [Pa] (0 in full contact)."""
    theta, area = np.asarray(s["theta"]), np.asarray(s["area"])
    fr, fc = -np.asarray(s["ref"]) * area, -np.asarray(s["ccx"]) * area
    pressed, n = np.asarray(s["pressed"]), theta.size
    worst = 0.0
    for i in range(n):
        if pressed[i] != pressed[(i + 1) % n]:
            e = 0.5 * (theta[i] + theta[(i + 1) % n] + (360.0 if i + 1 == n else 0.0))
            win = np.abs((theta - e + 180.0) % 360.0 - 180.0) <= cell_deg + 1e-9
            worst = max(worst, abs(fr[win].sum() - fc[win].sum()) / area[win].sum())
    return worst


CCX_ALPHA = 0.2      # ccx 2.20 TYPE=MORTAR: each corner function takes 1/5 of its edges' mid-side ones


def dual_multipliers(mesh, cols: TableColumns, rf: np.ndarray, alpha: float = CCX_ALPHA) -> np.ndarray:
    """ccx's own mortar multipliers [Pa] of the table nodes from their forces ``rf`` [N] (> 0 compressive).

    ccx 2.20's ``TYPE=MORTAR`` (Sitzmann's dual mortar, quadratic-quadratic) interpolates the slave side with the
    transformed basis Nt = T N (a corner takes ``alpha`` of each mid-side function of its face edges, a mid-side
    keeps 1 - 2 alpha of its own) and its pressure with the dual functions psi_j (int psi_j Nt_k dA = delta_jk d_k,
    d_k = int Nt_k dA > 0): the forces on the Nt dofs are d_j lambda_j, and on the nodes r = T^-1 (d lambda), so
    lambda = (T r) / d, >= 0 where ccx's law holds. Exact (p) for a uniform pressure p."""
    pos = {int(n): i for i, n in enumerate(cols.nodes)}
    d = np.zeros(cols.nodes.size)
    edges = set()                                  # (corner, corner, mid-side) once per edge, not per face
    for ftype, conn in cols.faces:
        nc = {"quad8": 4, "tri6": 3}[ftype.name]
        tf = np.eye(2 * nc)
        for e in range(nc):
            tf[e, nc + e] = tf[(e + 1) % nc, nc + e] = alpha
            tf[nc + e, nc + e] = 1.0 - 2.0 * alpha
        local = np.vectorize(pos.__getitem__)(conn)
        np.add.at(d, local.ravel(), (face_shares(ftype, mesh.nodes[conn]) @ tf.T).ravel())
        for f in local:
            edges.update((*sorted((int(f[e]), int(f[(e + 1) % nc]))), int(f[nc + e])) for e in range(nc))
    tr = np.array(rf, float)
    mids = np.array(sorted({m for _, _, m in edges}))
    tr[mids] *= 1.0 - 2.0 * alpha
    for a, b, m in edges:
        tr[a] += alpha * rf[m]
        tr[b] += alpha * rf[m]
    return tr / d
