"""Ids of the inp-family decks (Abaqus/Standard and CalculiX).

Skirt node id = mesh index + 1, skirt element id = hex index + 1 (:mod:`.skirt`). Then, in order:
the reference node (top centre), the nodes of the fixed master rings (table, then stop), the
grounded GAPUNI nodes (CalculiX); elements: the master rings, one SPRING1 per table slave node
(circumferential restraint), the GAPUNI gaps (CalculiX). Hexahedron faces use the C3D8 labels
shared by both codes: S1 = 1-2-3-4 (base, outward -z), S2 = 5-8-7-6 (top, +z), S4 = 2-6-7-3 (outer
wall, +r), S6 = 4-8-5-1 (inner wall, -r).

Master rings: the table is the top face (S2, normal +z) of a ring below z = 0 that overhangs both
wall faces by one wall thickness and uses the skirt's azimuths; the stop is the wall face of a ring
at the stop radius, facing the skirt (S4 = +r for an inner stop, S6 = -r for an outer stop),
spanning z in [-h1/2, +h1/2] with h1 the first-row height.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..mesh import SkirtMesh, node_index
from ..model import Model
from .skirt import elem_ids, first_row_height, max_elem_id, max_node_id, mesh_node_ids

FACE_BASE, FACE_TOP, FACE_OUTER, FACE_INNER = "S1", "S2", "S4", "S6"


@dataclass(frozen=True)
class Ring:
    """A ring of hexahedra: node ids/coordinates, element ids/connectivity, the contact face label."""
    node_ids: np.ndarray
    nodes: np.ndarray
    elem_ids: np.ndarray
    conn: np.ndarray          # node ids, C3D8 order
    face: str


def ring(radii, zs, n_theta: int, first_node: int, first_elem: int, face: str, centred: bool = False) -> Ring:
    """Hexahedra between ``radii`` (2 values) and ``zs`` (2 values) at the skirt's azimuths; ``centred``:
    the azimuths shifted by half a spacing and the radii divided by cos(pi / n_theta), so that each skirt
    azimuth meets the middle of a face at the given radius, where the face's normal is exactly radial (a
    node on the corner between two faces gets either face's normal, pi / n_theta off the radial)."""
    theta = 2.0 * np.pi * (np.arange(n_theta) + (0.5 if centred else 0.0)) / n_theta
    if centred:
        radii = [r / np.cos(np.pi / n_theta) for r in radii]
    pts = [(r * np.cos(t), r * np.sin(t), z) for z in zs for r in radii for t in theta]
    nodes = np.array(pts, float)
    ids = first_node + np.arange(nodes.shape[0])
    j = np.arange(n_theta)
    ix = lambda k, i, jj: node_index(k, i, jj, 1, n_theta)  # noqa: E731
    conn = np.stack([ix(0, 0, j), ix(0, 1, j), ix(0, 1, j + 1), ix(0, 0, j + 1),
                     ix(1, 0, j), ix(1, 1, j), ix(1, 1, j + 1), ix(1, 0, j + 1)], axis=1)
    return Ring(node_ids=ids, nodes=nodes, elem_ids=first_elem + j, conn=ids[conn], face=face)


@dataclass(frozen=True)
class Layout:
    """Ids, sets and surfaces of one inp deck of ``model`` (shared by both dialects)."""
    model: Model
    mesh: SkirtMesh
    ref_node: int
    ref_xyz: np.ndarray
    table_master: Ring | None
    stop_master: Ring | None
    next_node: int                   # first free node id after the rings
    next_elem: int                   # first free element id after the rings (first SPRING1)
    base_elems: np.ndarray           # first-row element ids (table slave faces S1; the EBASE stress set)
    stop_elems: np.ndarray           # first-row element ids on the stop side (faces S6 inner / S4 outer)
    stop_face: str
    top_elems: np.ndarray            # top-row element ids (coupling faces S2)
    loads: dict = field(default_factory=dict)

    @property
    def first_row_height(self) -> float:
        z = self.mesh.nodes[:, 2]
        return float(np.min(z[z > 1e-12 * self.model.geometry.height]))

    @property
    def master_node_ids(self) -> np.ndarray:
        parts = [r.node_ids for r in (self.table_master, self.stop_master) if r is not None]
        return np.concatenate(parts) if parts else np.zeros(0, int)

    @property
    def first_gap_elem(self) -> int:
        """First element id after the SPRING1 restraints (one per table slave node)."""
        return self.next_elem + self.mesh.table.nodes.size


def layout(model: Model, mesh: SkirtMesh, *, masters: tuple[str, ...] = ()) -> Layout:
    """Number the deck: skirt, reference node, and the fixed master rings named in ``masters``
    (``"table"``, ``"stop"``; the stop ring only when the model has a stop, its faces centred on the
    skirt's azimuths in every inp dialect, see :func:`ring`: a radial stop normal at every slave)."""
    g = model.geometry
    n_nodes, n_elems = mesh.n_nodes, mesh.hexes.shape[0]
    nt, nr, nz = mesh.n_theta, mesh.n_r, mesh.n_z
    if mesh.node_ids is not None:   # imported mesh: ids after the user's largest
        n_nodes, n_elems = max_node_id(mesh), max_elem_id(mesh)
    ref_node = n_nodes + 1
    next_node, next_elem = ref_node + 1, n_elems + 1
    t = g.thickness
    r_in, r_out = g.radius - t / 2, g.radius + t / 2
    h1 = (float(mesh.nodes[node_index(1, 0, 0, nr, nt), 2]) if mesh.node_ids is None   # first-row height
          else first_row_height(mesh))
    if mesh.node_ids is None and getattr(mesh, "element", "c3d8i") not in ("c3d8i", "c3d8"):
        h1 = g.height / nz            # issue 23: quadratic / tetrahedral skirt (deckbridge/mesh_order.py)
    table_master = stop_master = None
    if "table" in masters:
        table_master = ring([r_in - t, r_out + t], [-t, 0.0], nt, next_node, next_elem, FACE_TOP)
        next_node += table_master.node_ids.size
        next_elem += table_master.elem_ids.size
    if "stop" in masters and mesh.stop is not None:
        inner = model.contact.stop.side == "inner"
        r_stop = float(np.mean(mesh.stop.r - mesh.stop.clearance if inner else mesh.stop.r + mesh.stop.clearance))
        if inner:
            radii, face = [r_stop - t, r_stop], FACE_OUTER
        else:
            radii, face = [r_stop, r_stop + t], FACE_INNER
        stop_master = ring(radii, [-h1 / 2, h1 / 2], nt, next_node, next_elem, face, centred=True)
        next_node += stop_master.node_ids.size
        next_elem += stop_master.elem_ids.size
    # element index e = (k * n_r + i) * n_theta + j  (k along z, i through the wall, j around)
    j = np.arange(nt)
    base = np.concatenate([(0 * nr + i) * nt + j for i in range(nr)]) + 1
    side = model.contact.stop.side
    if side == "outer":
        stop_elems, stop_face = ((nr - 1) * nt + j) + 1, FACE_OUTER
    else:
        stop_elems, stop_face = j + 1, FACE_INNER
    top = np.concatenate([((nz - 1) * nr + i) * nt + j for i in range(nr)]) + 1
    if mesh.base_elems is not None:   # the mesh's own face sets (pads, imported meshes)
        base, top = elem_ids(mesh, mesh.base_elems), elem_ids(mesh, mesh.top_elems)
        stop_elems = elem_ids(mesh, mesh.stop_elems)
    return Layout(model=model, mesh=mesh, ref_node=ref_node, ref_xyz=np.asarray(mesh.ref_point, float),
                  table_master=table_master, stop_master=stop_master, next_node=next_node,
                  next_elem=next_elem, base_elems=base, stop_elems=stop_elems, stop_face=stop_face,
                  top_elems=top, loads=model.load_vectors())


def largest_id(mesh: SkirtMesh) -> int:
    """An upper bound of the largest node or element id an inp-family deck of ``mesh`` writes: the skirt's
    largest id plus the reference node, two master rings (4 n_theta nodes, n_theta elements each), a
    grounded node and a gap per contact row and a SPRING1 per table node."""
    n_contact = mesh.table.nodes.size + (0 if mesh.stop is None else mesh.stop.nodes.size)
    return max(max_node_id(mesh), max_elem_id(mesh)) + 1 + 8 * mesh.n_theta + 2 * n_contact + mesh.table.nodes.size


# --- CalculiX decks ----------------------------------------------------------------------------------
CCX_MASTERS = {"penalty": (), "mortar": ("table",), "penalty_n2f": ("table", "stop")}   # master rings


def ccx_penalty_is_n2f(model: Model) -> bool:
    """The CalculiX penalty deck is node-to-surface LINEAR contact (geometrically linear) unless NLGEOM is
    asked for; with NLGEOM it is GAPUNI gaps (which give wrong reactions without NLGEOM in ccx 2.20)."""
    return not model.analysis.nlgeom


def ccx_layout(model: Model, mesh: SkirtMesh, method: str) -> Layout:
    """Numbering of the CalculiX ``method`` deck ('penalty': GAPUNI gaps only, or table and stop rings for
    node-to-surface contact; 'mortar': table ring)."""
    key = "penalty_n2f" if method == "penalty" and ccx_penalty_is_n2f(model) else method
    return layout(model, mesh, masters=CCX_MASTERS[key])


def ccx_node_slave_areas(mesh: SkirtMesh) -> np.ndarray:
    """Area [m^2] that ccx 2.20 gives each skirt node of a node-based slave surface (``*SURFACE, TYPE=NODE``)
    in node-to-surface contact: a quarter of every free (exterior) face of the skirt at the node, base and
    wall faces alike (measured: the spring force is slope x this area x penetration). Indexed by mesh node.
    """
    faces = mesh.hexes[:, [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]]
    faces = faces.reshape(-1, 4)
    key = np.sort(faces, axis=1)
    _, inv, count = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    free = faces[count[inv.ravel()] == 1]
    x = mesh.nodes[free]                                       # (f, 4, 3)
    area = 0.5 * np.linalg.norm(np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 1]), axis=1)
    out = np.zeros(mesh.n_nodes)
    np.add.at(out, free.ravel(), np.repeat(area / 4.0, 4))
    return out


@dataclass(frozen=True)
class N2fGroup:
    """Slave nodes of one surface whose k_c / A_ccx is equal: one node-based surface, one interaction."""
    name: str                # e.g. TABLE1
    surface: str             # 'table' | 'stop'
    nodes: np.ndarray        # skirt node ids
    slope: float             # K = k_c / A_ccx [Pa/m]
    rows: np.ndarray         # rows of the slave set


def ccx_n2f_groups(mesh: SkirtMesh, rel: float = 1e-9) -> list[N2fGroup]:
    """Node-to-surface penalty groups of the CalculiX penalty deck: table groups first, then stop groups,
    each sorted by slope; within a group the nodes by ascending deck id (ccx prints a node surface's contact
    rows in that order; the structured mesh's slave-set order is the same, an imported mesh's need not be)."""
    a_ccx = ccx_node_slave_areas(mesh)
    out = []
    for ss in (mesh.table, mesh.stop):
        if ss is None:
            continue
        slope = np.asarray(ss.k, float) / a_ccx[ss.nodes]
        order = np.argsort(slope, kind="stable")
        groups: list[list[int]] = []
        for i in order:
            if groups and abs(slope[i] - slope[groups[-1][0]]) <= rel * abs(slope[groups[-1][0]]):
                groups[-1].append(int(i))
            else:
                groups.append([int(i)])
        ids = mesh_node_ids(mesh, ss.nodes)
        for n, g in enumerate(groups, start=1):
            rows = np.array(sorted(g, key=lambda r: ids[r]))   # ascending node id: ccx's order of a node set
            out.append(N2fGroup(name=f"{ss.surface.upper()}{n}", surface=ss.surface, nodes=ids[rows],
                                slope=float(np.mean(slope[rows])), rows=rows))
    return out


@dataclass(frozen=True)
class GapIds:
    """GAPUNI gaps of a CalculiX deck, one per slave node, in deck order. Arrays of equal length.

    ``set_index`` / ``row``: which slave set (of ``sets``) and which node of it each gap is on.
    """
    sets: tuple
    set_index: np.ndarray
    row: np.ndarray
    slave: np.ndarray        # skirt node id
    surface: np.ndarray      # 'table' or 'stop'
    ground: np.ndarray       # grounded node id (placed at the slave node)
    elem: np.ndarray         # GAPUNI element id


def ccx_gaps(model: Model, mesh: SkirtMesh, method: str, lay: Layout | None = None) -> GapIds:
    """Gaps of the CalculiX ``method`` deck: every slave (table, stop) for 'penalty', the stop for 'mortar'.

    Grounded nodes follow the master rings; gap elements follow the SPRING1 restraints.
    """
    lay = lay or ccx_layout(model, mesh, method)
    if method == "penalty" and ccx_penalty_is_n2f(model):
        chosen = ()
    else:
        chosen = (mesh.table, mesh.stop) if method == "penalty" else (mesh.stop,)
    sets = tuple(ss for ss in chosen if ss is not None)
    set_index = np.concatenate([np.full(ss.nodes.size, k) for k, ss in enumerate(sets)] or [np.zeros(0, int)])
    row = np.concatenate([np.arange(ss.nodes.size) for ss in sets] or [np.zeros(0, int)])
    n = row.size
    return GapIds(sets=sets, set_index=set_index.astype(int), row=row.astype(int),
                  slave=np.concatenate([mesh_node_ids(mesh, ss.nodes) for ss in sets] or [np.zeros(0, np.int64)]),
                  surface=np.array([sets[k].surface for k in set_index.astype(int)], dtype=object),
                  ground=lay.next_node + np.arange(n), elem=lay.first_gap_elem + np.arange(n))


def ccx_ground_node_ids(model: Model, mesh: SkirtMesh, method: str) -> dict[tuple[int, str], int]:
    """(slave node id, surface) -> grounded GAPUNI node id, as numbered in the ``method`` deck."""
    gaps = ccx_gaps(model, mesh, method)
    return {(int(s), str(f)): int(g) for s, f, g in zip(gaps.slave, gaps.surface, gaps.ground)}
