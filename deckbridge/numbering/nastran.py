"""Ids of the Nastran-family decks (penalty ``.bdf``, MYSTRAN linear ``.bdf``).

``node_offset`` and ``elem_offset`` are powers of ten above the mesh's counts:

- skirt grids 1..n, CHEXA 1..m (mesh index + 1, :mod:`.skirt`);
- reference node (top centre) = ``node_offset``; grounded gap nodes ``node_offset + 1 + i``;
- contact element i (CGAP in the penalty deck, CELAS2 in the linear deck), table slaves first,
  then stop slaves: ``elem_offset + 1 + i``; its PGAP id equals its element id;
- circumferential CELAS2 of table node i: ``2 * elem_offset + 1 + i``;
- RBE3 / RBE2: ``3 * elem_offset + 1``;
- case-control ``SET`` :data:`SET_BOTTOM_ROW` = the bottom-row CHEXAs (:func:`bottom_row_elements`).

Gap convention (REFERENCE.md section 4): GA is the skirt node, GB a grounded node placed at a
distance ``h`` (height of the first element row) along the master normal *away* from the skirt, so
the gap axis GA->GB is ``-normal``: the gap closes when (uA - uB).x > U0, i.e. when the skirt node
moves into the master; a positive axial force is compression.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..mesh import SkirtMesh
from .skirt import bottom_row_index, elem_ids, first_row_height, max_elem_id, max_node_id, mesh_node_ids


SET_BOTTOM_ROW = 1   # case-control SET of the bottom-row CHEXAs (element stress output)


def bottom_row_elements(mesh: SkirtMesh) -> np.ndarray:
    """CHEXA ids of the first element row (z in [0, h]): the first n_theta * n_r elements of the
    structured mesh (:mod:`deckbridge.mesh`), the user's ids of an imported one (:mod:`.skirt`)."""
    return elem_ids(mesh, bottom_row_index(mesh))


def _offset(*counts: int) -> int:
    """Smallest power of ten strictly above every count."""
    return 10 ** len(str(max(counts)))


@dataclass(frozen=True)
class Numbering:
    node_offset: int
    elem_offset: int

    @property
    def ref_node(self) -> int:
        return self.node_offset

    @property
    def spring_base(self) -> int:
        """Id of the first circumferential CELAS2."""
        return 2 * self.elem_offset + 1

    @property
    def rigid_eid(self) -> int:
        return 3 * self.elem_offset + 1


@dataclass(frozen=True)
class GapLayout:
    """One contact element per slave node (table first, then stop). Arrays of equal length.

    ``axis`` is the unit gap axis GA->GB (= -master normal); ``k`` the closed stiffness KA [N/m],
    ``u0`` the clearance [m], ``area`` the slave node's tributary area [m^2], ``k_t`` the tangent
    stiffness KT [N/m] (the circumferential restraint of that base node; 0 on a stop node off the pads).
    """
    eid: np.ndarray
    node: np.ndarray
    ground: np.ndarray
    surface: np.ndarray
    axis: np.ndarray
    ground_xyz: np.ndarray
    k: np.ndarray
    k_t: np.ndarray
    u0: np.ndarray
    area: np.ndarray
    theta_deg: np.ndarray
    r: np.ndarray
    z: np.ndarray

    def __len__(self) -> int:
        return self.eid.size


def numbering(mesh: SkirtMesh) -> Numbering:
    n_stop = 0 if mesh.stop is None else mesh.stop.nodes.size
    n_contact = mesh.table.nodes.size + n_stop
    return Numbering(node_offset=_offset(max_node_id(mesh) + n_contact),
                     elem_offset=_offset(max_elem_id(mesh), n_contact))


def largest_id(mesh: SkirtMesh) -> int:
    """The largest grid or element id a Nastran-family deck of ``mesh`` writes (the RBE, gap nodes, skirt)."""
    nb = numbering(mesh)
    n_contact = mesh.table.nodes.size + (0 if mesh.stop is None else mesh.stop.nodes.size)
    return max(nb.node_offset + n_contact, nb.rigid_eid + 1, max_node_id(mesh), max_elem_id(mesh))


def ground_distance(mesh: SkirtMesh) -> float:
    """Distance of a grounded gap node from its slave node: height of the first element row [m]."""
    if mesh.node_ids is not None:   # imported mesh
        return first_row_height(mesh)
    n_ring = (mesh.n_r + 1) * mesh.n_theta
    return float(mesh.nodes[n_ring * 1, 2] - mesh.nodes[0, 2]) if mesh.n_nodes > n_ring else 1.0


def clean_xyz(xyz: np.ndarray) -> np.ndarray:
    """Coordinates with round-off residues (|x| < 1e-13 of the model size) set to 0."""
    out = np.array(xyz, float)
    out[np.abs(out) < 1e-13 * max(float(np.abs(out).max()), 1e-300)] = 0.0
    return out


def gap_layout(mesh: SkirtMesh) -> GapLayout:
    """Contact elements of ``mesh`` with their ids, grounded nodes and properties."""
    num = numbering(mesh)
    sets = mesh.slave_sets
    kt_of_node = dict(zip(mesh.table.nodes.tolist(), mesh.k_tangent.tolist()))
    d = ground_distance(mesh)
    index = []
    cols: dict[str, list] = {k: [] for k in ("node", "surface", "axis", "k", "k_t", "u0", "area",
                                              "theta_deg", "r", "z")}
    for s in sets:
        n = s.nodes.size
        cols["node"].append(mesh_node_ids(mesh, s.nodes))
        index.append(s.nodes)
        cols["surface"].append(np.full(n, s.surface, dtype=object))
        cols["axis"].append(-np.asarray(s.normal, float))
        cols["k"].append(np.asarray(s.k, float))
        # a stop node off the pads (contact.pads) is no table node: no tangential stiffness there
        cols["k_t"].append(np.array([kt_of_node.get(int(i), 0.0) for i in s.nodes], float))
        cols["u0"].append(np.asarray(s.clearance, float))
        for key in ("area", "theta_deg", "r", "z"):
            cols[key].append(np.asarray(getattr(s, key), float))
    c = {k: np.concatenate(v) for k, v in cols.items()}
    n = c["node"].size
    ground_xyz = clean_xyz(mesh.nodes[np.concatenate(index)] + d * c["axis"])
    return GapLayout(eid=num.elem_offset + 1 + np.arange(n), ground=num.node_offset + 1 + np.arange(n),
                     ground_xyz=ground_xyz, **c)
