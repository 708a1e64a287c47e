"""Mesh data shared by every mesh producer (structured :mod:`deckbridge.mesh`, imported
:mod:`deckbridge.importers.general`): quad nodal areas, hexahedron volumes, slave sets, contact rows,
the mesh object. Moved out of mesh.py unchanged (issue 15)."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .azimuth import azimuth_deg

_G = 1.0 / np.sqrt(3.0)
_GAUSS2 = np.array([-_G, _G])


def quad_nodal_areas(xyz: np.ndarray) -> np.ndarray:
    """Consistent nodal shares of bilinear quad areas: int N_a dA, shape (nf, 4) [m^2].

    ``xyz`` has shape (nf, 4, 3), corners in cyclic order.
    """
    out = np.zeros(xyz.shape[:2])
    for s in _GAUSS2:
        for t in _GAUSS2:
            n = 0.25 * np.array([(1 - s) * (1 - t), (1 + s) * (1 - t), (1 + s) * (1 + t), (1 - s) * (1 + t)])
            dns = 0.25 * np.array([-(1 - t), (1 - t), (1 + t), -(1 + t)])
            dnt = 0.25 * np.array([-(1 - s), -(1 + s), (1 + s), (1 - s)])
            a = np.einsum("a,fad->fd", dns, xyz)
            b = np.einsum("a,fad->fd", dnt, xyz)
            jac = np.linalg.norm(np.cross(a, b), axis=1)
            out += jac[:, None] * n[None, :]
    return out


def base_wall_areas(nodes: np.ndarray, bottom_hexes: np.ndarray, wall_nodes: np.ndarray) -> np.ndarray:
    """Base area [m^2] each azimuth of the wall stands on: the nodal shares (:func:`quad_nodal_areas`) of
    the base faces (nodes 1-4) of every bottom-row hexahedron ``bottom_hexes`` (ne, 8), pad or not, summed
    over each azimuth's through-wall base nodes ``wall_nodes`` (na, nw) (``deckbridge.base_wall.BaseWall.nodes``).
    Sums to the whole base section, so that Sum sigma_zz x area is the wall's axial resultant there.
    Cells of other types (``mesh.element``, issue 23: 4-, 10-, 15-, 20-node): the positive (HRZ) nodal areas
    of their faces on the lowest plane (:func:`deckbridge.face_areas.base_face_areas`)."""
    cells = np.asarray(bottom_hexes, np.int64)
    mixed = bool((cells < 0).any())          # a mixed mesh's padded cells (SkirtMesh.blocks)
    if cells.shape[1] != 8 or mixed:
        from .face_areas import base_face_areas
        area = base_face_areas(nodes, cells)
        wall_nodes = np.asarray(wall_nodes, np.int64)
        if cells.shape[1] == 4 or (mixed and cells.shape[1] == 8):   # no mid-side nodes: every base node in a row
            return area[wall_nodes].sum(axis=1)
        return nearest_row_sums(nodes, area, wall_nodes)   # mid-side nodes' areas to the corner azimuths
    faces = cells[:, :4]
    area = np.zeros(nodes.shape[0])
    np.add.at(area, faces.ravel(), quad_nodal_areas(nodes[faces]).ravel())
    return area[np.asarray(wall_nodes, np.int64)].sum(axis=1)


def nearest_row_sums(nodes: np.ndarray, area: np.ndarray, wall_nodes: np.ndarray) -> np.ndarray:
    """Nodal values ``area`` (n,; areas [m^2], or any signed nodal quantity such as forces [N]) summed per
    through-wall row ``wall_nodes`` (na, nw; rows sorted by azimuth about z): each node's value to the row of
    nearest azimuth, half to each of two equally near rows (a mid-side node half way between two corner
    azimuths). Sums to ``area``'s total."""
    from .azimuth import azimuth_deg
    row_th = azimuth_deg(*nodes[wall_nodes].mean(axis=1)[:, :2].T)
    have = np.flatnonzero(area != 0)
    th = azimuth_deg(nodes[have, 0], nodes[have, 1])
    d = (th[:, None] - row_th[None, :] + 180.0) % 360.0 - 180.0
    near = np.abs(d)
    first = near.argmin(axis=1)
    near2 = near.copy()
    near2[np.arange(have.size), first] = np.inf
    second = near2.argmin(axis=1)
    tie = np.isclose(near2[np.arange(have.size), second], near[np.arange(have.size), first], rtol=1e-6, atol=1e-9)
    share = np.where(tie, 0.5, 1.0) * area[have]
    out = np.zeros(wall_nodes.shape[0])
    np.add.at(out, first, share)
    np.add.at(out, second[tie], share[tie])
    return out


def hex_volumes(xyz: np.ndarray) -> np.ndarray:
    """Volumes of trilinear hexahedra, ``xyz`` shape (ne, 8, 3) in C3D8 order [m^3]."""
    sg = np.array([-1, 1, 1, -1, -1, 1, 1, -1], float)
    tg = np.array([-1, -1, 1, 1, -1, -1, 1, 1], float)
    ug = np.array([-1, -1, -1, -1, 1, 1, 1, 1], float)
    vol = np.zeros(xyz.shape[0])
    for s in _GAUSS2:
        for t in _GAUSS2:
            for u in _GAUSS2:
                d = np.stack([sg * (1 + tg * t) * (1 + ug * u),
                              tg * (1 + sg * s) * (1 + ug * u),
                              ug * (1 + sg * s) * (1 + tg * t)]) / 8.0  # (3, 8)
                jac = np.einsum("ca,ead->ecd", d, xyz)
                vol += np.linalg.det(jac)
    return vol


@dataclass(frozen=True)
class SlaveSet:
    """Slave nodes of one master surface.

    ``normal`` is the unit outward normal of the master (pointing into the skirt) at each node;
    a gap opens when the node moves along it. ``area`` is the tributary contact area [m^2],
    ``k`` the closed penalty stiffness per node [N/m] (k_c = alpha A^2 K / V unless explicit).
    """
    surface: str
    nodes: np.ndarray
    theta_deg: np.ndarray
    r: np.ndarray
    z: np.ndarray
    area: np.ndarray
    k: np.ndarray
    normal: np.ndarray
    clearance: np.ndarray


@dataclass(frozen=True)
class ContactRows:
    """Every contact row of the mesh in solver order: the table's slave nodes, then the stop's (if any).

    Row arrays: ``nodes`` (0-based), ``normals`` (n, 3), ``area`` [m^2], ``k`` [N/m], ``clearance`` [m],
    ``surface`` ('table' | 'stop'), ``theta`` [deg, 0..360), ``z`` [m], ``r`` [m].
    """
    nodes: np.ndarray
    normals: np.ndarray
    area: np.ndarray
    k: np.ndarray
    clearance: np.ndarray
    surface: np.ndarray
    theta: np.ndarray
    z: np.ndarray
    r: np.ndarray

    @classmethod
    def of(cls, sets: list[SlaveSet]) -> "ContactRows":
        cat = lambda name: np.concatenate([getattr(s, name) for s in sets])  # noqa: E731
        return cls(nodes=cat("nodes"), normals=cat("normal"), area=cat("area"), k=cat("k"),
                   clearance=cat("clearance"),
                   surface=np.concatenate([[s.surface] * s.nodes.size for s in sets]),
                   theta=cat("theta_deg"), z=cat("z"), r=cat("r"))

    @property
    def size(self) -> int:
        return int(self.nodes.size)


@dataclass(frozen=True)
class SkirtMesh:
    """The skirt's hexahedral mesh with the contact and load-introduction data derived from the model."""
    nodes: np.ndarray          # (n, 3) [m]
    hexes: np.ndarray          # (m, k) 0-based node indices of the cells of ``element`` (CalculiX order)
    table: SlaveSet            # base ring on the table plane z = 0
    stop: SlaveSet | None      # base-ring nodes on the stop face, None when contact.stop.side = none
    k_tangent: np.ndarray      # circumferential restraint per table slave node [N/m]
    k_open_ratio: float        # open-gap stiffness / closed stiffness
    top_nodes: np.ndarray      # nodes of the loaded top face
    top_weights: np.ndarray    # their distributing (RBE3) weights [m^2]: tributary areas; 8-/6-node: int N dA
    ref_point: np.ndarray      # reference node position, top centre [m]
    n_theta: int
    n_r: int
    n_z: int
    base_elems: np.ndarray | None = None   # hexahedra whose face 1-2-3-4 (S1) is a table slave face
    top_elems: np.ndarray | None = None    # hexahedra whose face 5-6-7-8 (S2) is loaded
    stop_elems: np.ndarray | None = None   # first-row hexahedra on the stop side (S6 inner / S4 outer)
    node_ids: np.ndarray | None = None     # user node id of every node (None: index + 1)
    elem_ids: np.ndarray | None = None     # user element id of every hexahedron (None: index + 1)
    element: str = "c3d8i"                 # solver name of the cells' type (issue 23, mesh_order.py); mixed: 'a+b'
    table_faces: tuple | None = None       # quadratic/tet types: the table's faces [(FaceType, conn), ...]
    blocks: tuple = ()                     # a mixed mesh: ((solver name, cells (m_b, k_b)), ...), cells numbered
                                           # block by block; ``hexes`` then holds them padded with -1

    @property
    def cell_blocks(self) -> tuple:
        """((solver name, cells), ...) in element order: a mixed mesh's ``blocks``, else ((element, hexes),)."""
        return self.blocks or ((self.element, self.hexes),)

    @property
    def quadratic_faces(self) -> bool:
        """True when a contact face has mid-side nodes (8- or 6-node faces: nodal contact is not exact)."""
        return self.table_faces is not None and any(f.n_nodes > f.n_corners for f, _ in self.table_faces)

    @property
    def n_nodes(self) -> int:
        return self.nodes.shape[0]

    @property
    def slave_sets(self) -> list[SlaveSet]:
        """The slave sets in contact-row order: table, then stop when there is one."""
        return [self.table] + ([self.stop] if self.stop is not None else [])

    @cached_property
    def contact_rows(self) -> ContactRows:
        """The one contact-row table (table rows, then stop rows) that the solver and the readers use."""
        return ContactRows.of(self.slave_sets)

    @cached_property
    def theta_deg(self) -> np.ndarray:
        """Azimuth of every node in [0, 360) degrees."""
        return azimuth_deg(self.nodes[:, 0], self.nodes[:, 1])


def element_key(model, mesh) -> tuple[str, str]:
    """(key, value) that name the skirt's element type in a one-line message: ``('mesh.element', 'hex20')`` on
    the parametric skirt; on an imported mesh (``mesh.file`` set) the file with the CalculiX names of the solids
    it was read as (``('mesh.file', 'skirt.inp (C3D20R)')``, a mixed mesh ``'skirt.inp (C3D20 + C3D15)'``):
    ``mesh.element`` is the parametric skirt's key and keeps its default ``hex8i`` there."""
    from pathlib import Path
    file = getattr(model.mesh, "file", None)
    if file is None:
        return "mesh.element", str(model.mesh.element)
    names = " + ".join(n.upper() for n in str(getattr(mesh, "element", "c3d8")).split("+"))
    return "mesh.file", f"{Path(file).name} ({names})"


def _slave_set(surface, nodes, slave_nodes, faces, a_nodes, k_share, k_explicit, normal, clearance):
    n = nodes.shape[0]
    area = np.zeros(n)
    kk = np.zeros(n)
    np.add.at(area, faces.ravel(), a_nodes.ravel())
    np.add.at(kk, faces.ravel(), k_share.ravel())
    a = area[slave_nodes]
    kc = kk[slave_nodes] if k_explicit is None else np.full(slave_nodes.size, float(k_explicit))
    xyz = nodes[slave_nodes]
    th = azimuth_deg(xyz[:, 0], xyz[:, 1])
    return SlaveSet(surface=surface, nodes=slave_nodes, theta_deg=th, r=np.hypot(xyz[:, 0], xyz[:, 1]),
                    z=xyz[:, 2], area=a, k=kc, normal=np.asarray(normal, float),
                    clearance=np.asarray(clearance, float))
