"""Face types of the solid elements: shape functions on the face and the face quadrature.

Node order of a face: corners in cyclic order, then the mid-side nodes of edges (1-2), (2-3), ...
Natural coordinates: quadrilaterals (s, t) in [-1, 1]^2 (corners (-1,-1) (1,-1) (1,1) (-1,1));
triangles (s, t) >= 0, s + t <= 1 (corners (0,0) (1,0) (0,1)). The quadratures integrate the face
mass N_a N_b exactly on flat faces with straight edges (quad: 3 x 3 Gauss; triangle: degree 4).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .polynomials import NodalBasis, exponents
from .quadrature import quad_rule, tri_rule


@dataclass(frozen=True, eq=False)
class FaceType:
    """One face type: ``name``, ``n_nodes``, natural node coordinates ``nodes`` (k, 2), the nodal basis
    and the quadrature (``points`` (p, 2), ``weights`` (p,)) used for areas and face matrices."""
    name: str
    nodes: np.ndarray
    basis: NodalBasis
    points: np.ndarray
    weights: np.ndarray

    @property
    def n_nodes(self) -> int:
        return self.nodes.shape[0]

    @property
    def n_corners(self) -> int:
        return 4 if self.name.startswith("quad") else 3

    def shape(self, st) -> np.ndarray:
        """N_a (p, k) at points ``st`` (p, 2)."""
        return self.basis.values(st)

    def dshape(self, st) -> np.ndarray:
        """dN_a/ds, dN_a/dt (p, 2, k)."""
        return self.basis.gradients(st)

    def area_jacobian(self, xyz: np.ndarray) -> np.ndarray:
        """|dx/ds x dx/dt| (nf, p) at the quadrature points of faces with node coordinates ``xyz`` (nf, k, 3)."""
        d = self.dshape(self.points)                                  # (p, 2, k)
        a = np.einsum("pa,fad->fpd", d[:, 0], xyz)
        b = np.einsum("pa,fad->fpd", d[:, 1], xyz)
        return np.linalg.norm(np.cross(a, b), axis=2)


def _face(name, nodes, terms, rule) -> FaceType:
    pts, wts = rule
    nodes = np.asarray(nodes, float)
    e = exponents(terms)[:, :2]
    return FaceType(name, nodes, NodalBasis(nodes, e), pts, wts)


_Q4 = [[-1, -1], [1, -1], [1, 1], [-1, 1]]
_T3 = [[0, 0], [1, 0], [0, 1]]
QUAD4 = _face("quad4", _Q4, "1 x y xy", quad_rule(2))
QUAD8 = _face("quad8", _Q4 + [[0, -1], [1, 0], [0, 1], [-1, 0]], "1 x y x2 xy y2 x2y xy2", quad_rule(3))
TRI3 = _face("tri3", _T3, "1 x y", tri_rule(2))
TRI6 = _face("tri6", _T3 + [[0.5, 0], [0.5, 0.5], [0, 0.5]], "1 x y x2 xy y2", tri_rule(4))
FACE_TYPES = {f.name: f for f in (QUAD4, QUAD8, TRI3, TRI6)}
