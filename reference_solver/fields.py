"""Post-processing of recovered displacement fields: element-centre stresses and von Mises (any element type)."""

from __future__ import annotations

import numpy as np

from .elements import centroid_strain
from .kinematics import elasticity_matrix, von_mises
from .problem import Problem


def element_stress(p: Problem, u: np.ndarray) -> np.ndarray:
    """Voigt stresses (ne, 6) [Pa] at element centres for nodal displacements ``u`` (n, 3) [m]
    (elements numbered block by block, ``p.blocks``)."""
    u = np.asarray(u, float)
    eps = [centroid_strain(p.nodes[b.cells], u[b.cells].reshape(len(b.cells), -1), b.element) for b in p.blocks]
    return np.concatenate(eps) @ elasticity_matrix(p.E, p.nu).T


def element_von_mises(p: Problem, u: np.ndarray) -> np.ndarray:
    """Von Mises stress (ne,) [Pa] at element centres."""
    return von_mises(element_stress(p, u))
