"""An imported mesh of 10-, 15- or 20-node solids (issue 23) as a :class:`deckbridge.mesh.SkirtMesh`.

The file's solid type names the reference solver's element (:data:`SOLID_TYPES`: ``C3D20R`` -> c3d20r;
``C3D20``, a 20-node ``CHEXA`` or Gmsh's ``hexahedron20`` -> c3d20; ``C3D10`` / 10-node ``CTETRA`` -> c3d10;
``C3D15`` / 15-node ``CPENTA`` -> c3d15). Gmsh's 27-node hexahedra (second order without
``Mesh.SecondOrderIncomplete``) are read as 20-node ones: their 7 face and centre nodes are dropped with a
warning (CalculiX has no 27-node brick). Node orders are checked geometrically
(:func:`.node_order.node_order_problem`, Nastran's mid-side order permuted first); a wrong one is refused in
one line naming the element. The contact data are those of the parametric skirt in any order
(:func:`deckbridge.mesh_order.build_any_order`): table faces = the element faces whose nodes are all in the
base set, positive nodal areas (:func:`deckbridge.face_areas.contact_areas`), k_c = alpha K A / h (h the mean
axial size of the base elements), top weights = HRZ areas of the faces in the top set, stop = the base nodes
on the innermost (outermost) base circle, line weights of the base faces' edges on it (Simpson on a quadratic edge) x h / 2. Every table / stop
node's azimuth is its through-wall row's (:func:`reference_solver.azimuths.azimuth_clusters`, tolerance 1e-3
of the smallest element's angular span), so a Gmsh file's round-off does not split a row.
"""

from __future__ import annotations

import warnings

import numpy as np

import reference_solver as rs
from reference_solver.azimuths import azimuth_clusters, element_span_deg
from reference_solver.elements import element_type

from .node_order import N_CORNERS, node_order_problem, to_calculix_order

# (type-name prefix, nodes per element) -> reference solver element; the first prefix that matches wins
SOLID_TYPES = ((("C3D20R",), 20, "c3d20r"), (("C3D20", "CHEXA", "HEXAHEDRON"), 20, "c3d20"),
               (("C3D27", "CHEXA", "HEXAHEDRON"), 27, "c3d20"),
               (("C3D10",), 10, "c3d10"), (("CTETRA", "TETRA"), 10, "c3d10"),
               (("C3D15", "CPENTA", "WEDGE"), 15, "c3d15"), (("C3D6", "CPENTA", "WEDGE"), 6, "c3d6"))
REFUSED_VARIANTS = ("C3D10M", "C3D10T", "C3D20RH", "C3D20H", "C3D10H", "C3D10MH")


def solver_element(etype: str, n_nodes: int) -> str | None:
    """The reference solver's name of a file's solid type with ``n_nodes`` nodes, None when not taken."""
    t = etype.upper()
    if t in REFUSED_VARIANTS:
        return None
    for prefixes, n, name in SOLID_TYPES:
        if n == n_nodes and t.startswith(prefixes):
            return name
    return None


def quadratic_cells(raw, etype: str, elem_ids, conn_ids, key: str = "mesh.file"):
    """(solver name, element ids, connectivity of node ids in CalculiX order) of the file's solids of type
    ``etype``; 27-node hexahedra lose their face and centre nodes (warned), and those nodes leave ``raw``."""
    from ..errors import ModelError
    name = solver_element(etype, conn_ids.shape[1])
    if name is None:
        raise ModelError(key, raw.path, f"{len(elem_ids)} elements of type {etype} with {conn_ids.shape[1]} "
                         "nodes: deckbridge takes 8-node hexahedra (C3D8, C3D8I, C3D8R) and the 20-node (C3D20, "
                         "C3D20R), 10-node (C3D10) and 15-node (C3D15) solids")
    if conn_ids.shape[1] == 27:
        warnings.warn(f"{raw.path}: {len(elem_ids)} 27-node hexahedra read as 20-node ones (C3D20): their face and "
                      "centre nodes are dropped (Gmsh: set Mesh.SecondOrderIncomplete = 1 to write C3D20)",
                      UserWarning, stacklevel=3)
        conn_ids = conn_ids[:, :20]
        keep = np.isin(raw.node_ids, conn_ids)
        raw.node_ids, raw.nodes = raw.node_ids[keep], np.asarray(raw.nodes)[keep]
        raw.sets = {k: v[np.isin(v, raw.node_ids)] for k, v in raw.sets.items()}
    return name, elem_ids, to_calculix_order(etype, conn_ids)


def check_node_order(nodes, cells, name: str, elem_ids, path: str = "") -> np.ndarray:
    """The cells with inverted elements mirrored (:func:`.node_order.turn_inverted`, warned with their count);
    a one-line ModelError naming the first element whose node order is still not CalculiX's."""
    from ..errors import ModelError
    from .node_order import turn_inverted
    why = node_order_problem(nodes, cells, name, elem_ids)
    if why and "Jacobian" in why:
        cells, n = turn_inverted(nodes, cells, name)
        if n:
            warnings.warn(f"{path}: {n} of {len(cells)} {name.upper()} elements were inverted (every integration "
                          "point's Jacobian negative) and are read mirrored (two corners swapped)", UserWarning,
                          stacklevel=3)
        why = node_order_problem(nodes, cells, name, elem_ids)
    if why:
        raise ModelError("mesh.file", "node order", why)
    return cells


def row_azimuths(nodes, cells, surf_nodes) -> np.ndarray:
    """Azimuth [deg, 0..360) of each of ``surf_nodes``: the circular mean of its through-wall row; ``cells``
    (m, k) or the blocks [(element, cells), ...] of a mixed mesh."""
    from ..azimuth import azimuth_deg
    th_all = azimuth_deg(nodes[:, 0], nodes[:, 1])
    parts = [c for _, c in cells] if isinstance(cells, list) else [cells]
    span = min(element_span_deg(th_all[c]).min() for c in parts)
    lab, centres = azimuth_clusters(th_all[surf_nodes], 1e-3 * max(span, 1e-9))
    return centres[lab]


def _edge_weights(blocks, on: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """Line weights [m] (n,) of the element edges of ``blocks`` [(element, cells), ...] whose nodes all have ``on``
    (each edge once, also where two blocks share it): Simpson on a quadratic edge (corners L/6, mid-side 2 L/3),
    L/2 to each end of a linear one; L the chord. The blocks are of one order (:data:`.checks.FAMILIES`)."""
    from .node_order import midside_edges
    w = np.zeros(nodes.shape[0])
    rows, quadratic = [], False
    for et, cells in blocks:
        edges = midside_edges(et)
        quadratic = bool(edges)
        if edges:
            rows += [cells[:, [a, m, b]] for m, a, b in edges]
        else:
            nc = et.n_nodes
            rows += [cells[:, [a, b, b]] for a in range(nc) for b in range(a + 1, nc)]
    rows = np.concatenate(rows)
    rows = rows[on[rows].all(axis=1)]
    key = np.sort(rows[:, [0, 2]], axis=1)
    _, first = np.unique(key, axis=0, return_index=True)
    rows = rows[first]
    length = np.linalg.norm(nodes[rows[:, 2]] - nodes[rows[:, 0]], axis=1)
    if quadratic:
        np.add.at(w, rows[:, 0], length / 6)
        np.add.at(w, rows[:, 2], length / 6)
        np.add.at(w, rows[:, 1], 2 * length / 3)
    else:
        np.add.at(w, rows[:, 0], length / 2)
        np.add.at(w, rows[:, 2], length / 2)
    return w


def _per_block(blocks, fn) -> np.ndarray:
    """``fn(element, cells)`` -> indices into the block's cells, as indices into all cells (block by block)."""
    out, offset = [], 0
    for et, cells in blocks:
        out.append(np.asarray(fn(et, cells), np.int64) + offset)
        offset += cells.shape[0]
    return np.concatenate(out)


def padded_cells(blocks) -> np.ndarray:
    """All cells of ``blocks`` [(element, cells (m_b, k_b)), ...] in one (m, max k) array, block by block, a
    shorter cell's row filled with -1 (``SkirtMesh.hexes`` of a mixed mesh; its ``blocks`` hold the types)."""
    k = max(c.shape[1] for _, c in blocks)
    return np.vstack([np.pad(c, ((0, 0), (0, k - c.shape[1])), constant_values=-1) for _, c in blocks])


def quadratic_mesh(model, cell_blocks, nodes, base, top, stop_set, node_ids, elem_ids):
    """The :class:`SkirtMesh` of an imported mesh of ``cell_blocks`` [(solver name, cells), ...] (module
    docstring): one block, or a mixed mesh (several types of one :data:`.checks.FAMILIES` member, cells numbered
    block by block as ``elem_ids``); ``nodes`` in the skirt frame with the base plane at z = 0,
    ``base``/``top``/``stop_set`` node indices."""
    from reference_solver.face_weights import surface_faces

    from ..errors import ModelError
    from ..face_areas import contact_areas
    from ..mesh_data import SkirtMesh, _slave_set
    from ..mesh_order import _elems_with_face, top_weights
    name = "+".join(n for n, _ in cell_blocks)            # 'c3d20r', or a mixed mesh's 'c3d20+c3d15'
    ets = [(element_type(n), c) for n, c in cell_blocks]
    pen, kbulk = model.contact.penalty, model.material.bulk_modulus
    blocks = tuple(rs.ElementBlock(et, c) for et, c in ets)
    cells = padded_cells(ets)
    on_base = np.zeros(len(nodes), bool)
    on_base[base] = True
    tfaces = tuple(surface_faces(blocks, on_base))
    stray = np.setdiff1d(base, np.concatenate([c.ravel() for _, c in tfaces]) if tfaces else [])
    if stray.size:
        raise ModelError("mesh.sets.base", model.mesh.sets.base, f"node {int(node_ids[stray[0]])} is on no base "
                         "element face (every base node must be a node of a bottom face)")
    if model.contact.pads is not None:
        from ..mesh_order import PADS_REASON
        raise ModelError("contact.pads", "set", f"needs 8-node hexahedra in an imported mesh (not {name.upper()}): "
                         + PADS_REASON)
    base_elems = _per_block(ets, lambda et, c: _elems_with_face(et, c, on_base))
    z_span = np.concatenate([np.ptp(nodes[c, 2], axis=1) for _, c in ets])     # axial size of each cell [m]
    h1 = float(np.mean(z_span[base_elems]))
    tnodes, tarea = contact_areas(tfaces, nodes)
    one = lambda a: np.asarray(a)[:, None]  # noqa: E731
    table = _slave_set("table", nodes, tnodes, one(tnodes), one(tarea), one(pen.alpha * kbulk * tarea / h1),
                       pen.k_normal, normal=np.tile([0.0, 0.0, 1.0], (tnodes.size, 1)), clearance=np.zeros(tnodes.size))
    from dataclasses import replace
    table = replace(table, theta_deg=row_azimuths(nodes, ets, tnodes))
    r = np.hypot(nodes[:, 0], nodes[:, 1])
    r_in, r_out = r[tnodes].min(), r[tnodes].max()
    stop, stop_elems = None, np.zeros(0, np.int64)
    side = model.contact.stop.side
    if side != "none":
        tol = 1e-3 * (r_out - r_in)
        if stop_set is None:
            stop_set = tnodes[(r[tnodes] <= r_in + tol) if side == "inner" else (r[tnodes] >= r_out - tol)]
        on_stop = np.zeros(len(nodes), bool)
        on_stop[stop_set] = True
        sw = _edge_weights(ets, on_stop, nodes)
        snodes = np.flatnonzero(on_stop)
        sarea = sw[snodes] * h1 / 2.0
        if (sarea <= 0).any():
            raise ModelError("mesh.sets.stop", "stop", f"node {int(node_ids[snodes[sarea <= 0][0]])} is on no "
                             "base element edge of the stop circle")
        r_span = np.concatenate([np.ptp(r[c], axis=1) for _, c in ets])
        n_r_est = max(1, round((r_out - r_in) / max(np.median(r_span[base_elems]), 1e-300)))
        ks = 2.0 * pen.alpha * kbulk * sarea / ((r_out - r_in) / n_r_est)
        row_of = dict(zip(tnodes.tolist(), table.theta_deg.tolist()))   # the table's row azimuths (springs)
        th = np.radians([row_of.get(int(n), np.nan) for n in snodes])
        if np.isnan(th).any():
            raise ModelError("mesh.sets.stop", model.mesh.sets.stop, f"node {int(node_ids[snodes[np.isnan(th)][0]])} "
                             "is not a base node")
        sign = 1.0 if side == "inner" else -1.0
        normal = sign * np.stack([np.cos(th), np.sin(th), np.zeros_like(th)], axis=1)
        r_stop = model.contact.stop.radius
        clearance = np.zeros(snodes.size)
        if r_stop is not None:
            clearance = np.maximum((r[snodes] - r_stop) if side == "inner" else (r_stop - r[snodes]), 0.0)
        stop = _slave_set("stop", nodes, snodes, one(snodes), one(sarea), one(ks), pen.k_normal, normal, clearance)
        stop = replace(stop, theta_deg=np.degrees(th) % 360.0)
        stop_elems = _per_block(ets, lambda et, c: np.flatnonzero(on_stop[c].sum(axis=1) >= 2))
        stop_elems = np.intersect1d(stop_elems, base_elems)
    k_t = table.k.copy() if pen.k_tangent is None else np.full(table.nodes.size, float(pen.k_tangent))
    on_top = np.zeros(len(nodes), bool)
    on_top[top] = True
    top_faces = tuple(surface_faces(blocks, on_top))
    if not top_faces:
        raise ModelError("mesh.sets.top", model.mesh.sets.top, "holds no element's top face")
    top_nodes, top_w = top_weights(top_faces, nodes)
    corners = np.unique(np.concatenate([c[_elems_with_face(et, c, on_base)][:, :N_CORNERS[et.n_nodes]].ravel()
                                        for et, c in ets]))
    base_corners = np.intersect1d(corners, tnodes)
    n_theta = int(np.unique(row_azimuths(nodes, ets, base_corners)).size)
    n_z = max(1, round(float(np.ptp(nodes[:, 2])) / h1))
    rc = np.sort(r[base_corners])
    n_r = max(1, int((np.diff(rc) > 1e-3 * (r_out - r_in)).sum()))
    return SkirtMesh(nodes=nodes, hexes=cells, table=table, stop=stop, k_tangent=k_t,
                     k_open_ratio=pen.open_ratio, top_nodes=top_nodes, top_weights=top_w,
                     ref_point=np.array([0.0, 0.0, float(np.mean(nodes[top_nodes, 2]))]),
                     n_theta=n_theta, n_r=n_r, n_z=n_z, base_elems=base_elems,
                     top_elems=_per_block(ets, lambda et, c: _elems_with_face(et, c, on_top)),
                     stop_elems=stop_elems, node_ids=np.asarray(node_ids, np.int64),
                     elem_ids=np.asarray(elem_ids, np.int64), element=name, table_faces=tfaces,
                     blocks=tuple((et.name, c) for et, c in ets) if len(ets) > 1 else ())
