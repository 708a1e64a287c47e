"""Post-processing of recovered displacement fields: element-centre stresses and von Mises."""

from __future__ import annotations

import numpy as np

from .elements import centroid_strain, elasticity_matrix, von_mises
from .problem import Problem


def element_stress(p: Problem, u: np.ndarray) -> np.ndarray:
    """Voigt stresses (ne, 6) [Pa] at element centres for nodal displacements ``u`` (n, 3) [m]."""
    ue = np.asarray(u, float)[p.hexes].reshape(len(p.hexes), 24)
    eps = centroid_strain(p.nodes[p.hexes], ue)
    return eps @ elasticity_matrix(p.E, p.nu).T


def element_von_mises(p: Problem, u: np.ndarray) -> np.ndarray:
    """Von Mises stress (ne,) [Pa] at element centres."""
    return von_mises(element_stress(p, u))
