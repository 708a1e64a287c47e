"""The element interface: what one element type holds and computes, vectorised over a block of elements.

An element type (one instance per type, registered in :mod:`reference_solver.elements`) holds
- ``name`` (the solver's name, CalculiX-like: 'c3d8i', 'c3d20r', ...), ``aliases`` ('hex8i', ...),
  ``n_nodes``, ``nodes`` (n, 3) natural coordinates of its nodes (CalculiX node order), ``centre``;
- shape functions :meth:`shape` N_a(xi) and :meth:`dshape` dN_a/dxi_i;
- the volume quadrature ``points`` (ng, 3), ``weights`` (ng,);
- the face rule ``faces`` (local node lists, CalculiX face order S1, S2, ...: corners cyclic, then
  mid-side nodes) and ``face_types`` (one :class:`element_faces.FaceType` per face);
- stress recovery: ``recovery`` (monomials fitted by least squares to the Gauss values) giving
  :meth:`extrapolation` (n, ng), Gauss values -> node values (exact for fields in that space);
- ``bending``: False where the element fails the bending patch test (the 4-node tetrahedron);
  ``hourglass``: True where reduced integration allows zero-energy modes (Hex20R), with
  ``opposite_faces`` the pairs of opposite faces (:mod:`reference_solver.hourglass`).
Computations (``xyz`` (ne, n, 3) node coordinates [m], E [Pa], nu): :meth:`stiffness_pairs`
(ne, 3, 3, n, n) [N/m], :meth:`gauss_strain_operator` (ne, ng, 6, 3n), :meth:`volume_weights`
(ne, ng) w det J [m^3], :meth:`centre_strain_operator` (ne, 6, 3n); for the stress recovery of many states
:meth:`gauss_gradients` (ne, ng) det J and (ne, ng, 3, n) dN/dx, :meth:`displacement_gradients` du/dx of m
states (ne, ng, 3, 3, m) and w det J, without the (ne, ng, 6, 3n) operator.
Element dofs are (u_x, u_y, u_z) per node, node by node. Voigt order (xx, yy, zz, xy, yz, zx).
"""

from __future__ import annotations

import numpy as np

from .errors import ReferenceSolverError
from .kinematics import det_inverse, isotropic_pairs, jacobian, lame, strain_operator
from .polynomials import NodalBasis, exponents, monomials


class Element:
    """Isoparametric solid element; subclasses set the class attributes and, if not polynomial,
    override :meth:`shape` / :meth:`dshape`."""
    name: str = ""
    aliases: tuple = ()
    meshio_type: str = ""
    nodes: np.ndarray
    points: np.ndarray
    weights: np.ndarray
    faces: tuple = ()
    face_types: tuple = ()
    recovery: str = "1"
    bending: bool = True
    hourglass: bool = False
    opposite_faces: tuple = ()
    basis: NodalBasis | None = None

    @property
    def n_nodes(self) -> int:
        return self.nodes.shape[0]

    @property
    def n_points(self) -> int:
        return self.points.shape[0]

    @property
    def centre(self) -> np.ndarray:
        """Natural coordinates of the reference shape's centroid (the quadrature's mean point)."""
        return (self.weights @ self.points) / self.weights.sum()

    def __repr__(self) -> str:
        return f"<element {self.name}>"

    # shape functions -----------------------------------------------------------------------------
    def shape(self, xi) -> np.ndarray:
        """N_a (p, n) at natural points ``xi`` (p, 3)."""
        return self.basis.values(xi)

    def dshape(self, xi) -> np.ndarray:
        """dN_a/dxi_i (p, 3, n) at natural points ``xi`` (p, 3)."""
        return self.basis.gradients(xi)

    # geometry ------------------------------------------------------------------------------------
    def point_gradients(self, xyz: np.ndarray, xi: np.ndarray):
        """det J (ne,) and spatial gradients dN_a/dx_i (ne, 3, n) at one natural point ``xi`` (3,)."""
        dn = self.dshape(np.asarray(xi, float)[None])[0]
        _, det, inv = jacobian(xyz, dn)
        if np.any(~(det > 0)):
            bad = int(np.flatnonzero(~(det > 0))[0])
            raise ReferenceSolverError(f"element {bad} ({self.name}): non-positive Jacobian "
                                       "(inverted or degenerate element)")
        return det, inv @ dn

    def volume_weights(self, xyz: np.ndarray) -> np.ndarray:
        """Quadrature weight x det J (ne, ng) [m^3]; sums to each element's volume."""
        xyz = np.asarray(xyz, float)
        return np.stack([self.point_gradients(xyz, xi)[0] * w for xi, w in zip(self.points, self.weights)], 1)

    # stiffness and strains -----------------------------------------------------------------------
    def stiffness_pairs(self, xyz: np.ndarray, E: float, nu: float) -> np.ndarray:
        """Element stiffness (ne, 3, 3, n, n) [N/m]: [e, i, j, a, b] couples component i of node a to
        component j of node b (symmetric)."""
        xyz = np.asarray(xyz, float)
        lam, mu = lame(E, nu)
        X = np.empty((xyz.shape[0], 3, self.n_nodes, self.n_points))
        for g, (xi, w) in enumerate(zip(self.points, self.weights)):
            det, grad = self.point_gradients(xyz, xi)
            X[..., g] = grad * np.sqrt(w * det)[:, None, None]
        K = isotropic_pairs(X, X, lam, mu)
        K = np.add(K, K.transpose(0, 2, 1, 4, 3))
        K *= 0.5
        return K

    def gauss_strain_operator(self, xyz: np.ndarray, E: float, nu: float) -> np.ndarray:
        """Linear map (ne, ng, 6, 3n) from element displacements to Gauss-point strains (E, nu unused
        by purely displacement-based elements)."""
        xyz = np.asarray(xyz, float)
        return np.stack([strain_operator(self.point_gradients(xyz, xi)[1]) for xi in self.points], 1)

    def gauss_gradients(self, xyz: np.ndarray):
        """det J (ne, ng) and spatial gradients dN_a/dx_i (ne, ng, 3, n) at every Gauss point, in one
        batched product (what :meth:`point_gradients` gives point by point)."""
        dn = self.dshape(self.points)                                       # (ng, 3, n)
        det, inv = det_inverse(dn @ np.asarray(xyz, float)[:, None])        # J (ne, ng, 3, 3)
        if np.any(~(det > 0)):
            bad = int(np.flatnonzero(~(det > 0).all(axis=1))[0])
            raise ReferenceSolverError(f"element {bad} ({self.name}): non-positive Jacobian "
                                       "(inverted or degenerate element)")
        return det, inv @ dn

    def displacement_gradients(self, xyz: np.ndarray, ue: np.ndarray, E: float, nu: float):
        """Displacement gradients H (ne, ng, 3, 3, m), H[..., i, c, s] = du_c/dx_i of state s at the Gauss
        points, and the weights w det J (ne, ng) [m^3].

        ``ue`` (ne, n, 3, m) element displacements [m] (node, component, state). The strains are
        :func:`kinematics.gradient_to_strain` @ H: equal to :meth:`gauss_strain_operator` applied to each
        state (to rounding), without building the operator (the stress recovery of a load path's states)."""
        ne, n, _, m = ue.shape
        det, grad = self.gauss_gradients(xyz)
        H = grad.reshape(ne, -1, n) @ ue.reshape(ne, n, 3 * m)              # (ne, ng x 3, 3m)
        return H.reshape(ne, -1, 3, 3, m), det * self.weights

    def centre_strain_operator(self, xyz: np.ndarray) -> np.ndarray:
        """B (ne, 6, 3n) at the element centre (the strain of a centre-point recovery)."""
        return strain_operator(self.point_gradients(np.asarray(xyz, float), self.centre)[1])

    # stress recovery -----------------------------------------------------------------------------
    def extrapolation(self) -> np.ndarray:
        """(n, ng): node values = this @ Gauss values. Least-squares fit of the ``recovery`` monomials
        to the Gauss values, evaluated at the nodes (an estimate; exact inside that space)."""
        e = exponents(self.recovery)
        return monomials(self.nodes, e) @ np.linalg.pinv(monomials(self.points, e))
