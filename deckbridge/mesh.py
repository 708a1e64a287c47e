"""Hexahedral mesh of the skirt wall and its contact data (slave nodes, areas, penalties).

Node numbering: index = (k * (n_r + 1) + i) * n_theta + j with k along z (0 = base),
i through the wall (0 = inner face), j around (theta_j = 360 j / n_theta, counter-clockwise from +x).
Deck node ids are index + 1. Hexahedra follow the C3D8/CHEXA order: (r, theta, z) is right-handed,
so nodes 1-4 (base face, counter-clockwise seen from +z) then 5-8 above them.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .azimuth import azimuth_deg  # noqa: F401 (re-exported: mesh.azimuth_deg)
from .model import Model
from .supports import pad_face_mask

_G = 1.0 / np.sqrt(3.0)
_GAUSS2 = np.array([-_G, _G])


def node_index(k: np.ndarray | int, i: np.ndarray | int, j: np.ndarray | int, n_r: int, n_theta: int):
    """Index of the node at height level k, wall level i, azimuth step j (j wraps)."""
    return (np.asarray(k) * (n_r + 1) + np.asarray(i)) * n_theta + np.mod(j, n_theta)


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
    hexes: np.ndarray          # (m, 8) 0-based node indices
    table: SlaveSet            # base ring on the table plane z = 0
    stop: SlaveSet | None      # base-ring nodes on the stop face, None when contact.stop.side = none
    k_tangent: np.ndarray      # circumferential restraint per table slave node [N/m]
    k_open_ratio: float        # open-gap stiffness / closed stiffness
    top_nodes: np.ndarray      # nodes of the loaded top face
    top_weights: np.ndarray    # their tributary areas on the top face (RBE3 / distributing weights) [m^2]
    ref_point: np.ndarray      # reference node position, top centre [m]
    n_theta: int
    n_r: int
    n_z: int
    base_elems: np.ndarray | None = None   # hexahedra whose face 1-2-3-4 (S1) is a table slave face
    top_elems: np.ndarray | None = None    # hexahedra whose face 5-6-7-8 (S2) is loaded
    stop_elems: np.ndarray | None = None   # first-row hexahedra on the stop side (S6 inner / S4 outer)
    node_ids: np.ndarray | None = None     # user node id of every node (None: index + 1)
    elem_ids: np.ndarray | None = None     # user element id of every hexahedron (None: index + 1)

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


def build_mesh(model: Model) -> SkirtMesh:
    """Mesh the skirt of ``model`` and derive slave sets, penalties and load-introduction weights."""
    if model.mesh.file is not None:   # the analyst's own mesh (deckbridge/importers)
        from .importers.general import imported_mesh
        return imported_mesh(model)
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
    on_pad = pad_face_mask(model.contact.pads, nodes[hexes[base][:, :4]], 360.0 / nt)
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
                from .model import ModelError
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
                     base_elems=base_elems, top_elems=np.flatnonzero(top), stop_elems=stop_elems)


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
