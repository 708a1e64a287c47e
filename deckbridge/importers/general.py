"""An imported hexahedral mesh as a :class:`deckbridge.mesh.SkirtMesh` (the general mesh object).

The nodes are brought into the skirt frame (SI metres, axis = +z through the origin, base plane
z = z0 of the file). Each hexahedron's node order is rotated (one of the 24 orientation-preserving
C3D8 orders, the element itself is unchanged) so that its local axes run (r, theta, z) as in the
structured mesh: face 1-2-3-4 (S1) faces the table, 5-6-7-8 (S2) the top, 2-3-7-6 (S4) outwards.
Then the contact data follow the paper's eq. 4 on a general mesh: the table slave faces are the S1
faces whose four nodes are in the base set; each face's consistent nodal areas A_a are shared to its
nodes and k_c = alpha K A_face A_a / V_element; top weights are the S2 nodal areas of the top set.
User node and element ids are kept (``node_ids``, ``elem_ids``) for the decks and the readers.
"""

from __future__ import annotations

from dataclasses import replace
from itertools import permutations, product

import numpy as np

from ..mesh_data import SkirtMesh, _slave_set, hex_volumes, quad_nodal_areas
from ..supports import pad_face_mask
from . import checks, measure, quadratic
from .read import read_mesh_file
from .spec import MESH_UNITS, PLAUSIBLE_RADIUS_M

CUBE = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                 [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]])


def _rotations() -> np.ndarray:
    """The 24 orientation-preserving reorderings of a C3D8 element's nodes, shape (24, 8)."""
    out = []
    key = {tuple(v): a for a, v in enumerate(CUBE)}
    for perm in permutations(range(3)):
        for signs in product((1, -1), repeat=3):
            r = np.zeros((3, 3))
            r[range(3), perm] = signs
            if np.linalg.det(r) > 0:
                out.append([key[tuple((r @ v).astype(int))] for v in CUBE])
    return np.array(out)


ROTATIONS = _rotations()


def orient(nodes: np.ndarray, hexes: np.ndarray) -> np.ndarray:
    """Each hexahedron reordered so that its local (xi, eta, zeta) follow (r, theta, z) best."""
    x = nodes[hexes]                                           # (m, 8, 3)
    c = x.mean(axis=1)
    rhat = np.stack([c[:, 0], c[:, 1], np.zeros(len(c))], axis=1)
    rhat /= np.maximum(np.linalg.norm(rhat, axis=1, keepdims=True), 1e-300)
    best, score = None, None
    for p in ROTATIONS:
        y = x[:, p]
        e_xi = y[:, [1, 2, 5, 6]].mean(1) - y[:, [0, 3, 4, 7]].mean(1)
        e_zeta = y[:, 4:].mean(1) - y[:, :4].mean(1)
        sc = e_zeta[:, 2] / np.linalg.norm(e_zeta, axis=1) + np.einsum("ed,ed->e", e_xi, rhat) / np.linalg.norm(e_xi, axis=1)
        if best is None:
            best, score = np.tile(p, (len(x), 1)), sc
        else:
            take = sc > score + 1e-12
            best[take], score[take] = p, sc[take]
    return np.take_along_axis(hexes, best, axis=1)


def _to_skirt_frame(xyz: np.ndarray, axis) -> np.ndarray:
    """File coordinates [m] -> skirt frame: origin on the axis at ``axis[:3]``, z along ``axis[3:]``."""
    if axis is None:
        return xyz
    o, d = np.array(axis[:3]), np.array(axis[3:]) / np.linalg.norm(axis[3:])
    a = np.array([1.0, 0, 0]) if abs(d[0]) < 0.9 else np.array([0, 1.0, 0])
    e1 = a - (a @ d) * d        # azimuth 0 along the file's +x projected on the base plane (+y if x ~ axis)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(d, e1)
    return (xyz - o) @ np.stack([e1, e2, d], axis=1)


def imported_mesh(model) -> SkirtMesh:
    """Read, check and convert ``model.mesh.file`` (with its sets, units and axis). A mesh of 8-node hexahedra
    only takes :func:`contact_mesh`; any other (10-/15-/20-node solids, or a mixed mesh of one
    :data:`.checks.FAMILIES` member: one cell block per solver type) :func:`.quadratic.quadratic_mesh`."""
    ms = model.mesh
    raw = read_mesh_file(ms.file)
    groups = checks.solid_elements(raw)
    blocks = {}                          # solver name -> [(element ids, connectivity of node ids)]
    for etype, ids, conn, kind in groups:
        if kind != "c3d8i":              # 6-, 10-, 15-, 20-node solids (issue 23): CalculiX order
            kind, ids, conn = quadratic.quadratic_cells(raw, etype, ids, conn)
        blocks.setdefault(kind, []).append((ids, conn))
    names = list(blocks)
    elem_ids = np.concatenate([i for n in names for i, _ in blocks[n]])
    conn_blocks = [np.vstack([c for _, c in blocks[n]]) for n in names]
    checks.ids_in_range(raw, elem_ids)
    unit = MESH_UNITS[ms.units]
    axis = None if ms.axis is None else (*(unit * np.array(ms.axis[:3])), *ms.axis[3:])
    checks.finite_coordinates(raw)
    raw.nodes = _to_skirt_frame(np.asarray(raw.nodes, float) * unit, axis)
    checks.plausible_size(raw.nodes, ms.units, MESH_UNITS, PLAUSIBLE_RADIUS_M)
    size = float(np.ptp(raw.nodes, axis=0).max()) if raw.nodes.size else 1.0
    checks.nodes_unique_and_used(raw, np.concatenate([c.ravel() for c in conn_blocks]), size)
    index_of = {int(n): i for i, n in enumerate(raw.node_ids)}
    cells = [np.vectorize(index_of.__getitem__, otypes=[np.int64])(c) for c in conn_blocks]
    base = checks.set_nodes(raw, ms.sets, "base", index_of)
    top = checks.set_nodes(raw, ms.sets, "top", index_of)
    stop_set = checks.set_nodes(raw, ms.sets, "stop", index_of) if ms.sets.stop else None
    nodes = raw.nodes.copy()
    z0 = checks.base_plane(nodes, base, top, raw.node_ids, ms.sets, size)
    if z0 != 0.0:
        nodes[:, 2] -= z0
    checks.connected(len(nodes), cells, raw.node_ids)
    if names != ["c3d8i"]:
        first = np.cumsum([0] + [c.shape[0] for c in cells])
        cells = [quadratic.check_node_order(nodes, c, n, elem_ids[a:b], raw.path)
                 for n, c, a, b in zip(names, cells, first[:-1], first[1:])]
        return quadratic.quadratic_mesh(model, list(zip(names, cells)), nodes, base, top, stop_set, raw.node_ids,
                                        elem_ids)
    hexes = cells[0]
    checks.not_inverted(nodes, hexes, elem_ids)
    hexes = orient(nodes, hexes)
    return contact_mesh(model, nodes, hexes, base, top, stop_set, raw.node_ids, elem_ids)


def contact_mesh(model, nodes, hexes, base, top, stop_set, node_ids, elem_ids) -> SkirtMesh:
    """Slave sets, penalties and top weights of an oriented hexahedral mesh (formulas of build_mesh)."""
    from ..errors import ModelError
    kbulk, pen = model.material.bulk_modulus, model.contact.penalty
    in_base = np.zeros(len(nodes), bool)
    in_base[base] = True
    on_base = np.flatnonzero(in_base[hexes[:, :4]].all(axis=1))
    stray = np.setdiff1d(base, hexes[on_base, :4])
    if stray.size:
        raise ModelError("mesh.sets.base", model.mesh.sets.base, f"node {int(node_ids[stray[0]])} is on no base "
                         "element face (every base node must be a corner of a bottom face)")
    base_rings = measure.rings(nodes, hexes[on_base, :4])
    n_theta = max(8, base_rings.n_theta)   # through-wall rows of the base faces (by connectivity)
    on_pad = pad_face_mask(model.contact.pads, nodes[hexes[on_base, :4]], 360.0 / n_theta, ModelError)
    base_elems = on_base[on_pad]
    vol = hex_volumes(nodes[hexes])
    faces = hexes[base_elems, :4]
    a_nodes = quad_nodal_areas(nodes[faces])
    kc = pen.alpha * kbulk * a_nodes.sum(1)[:, None] * a_nodes / vol[base_elems][:, None]
    tnodes = np.unique(faces)
    table = _slave_set("table", nodes, tnodes, faces, a_nodes, kc, pen.k_normal,
                       normal=np.tile([0.0, 0.0, 1.0], (tnodes.size, 1)), clearance=np.zeros(tnodes.size))
    stop, stop_elems = None, np.zeros(0, np.int64)
    side = model.contact.stop.side
    if side != "none":
        cols, sign = ([0, 3, 7, 4], 1.0) if side == "inner" else ([1, 2, 6, 5], -1.0)
        r = np.hypot(nodes[:, 0], nodes[:, 1])
        if stop_set is None:           # the innermost (outermost) ring of the base faces
            stop_set = base_rings.rings[0 if side == "inner" else -1]
        in_stop = np.zeros(len(nodes), bool)
        in_stop[stop_set] = True
        stop_elems = on_base[in_stop[hexes[on_base][:, cols[:2]]].all(axis=1)]
        if stop_elems.size == 0:
            raise ModelError("contact.stop.side", side, "no base element has its wall face on the stop nodes")
        sfaces = hexes[stop_elems][:, cols]
        sa = quad_nodal_areas(nodes[sfaces])
        sa[:, 2:] = 0.0
        ks = pen.alpha * kbulk * sa.sum(axis=1, keepdims=True) * 2.0 * sa / vol[stop_elems][:, None]
        snodes = np.unique(sfaces[:, :2])
        th = np.radians(base_rings.theta[snodes])   # the row's azimuth: normal orthogonal to the table's tangent
        normal = sign * np.stack([np.cos(th), np.sin(th), np.zeros(th.size)], axis=1)
        r_stop = model.contact.stop.radius
        clearance = np.zeros(snodes.size) if r_stop is None else np.maximum(
            (r[snodes] - r_stop) if side == "inner" else (r_stop - r[snodes]), 0.0)
        stop = _slave_set("stop", nodes, snodes, sfaces, sa, ks, pen.k_normal, normal, clearance)
    table = replace(table, theta_deg=base_rings.theta[table.nodes])   # one azimuth per through-wall row
    if stop is not None:
        stop = replace(stop, theta_deg=base_rings.theta[stop.nodes])
    k_t = table.k.copy() if pen.k_tangent is None else np.full(table.nodes.size, float(pen.k_tangent))
    in_top = np.zeros(len(nodes), bool)
    in_top[top] = True
    top_elems = np.flatnonzero(in_top[hexes[:, 4:]].all(axis=1))
    if top_elems.size == 0:
        raise ModelError("mesh.sets.top", model.mesh.sets.top, "holds no element's top face")
    tfaces = hexes[top_elems, 4:]
    w = np.zeros(len(nodes))
    np.add.at(w, tfaces.ravel(), quad_nodal_areas(nodes[tfaces]).ravel())
    top_nodes = np.unique(tfaces)
    n_r = max(1, len(base_rings.rings) - 1)
    n_z = max(1, measure.axial_layers(len(nodes), hexes) - 1)
    return SkirtMesh(nodes=nodes, hexes=hexes, table=table, stop=stop, k_tangent=k_t,
                     k_open_ratio=pen.open_ratio, top_nodes=top_nodes, top_weights=w[top_nodes],
                     ref_point=np.array([0.0, 0.0, float(np.mean(nodes[top_nodes, 2]))]),
                     n_theta=n_theta, n_r=n_r, n_z=n_z, base_elems=base_elems, top_elems=top_elems,
                     stop_elems=stop_elems, node_ids=np.asarray(node_ids, np.int64),
                     elem_ids=np.asarray(elem_ids, np.int64))

