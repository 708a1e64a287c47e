"""The layout of an imported skirt measured by its connectivity, not by rounding coordinates.

A mesh file carries its coordinates to a limited precision (Gmsh's azimuths sit 1e-7 deg off nominal,
a Nastran 8-character field keeps 7 digits), so equal radii or azimuths are not equal numbers. The
oriented hexahedra (:func:`deckbridge.importers.general.orient`: local axes (r, theta, z)) say which
nodes share them: on a base face 1-2-3-4 the edges 1-2 and 4-3 run through the wall (one azimuth), the
edges 1-4 and 2-3 along a ring (one radius); every edge of a face 1-2-3-4 or 5-6-7-8 lies in one axial
layer. Counts are the connected components of those edges; radii are means over a ring's nodes [m].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

THROUGH_WALL = ((0, 1), (3, 2))       # face corner pairs of one azimuth
ALONG_RING = ((0, 3), (1, 2))         # face corner pairs of one ring (radius)
IN_LAYER = ((0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4))


def components(n: int, pairs: np.ndarray) -> np.ndarray:
    """Connected-component label (n,) of nodes 0..n-1 joined by ``pairs`` (m, 2)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    p = np.asarray(pairs, np.int64).reshape(-1, 2)
    g = coo_matrix((np.ones(len(p)), (p[:, 0], p[:, 1])), shape=(n, n))
    return connected_components(g, directed=False)[1]


def _groups(nodes_used: np.ndarray, n: int, pairs: np.ndarray) -> list[np.ndarray]:
    lab = components(n, pairs)[nodes_used]
    return [nodes_used[lab == k] for k in np.unique(lab)]


@dataclass(frozen=True)
class Rings:
    """Rings of a face row (base or top), inner first: ``rings`` node index arrays, ``radius`` their mean
    radii [m]; ``n_theta`` through-wall rows (azimuths); ``theta`` (n_nodes,) [deg, 0..360): the azimuth
    of each face node's through-wall row (circular mean of the row's node azimuths), NaN off the faces."""
    rings: list
    radius: np.ndarray
    n_theta: int
    theta: np.ndarray

    @property
    def mid_radius(self) -> float:
        """Mid-wall radius (inner + outer) / 2 [m]."""
        return float((self.radius[0] + self.radius[-1]) / 2)

    @property
    def thickness(self) -> float:
        """Wall thickness outer - inner [m]."""
        return float(self.radius[-1] - self.radius[0])


def rings(nodes: np.ndarray, faces: np.ndarray) -> Rings:
    """Rings and azimuth count of oriented faces (nf, 4) (node indices, corners 1-2 through the wall)."""
    faces = np.asarray(faces, np.int64)
    used = np.unique(faces)
    n = len(nodes)
    ring = _groups(used, n, np.vstack([faces[:, list(p)] for p in ALONG_RING]))
    r = np.hypot(nodes[:, 0], nodes[:, 1])
    rad = np.array([r[g].mean() for g in ring])
    order = np.argsort(rad)
    rows = _groups(used, n, np.vstack([faces[:, list(p)] for p in THROUGH_WALL]))
    theta = np.full(n, np.nan)
    for g in rows:
        a = np.arctan2(nodes[g, 1], nodes[g, 0])
        theta[g] = np.mod(np.degrees(np.arctan2(np.sin(a).mean(), np.cos(a).mean())), 360.0) % 360.0
    return Rings(rings=[ring[i] for i in order], radius=rad[order], n_theta=len(rows), theta=theta)


def axial_layers(n_nodes: int, hexes: np.ndarray) -> int:
    """Number of axial node layers of oriented hexahedra (n_z + 1)."""
    hexes = np.asarray(hexes, np.int64)
    return len(_groups(np.unique(hexes), n_nodes, np.vstack([hexes[:, list(p)] for p in IN_LAYER])))
