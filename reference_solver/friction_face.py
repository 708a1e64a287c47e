"""Coulomb friction with face-weighted (mortar-type) contact rows: the nodal friction laws on the multipliers.

The face-weighted Lagrange law (:mod:`reference_solver.face_law`) is a change of variables on the condensed
contact system: weighted gaps g~ = D g [m^3] and multipliers lambda [Pa] with nodal forces r = D^T lambda [N],
D_ab = int Phi_a N_b dA the surface's mortar matrix (hat basis 'face', CalculiX's dual basis 'face-dual',
row sums 'face-lumped'). With friction the same D weighs the two tangential components of every friction row
(the traction field t = sum lambda_t,a Phi_a, the weighted slip s~_a = int Phi_a s dA = sum_b D_ab s_b):

    x~ = W x,   W = D on the normal dofs, D_ab (e_a,i . e_b,j) on the tangential axes (i, j) of the rows'
    frames (the identity where the frames coincide: a flat table), the identity on spring dofs;
    S~ = W^-T S W^-1,  f~ = W^-T f,  clearance~ = D clearance,  forces lambda = W^-T R.

Every retained dof of the weighted system still carries exactly one force (a normal multiplier, a tangential
multiplier, a spring's), so the nodal laws of :mod:`reference_solver.friction` run on it unchanged: Coulomb on
the multipliers, |lambda_t,a| <= mu lambda_n,a, stick in the weighted slip (s~_a = s~_a,ref) or slip opposing it.
With the hat basis (Phi >= 0, sum Phi = 1) this bounds the traction field pointwise: |t(x)| <= sum |lambda_t,a|
Phi_a(x) <= mu p(x) on every face; the dual basis (negative in parts of a face) bounds its multipliers only,
as CalculiX's mortar friction does. Penalty and augmented Lagrangian act on the multipliers too: lambda_n =
k~ (-g~), k~_a = k_a / (A_a s_a) [Pa/m^3] (A_a = ``contact_area``, s_a = sum_b D_ab = int Phi_a dA), so a
uniform penetration d gives the pressure k_a d / A_a, the nodal law's; likewise k_t~ (a mortar penalty, not
the face-integrated penalty of :mod:`reference_solver.face_penalty`, which is frictionless).

Outputs are the nodal quantities (``arrays``): displacements W^-1 x~, normal forces D^T lambda_n, tangential
forces D^T lambda_t (global vectors), slip increments D^-1 Delta s~; the dissipation -lambda . Delta s~ = -r .
Delta s (W^T lambda = r); stick / slip / open and ``closed`` are the multipliers' status; sigma_N = -lambda.
A friction row whose tangential axis is another row's normal (a base corner on the radial stop) is refused
in one line: one retained dof cannot take the two weightings. Which basis: deckbridge takes the dual one
(:func:`dual_shares`), measured against beam theory, a fine hex8i skirt and ccx's mortar ``*FRICTION``
(docs/elements.md, "Friction on 8-/6-node contact faces"); the hat basis stays selectable ('face').
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .errors import ReferenceSolverError
from .face_law import weighting_matrix
from .friction_law import FrictionLaw


def dual_shares(p):
    """``p`` with CalculiX's dual multiplier basis (``contact_weighting='face-dual'``), the basis of friction on 8-/6-node
    faces (docs/elements.md: measured against a fine hex8i skirt and beam theory, the hat basis lifted a tet10 skirt
    with friction at lambda 0.02): every row on a face gets the area d_a = int psi_a dA (the row sums of D, so that
    Sum -sigma_N A = the normal resultant) and its stiffnesses k, k_t scaled by d_a / area (the same slope [Pa/m])."""
    q = dataclasses.replace(p, contact_weighting="face-dual")
    d = np.asarray(weighting_matrix(q) @ np.ones(p.n_contacts)).ravel()
    scale = d / p.contact_area
    return dataclasses.replace(q, contact_area=d, contact_k=p.contact_k * scale, contact_kt=p.contact_kt * scale)


class WeightedFriction:
    """The map of a :class:`reference_solver.friction.FrictionSystem` onto its face-weighted variables (module
    doc): ``system`` is the weighted FrictionSystem (its problem carries the weighted clearance and stiffnesses),
    ``W`` (nr x nr) the change of variables, ``D`` (nc x nc) the normal block."""

    def __init__(self, sysf):
        p = sysf.problem
        nc, ns, nr = p.n_contacts, p.n_springs, sysf.S.shape[0]
        if np.any(sysf.tdofs < nc + ns):
            j = int(sysf.rows[np.flatnonzero((sysf.tdofs < nc + ns).any(axis=1))[0]])
            raise ReferenceSolverError(f"contact_weighting = {p.contact_weighting!r}: friction row {j} (node "
                                       f"{int(p.contact_nodes[j])}) has a tangential axis that is another contact "
                                       "row's normal (a base corner on the radial stop); face-weighted friction "
                                       "needs the stop off")
        D = weighting_matrix(p).tocsr()
        fr = sysf.rows
        isf = np.zeros(nc, bool)
        isf[fr] = True
        Dc = D.tocoo()
        if np.any(isf[Dc.row] != isf[Dc.col]):
            raise ReferenceSolverError("friction_surfaces: a face couples a friction row with a frictionless one")
        pos = np.full(nc, -1)
        pos[fr] = np.arange(fr.size)
        keep = isf[Dc.row]
        a, b, v = pos[Dc.row[keep]], pos[Dc.col[keep]], Dc.data[keep]
        rows, cols, vals = [Dc.row, nc + np.arange(ns)], [Dc.col, nc + np.arange(ns)], [Dc.data, np.ones(ns)]
        for i in range(2):
            for j in range(2):
                rows.append(sysf.tdofs[a, i]), cols.append(sysf.tdofs[b, j])
                vals.append(v * np.einsum("sk,sk->s", sysf.tdir[a, i], sysf.tdir[b, j]))
        W = sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(nr, nr))
        W.eliminate_zeros()
        self.D, self.W, self.rows = D, W, fr
        self.Dff = D[fr][:, fr].tocsc()
        self._lu, self._luf, self._lud = spla.splu(W), spla.splu(self.Dff), spla.splu(D.tocsc())
        Y = self._lu.solve(np.asarray(sysf.S, float), trans="T")           # W^-T S
        St = self._lu.solve(np.ascontiguousarray(Y.T), trans="T").T         # W^-T S W^-1 (S symmetric)
        s = np.asarray(D @ np.ones(nc)).ravel()                              # int Phi_a dA [m^2]
        if np.any(s <= 0):
            raise ReferenceSolverError(f"contact_weighting = {p.contact_weighting!r}: a row's weight int Phi dA "
                                       "is not positive")
        scale = p.contact_area * s                                           # k~ = k / (A s)  [m^4]
        pw = dataclasses.replace(p, contact_clearance=D @ p.contact_clearance, contact_k=p.contact_k / scale,
                                 contact_kt=p.contact_kt / scale)
        modes = W @ sysf.slide_modes                                        # rigid slides, weighted
        self.system = dataclasses.replace(sysf, problem=pw, S=0.5 * (St + St.T),
                                          fhat=self._lu.solve(np.asarray(sysf.fhat, float), trans="T"),
                                          cache={}, views={}, modes=modes, dirs=None)
        self.original = sysf

    def to_nodal(self, X: np.ndarray) -> np.ndarray:
        """W^-1 x~: retained displacements [m] from weighted ones, rows of ``X`` (m, nr)."""
        return self._lu.solve(np.ascontiguousarray(np.atleast_2d(X).T)).T

    def forces(self, lam: np.ndarray) -> np.ndarray:
        """D^T lambda: nodal normal forces [N] from multipliers [Pa], rows of ``lam`` (m, nc)."""
        return (self.D.T @ np.atleast_2d(lam).T).T

    def pressures(self, force: np.ndarray) -> np.ndarray:
        """D^-T r: multipliers [Pa] from nodal normal forces [N], rows of ``force`` (m, nc)."""
        return self._lud.solve(np.ascontiguousarray(np.atleast_2d(force).T), trans="T").T


class FaceFrictionLaw(FrictionLaw):
    """The friction law of ``method`` on the face-weighted variables of ``sysf`` (module doc); the path sees its
    states in those variables, ``arrays`` / ``retained`` / ``sigma_n`` give the nodal quantities."""

    def __init__(self, sysf, method: str, k_factor: float = 1.0, algorithm: str | None = None,
                 corner: str | None = None):
        self.weighted = WeightedFriction(sysf)
        self._raw = False                                    # retained() in the weighted variables (arrays)
        super().__init__(self.weighted.system, method, k_factor, algorithm, corner)
        self._k_nodal = (k_factor if self.uses_k else 1.0) * sysf.problem.contact_k

    @property
    def penalty_k(self):
        """The nodal penalty stiffness [N/m] (k~ A s: what a uniform penetration gives a row)."""
        return self._k_nodal if self.uses_k else None

    def lifted(self, st, watch):
        """Watched rows whose multiplier is open (lambda = 0: the pressure field is 0 at the node, hat basis)."""
        return watch & ~st.active

    def retained(self, states) -> np.ndarray:
        """The nodal retained displacements W^-1 x~ [m] of ``states``."""
        X = np.array([st.x for st in states])
        return X if self._raw else self.weighted.to_nodal(X)

    def sigma_n(self, force):
        """sigma_N = -lambda = -D^-T r [Pa] (< 0 compression)."""
        return 0.0 - self.weighted.pressures(np.asarray(force, float))

    def arrays(self, states, coeffs) -> dict:
        self._raw = True
        try:
            out = super().arrays(states, coeffs)             # in the weighted variables
        finally:
            self._raw = False
        wf, p = self.weighted, self.weighted.original.problem
        Xw = out["retained_u"]
        X = wf.to_nodal(Xw)
        nc, fr, td = p.n_contacts, wf.rows, self.sysf.tdofs
        U = X[:, :nc]
        out.update(u=U, gap=p.contact_clearance + U, force=wf.forces(out["force"]), retained_u=X)
        ft, ds = out["tangential_force"], out["slip_increment"]
        out["tangential_traction"] = ft.copy()               # lambda_t [Pa], global (Solution.friction_check)
        T = np.array([st.t for st in states])
        dw = np.diff(Xw[:, td], axis=0, prepend=0.0 * Xw[:1, td])          # weighted increments (ni, nf, 2)
        if self.name == "penalty":                                          # minus the elastic part
            dw = dw + np.diff(T, axis=0, prepend=0.0 * T[:1]) / self.kt[None, :, None]
        for i, st in enumerate(states):
            ft[i, fr] = wf.Dff.T @ ft[i, fr]                  # r_t = D^T lambda_t, per global component
            d = wf._luf.solve(np.ascontiguousarray(np.einsum("fa,fak->fk", dw[i], self.sysf.tdir)))
            ds[i, fr] = np.where(st.active[fr][:, None], d, 0.0)   # Delta s = D^-1 Delta s~, open rows 0
        if "penetration" in out:
            out["penetration"] = np.maximum(-(p.contact_clearance + U), 0.0).max(axis=1)
        return out
