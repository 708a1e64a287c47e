"""Positive nodal areas of element faces of any type (issue 23): HRZ-lumped face mass matrices, and the
contact rows' areas (the hat multiplier basis on quadratic faces, :func:`contact_areas`).

A leaf of the base layer (numpy and the reference solver's face rules only), shared by the mesh data
(:func:`deckbridge.mesh_data.base_wall_areas`), the any-order skirt builder (:mod:`deckbridge.mesh_order`) and
the quadratic importer (:mod:`deckbridge.importers.quadratic`).
"""

from __future__ import annotations

import numpy as np

import reference_solver as rs
from reference_solver.elements import element_type


def hrz_areas(faces, nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Positive nodal areas [m^2] of a surface ``faces`` [(face type, conn), ...]: the diagonal of each
    face's consistent M scaled to its area (HRZ lumping; the row sums of 8- and 6-node faces are <= 0 at
    the corners). Returns (surface nodes ascending, areas)."""
    from reference_solver.face_weights import face_mass
    surf = np.unique(np.concatenate([c.ravel() for _, c in faces]))
    area = np.zeros(nodes.shape[0])
    for ftype, conn in faces:
        M = face_mass(ftype, nodes[conn])
        d = np.einsum("faa->fa", M)
        np.add.at(area, conn.ravel(), (d * (M.sum(axis=(1, 2)) / d.sum(axis=1))[:, None]).ravel())
    return surf, area[surf]


def contact_areas(faces, nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The area A_a [m^2] (> 0) of each contact row a of a surface ``faces`` [(face type, conn), ...], the one
    definition of ``mesh.table.area`` on every face type: on 8- and 6-node faces A_a = int Phi_a dA, Phi_a the
    non-negative hat multiplier basis of the face-weighted laws (:func:`reference_solver.face_weights.hat_mortar`,
    ``face_matrix(..., mortar=True)``), i.e. the row sums of their mortar matrix D. Their
    sigma_N at a row is its multiplier -lambda_a (the pressure field sum lambda_a Phi_a), so
    Sum_a sigma_N,a A_a = -(D^T lambda).1 = -Sum of the nodal contact forces exactly (= -N under N alone).
    Regular quad8: corners A/24, mid-sides 5 A/24; tri6: corners A/12, mid-sides A/4. 4- and 3-node faces keep
    :func:`hrz_areas` (= the tributary row sums of M on triangles and parallelograms; pinned results unchanged).
    Returns (surface nodes ascending, areas)."""
    from reference_solver.face_weights import hat_mortar
    surf = np.unique(np.concatenate([c.ravel() for _, c in faces]))
    area = np.zeros(nodes.shape[0])
    for ftype, conn in faces:
        if ftype.n_nodes > ftype.n_corners:
            np.add.at(area, conn.ravel(), hat_mortar(ftype, nodes[conn]).sum(axis=2).ravel())
        else:
            lin, a = hrz_areas(((ftype, conn),), nodes)
            area[lin] += a
    return surf, area[surf]


def base_face_areas(nodes: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """Nodal areas [m^2] (n,) of the faces of ``cells`` (m, k: 4, 10, 15 or 20 nodes, CalculiX order; or a mixed
    mesh's cells padded with -1, each row's type by its node count) that lie
    on their lowest plane (z within 1e-9 of the height span): :func:`hrz_areas`, positive, summing to the area."""
    from reference_solver.face_weights import surface_faces
    cells = np.asarray(cells, np.int64)
    k = (cells >= 0).sum(axis=1)            # a mixed mesh's cells padded with -1 (SkirtMesh.hexes): by node count
    names = {4: "c3d4", 6: "c3d6", 8: "c3d8", 10: "c3d10", 15: "c3d15", 20: "c3d20"}
    blocks = tuple(rs.ElementBlock(element_type(names[int(n)]), cells[k == n][:, :n]) for n in np.unique(k))
    z = nodes[:, 2]
    on = z <= z[np.unique(cells[cells >= 0])].min() + 1e-9 * max(float(np.ptp(z)), 1e-300)
    surf, area = hrz_areas(tuple(surface_faces(blocks, on)), nodes)
    out = np.zeros(nodes.shape[0])
    out[surf] = area
    return out
