"""Second-order solids and the tetrahedra: Hex20 (C3D20, 3x3x3), Hex20R (C3D20R, 2x2x2), Tet10 (C3D10),
Wedge15 (C3D15), Tet4 (C3D4), Wedge6 (C3D6). Shape functions from their monomial spaces (:mod:`polynomials`).

Node orders are CalculiX's (and VTK's for these types):
- Hex20: corners as Hex8, then mid-sides of edges 1-2, 2-3, 3-4, 4-1, 5-6, 6-7, 7-8, 8-5, 1-5, 2-6, 3-7, 4-8;
  serendipity space (complete quadratic + x2y, x2z, y2x, y2z, z2x, z2y, xyz, x2yz, xy2z, xyz2).
- Tet10 / Tet4: corners (0,0,0) (1,0,0) (0,1,0) (0,0,1), then mid-sides 1-2, 2-3, 3-1, 1-4, 2-4, 3-4.
- Wedge15: triangle (xi, eta) x zeta in [-1, 1]; corners 1-3 at zeta = -1, 4-6 at +1; mid-sides 1-2, 2-3,
  3-1, 4-5, 5-6, 6-4, then 1-4, 2-5, 3-6; space P2(triangle) x P1(zeta) + P1(triangle) zeta^2.
Quadratures: exact for the stiffness of straight-edged affine elements (the patch tests), and for
B^T sigma with sigma linear (the tilt patch test): Hex20 3x3x3, Hex20R 2x2x2 (reduced: hourglass modes
possible in one-element rows), Tet10 4 points, Tet4 1 point, Wedge15 6-point triangle x 3 in zeta, Wedge6
3-point triangle x 2 in zeta.
Tet4 is constant strain: accepted, ``bending = False`` (it fails the bending patch test; mesh finely).
"""

from __future__ import annotations

import numpy as np

from .element_base import Element
from .element_faces import QUAD4, QUAD8, TRI3, TRI6
from .element_hex8 import CORNERS
from .polynomials import NodalBasis, exponents
from .quadrature import hex_rule, tet_rule, wedge_rule

_HEX_EDGES = ((0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7))
_TET_EDGES = ((0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3))
_WEDGE_EDGES = ((0, 1), (1, 2), (2, 0), (3, 4), (4, 5), (5, 3), (0, 3), (1, 4), (2, 5))


def _with_midsides(corners, edges) -> np.ndarray:
    c = np.asarray(corners, float)
    return np.vstack([c, [(c[a] + c[b]) / 2 for a, b in edges]])


HEX20_NODES = _with_midsides(CORNERS, _HEX_EDGES)
TET_CORNERS = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
WEDGE_CORNERS = np.array([[0, 0, -1], [1, 0, -1], [0, 1, -1], [0, 0, 1], [1, 0, 1], [0, 1, 1]], float)


class Hex20(Element):
    """20-node serendipity hexahedron, full 3 x 3 x 3 integration (C3D20)."""
    name, aliases, meshio_type = "c3d20", ("hex20",), "hexahedron20"
    nodes = HEX20_NODES
    basis = NodalBasis(HEX20_NODES, exponents("1 x y z x2 y2 z2 xy yz xz xyz x2y x2z xy2 y2z xz2 yz2 x2yz xy2z xyz2"))
    points, weights = hex_rule(3)
    faces = ((0, 1, 2, 3, 8, 9, 10, 11), (4, 7, 6, 5, 15, 14, 13, 12), (0, 4, 5, 1, 16, 12, 17, 8),
             (1, 5, 6, 2, 17, 13, 18, 9), (2, 6, 7, 3, 18, 14, 19, 10), (3, 7, 4, 0, 19, 15, 16, 11))
    face_types = (QUAD8,) * 6
    opposite_faces = ((0, 1), (2, 4), (3, 5))    # zeta, eta, xi
    recovery = " ".join(f"x{a}y{b}z{c}" for a in range(3) for b in range(3) for c in range(3))
    centre = np.zeros(3)


class Hex20R(Hex20):
    """20-node hexahedron, reduced 2 x 2 x 2 integration (C3D20R): zero-energy modes possible in
    one-element rows (count them with the stiffness's null space)."""
    name, aliases = "c3d20r", ("hex20r",)
    points, weights = hex_rule(2)
    hourglass = True              # :func:`reference_solver.hourglass.hourglass_elements` finds the elements at risk
    recovery = "1 x y z xy yz xz xyz"


class Tet10(Element):
    """10-node tetrahedron, 4-point rule (C3D10)."""
    name, aliases, meshio_type = "c3d10", ("tet10",), "tetra10"
    nodes = _with_midsides(TET_CORNERS, _TET_EDGES)
    basis = NodalBasis(nodes, exponents("1 x y z x2 y2 z2 xy yz xz"))
    points, weights = tet_rule(2)
    faces = ((0, 1, 2, 4, 5, 6), (0, 3, 1, 7, 8, 4), (1, 3, 2, 8, 9, 5), (2, 3, 0, 9, 7, 6))
    face_types = (TRI6,) * 4
    recovery = "1 x y z"


class Tet4(Element):
    """4-node constant-strain tetrahedron (C3D4). Fails the bending patch test: ``bending = False``."""
    name, aliases, meshio_type = "c3d4", ("tet4",), "tetra"
    nodes = TET_CORNERS
    basis = NodalBasis(TET_CORNERS, exponents("1 x y z"))
    points, weights = tet_rule(1)
    faces = ((0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0))
    face_types = (TRI3,) * 4
    recovery = "1"
    bending = False


class Wedge6(Element):
    """6-node wedge (C3D6, issue 23: the prisms of a mixed first-order mesh beside hexahedra), 3-point
    triangle rule x 2 Gauss points in zeta (exact for its stiffness on affine wedges)."""
    name, aliases, meshio_type = "c3d6", ("wedge6",), "wedge"
    nodes = WEDGE_CORNERS
    basis = NodalBasis(WEDGE_CORNERS, exponents("1 x y z xz yz"))
    points, weights = wedge_rule(2, 2)
    faces = ((0, 1, 2), (3, 4, 5), (0, 1, 4, 3), (1, 2, 5, 4), (2, 0, 3, 5))
    face_types = (TRI3, TRI3, QUAD4, QUAD4, QUAD4)
    recovery = "1 x y z xz yz"


class Wedge15(Element):
    """15-node wedge (C3D15), 6-point triangle rule x 3 Gauss points in zeta."""
    name, aliases, meshio_type = "c3d15", ("wedge15",), "wedge15"
    nodes = _with_midsides(WEDGE_CORNERS, _WEDGE_EDGES)
    basis = NodalBasis(nodes, exponents("1 x y x2 xy y2 z xz yz x2z xyz y2z z2 xz2 yz2"))
    points, weights = wedge_rule(4, 3)
    faces = ((0, 1, 2, 6, 7, 8), (3, 4, 5, 9, 10, 11), (0, 1, 4, 3, 6, 13, 9, 12),
             (1, 2, 5, 4, 7, 14, 10, 13), (2, 0, 3, 5, 8, 12, 11, 14))
    face_types = (TRI6, TRI6, QUAD8, QUAD8, QUAD8)
    recovery = "1 x y z xz yz"
