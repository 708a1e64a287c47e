"""Stress recovery, generic over the element type: Gauss points, element nodes, nodal averages.

Units: coordinates and displacements [m], stresses [Pa], tension > 0, compression < 0.
Voigt order of every stress array here: (xx, yy, zz, xy, yz, zx), as :func:`kinematics.elasticity_matrix`.

Gauss points are the element's own volume quadrature (:class:`element_base.Element`, ``points``), in its
order; for the 8-node hexahedra the 2 x 2 x 2 rule numbered xi fastest, then eta, then zeta (CalculiX's
order, checked against ccx 2.20 in tests/test_wall_stress.py). ``c3d8i``: the incompatible modes are
recovered by the stiffness's own condensation (:class:`element_hex8.Hex8i`).

Nodes: the element's ``extrapolation`` matrix maps Gauss values to its nodes (for the 8-node hexahedra the
trilinear field through the eight Gauss values, evaluated at the corners: exact for stress fields trilinear
in the natural coordinates). An estimate. Element indices ``elems`` count over the problem's blocks in
order (block 0's elements first); one call handles elements of one block.
"""

from __future__ import annotations

import numpy as np

from .element_hex8 import CORNERS, GAUSS, Hex8i, shape_gradients, shape_values  # noqa: F401 (kept names)
from .elements import element_type
from .errors import ReferenceSolverError
from .kinematics import elasticity_matrix, jacobian, strain_operator
from .problem import ElementBlock


def extrapolation_matrix(element="c3d8i") -> np.ndarray:
    """(n nodes, ng Gauss points): node values = this @ Gauss values (8 x 8 for the hexahedra)."""
    return element_type(element).extrapolation()


def gauss_strain_operator(xyz: np.ndarray, E: float, nu: float, element="c3d8i") -> np.ndarray:
    """Linear map (ne, ng, 6, 3n) from element displacements to Gauss-point strains: strains =
    operator @ ue (:func:`gauss_strain`). Build it once to recover the strains of many states.

    ``xyz`` (ne, n, 3) node coordinates [m]; E [Pa] and nu enter only the incompatible-mode
    condensation of ``c3d8i``.
    """
    return element_type(element).gauss_strain_operator(np.asarray(xyz, float), E, nu)


def gauss_strain(xyz: np.ndarray, ue: np.ndarray, E: float, nu: float, element="c3d8i") -> np.ndarray:
    """Strains (ne, ng, 6) at the Gauss points, engineering shear, Voigt (xx, yy, zz, xy, yz, zx).

    ``xyz`` (ne, n, 3) node coordinates [m], ``ue`` (ne, 3n) element displacements [m] (u_x, u_y, u_z
    per node).
    """
    return np.einsum("egij,ej->egi", gauss_strain_operator(xyz, E, nu, element), np.asarray(ue, float))


def condensed_stiffness(xyz: np.ndarray, E: float, nu: float) -> np.ndarray:
    """K_uu - K_ua K_aa^-1 K_au (ne, 24, 24) [N/m] of c3d8i built from the B matrices of the strain recovery.

    Equal to :func:`elements.hex8_stiffness` ('c3d8i'): the check that the recovered modes are the
    stiffness's own (tests/test_wall_stress.py).
    """
    xyz = np.asarray(xyz, float)
    el = element_type("c3d8i")
    D = elasticity_matrix(E, nu)
    _, det0, inv0 = jacobian(xyz, shape_gradients(np.zeros(3)))
    K = np.zeros((xyz.shape[0], 33, 33))
    for xi in GAUSS:
        det, grad = el.point_gradients(xyz, xi)
        B = np.concatenate([strain_operator(grad), strain_operator(Hex8i._mode_gradients(inv0, det0, det, xi))], 2)
        K += np.einsum("eki,kl,elj->eij", B * det[:, None, None], D, B)
    Kuu, Kua, Kaa = K[:, :24, :24], K[:, :24, 24:], K[:, 24:, 24:]
    return Kuu - Kua @ np.linalg.solve(Kaa, np.swapaxes(Kua, 1, 2))


def problem_blocks(p) -> tuple:
    """``p.blocks`` of a :class:`problem.Problem`, or the one block (``p.element``, ``p.hexes``) of any object
    with ``nodes``, ``hexes``, ``E``, ``nu`` and ``element`` (default 'c3d8i')."""
    blocks = getattr(p, "blocks", None)
    return tuple(blocks) if blocks else (ElementBlock(getattr(p, "element", "c3d8i"), p.hexes),)


def block_of(p, elems=None):
    """(block, local element indices) of global element indices ``elems`` (default: the one block)."""
    blocks = problem_blocks(p)
    if elems is None:
        if len(blocks) != 1:
            raise ReferenceSolverError("elems: a mixed mesh needs the elements of one block")
        return blocks[0], np.arange(blocks[0].cells.shape[0])
    elems = np.asarray(elems, np.int64)
    start = 0
    for b in blocks:
        m = b.cells.shape[0]
        if elems.size and elems.min() >= start and elems.max() < start + m:
            return b, elems - start
        start += m
    raise ReferenceSolverError("elems: the elements are not all of one block (element type)")


def gauss_stress(p, u: np.ndarray, elems: np.ndarray | None = None) -> np.ndarray:
    """Stresses (ne, ng, 6) [Pa] at the Gauss points of elements ``elems`` (global element indices of one
    block, default all of a one-block problem) of problem ``p`` for nodal displacements ``u`` (n, 3) [m].
    Voigt (xx, yy, zz, xy, yz, zx), tension > 0."""
    block, local = block_of(p, elems)
    cells = block.cells[local]
    ue = np.asarray(u, float)[cells].reshape(len(cells), -1)
    eps = gauss_strain(p.nodes[cells], ue, p.E, p.nu, block.element)
    return eps @ elasticity_matrix(p.E, p.nu).T


def extrapolate_to_nodes(gauss: np.ndarray, element="c3d8i") -> np.ndarray:
    """Node values (ne, n, k) from Gauss-point values (ne, ng, k) of elements of type ``element`` (estimate)."""
    return np.einsum("ag,egk->eak", extrapolation_matrix(element), np.asarray(gauss, float))


extrapolate_to_corners = extrapolate_to_nodes


def node_stress(p, u: np.ndarray, elems: np.ndarray | None = None) -> np.ndarray:
    """Stresses (ne, n, 6) [Pa] extrapolated from the Gauss points to the element nodes (element order)."""
    block, _ = block_of(p, elems)
    return extrapolate_to_nodes(gauss_stress(p, u, elems), block.element)


corner_stress = node_stress


def nodal_average(corner: np.ndarray, hexes: np.ndarray, n_nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """Unweighted mean over the elements sharing a node of their element-node values.

    ``corner`` (ne, n, k) belongs to the connectivity ``hexes`` (ne, n) (node indices); returns the
    nodal values (n_nodes, k), NaN at nodes none of these elements touches, and the counts (n_nodes,).
    Several blocks: sum :func:`nodal_sums` of each, then divide.
    """
    total, count = nodal_sums(corner, hexes, n_nodes)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count[:, None] > 0, total / count[:, None], np.nan), count


def nodal_sums(values: np.ndarray, cells: np.ndarray, n_nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """Sums (n_nodes, k) of element-node ``values`` (ne, n, k) per node and the counts (n_nodes,)."""
    values = np.asarray(values, float)
    cells = np.asarray(cells, np.int64)
    k = values.shape[2]
    total = np.zeros((n_nodes, k))
    count = np.zeros(n_nodes)
    np.add.at(total, cells.ravel(), values.reshape(-1, k))
    np.add.at(count, cells.ravel(), 1.0)
    return total, count
