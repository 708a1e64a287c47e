"""Quadrature rules on the reference shapes of the elements and their faces.

Every rule returns ``(points, weights)``: points in natural coordinates, weights summing to the
reference measure (cube [-1, 1]^3: 8; square [-1, 1]^2: 4; triangle {s, t >= 0, s + t <= 1}: 1/2;
tetrahedron {xi, eta, zeta >= 0, sum <= 1}: 1/6; wedge = triangle x [-1, 1]: 1). Degrees (the
polynomial degree integrated exactly) are checked against exact monomial integrals in
tests/test_elements_interface.py.
"""

from __future__ import annotations

import numpy as np


def gauss_line(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre on [-1, 1] with ``n`` points (degree 2n - 1)."""
    return np.polynomial.legendre.leggauss(n)


def hex_rule(n: int) -> tuple[np.ndarray, np.ndarray]:
    """n x n x n Gauss points, xi fastest, then eta, then zeta (the CalculiX order)."""
    x, w = gauss_line(n)
    pts = np.array([[a, b, c] for c in x for b in x for a in x])
    wts = np.array([wa * wb * wc for wc in w for wb in w for wa in w])
    return pts, wts


def quad_rule(n: int) -> tuple[np.ndarray, np.ndarray]:
    """n x n Gauss points on [-1, 1]^2, s fastest."""
    x, w = gauss_line(n)
    return np.array([[a, b] for b in x for a in x]), np.array([wa * wb for wb in w for wa in w])


def tri_rule(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Symmetric rules on the unit triangle: degree 1 (centroid), 2 (3 points), 4 (6 points, Dunavant)."""
    if degree <= 1:
        return np.array([[1 / 3, 1 / 3]]), np.array([0.5])
    if degree == 2:
        return np.array([[1 / 6, 1 / 6], [2 / 3, 1 / 6], [1 / 6, 2 / 3]]), np.full(3, 1 / 6)
    a, b = 0.445948490915965, 0.091576213509771
    wa, wb = 0.223381589678011 / 2, 0.109951743655322 / 2
    pts = np.array([[a, a], [1 - 2 * a, a], [a, 1 - 2 * a], [b, b], [1 - 2 * b, b], [b, 1 - 2 * b]])
    return pts, np.array([wa, wa, wa, wb, wb, wb])


def tet_rule(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Rules on the unit tetrahedron: degree 1 (centroid), 2 (4 points), 3 (5 points, one negative weight)."""
    if degree <= 1:
        return np.array([[0.25, 0.25, 0.25]]), np.array([1 / 6])
    if degree == 2:
        a, b = 0.1381966011250105, 0.5854101966249685
        pts = np.array([[a, a, a], [b, a, a], [a, b, a], [a, a, b]])
        return pts, np.full(4, 1 / 24)
    pts = np.array([[0.25, 0.25, 0.25], [1 / 6, 1 / 6, 1 / 6], [0.5, 1 / 6, 1 / 6],
                    [1 / 6, 0.5, 1 / 6], [1 / 6, 1 / 6, 0.5]])
    return pts, np.array([-4 / 30, 9 / 120, 9 / 120, 9 / 120, 9 / 120])


def wedge_rule(tri_degree: int, n_line: int) -> tuple[np.ndarray, np.ndarray]:
    """Triangle rule x Gauss line in zeta (triangle points fastest)."""
    tp, tw = tri_rule(tri_degree)
    x, w = gauss_line(n_line)
    pts = np.array([[s, t, z] for z in x for s, t in tp])
    wts = np.array([a * b for b in w for a in tw])
    return pts, wts
