"""Which dialect can carry which element type of the skirt (issue 23), and the inp cards that depend on it.

``element_problem(dialect, model, mesh)``: one line saying why a dialect's decks cannot carry the mesh's
element type (:class:`deckbridge.errors.DeckUnsupported` in :func:`deckbridge.render.render_all`; ``decks``
and ``run`` leave the dialect out with that note), None when they can. Rules:
- hex8i (C3D8I): every dialect, unchanged;
- a node-based contact law on a quadratic face (8-node quadrilateral, 6-node triangle) is refused, never
  written: a uniform pressure gives the corner nodes -1/12 (8-node) or 0 (6-node) of its load, so a sign
  condition on nodal forces (Nastran/MYSTRAN CGAP, ccx node-to-surface and GAPUNI, Abaqus node-to-surface)
  opens the corners at zero load. CalculiX writes its mortar deck (``*CONTACT PAIR, TYPE=MORTAR``, no SPC on
  slave nodes, circumferential springs on corner nodes only: :func:`corner_spring_k`) and its face-to-face
  penalty deck (``SURFACE TO SURFACE``, LINEAR slope :func:`quadratic_face_slopes`, master
  ``dialects/calculix/quadratic_master.f2f_ring``), and only without the radial stop (its GAPUNI gaps are
  node-based); Abaqus writes its table pair surface to surface (``TYPE=SURFACE TO SURFACE``, element-based
  slave faces), also only without the radial stop (its slaves are base nodes);
- hex8 (C3D8): CalculiX and Abaqus (C3D8 cards); the Nastran family writes CHEXA as C3D8I-like (not yet);
- the Simcenter surface-contact deck (nastran_surface) writes CHEXA (20 grids) / CTETRA (10) / CPENTA (15) with
  their mid-side grids and BSURFS faces (the radial stop where the stop-side cells have 8-node wall faces: hex20,
  hex20r, wedge15 and mixed meshes of them, not on tetrahedra); the CGAP deck's
  refusal names it;
- tet4: not written yet (one line saying so);
- mixed meshes (one block per type, ``mesh.blocks``): first order (C3D8I + C3D6) in :data:`MIXED_DIALECTS`
  (one ``*ELEMENT`` per type, CHEXA + CPENTA); second order (C3D20/C3D20R + C3D15, C3D10 + C3D15) in
  :data:`MIXED_QUADRATIC_DIALECTS` on each cell's own faces (quad8 and tri6 slave faces: :func:`cell_types`),
  the node-based ones refused as above; first order without the radial stop, second order with it in the
  Simcenter deck only (its wall faces: quad8 of either cell type; CalculiX and Abaqus refuse it on any 8-/6-node
  face, as above).
CalculiX element names: :data:`CCX_TYPE`; faces S1.. in the element's own face order (reference_solver).
"""

from __future__ import annotations

import numpy as np

from reference_solver.elements import element_type

from .mesh_data import element_key

CCX_TYPE = {"c3d8i": "C3D8I", "c3d8": "C3D8", "c3d20": "C3D20", "c3d20r": "C3D20R", "c3d10": "C3D10",
            "c3d15": "C3D15", "c3d4": "C3D4", "c3d6": "C3D6"}
CCX_PER_LINE = 16          # entries per *ELEMENT data line before a continuation line (ccx and Abaqus)
NODE_BASED = {"nastran": "CGAP gaps", "mystran": "CGAP gaps"}
MIXED_DIALECTS = ("calculix", "abaqus", "nastran")   # decks written for a first-order mixed mesh (C3D8I + C3D6)
# decks written for a second-order mixed mesh (C3D20/C3D20R + C3D15, C3D10 + C3D15): the face-weighted ones
# (CalculiX mortar and face-to-face, Abaqus surface to surface: without the radial stop; Simcenter surface contact)
MIXED_QUADRATIC_DIALECTS = ("calculix", "abaqus", "nastran_surface")
QUADRATIC_ELEMENTS = ("c3d20", "c3d20r", "c3d10", "c3d15")


def element_problem(dialect: str, model, mesh) -> str | None:
    """Why ``dialect``'s decks cannot carry the element type of ``mesh`` (one line), or None."""
    el = getattr(mesh, "element", "c3d8i")
    if el == "c3d8i":
        return None
    key = " = ".join(element_key(model, mesh))   # the imported file's types, not mesh.element's default
    quad = bool(getattr(mesh, "quadratic_faces", False))
    if getattr(mesh, "blocks", ()) and not quad:  # a first-order mixed mesh (issue 23): without the stop
        return (None if dialect in MIXED_DIALECTS and mesh.stop is None else
                f"{key}: this dialect's decks are not written for a mixed mesh yet (first order without the radial "
                f"stop: {', '.join(MIXED_DIALECTS)})")
    if quad:
        if dialect == "calculix":
            if mesh.stop is not None:
                return (f"{key}: the radial stop is GAPUNI gaps (node-based), wrong on 8-/6-node faces (corner "
                        "nodes carry -1/12 or 0 of a pressure and open at zero load): set contact.stop.side: "
                        "none for the CalculiX mortar and face-to-face decks")
            return None if _quadratic_types(el) else f"{key}: not written yet"
        if dialect == "abaqus":       # surface-to-surface table pair (dialects/abaqus/render.py)
            if mesh.stop is not None:
                return (f"{key}: the radial stop's slaves are base nodes (node-based contact), wrong on 8-/6-node "
                        "faces (corner nodes carry -1/12 or 0 of a pressure and open at zero load): set "
                        "contact.stop.side: none for the Abaqus surface-to-surface deck")
            return None if _quadratic_types(el) else f"{key}: not written yet"
        if dialect == "nastran_surface":       # BSURFS faces, CHEXA/CPENTA/CTETRA with mid-side grids
            if mesh.stop is not None and not _stop_wall_faces_quadrilateral(mesh):   # tetrahedra on the stop
                return (f"{key}: the surface-contact deck's radial stop on a tetrahedral skirt's wall faces is not "
                        "written yet: set contact.stop.side: none for it, or use the calculix dialect (mortar deck)")
            return None if _quadratic_types(el) else f"{key}: not written yet"
        why = NODE_BASED.get(dialect, "its contact")
        other = ("the nastran_surface dialect (Simcenter surface contact, BSURFS) or " if dialect == "nastran"
                 else "")
        return (f"{key}: a node-based law ({why}) opens the corner nodes of 8-/6-node faces at zero load "
                f"(they carry -1/12 or 0 of a uniform pressure): use {other}the calculix dialect (mortar or "
                "face-to-face deck)")
    if el == "c3d8" and dialect in ("calculix", "abaqus"):
        return None
    return f"{key}: this dialect's decks are written for hex8i only so far (hex8: calculix, abaqus)"


def _stop_wall_faces_quadrilateral(mesh) -> bool:
    """True when every first-row cell on the stop side (``mesh.stop_elems``) has 8-node faces (a C3D20 / C3D15 wall
    face for the surface-contact deck's stop layer); a tetrahedral skirt, or tetrahedra on the stop of a mixed one,
    has none."""
    elems = getattr(mesh, "stop_elems", None)
    if elems is None or not len(elems):
        return "c3d10" not in str(getattr(mesh, "element", "")).split("+")
    types = cell_types(mesh)
    return all(any(len(f) == 8 for f in types[int(e)].faces) for e in elems)


def _quadratic_types(el: str) -> bool:
    """True when every type of ``el`` ('c3d20r', or a mixed mesh's 'c3d20+c3d15') is a quadratic one decks carry."""
    return all(t in QUADRATIC_ELEMENTS for t in el.split("+"))


def cell_types(mesh) -> list:
    """The element type (:func:`reference_solver.elements.element_type`) of every cell of ``mesh``, in cell order
    (a mixed mesh: block by block, ``mesh.blocks``)."""
    return [et for n, c in mesh.cell_blocks for et in [element_type(n)] * c.shape[0]]


def ccx_element_lines(ids, conn) -> str:
    """``*ELEMENT`` data lines ``id, n1, ..., nk``, continued on the next line after 16 entries."""
    out = []
    for e, c in zip(ids, conn):
        entries = [str(int(e))] + [str(int(n)) for n in c]
        chunks = [entries[k:k + CCX_PER_LINE] for k in range(0, len(entries), CCX_PER_LINE)]
        out.append(",\n".join(", ".join(ch) for ch in chunks))
    return "\n".join(out)


def face_label_lines(mesh, elems: np.ndarray, ids: np.ndarray, z: float) -> str:
    """Element-based ``*SURFACE`` lines ``id, Sk`` of the faces of cells ``elems`` (indices; deck ids ``ids``)
    whose nodes all lie at height ``z`` [m] (1e-9 of the height): k = the face's place in the element's face
    order (CalculiX's S1, S2, ...)."""
    types = cell_types(mesh)                              # a mixed mesh: per cell
    on = np.abs(mesh.nodes[:, 2] - z) <= 1e-9 * np.ptp(mesh.nodes[:, 2])
    lines = []
    for e, eid in zip(np.asarray(elems, np.int64), ids):
        for f, local in enumerate(types[e].faces):
            if on[mesh.hexes[e, list(local)]].all():
                lines.append(f"{int(eid)}, S{f + 1}")
    return "\n".join(lines)


def corner_spring_k(mesh) -> np.ndarray:
    """Circumferential spring stiffness per table slave row [N/m] for a CalculiX mortar deck on quadratic base
    faces: ``mesh.k_tangent`` with each mid-side node's stiffness moved, half and half, onto the two corner nodes
    of its edge (mid-side rows 0). The total per edge, and so the shear the springs carry, is kept.

    Why: ccx 2.20's mortar on 8-/6-node slave faces leaves a SPRING1 on a mid-side slave node out of balance
    (measured, hex20r 24 x 3 x 1, default loads: the largest residual stuck at 468.6 N in dof 1 of the mid-wall
    nodes at theta 90 / 270 at lambda 0.1 -- about that node's whole spring force -- and 117.1 N at a quarter of
    the increment, until 'too many cutbacks'); with the same springs on the corner nodes only it runs to lambda 1."""
    tab = mesh.table
    k = np.asarray(mesh.k_tangent, float).copy()
    row = np.full(mesh.n_nodes, -1)
    row[tab.nodes] = np.arange(tab.nodes.size)
    z = mesh.nodes[:, 2]
    on = np.abs(z - z[tab.nodes].min()) <= 1e-9 * max(float(np.ptp(z)), 1e-300)
    edges = {}                                          # mid-side node -> its edge's two corner nodes
    for name, cells in mesh.cell_blocks:                # a mixed mesh: every block's own faces
        for local in element_type(name).faces:
            n = len(local)
            if n not in (6, 8):
                continue
            conn = cells[:, list(local)]
            conn = conn[on[conn].all(axis=1)]
            c = n // 2
            for m in range(c):
                for f in conn:
                    edges.setdefault(int(f[c + m]), (int(f[m]), int(f[(m + 1) % c])))
    moved = k.copy()
    for mid, (a, b) in edges.items():
        if row[mid] < 0 or row[a] < 0 or row[b] < 0:
            continue
        moved[row[mid]] -= k[row[mid]]
        moved[row[a]] += k[row[mid]] / 2
        moved[row[b]] += k[row[mid]] / 2
    return moved


def base_faces(mesh) -> list[tuple[int, int, np.ndarray]]:
    """The table slave faces of a quadratic skirt: (element index, face number k of ``Sk``, node indices in
    the face's CalculiX order, corners first, mid-side node m between corners m and m + 1), for every face of
    the base elements whose nodes all lie on the table plane (1e-9 of the height)."""
    types = cell_types(mesh)                            # a mixed mesh: each cell's own faces
    z = mesh.nodes[:, 2]
    on = np.abs(z - z[mesh.table.nodes].min()) <= 1e-9 * max(float(np.ptp(z)), 1e-300)
    elems = mesh.base_elems if mesh.base_elems is not None else np.arange(mesh.hexes.shape[0])
    out = []
    for e in np.asarray(elems, np.int64):
        for f, local in enumerate(types[e].faces):
            conn = mesh.hexes[e, list(local)]
            if on[conn].all():
                out.append((int(e), f + 1, conn))
    return out


def quadratic_face_slopes(mesh, faces, k_node: np.ndarray) -> np.ndarray:
    """Face-to-face penalty slope K [Pa/m, SI] of each quadratic slave face of ``faces`` (:func:`base_faces`):
    :func:`reference_solver.face_weights.face_slope`, the reference face penalty's own, sum_i s_i (k_i / A_i) /
    sum_i s_i with s_i = int Phi_i dA the hat multiplier basis' shares (corners A/24, mid-sides 5 A/24 of a
    regular 8-node face; A/12, A/4 of a 6-node one), k_i [N/m] per table row (the model's k_c, or k_t for the
    stick slope) and A_i the row's area (``mesh.table.area``, :func:`deckbridge.face_areas.contact_areas`, the
    sum of its hat shares): sum over the faces of K x area = sum of k_i for any k (an explicit
    ``contact.penalty.k_normal`` included), and K = k_i / A_i = alpha K_bulk / h1 where that ratio is the same on
    every node (the model's own penalty)."""
    from reference_solver.face_weights import face_slope
    tab = mesh.table
    row = np.full(mesh.n_nodes, -1)
    row[tab.nodes] = np.arange(tab.nodes.size)
    k, area = np.asarray(k_node, float), np.asarray(tab.area, float)
    types = cell_types(mesh)                            # a mixed mesh: each cell's own face types
    out = np.empty(len(faces))
    for n, (e, f, conn) in enumerate(faces):
        r = row[conn][None]
        out[n] = face_slope(types[e].face_types[f - 1], mesh.nodes[conn][None], k[r], area[r])[0]
    return out
