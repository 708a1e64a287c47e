"""The element types of the solver, by name: one registry, and the hexahedron-era entry points.

Each type is an :class:`element_base.Element` (shape functions, quadrature, face rule, stress
recovery; see that module): ``Hex8`` ('c3d8'), ``Hex8i`` ('c3d8i', incompatible modes, the default)
in :mod:`element_hex8`; ``Hex20`` ('c3d20'), ``Hex20R`` ('c3d20r'), ``Tet10`` ('c3d10'), ``Wedge15``
('c3d15'), ``Tet4`` ('c3d4'), ``Wedge6`` ('c3d6') in :mod:`element_quadratic`. :func:`element_type` resolves a
name or an alias ('hex8i', 'hex20r', 'tet10', ...) or passes an element object through.

Kept names (callers import them from here): :func:`elasticity_matrix`, :func:`strain_operator`,
:func:`von_mises` (:mod:`kinematics`), :func:`shape_gradients` (trilinear hexahedron),
:func:`hex8_stiffness_pairs`, :func:`hex8_stiffness`, :func:`centroid_strain`, ``ELEMENTS``.
Units: coordinates [m], E [Pa] -> stiffness [N/m]; stresses [Pa].
"""

from __future__ import annotations

import numpy as np

from .element_base import Element
from .element_hex8 import Hex8, Hex8i, shape_gradients, shape_values
from .element_quadratic import Hex20, Hex20R, Tet4, Tet10, Wedge6, Wedge15
from .errors import ReferenceSolverError
from .kinematics import as_matrix, elasticity_matrix, isotropic_pairs, jacobian, lame, strain_operator, von_mises

ELEMENT_TYPES: dict[str, Element] = {e.name: e for e in (Hex8i(), Hex8(), Hex20(), Hex20R(), Tet10(), Wedge15(), Tet4(),
                                                         Wedge6())}
ELEMENTS = tuple(ELEMENT_TYPES)                # solver names, 'c3d8i' first (the default)
_BY_ALIAS = {a: e for e in ELEMENT_TYPES.values() for a in e.aliases}

# the private names of the hexahedron-only module, kept for callers
_jacobian, _lame, _isotropic_pairs, _as_matrix = jacobian, lame, isotropic_pairs, as_matrix

__all__ = ["ELEMENTS", "ELEMENT_TYPES", "Element", "element_type", "Hex8", "Hex8i", "Hex20", "Hex20R", "Tet10",
           "Wedge15", "Tet4", "Wedge6", "elasticity_matrix", "strain_operator", "von_mises", "shape_gradients",
           "shape_values", "hex8_stiffness_pairs", "hex8_stiffness", "centroid_strain", "element_stiffness"]


def element_type(element) -> Element:
    """The element object of a name ('c3d20r'), an alias ('hex20r') or an element object."""
    if isinstance(element, Element):
        return element
    key = str(element).lower()
    found = ELEMENT_TYPES.get(key) or _BY_ALIAS.get(key)
    if found is None:
        names = ", ".join(f"{n} ({'/'.join(e.aliases)})" for n, e in ELEMENT_TYPES.items())
        raise ReferenceSolverError(f"element = {element!r}: must be one of {names}")
    return found


def hex8_stiffness_pairs(xyz: np.ndarray, E: float, nu: float, element="c3d8i") -> np.ndarray:
    """Element stiffness as node-pair blocks (ne, 3, 3, n, n) [N/m] of elements ``xyz`` (ne, n, 3) of
    type ``element`` (any registered type; the name is historical)."""
    return element_type(element).stiffness_pairs(xyz, E, nu)


def element_stiffness(xyz: np.ndarray, E: float, nu: float, element="c3d8i") -> np.ndarray:
    """Element stiffness matrices (ne, 3n, 3n) [N/m], dofs (u_x, u_y, u_z) node by node."""
    return as_matrix(hex8_stiffness_pairs(xyz, E, nu, element))


hex8_stiffness = element_stiffness


def centroid_strain(xyz: np.ndarray, ue: np.ndarray, element="c3d8i") -> np.ndarray:
    """Strain (ne, 6) at element centres from element displacements ``ue`` (ne, 3n).

    For c3d8i the incompatible modes have zero gradient at the centre, so B_u alone is exact there.
    """
    B = element_type(element).centre_strain_operator(np.asarray(xyz, float))
    return np.einsum("eij,ej->ei", B, np.asarray(ue, float))
