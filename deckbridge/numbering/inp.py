"""Ids of the inp-family decks (Abaqus/Standard and CalculiX).

Skirt node id = mesh index + 1, skirt element id = hex index + 1 (:mod:`.skirt`). Then, in order:
the reference node (top centre), the nodes of the fixed master rings (table, then stop), the
grounded GAPUNI nodes (CalculiX); elements: the master rings, one SPRING1 per table slave node
(circumferential restraint), the GAPUNI gaps (CalculiX). What only the CalculiX decks number (their master
rings per deck, node-to-surface groups, GAPUNI gaps) is :mod:`deckbridge.dialects.calculix.numbering`. Hexahedron faces use the C3D8 labels
shared by both codes: S1 = 1-2-3-4 (base, outward -z), S2 = 5-8-7-6 (top, +z), S4 = 2-6-7-3 (outer
wall, +r), S6 = 4-8-5-1 (inner wall, -r).

Master rings: the table is the top face (S2, normal +z) of a ring below z = 0 that overhangs both
wall faces by one wall thickness and uses the skirt's azimuths (on quadratic skirts, whose faces follow the true
cylinder, its outer edges' mid-points are one wall thickness outside); the stop is the wall face of a ring
at the stop radius, facing the skirt (S4 = +r for an inner stop, S6 = -r for an outer stop),
spanning z in [-h1/2, +h1/2] with h1 the first-row height.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..mesh import SkirtMesh, node_index
from ..model import Model
from .skirt import elem_ids, first_row_height, max_elem_id, max_node_id

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
        r_top = r_out + t
        if getattr(mesh, "quadratic_faces", False):
            # mid-side nodes on the true cylinder reach r_out between azimuths, where the ring's straight outer
            # edge is at r cos(pi / n_theta) (16 azimuths: 1.53 -> 1.5006 m < r_out 1.51: a strip of the skirt's
            # base faces saw no master, measured in ccx); its corners pushed out so the chords pass r_out + t
            r_top = r_top / np.cos(np.pi / nt)
        table_master = ring([r_in - t, r_top], [-t, 0.0], nt, next_node, next_elem, FACE_TOP)
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
