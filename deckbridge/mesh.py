"""Hexahedral mesh of the skirt wall and its contact data (slave nodes, areas, penalties).

Node numbering: index = (k * (n_r + 1) + i) * n_theta + j with k along z (0 = base),
i through the wall (0 = inner face), j around (theta_j = 360 j / n_theta, counter-clockwise from +x).
Deck node ids are index + 1. Hexahedra follow the C3D8/CHEXA order: (r, theta, z) is right-handed,
so nodes 1-4 (base face, counter-clockwise seen from +z) then 5-8 above them.
"""

from __future__ import annotations

import numpy as np

from .azimuth import azimuth_deg  # noqa: F401 (re-exported: mesh.azimuth_deg)
from .model import Model, ModelError
from .supports import pad_face_mask

from .mesh_data import (ContactRows, SkirtMesh, SlaveSet, _slave_set, hex_volumes,  # noqa: F401 (re-exported)
                        quad_nodal_areas)


def node_index(k: np.ndarray | int, i: np.ndarray | int, j: np.ndarray | int, n_r: int, n_theta: int):
    """Index of the node at height level k, wall level i, azimuth step j (j wraps)."""
    return (np.asarray(k) * (n_r + 1) + np.asarray(i)) * n_theta + np.mod(j, n_theta)


def build_mesh(model: Model) -> SkirtMesh:
    """Mesh the skirt of ``model`` and derive slave sets, penalties and load-introduction weights."""
    if model.mesh.file is not None:   # the analyst's own mesh (deckbridge/importers)
        from .importers.general import imported_mesh
        return imported_mesh(model)
    from .mesh_order import EIGHT_NODE, build_any_order, solver_name
    element = solver_name(model)
    if element not in EIGHT_NODE:      # quadratic and tetrahedral skirts (issue 23)
        return build_any_order(model)
    g, ms = model.geometry, model.mesh
    nt, nr, nz = ms.n_theta, ms.n_r, ms.n_z
    theta = 2.0 * np.pi * np.arange(nt) / nt
    zs = np.linspace(0.0, g.height, nz + 1)
    rmid = g.radius + (g.r_top - g.radius) * zs / g.height
    offs = (np.arange(nr + 1) / nr - 0.5) * g.thickness
    rr = rmid[:, None] + offs[None, :]                      # (nz+1, nr+1)
    r3 = np.broadcast_to(rr[:, :, None], (nz + 1, nr + 1, nt))
    z3 = np.broadcast_to(zs[:, None, None], (nz + 1, nr + 1, nt))
    t3 = np.broadcast_to(theta[None, None, :], (nz + 1, nr + 1, nt))
    nodes = np.stack([(r3 * np.cos(t3)).ravel(), (r3 * np.sin(t3)).ravel(), z3.ravel()], axis=1)

    k, i, j = np.meshgrid(np.arange(nz), np.arange(nr), np.arange(nt), indexing="ij")
    k, i, j = k.ravel(), i.ravel(), j.ravel()
    ix = lambda dk, di, dj: node_index(k + dk, i + di, j + dj, nr, nt)  # noqa: E731
    hexes = np.stack([ix(0, 0, 0), ix(0, 1, 0), ix(0, 1, 1), ix(0, 0, 1),
                      ix(1, 0, 0), ix(1, 1, 0), ix(1, 1, 1), ix(1, 0, 1)], axis=1)
    vol = hex_volumes(nodes[hexes])
    if np.any(vol <= 0):
        raise ValueError("mesh has elements with non-positive volume")

    kbulk = model.material.bulk_modulus
    pen = model.contact.penalty

    # --- table: base faces (nodes 1-4) of the first element row ------------------------------
    base = k == 0
    on_pad = pad_face_mask(model.contact.pads, nodes[hexes[base][:, :4]], 360.0 / nt, ModelError)
    base_elems = np.flatnonzero(base)[on_pad]
    faces = hexes[base_elems][:, :4]
    a_nodes = quad_nodal_areas(nodes[faces])                  # (nf, 4)
    a_face = a_nodes.sum(axis=1)
    kc_share = pen.alpha * kbulk * a_face[:, None] * a_nodes / vol[base_elems][:, None]
    table_nodes = np.unique(faces)      # = every base-ring node, ascending, without pads
    table = _slave_set("table", nodes, table_nodes, faces, a_nodes, kc_share, pen.k_normal,
                       normal=np.tile([0.0, 0.0, 1.0], (table_nodes.size, 1)),
                       clearance=np.zeros(table_nodes.size))

    # --- radial stop: the wall face of the first element row, bottom nodes only ----------------
    stop, stop_elems = None, np.zeros(0, np.int64)
    side = model.contact.stop.side
    if side != "none":
        if side == "inner":   # face nodes 1, 4, 8, 5 (i = 0); stop resists inward motion
            fcols, iw, sign = [0, 3, 7, 4], 0, +1.0
        else:                 # face nodes 2, 3, 7, 6 (i = n_r - 1 side, outer); resists outward motion
            fcols, iw, sign = [1, 2, 6, 5], nr, -1.0
        row = base & (i == (0 if side == "inner" else nr - 1))
        stop_elems = np.flatnonzero(row)
        sfaces = hexes[row][:, fcols]
        sa = quad_nodal_areas(nodes[sfaces])
        sa[:, 2:] = 0.0   # only the two base nodes of each face are slaves
        ks = pen.alpha * kbulk * sa.sum(axis=1, keepdims=True) * 2.0 * sa / vol[row][:, None]
        snodes = node_index(0, iw, np.arange(nt), nr, nt)
        th = theta
        normal = sign * np.stack([np.cos(th), np.sin(th), np.zeros(nt)], axis=1)
        r_face = np.hypot(nodes[snodes, 0], nodes[snodes, 1])
        r_stop = model.contact.stop.radius
        if r_stop is None:
            clearance = np.zeros(nt)
        else:
            clearance = (r_face - r_stop) if side == "inner" else (r_stop - r_face)
            if np.any(clearance < -1e-12):
                raise ModelError("contact.stop.radius", r_stop,
                                 f"penetrates the {side} wall face (radius {r_face[0]:.6g} m)")
            clearance = np.maximum(clearance, 0.0)
        stop = _slave_set("stop", nodes, snodes, sfaces, sa, ks, pen.k_normal, normal, clearance)

    k_t = table.k.copy() if pen.k_tangent is None else np.full(table.nodes.size, float(pen.k_tangent))

    # --- top face: loads and couplings ---------------------------------------------------------
    top = k == nz - 1
    tfaces = hexes[top][:, 4:]
    ta = quad_nodal_areas(nodes[tfaces])
    top_nodes = node_index(nz, np.arange(nr + 1)[:, None], np.arange(nt)[None, :], nr, nt).ravel()
    w = np.zeros(nodes.shape[0])
    np.add.at(w, tfaces.ravel(), ta.ravel())
    return SkirtMesh(nodes=nodes, hexes=hexes, table=table, stop=stop, k_tangent=k_t,
                     k_open_ratio=pen.open_ratio, top_nodes=top_nodes, top_weights=w[top_nodes],
                     ref_point=np.array([0.0, 0.0, g.height]), n_theta=nt, n_r=nr, n_z=nz,
                     base_elems=base_elems, top_elems=np.flatnonzero(top), stop_elems=stop_elems,
                     element=element)
