"""Stress recovery in 8-node hexahedra: Gauss points, corners, nodal averages, base-wall sigma_zz.

Units: coordinates and displacements [m], stresses [Pa], tension > 0, compression < 0.
Voigt order of every stress array here: (xx, yy, zz, xy, yz, zx), as :func:`elements.elasticity_matrix`
(CalculiX prints (xx, yy, zz, xy, xz, yz): :data:`CCX_TO_VOIGT` reorders its columns).

Gauss points: the 2 x 2 x 2 rule at natural coordinates +-1/sqrt(3), numbered with xi fastest, then
eta, then zeta (point 1 (-,-,-), 2 (+,-,-), 3 (-,+,-), 4 (+,+,-), 5..8 the same at zeta = +): the order
of the stiffness integration in :mod:`elements` and of CalculiX's integration points (checked against
ccx 2.20 in tests/test_wall_stress.py).

``c3d8i``: the nine incompatible-mode amplitudes alpha of each element are recovered from its nodal
displacements by the static condensation the stiffness uses, alpha = -K_aa^-1 K_au u_e, with the mode
gradients taken at the element centre and scaled by det J0 / det J (:mod:`elements`); the strain at a
Gauss point is then B_u u_e + B_a alpha. ``c3d8``: B_u u_e.

Corners: the trilinear field through the eight Gauss values, evaluated at the corners (natural
coordinates +-1 are +-sqrt(3) in the Gauss points' own coordinates): sigma_corner = E sigma_gauss with
E the inverse of the matrix of corner shape functions at the Gauss points. An extrapolated estimate,
exact for stress fields that are trilinear in the natural coordinates (e.g. uniform).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .azimuths import azimuth_clusters, element_span_deg
from .elements import ELEMENTS, elasticity_matrix, shape_gradients, strain_operator

CORNERS = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                    [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], float)
GAUSS = np.array([[s, t, u] for u in (-1, 1) for t in (-1, 1) for s in (-1, 1)], float) / np.sqrt(3.0)
CCX_TO_VOIGT = np.array([0, 1, 2, 3, 5, 4])   # ccx (xx, yy, zz, xy, xz, yz)[CCX_TO_VOIGT] -> (.., yz, zx)
AXES = {"x": 0, "y": 1, "z": 2}


def shape_values(xi: np.ndarray) -> np.ndarray:
    """Trilinear shape functions N_a (8,) of the corners at natural point ``xi`` (3,)."""
    return np.prod(1.0 + CORNERS * np.asarray(xi, float)[None, :], axis=1) / 8.0


def extrapolation_matrix() -> np.ndarray:
    """(8 corners, 8 Gauss points): corner values = this @ Gauss values (inverse of N_a(Gauss_g))."""
    at_gauss = np.stack([shape_values(g) for g in GAUSS])          # (g, a)
    return np.linalg.inv(at_gauss)


def _jacobian(xyz: np.ndarray, xi: np.ndarray):
    """det J (ne,) and inverse J^-1 (ne, 3, 3) with J_ij = dx_j / dxi_i at natural point ``xi``."""
    J = np.einsum("ia,eaj->eij", shape_gradients(xi), xyz)
    a, b, c = J[:, 0], J[:, 1], J[:, 2]
    adj = np.stack([np.cross(b, c), np.cross(c, a), np.cross(a, b)], axis=-1)   # columns: J adj = det I
    det = np.einsum("ej,ej->e", a, adj[:, :, 0])
    if np.any(det <= 0):
        bad = int(np.flatnonzero(det <= 0)[0])
        raise ValueError(f"element {bad}: non-positive Jacobian (inverted or degenerate hexahedron)")
    return det, adj / det[:, None, None]


def gauss_strain_operator(xyz: np.ndarray, E: float, nu: float, element: str = "c3d8i") -> np.ndarray:
    """Linear map (ne, 8, 6, 24) from element displacements to Gauss-point strains: strains =
    operator @ ue (:func:`gauss_strain`). Build it once to recover the strains of many states.

    ``xyz`` (ne, 8, 3) corner coordinates [m]; E [Pa] and nu enter only the incompatible-mode
    condensation of ``c3d8i`` (alpha = -K_aa^-1 K_au u_e folded into the operator).
    """
    if element not in ELEMENTS:
        raise ValueError(f"element = {element!r}: must be one of {', '.join(ELEMENTS)}")
    xyz = np.asarray(xyz, float)
    ne = xyz.shape[0]
    Bu = np.empty((8, ne, 6, 24))
    dets = np.empty((8, ne))
    for g, xi in enumerate(GAUSS):
        det, inv = _jacobian(xyz, xi)
        Bu[g] = strain_operator(inv @ shape_gradients(xi))
        dets[g] = det
    if element == "c3d8":
        return Bu.transpose(1, 0, 2, 3)
    det0, inv0 = _jacobian(xyz, np.zeros(3))
    Ba = np.empty((8, ne, 6, 9))
    for g, xi in enumerate(GAUSS):                    # modes P_m = 1 - xi_m^2, dP_m/dxi_i = -2 xi_m delta_im
        grad = (inv0 @ np.diag(-2.0 * xi)) * (det0 / dets[g])[:, None, None]
        Ba[g] = strain_operator(grad)
    D = elasticity_matrix(E, nu)
    w = dets[:, :, None, None]                        # Gauss weights 1
    Kaa = np.einsum("geki,kl,gelj->eij", Ba * w, D, Ba, optimize=True)
    Kau = np.einsum("geki,kl,gelj->eij", Ba * w, D, Bu, optimize=True)
    A = -np.linalg.solve(Kaa, Kau)                    # (ne, 9, 24): alpha = A u_e
    return (Bu + np.einsum("geij,ejk->geik", Ba, A, optimize=True)).transpose(1, 0, 2, 3)


def gauss_strain(xyz: np.ndarray, ue: np.ndarray, E: float, nu: float, element: str = "c3d8i") -> np.ndarray:
    """Strains (ne, 8, 6) at the Gauss points, engineering shear, Voigt (xx, yy, zz, xy, yz, zx).

    ``xyz`` (ne, 8, 3) corner coordinates [m], ``ue`` (ne, 24) element displacements [m] (u_x, u_y, u_z
    per node). E [Pa] and nu enter only the incompatible-mode condensation of ``c3d8i``.
    """
    return np.einsum("egij,ej->egi", gauss_strain_operator(xyz, E, nu, element), np.asarray(ue, float))


def condensed_stiffness(xyz: np.ndarray, E: float, nu: float) -> np.ndarray:
    """K_uu - K_ua K_aa^-1 K_au (ne, 24, 24) [N/m] built from the same B matrices as :func:`gauss_strain`.

    Equal to :func:`elements.hex8_stiffness` ('c3d8i'): the check that the recovered modes are the
    stiffness's own (tests/test_wall_stress.py).
    """
    xyz = np.asarray(xyz, float)
    ne = xyz.shape[0]
    D = elasticity_matrix(E, nu)
    det0, inv0 = _jacobian(xyz, np.zeros(3))
    K = np.zeros((ne, 33, 33))
    for xi in GAUSS:
        det, inv = _jacobian(xyz, xi)
        grad_a = (inv0 @ np.diag(-2.0 * xi)) * (det0 / det)[:, None, None]
        B = np.concatenate([strain_operator(inv @ shape_gradients(xi)), strain_operator(grad_a)], axis=2)
        K += np.einsum("eki,kl,elj->eij", B * det[:, None, None], D, B)
    Kuu, Kua, Kaa = K[:, :24, :24], K[:, :24, 24:], K[:, 24:, 24:]
    return Kuu - Kua @ np.linalg.solve(Kaa, np.swapaxes(Kua, 1, 2))


def gauss_stress(p, u: np.ndarray, elems: np.ndarray | None = None) -> np.ndarray:
    """Stresses (ne, 8, 6) [Pa] at the Gauss points of elements ``elems`` (indices into ``p.hexes``,
    default all) of problem ``p`` (``nodes``, ``hexes``, ``E``, ``nu``, ``element``) for nodal
    displacements ``u`` (n, 3) [m]. Voigt (xx, yy, zz, xy, yz, zx), tension > 0."""
    hexes = p.hexes if elems is None else p.hexes[np.asarray(elems, np.int64)]
    ue = np.asarray(u, float)[hexes].reshape(len(hexes), 24)
    eps = gauss_strain(p.nodes[hexes], ue, p.E, p.nu, p.element)
    return eps @ elasticity_matrix(p.E, p.nu).T


def extrapolate_to_corners(gauss: np.ndarray) -> np.ndarray:
    """Corner values (ne, 8, k) from Gauss-point values (ne, 8, k) of the same elements (estimate)."""
    return np.einsum("ag,egk->eak", extrapolation_matrix(), np.asarray(gauss, float))


def corner_stress(p, u: np.ndarray, elems: np.ndarray | None = None) -> np.ndarray:
    """Stresses (ne, 8, 6) [Pa] extrapolated from the Gauss points to the corners (C3D8 node order)."""
    return extrapolate_to_corners(gauss_stress(p, u, elems))


def nodal_average(corner: np.ndarray, hexes: np.ndarray, n_nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """Unweighted mean over the elements sharing a node of their corner values.

    ``corner`` (ne, 8, k) belongs to the connectivity ``hexes`` (ne, 8) (node indices); returns the
    nodal values (n_nodes, k), NaN at nodes none of these elements touches, and the counts (n_nodes,).
    """
    corner = np.asarray(corner, float)
    hexes = np.asarray(hexes, np.int64)
    k = corner.shape[2]
    total = np.zeros((n_nodes, k))
    count = np.zeros(n_nodes)
    np.add.at(total, hexes.ravel(), corner.reshape(-1, k))
    np.add.at(count, hexes.ravel(), 1.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count[:, None] > 0, total / count[:, None], np.nan), count


@dataclass(frozen=True)
class BaseWall:
    """Axial stress across the wall at the base, one entry per azimuth (sorted by ``theta_deg``).

    ``nodes`` (na, nw): base nodes at each azimuth, inner face first (sorted by radius); ``radius``
    (na, nw) [m]; ``s_axial`` (na, nw) [Pa] their axial stress. ``inner``, ``outer`` [Pa]: the faces;
    ``mean`` [Pa]: membrane, the trapezoid rule over the node radii divided by the wall thickness,
    (1 / (r_out - r_in)) int s dr with s linear between nodes; ``bending`` [Pa]: (outer - inner) / 2
    (> 0 when the outer face is more tensile). Tension > 0, compression < 0 (as sigma_N).
    """
    theta_deg: np.ndarray
    nodes: np.ndarray
    radius: np.ndarray
    s_axial: np.ndarray
    inner: np.ndarray
    outer: np.ndarray
    mean: np.ndarray
    bending: np.ndarray


def through_wall_weights(radius: np.ndarray) -> np.ndarray:
    """Trapezoid weights (na, nw) over the node radii, summing to 1 per azimuth."""
    dr = np.diff(radius, axis=1)
    w = np.zeros_like(radius)
    w[:, :-1] += 0.5 * dr
    w[:, 1:] += 0.5 * dr
    return w / w.sum(axis=1, keepdims=True)


def base_wall(nodes: np.ndarray, bottom_hexes: np.ndarray, s_axial_nodal: np.ndarray, axis: str = "z",
              rel_tol: float = 1e-3) -> BaseWall:
    """Group the base nodes of the bottom element row by azimuth and reduce across the wall.

    ``nodes`` (n, 3) [m], ``bottom_hexes`` (ne, 8) node indices of the bottom element row, the wall's axis
    through the origin along ``axis`` ('x', 'y' or 'z'); base nodes are the row's nodes at the lowest
    axial coordinate. ``s_axial_nodal`` (n,) [Pa]: the axial normal stress per node (e.g. column zz of
    :func:`nodal_average` over the bottom row). Azimuth [deg, 0..360) counter-clockwise about ``axis``
    (from +x towards +y for 'z'); nodes whose azimuths agree to ``rel_tol`` of the smallest element's
    angular span share an azimuth (:func:`azimuths.azimuth_clusters`: an imported mesh's nodes sit off
    their nominal azimuth by round-off, 1e-7 deg in Gmsh's files, 1e-5 deg in 8-character Nastran
    fields), ``theta_deg`` is each group's mean.
    """
    if axis not in AXES:
        raise ValueError(f"axis = {axis!r}: must be one of x, y, z")
    a = AXES[axis]
    b, c = (a + 1) % 3, (a + 2) % 3
    nodes = np.asarray(nodes, float)
    row = np.unique(np.asarray(bottom_hexes, np.int64))
    h = nodes[row, a]
    tol = 1e-9 * max(float(np.ptp(nodes, axis=0).max()), 1.0)
    base = row[h <= h.min() + tol]
    az = lambda i: np.mod(np.degrees(np.arctan2(nodes[i, c], nodes[i, b])), 360.0)  # noqa: E731
    span = element_span_deg(az(np.asarray(bottom_hexes, np.int64)))
    th, centres = azimuth_clusters(az(base), rel_tol * float(span[span > 0].min() if (span > 0).any() else 360.0))
    rad = np.hypot(nodes[base, b], nodes[base, c])
    order = np.lexsort((rad, th))
    base, th, rad = base[order], th[order], rad[order]
    uth, counts = np.unique(th, return_counts=True)
    uth = centres[uth]
    if np.any(counts != counts[0]) or counts[0] < 2:
        raise ValueError("bottom_hexes: base nodes do not form the same through-wall row at every azimuth")
    shape = (uth.size, int(counts[0]))
    nd, rr = base.reshape(shape), rad.reshape(shape)
    s = np.asarray(s_axial_nodal, float)[nd]
    if not np.all(np.isfinite(s)):
        raise ValueError("s_axial_nodal: NaN or infinite at a base node")
    inner, outer = s[:, 0], s[:, -1]
    mean = np.sum(through_wall_weights(rr) * s, axis=1)
    return BaseWall(theta_deg=uth, nodes=nd, radius=rr, s_axial=s, inner=inner, outer=outer,
                    mean=mean, bending=0.5 * (outer - inner))


def reference_base_wall(p, u: np.ndarray, bottom_elems: np.ndarray, axis: str = "z") -> BaseWall:
    """:func:`base_wall` of the reference solution: corner stresses of the bottom row ``bottom_elems``
    (indices into ``p.hexes``) averaged over the row's elements sharing a node; axial component."""
    bottom = p.hexes[np.asarray(bottom_elems, np.int64)]
    avg, _ = nodal_average(corner_stress(p, u, bottom_elems), bottom, p.nodes.shape[0])
    return base_wall(p.nodes, bottom, avg[:, AXES[axis]], axis)
