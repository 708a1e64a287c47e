"""Import checks: each raises a one-line ModelError naming the set (or the file) and the node/element."""

from __future__ import annotations

import numpy as np

from .raw import HEX8, is_solid, solid_shape

# element families that may share an imported mesh (solver names; 8-node hexahedra are read as c3d8i): their faces
# conform (a hexahedron's quadrilateral against a wedge's, a wedge's triangle against a tetrahedron's) and one
# contact law fits all their base faces (node-based on 4-/3-node faces, face-weighted on 8-/6-node faces)
FAMILIES = (("first-order", ("c3d8i", "c3d6")), ("second-order", ("c3d20", "c3d20r", "c3d15", "c3d10")))


def solid_elements(raw, key: str = "mesh.file") -> list[tuple[str, np.ndarray, np.ndarray, str]]:
    """The mesh's solids by file type: [(file type, element ids, connectivity of node ids, solver name)], the
    solver name ``c3d8i`` for 8-node hexahedra (C3D8 order) or that of a 6-, 10-, 15-, 20- or 27-node type
    (:func:`.quadratic.solver_element`). Elements that are not solids (the 2D skin of physical groups Gmsh writes,
    CPS4 / CPS8 / S4 / CQUAD4 / CTRIA6, beams, springs) are ignored: their nodes are solid nodes and they may
    define the node sets. Several solid types are taken when they are of one :data:`FAMILIES` member (a mixed
    mesh: hexahedra and wedges of one order, 10-node tetrahedra with 15-node wedges); first- and second-order
    solids together, hexahedra with tetrahedra (no conforming face without pyramids), and a type deckbridge does
    not take (C3D4, pyramids), are refused, named."""
    from ..errors import ModelError
    from .quadratic import solver_element
    solids = {t: (i, c) for t, (i, c) in raw.elements.items() if is_solid(t)}
    if not solids:
        skin = ", ".join(sorted(raw.elements)) or "none"
        raise ModelError(key, raw.path, f"no solid elements in the file (elements found: {skin})")
    kinds = {t: ("c3d8i" if t.upper() in HEX8 and c.shape[1] == 8 else solver_element(t, c.shape[1]))
             for t, (i, c) in solids.items()}
    for t, (i, c) in solids.items():
        if kinds[t] is None:
            raise ModelError(key, raw.path, f"{len(i)} elements of type {t}: {solid_shape(c.shape[1])}; deckbridge "
                             "takes 8-node hexahedra (C3D8, C3D8I, C3D8R) with 6-node wedges (C3D6), and 20-node "
                             "hexahedra (C3D20, C3D20R), 10-node tetrahedra (C3D10) and 15-node wedges (C3D15)")
    family = {k: f for f, members in FAMILIES for k in members}
    if len({family[k] for k in kinds.values()}) > 1:
        (t1, (i1, c1)), (t2, (i2, c2)) = next(((a, solids[a]), (b, solids[b])) for a in solids for b in solids
                                              if family[kinds[a]] != family[kinds[b]])
        raise ModelError(key, raw.path, f"{len(i1)} elements of type {t1} ({c1.shape[1]}-node) and {len(i2)} of type "
                         f"{t2} ({c2.shape[1]}-node): first- and second-order solids are not mixed in one mesh "
                         "(contact on 4-/3-node faces is node-based, on 8-/6-node faces face-weighted, and a linear "
                         "face does not conform to a quadratic one): mesh it in one order")
    hexa = [t for t in solids if kinds[t] in ("c3d8i", "c3d20", "c3d20r")]
    tets = [t for t in solids if kinds[t] == "c3d10"]
    if hexa and tets:
        raise ModelError(key, raw.path, f"{len(solids[hexa[0]][0])} elements of type {hexa[0]} (hexahedra) and "
                         f"{len(solids[tets[0]][0])} of type {tets[0]} (tetrahedra): their faces do not conform "
                         "(quadrilateral against triangle; a mesh of both needs pyramids, which deckbridge does not "
                         "take): join them through wedges, or mesh in one type")
    ids = np.concatenate([i for i, _ in solids.values()])
    u, cnt = np.unique(ids, return_counts=True)
    if (cnt > 1).any():
        raise ModelError(key, raw.path, f"element {int(u[cnt > 1][0])} is defined twice")
    return [(t, np.asarray(i), np.asarray(c), kinds[t]) for t, (i, c) in solids.items()]


def ids_in_range(raw, elem_ids, key: str = "mesh.file") -> None:
    """Node and element ids positive and within the largest id some dialect carries
    (:attr:`deckbridge.dialects.Dialect.max_id`; a dialect whose fields are narrower is left out at render)."""
    from ..dialects import DIALECTS
    from ..errors import ModelError
    top = max(d.max_id for d in DIALECTS.values())
    for what, ids in (("node", np.asarray(raw.node_ids)), ("element", np.asarray(elem_ids))):
        bad = ids[(ids < 1) | (ids > top)]
        if bad.size:
            fits = ", ".join(f"{d.name} {d.max_id}" for d in DIALECTS.values())
            raise ModelError(key, raw.path, f"{what} id {int(bad[0])}: ids must lie in 1..{top} to be written "
                             f"to a deck (largest id per dialect: {fits}): renumber the mesh")


def finite_coordinates(raw, key: str = "mesh.file") -> None:
    """Every coordinate a finite number (a NaN or infinite one is named with its node and axis)."""
    from ..errors import ModelError
    bad = ~np.isfinite(np.asarray(raw.nodes, float))
    if bad.any():
        i, a = np.argwhere(bad)[0]
        raise ModelError(key, raw.path, f"node {int(raw.node_ids[i])}: coordinate {'xyz'[a]} = "
                         f"{raw.nodes[i, a]!r} is not a finite number")


def plausible_size(nodes, units: str, unit_m: dict, lo_hi: tuple, key: str = "mesh.units") -> None:
    """The skirt's largest radius ``nodes`` (skirt frame, m) within ``lo_hi`` [m] for the declared
    ``units``: outside it the unit is wrong (a mesh in mm declared m measures R = 1500 m); the message
    gives the radius each unit of ``unit_m`` (name -> metres per unit) would give."""
    from ..errors import ModelError
    r = float(np.hypot(nodes[:, 0], nodes[:, 1]).max())
    lo, hi = lo_hi
    if lo <= r <= hi:
        return
    alt = ", ".join(f"{u}: {r / unit_m[units] * f:.6g} m" for u, f in unit_m.items() if u != units)
    raise ModelError(key, units, f"the mesh's largest radius is {r:.6g} m, outside {lo:g}..{hi:g} m for a skirt: "
                     f"is the mesh in another unit? (mesh.units = {alt})")


def nodes_unique_and_used(raw, conn_ids: np.ndarray, size: float, key: str = "mesh.file") -> None:
    """Duplicate node ids, coincident nodes (unmerged), nodes no element uses, elements on unknown nodes."""
    from ..errors import ModelError
    u, cnt = np.unique(raw.node_ids, return_counts=True)
    if (cnt > 1).any():
        raise ModelError(key, raw.path, f"node {int(u[cnt > 1][0])} is defined twice")
    unknown = np.setdiff1d(conn_ids, raw.node_ids)
    if unknown.size:
        raise ModelError(key, raw.path, f"an element uses node {int(unknown[0])}, which is not defined")
    unused = np.setdiff1d(raw.node_ids, conn_ids)
    if unused.size:
        raise ModelError(key, raw.path, f"node {int(unused[0])} is used by no element (unreferenced node)")
    q = np.round(np.asarray(raw.nodes) / (1e-9 * size)).astype(np.int64)
    _, first, cnt = np.unique(q, axis=0, return_index=True, return_counts=True)
    if (cnt > 1).any():
        i = first[cnt > 1][0]
        same = np.flatnonzero((q == q[i]).all(axis=1))
        raise ModelError(key, raw.path, f"nodes {int(raw.node_ids[same[0]])} and {int(raw.node_ids[same[1]])} "
                         "coincide (duplicate nodes: merge them)")


def set_nodes(raw, sets, role: str, index_of: dict) -> np.ndarray:
    """Node indices of set ``sets.<role>``; an unknown name lists the sets found."""
    from ..errors import ModelError
    from .bdf_file import node_list_file
    name = getattr(sets, role)
    ids = raw.sets.get(name)
    if ids is None:
        ids = node_list_file(raw.path, name, f"mesh.sets.{role}")
    if ids is None:
        found = ", ".join(sorted(raw.sets)) or "none"
        raise ModelError(f"mesh.sets.{role}", name, f"no such node set in {raw.path} (found: {found})")
    missing = [int(i) for i in ids if int(i) not in index_of]
    if missing:
        raise ModelError(f"mesh.sets.{role}", name, f"node {missing[0]} is not a node of the mesh")
    return np.array([index_of[int(i)] for i in ids], np.int64)


def base_plane(nodes, base, top, node_ids, names, size: float) -> float:
    """Base nodes on one plane z = z0 normal to the axis (tolerance 1e-6 of the model size); the top set
    non-empty and above the base. Returns z0."""
    from ..errors import ModelError
    tol = 1e-6 * size
    if base.size == 0:
        raise ModelError("mesh.sets.base", names.base, "is empty")
    z0 = float(np.median(nodes[base, 2]))
    off = np.abs(nodes[base, 2] - z0) > tol
    if off.any():
        i = base[off][0]
        raise ModelError("mesh.sets.base", names.base, f"node {int(node_ids[i])} at axial position "
                         f"{nodes[i, 2]:.6g} is off the base plane {z0:.6g} (tolerance {tol:.3g}): "
                         "slave nodes must lie on one plane normal to the axis")
    if top.size == 0:
        raise ModelError("mesh.sets.top", names.top, "is empty")
    low = nodes[top, 2] <= z0 + tol
    if low.any():
        i = top[low][0]
        raise ModelError("mesh.sets.top", names.top, f"node {int(node_ids[i])} at axial position "
                         f"{nodes[i, 2]:.6g} is not above the base plane {z0:.6g}")
    return z0


def not_inverted(nodes, hexes, elem_ids) -> None:
    """Every hexahedron has a positive Jacobian at its 8 corners (C3D8 node order)."""
    from ..errors import ModelError
    x = nodes[hexes]                                   # (m, 8, 3)
    sg = np.array([-1, 1, 1, -1, -1, 1, 1, -1], float)
    tg = np.array([-1, -1, 1, 1, -1, -1, 1, 1], float)
    ug = np.array([-1, -1, -1, -1, 1, 1, 1, 1], float)
    det = []
    for s, t, u in zip(sg, tg, ug):                    # the Jacobian at each corner
        d = np.stack([sg * (1 + tg * t) * (1 + ug * u), tg * (1 + sg * s) * (1 + ug * u),
                      ug * (1 + sg * s) * (1 + tg * t)]) / 8.0
        det.append(np.linalg.det(np.einsum("ca,ead->ecd", d, x)))
    det = np.stack(det, axis=1)
    bad = np.flatnonzero((det <= 0).any(axis=1))
    if bad.size:
        raise ModelError("mesh.file", "elements", f"element {int(elem_ids[bad[0]])} is inverted "
                         "(negative Jacobian: node order)")


def connected(n_nodes: int, hexes, node_ids) -> None:
    """One connected body (elements sharing nodes); ``hexes`` (m, k) or a list of such blocks (a mixed mesh)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from ..errors import ModelError
    blocks = list(hexes) if isinstance(hexes, (list, tuple)) else [hexes]
    hexes = blocks[0]
    r = np.concatenate([np.repeat(b[:, :1], b.shape[1] - 1, axis=1).ravel() for b in blocks])
    c = np.concatenate([b[:, 1:].ravel() for b in blocks])
    g = coo_matrix((np.ones(r.size), (r, c)), shape=(n_nodes, n_nodes))
    n, lab = connected_components(g, directed=False)
    if n > 1:
        i = np.flatnonzero(lab != lab[hexes[0, 0]])[0]
        raise ModelError("mesh.file", "connectivity", f"the mesh is not connected: {n} parts "
                         f"(node {int(node_ids[i])} is not connected to node {int(node_ids[hexes[0, 0]])})")
