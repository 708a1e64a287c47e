"""The parametric skirt in any element type (issue 23): ``mesh.element`` and the structured cells.

``mesh.element`` (:data:`deckbridge.model_fields.MESH_ELEMENTS`): ``hex8i`` (default, C3D8I, :mod:`deckbridge.mesh`'s own builder),
``hex8``, ``hex20``, ``hex20r``, ``tet10``, ``wedge15``, ``tet4``. Every type is built on one refined
grid of the wall: levels kk = 0..2 n_z along z, ii = 0..2 n_r through the wall, jj = 0..2 n_theta - 1
around, at z = H kk / (2 n_z), r = r_mid(z) + (ii / (2 n_r) - 1/2) t, theta = 360 jj / (2 n_theta) deg,
so every node (corner or mid-side) lies on the true cylinder or cone. An element's corners are the even
points of a coarse cell (n_z x n_r x n_theta cells, as the 8-node mesh); its mid-side nodes the refined
points half way between two corners (in grid indices). Only the points some element uses are kept,
numbered in grid order (kk, then ii, then jj), so tet4 and hex8 number their nodes as the 8-node mesh;
the elements of one coarse cell follow each other, cells in the 8-node mesh's order (k, i, j).
Cells: hexahedra as the 8-node mesh (C3D8 order, + the 12 mid-sides of C3D20); wedges: each cell split
along its (r, theta) diagonal corner 1-3 into two prisms along z; tetrahedra: each cell split into six
along its 1-7 diagonal (Kuhn), which is conforming on the structured grid (every face diagonal runs
from the cell's low (r, theta, z) corner to the high one), turned to a positive volume.
"""

from __future__ import annotations

import warnings

import numpy as np

import reference_solver as rs
from reference_solver.elements import element_type
from reference_solver.quadrature import tri_rule

from .face_areas import contact_areas, hrz_areas
EIGHT_NODE = ("c3d8i", "c3d8")           # solver names built by deckbridge.mesh's own 8-node builder
TOP_TRI6_RULE = tri_rule(2)              # ccx 2.20's rule for a 6-node face's distributing weights (top_weights)

# hexahedron corners (dk, di, dj): C3D8 order of deckbridge.mesh
_HEX = np.array([(0, 0, 0), (0, 1, 0), (0, 1, 1), (0, 0, 1), (1, 0, 0), (1, 1, 0), (1, 1, 1), (1, 0, 1)])
_HEX_EDGES = ((0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7))
_TET_EDGES = ((0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3))
_WEDGE_EDGES = ((0, 1), (1, 2), (2, 0), (3, 4), (4, 5), (5, 3), (0, 3), (1, 4), (2, 5))
_WEDGES = ((0, 1, 2, 4, 5, 6), (0, 2, 3, 4, 6, 7))


def _kuhn_tets() -> list[tuple[int, ...]]:
    """The six tetrahedra (hex-local corners) of the path (0,0,0) -> (1,1,1) along each axis order."""
    where = {tuple(c): n for n, c in enumerate(_HEX)}
    out = []
    for order in ((0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)):
        v = np.zeros(3, int)
        path = [where[tuple(v)]]
        for ax in order:
            v[ax] = 1
            path.append(where[tuple(v)])
        out.append(tuple(path))
    return out


def solver_name(model) -> str:
    """The reference solver's name of the model's element ('c3d8i', 'c3d20r', ...)."""
    return element_type(model.mesh.element).name


def _shapes(name: str) -> list[tuple[tuple[int, ...], tuple]]:
    """(hex-local corners, edge table) of each element a coarse cell is cut into."""
    if name in ("c3d20", "c3d20r"):
        return [(tuple(range(8)), _HEX_EDGES)]
    if name == "c3d15":
        return [(w, _WEDGE_EDGES) for w in _WEDGES]
    if name in ("c3d10", "c3d4"):
        return [(t, _TET_EDGES if name == "c3d10" else ()) for t in _kuhn_tets()]
    raise ValueError(name)


def skirt_cells(model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(nodes (n, 3) [m], cells (m, k) in the element's CalculiX order, refined grid index (n, 3) of every
    node: kk, ii, jj) of the skirt meshed with ``model.mesh.element`` (not the 8-node types)."""
    g, ms = model.geometry, model.mesh
    nt, nr, nz = ms.n_theta, ms.n_r, ms.n_z
    et = element_type(model.mesh.element)
    k, i, j = (a.ravel() for a in np.meshgrid(np.arange(nz), np.arange(nr), np.arange(nt), indexing="ij"))
    cell0 = 2 * np.stack([k, i, j], axis=1)                                    # (nc, 3) refined
    blocks = []
    for corners, edges in _shapes(et.name):
        c = cell0[:, None, :] + 2 * _HEX[list(corners)][None]                   # (nc, nk, 3)
        if len(corners) == 4:                                                   # tetrahedra: turn positive
            x = _xyz(c[:, :4], g, nr, nz, nt)
            vol = np.einsum("ei,ei->e", np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), x[:, 3] - x[:, 0])
            neg = vol < 0
            c[neg, 1], c[neg, 2] = c[neg, 2].copy(), c[neg, 1].copy()
        mids = [(c[:, a] + c[:, b]) // 2 for a, b in edges]
        blocks.append(np.concatenate([c] + [m[:, None] for m in mids], axis=1) if mids else c)
    grid = np.stack(blocks, axis=1).reshape(-1, blocks[0].shape[1], 3)         # (m, k, 3) unwrapped, cell by cell
    grid[..., 2] %= 2 * nt
    flat = (grid[..., 0] * (2 * nr + 1) + grid[..., 1]) * (2 * nt) + grid[..., 2]
    used, cells = np.unique(flat, return_inverse=True)
    cells = cells.reshape(flat.shape)
    kk, rest = np.divmod(used, (2 * nr + 1) * 2 * nt)
    ii, jj = np.divmod(rest, 2 * nt)
    ijk = np.stack([kk, ii, jj], axis=1)
    nodes = _xyz(ijk, g, nr, nz, nt)
    et.volume_weights(nodes[cells])          # raises on a non-positive Jacobian (a builder bug)
    return nodes, cells, ijk


def _xyz(ijk: np.ndarray, g, nr: int, nz: int, nt: int) -> np.ndarray:
    """Coordinates [m] of refined grid points (..., 3) = (kk, ii, jj), on the true cylinder / cone."""
    kk, ii, jj = ijk[..., 0], ijk[..., 1], ijk[..., 2]
    z = g.height * kk / (2 * nz)
    r = g.radius + (g.r_top - g.radius) * z / g.height + (ii / (2 * nr) - 0.5) * g.thickness
    th = np.pi * jj / nt
    return np.stack([r * np.cos(th), r * np.sin(th), z], axis=-1)


def edge_weights(theta_rad: np.ndarray, radius: np.ndarray, quadratic: bool) -> np.ndarray:
    """Line weights [m] of nodes around one circle (sorted by angle): trapezoid (linear edges) or Simpson
    (quadratic edges: corners 1/6 of each edge's length, mid-sides 2/3), with n even for quadratic."""
    n = theta_rad.size
    step = 2 * np.pi / n * radius
    if not quadratic:
        return step.copy()
    w = np.where(np.arange(n) % 2 == 0, 2.0 / 6.0 * 2, 4.0 / 6.0 * 2)      # edge = 2 steps
    return w * step


def _elems_with_face(et, cells: np.ndarray, on: np.ndarray) -> np.ndarray:
    """Indices of the cells that have a face whose nodes all have ``on``."""
    hit = np.zeros(cells.shape[0], bool)
    for local in et.faces:
        hit |= on[cells[:, list(local)]].all(axis=1)
    return np.flatnonzero(hit)


def _pad_faces(model, tfaces, cells, ijk, et):
    """The table faces on ``contact.pads`` and the cells they bound: a face (quad8, or a triangle of a coarse
    cell's split base) is on a pad when its coarse cell's base quadrilateral is, by
    :func:`deckbridge.supports.pad_face_mask` on those quadrilaterals (the 8-node mesh's rule: centre azimuth
    between the snapped pad edges, mean corner radius in the radial band): every type takes hex8i's cells."""
    from .errors import ModelError
    from .supports import pad_face_mask
    g, ms = model.geometry, model.mesh
    nt, nr, nz = ms.n_theta, ms.n_r, ms.n_z
    out, on_nodes = [], np.zeros(ijk.shape[0], bool)
    for ftype, conn in tfaces:
        c = ijk[conn[:, :ftype.n_corners]]
        jj = np.where(c[..., 2].max(axis=1, keepdims=True) - c[..., 2] > nt, c[..., 2] + 2 * nt, c[..., 2])
        cell = np.stack([np.zeros(len(c), int), c[..., 1].min(axis=1), (jj.min(axis=1) % (2 * nt))], axis=1)
        quad = cell[:, None, :] + np.array([(0, 0, 0), (0, 2, 0), (0, 2, 2), (0, 0, 2)])[None]
        on = pad_face_mask(model.contact.pads, _xyz(quad, g, nr, nz, nt), 360.0 / nt, ModelError)
        out.append((ftype, conn[on]))
        on_nodes[conn[on].ravel()] = True
    return tuple(out), _elems_with_face(et, cells, on_nodes)


def pad_mesh_any_order(model):
    """The :class:`SkirtMesh` of ``model`` with ``contact.pads`` on a quadratic or tetrahedral skirt, the table
    the pad faces only (:func:`_pad_faces`). :func:`build_any_order` refuses these models (:data:`PADS_REASON`:
    the face-weighted Lagrange law opens pad-edge rows under N alone); this builder is kept to measure that
    (tests/test_pads_quadratic.py, docs/elements.md "Pads") and for a law that lifts the refusal."""
    return _build(model)


def build_any_order(model):
    """The skirt's :class:`SkirtMesh` in a quadratic or tetrahedral type (:func:`_build`); ``contact.pads`` is
    refused in one line (measured, docs/elements.md)."""
    from .errors import ModelError
    if model.contact.pads is not None:
        raise ModelError("contact.pads", "set", f"needs mesh.element hex8i or hex8 (not {model.mesh.element}): "
                         + (PADS_REASON_TET4 if element_type(model.mesh.element).name == "c3d4" else PADS_REASON))
    return _build(model)


# Why pads are refused on 10-/15-/20-node table faces (one line; also the imported meshes' refusal,
# deckbridge/importers/quadratic.py). Measured in tests/test_pads_quadratic.py; numbers in docs/elements.md, "Pads".
PADS_REASON = ("on 10-/15-/20-node faces the pad edge's singular pressure undershoots half a cell inside the edge and "
               "the face-weighted Lagrange law opens those rows under N alone (hex20 96 x 12 x 2: 18 of 69 rows a pad, "
               "pressing up to 1.3 um into the table, where a fine hex8i skirt carries 1.2 x the pad's mean pressure), "
               "so liftoff would read lambda = 0 (docs/elements.md, Pads)")
PADS_REASON_TET4 = ("4-node tetrahedra (constant strain, they fail the bending patch test) lift the outer and mid-wall "
                    "pad rows under N alone (96 x 12 x 2: 10 of 27 rows a pad, where a fine hex8i skirt presses every "
                    "node), so liftoff would read lambda = 0 (docs/elements.md, Pads)")


def _build(model):
    """The skirt's :class:`SkirtMesh` in a quadratic or tetrahedral type: slave areas are positive (table:
    :func:`deckbridge.face_areas.contact_areas`, int Phi_a dA of the hat basis on 8-/6-node faces; top: HRZ
    lumping of each face's M; Simpson / trapezoid line weights x h_1 / 2 on the stop's
    base circle); penalty per node k_c = alpha K A / h_1 (table), 2 alpha K A / (t / n_r) (stop), the 8-node
    mesh's alpha A^2 K / V on a regular cell; top weights = the HRZ areas of the top faces."""
    from reference_solver.face_weights import surface_faces

    from .mesh_data import SkirtMesh, _slave_set
    from .errors import ModelError
    g, ms, pen = model.geometry, model.mesh, model.contact.penalty
    et = element_type(ms.element)
    nodes, cells, ijk = skirt_cells(model)
    nt, nr, nz = ms.n_theta, ms.n_r, ms.n_z
    blocks = (rs.ElementBlock(et, cells),)
    if et.hourglass:
        from reference_solver.hourglass import hourglass_elements
        flagged = hourglass_elements(blocks)
        if flagged.size:
            warnings.warn(f"mesh.element = {ms.element}: {flagged.size} of {cells.shape[0]} elements have face "
                          "neighbours across fewer than two of their three directions, so C3D20R hourglass "
                          "(zero-energy) modes are possible: use hex20, or more elements along mesh.n_z / "
                          "mesh.n_r", stacklevel=4)
    kbulk, h1 = model.material.bulk_modulus, g.height / nz
    quadratic = et.name != "c3d4"

    on_table = ijk[:, 0] == 0
    tfaces = tuple(surface_faces(blocks, on_table))
    base_elems = _elems_with_face(et, cells, on_table)
    if model.contact.pads is not None:
        tfaces, base_elems = _pad_faces(model, tfaces, cells, ijk, et)
    tnodes, tarea = contact_areas(tfaces, nodes)
    kc = pen.alpha * kbulk * tarea / h1
    one = lambda a: np.asarray(a)[:, None]  # noqa: E731
    table = _slave_set("table", nodes, tnodes, one(tnodes), one(tarea), one(kc), pen.k_normal,
                       normal=np.tile([0.0, 0.0, 1.0], (tnodes.size, 1)), clearance=np.zeros(tnodes.size))

    stop, stop_elems = None, np.zeros(0, np.int64)
    side = model.contact.stop.side
    if side != "none":
        iw, sign = (0, 1.0) if side == "inner" else (2 * nr, -1.0)
        snodes = np.flatnonzero(on_table & (ijk[:, 1] == iw))              # ascending jj
        th = np.pi * ijk[snodes, 2] / nt
        r_face = np.hypot(nodes[snodes, 0], nodes[snodes, 1])
        sarea = edge_weights(th, r_face, quadratic) * h1 / 2.0
        ks = 2.0 * pen.alpha * kbulk * sarea / (g.thickness / nr)
        normal = sign * np.stack([np.cos(th), np.sin(th), np.zeros_like(th)], axis=1)
        r_stop = model.contact.stop.radius
        clearance = np.zeros(snodes.size)
        if r_stop is not None:
            clearance = (r_face - r_stop) if side == "inner" else (r_stop - r_face)
            if np.any(clearance < -1e-12):
                raise ModelError("contact.stop.radius", r_stop,
                                 f"penetrates the {side} wall face (radius {r_face[0]:.6g} m)")
            clearance = np.maximum(clearance, 0.0)
        stop = _slave_set("stop", nodes, snodes, one(snodes), one(sarea), one(ks), pen.k_normal, normal, clearance)
        wall = _elems_with_face(et, cells, ijk[:, 1] == iw)
        stop_elems = wall[on_table[cells[wall]].any(axis=1)]      # first-row cells on the stop's side

    k_t = table.k.copy() if pen.k_tangent is None else np.full(table.nodes.size, float(pen.k_tangent))
    on_top = ijk[:, 0] == 2 * nz
    top_nodes, top_w = top_weights(tuple(surface_faces(blocks, on_top)), nodes)
    return SkirtMesh(nodes=nodes, hexes=cells, table=table, stop=stop, k_tangent=k_t,
                     k_open_ratio=pen.open_ratio, top_nodes=top_nodes, top_weights=top_w,
                     ref_point=np.array([0.0, 0.0, g.height]), n_theta=nt, n_r=nr, n_z=nz,
                     base_elems=base_elems, top_elems=_elems_with_face(et, cells, on_top),
                     stop_elems=stop_elems, element=et.name, table_faces=tfaces)



def top_weights(faces, nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distributing coupling's node weights [m^2] of a top surface ``faces`` [(face type, conn), ...]
    (``SkirtMesh.top_weights``: the reference's ``coupling_weights`` and the RBE3 weights).

    On 8- and 6-node faces the consistent shares int N_a dA (:func:`reference_solver.face_weights.face_shares`;
    a regular quad8: corners -A/12, mid-sides A/3; tri6: corners 0, mid-sides A/3), integrated as ccx 2.20 does
    (quad8 3 x 3 Gauss, tri6 the 3-point rule: ``TOP_TRI6_RULE``): the weights by which ccx's ``*COUPLING,
    *DISTRIBUTING`` over the top surface spreads the force and the moment (measured: the same displacements as
    ``*CLOAD`` of :func:`reference_solver.distributing_forces` with these weights on graded blocks with curved
    top edges; the 6-point tri6 rule 0.19 % off there; tests/test_top_weights_ccx.py), so the reference loads
    a quadratic top as the ccx deck does (and the Abaqus deck, whose ``*DISTRIBUTING`` is the same keyword; not
    run here). A node's weight may be <= 0; their sum is the top's area.
    A surface of 4- and 3-node faces only keeps the HRZ areas (:func:`deckbridge.face_areas.hrz_areas`, = the
    tributary areas; pinned results). Returns (surface nodes ascending, weights)."""
    from dataclasses import replace

    from reference_solver.face_weights import face_shares
    if all(ftype.n_nodes == ftype.n_corners for ftype, _ in faces):
        return hrz_areas(faces, nodes)
    surf = np.unique(np.concatenate([c.ravel() for _, c in faces]))
    w = np.zeros(nodes.shape[0])
    for ftype, conn in faces:
        if ftype.n_nodes == 6:
            ftype = replace(ftype, points=TOP_TRI6_RULE[0], weights=TOP_TRI6_RULE[1])
        if ftype.n_nodes > ftype.n_corners:
            np.add.at(w, conn.ravel(), face_shares(ftype, nodes[conn]).ravel())
        else:
            lin, a = hrz_areas(((ftype, conn),), nodes)
            w[lin] += a
    return surf, w[surf]


# Measured (24 x 4 x 1 skirt, default loads, step 1 and lambda = 0.4 < liftoff; through-wall mean of the
# L2-projected table pressure -M^-1 r against beam theory, fraction of the peak): hex8i 0.012, tet4 0.012,
# wedge15 0.01 / 0.18 (Lagrange, steps 1 / 2), tet10 0.23, hex20 / hex20r 2.5 (Lagrange, corner nodes open at
# step 1) and 1.5-2.7 (penalty, every element type with mid-side nodes): the nodal law is unusable there, so
# build_problem gives quadratic faces the face-weighted laws (reference_solver/face_law.py; with friction
# reference_solver/friction_face.py; refused with the radial stop: solve.check_solvable).
QUADRATIC_REFUSED = ("with contact.tangential = friction on quadratic contact faces: not with the radial stop (a base "
                     "corner's tangential axis is the stop's normal, one dof that cannot take two weightings; "
                     "reference_solver/friction_face.py): set contact.stop.side = none, or use hex8i / hex8 / tet4")
# The face-weighted law is verified against closed forms in full contact and at a rigid top's liftoff, and
# against fine hex8i skirts past liftoff (docs/elements.md; tests/test_face_weighted_skirt.py and
# tests/test_face_weighted_liftoff.py), so solves on quadratic faces no longer warn.
