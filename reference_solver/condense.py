"""Assembly and static condensation onto the contact dofs: the reusable ``CondensedSystem``.

Reduced unknowns q (frames.py); retained dofs r = contact normal dofs c, then spring dofs s.
S (with the springs on the s diagonal) is condensed once more onto c: the contact operator
S_c = S_cc - S_cs S_ss^-1 S_sc and loads f_c = fhat_c - S_cs S_ss^-1 fhat_s, per basic load case.
Contact reactions (force of the master on the node along its normal, > 0 compressive) are
r_c = S_c u_c - f_c(load); spring dofs u_s = S_ss^-1 (fhat_s - S_sc u_c); spring forces -k u_s.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from typing import Mapping

import numpy as np
import scipy.linalg as sla

from .assembly import assemble_problem_blocks
from .errors import ReferenceSolverError
from .frames import DofMap, build_dofmap
from .linalg import (HAVE_CHOLMOD, Factorize, Schur, cholesky_dense, default_factorize, schur_rhs,
                     schur_trailing)
from .loads import distributing_forces, rigid_modes
from .problem import Problem
from .stages import mark
from .threads import blas_threads
from .trailing import rotate_blocks, schur_blocks


@dataclass
class CondensedSystem:
    """Everything the contact iterations need, independent of the method and of the penalty k."""
    problem: Problem
    dofmap: DofMap
    case_names: tuple[str, ...]
    S: np.ndarray                 # (nr, nr) condensed stiffness on r = c + s, springs included [N/m]
    fhat: np.ndarray              # (nr, ncase) condensed loads [N]
    Sc: np.ndarray                # (nc, nc) contact operator
    fc: np.ndarray                # (nc, ncase) contact loads
    Gs: np.ndarray                # (ns, nc) S_ss^-1 S_sc
    us0: np.ndarray               # (ns, ncase) S_ss^-1 fhat_s
    schur: Schur
    info: dict = field(default_factory=dict)

    @property
    def n_contacts(self) -> int:
        return self.problem.n_contacts

    def without_S(self) -> "CondensedSystem":
        """This system without the nr x nr S (0-row array) when its recovery does not read it (the trailing
        Schur with the factor read in place, the 'rhs' one): the contact laws run on Sc; S serves only to
        re-bind springs (deckbridge.tangent_springs). Else the system itself."""
        if self.schur is None or self.schur.recover_uses_S:
            return self
        return replace(self, S=np.zeros((0, 0)), schur=replace(self.schur, S=np.zeros((0, 0))))

    def released(self) -> "CondensedSystem":
        """This system without the sparse factor (``schur`` None: no field recovery) and without its dense
        blocks S, Sc, Gs (0-row arrays), for a caller that has recovered every field it needs: at millions of
        dofs the factor is most of the memory (``deckbridge solve`` releases it before writing its VTUs)."""
        empty = np.zeros((0, 0))
        return replace(self, S=empty, Sc=empty, Gs=empty, schur=None)

    @property
    def dofs(self) -> int:
        """Number of reduced unknowns (displacement dofs after couplings) [-]."""
        return self.dofmap.n_reduced

    def coeffs(self, combo: Mapping[str, float]) -> np.ndarray:
        """Vector of load-case coefficients from ``{case: factor}``."""
        c = np.zeros(len(self.case_names))
        for name, v in combo.items():
            if name not in self.case_names:
                raise ReferenceSolverError(f"load case {name!r}: unknown (known: {', '.join(self.case_names)})")
            c[self.case_names.index(name)] += v
        return c

    def spring_displacement(self, u_c: np.ndarray, coeffs: np.ndarray) -> np.ndarray:
        return self.us0 @ coeffs - self.Gs @ u_c

    def recover(self, u_c: np.ndarray, coeffs: np.ndarray) -> np.ndarray:
        """Global nodal displacements (n, 3) [m] for contact dofs ``u_c`` under load ``coeffs``.

        With ``u_c`` (m, nc) and ``coeffs`` (m, ncase), m states in one solve: (m, n, 3).
        """
        many = np.ndim(u_c) == 2
        uc = np.atleast_2d(u_c).T                                    # (nc, m)
        co = np.atleast_2d(coeffs).T                                 # (ncase, m)
        u_r = np.concatenate([uc, self.us0 @ co - self.Gs @ uc])
        q = self.schur.recover(u_r, co)
        u = (self.dofmap.T @ q).T.reshape(uc.shape[1], -1, 3)
        if not np.all(np.isfinite(u)):
            raise ReferenceSolverError("non-finite displacements in the recovered field")
        return u if many else u[0]


def contact_operator(S: np.ndarray, nc: int, Gs: np.ndarray, block: int = 512) -> np.ndarray:
    """S_c = sym(S_cc - S_cs Gs) (nc, nc) with one nc x nc array alive: the product is written over by the
    difference, then made exactly symmetric block by block; the same numbers as ``0.5 * (A + A.T)`` of
    ``A = S_cc - S_cs @ Gs`` (each entry 0.5 (a_ij + a_ji), addition commutes), without its three temporaries."""
    Sc = S[:nc, nc:] @ Gs
    np.subtract(S[:nc, :nc], Sc, out=Sc)
    for b in range(0, nc, block):
        e = min(b + block, nc)
        for c in range(0, b + 1, block):
            f = min(c + block, nc)
            avg = 0.5 * (Sc[b:e, c:f] + Sc[c:f, b:e].T)
            Sc[b:e, c:f] = avg
            Sc[c:f, b:e] = avg.T
    return Sc


def load_vectors(p: Problem, dm: DofMap, names: tuple[str, ...]) -> np.ndarray:
    """Reduced load vectors (nq, ncase) of the basic load cases."""
    F = np.zeros((dm.n_reduced, len(names)))
    for k, name in enumerate(names):
        v = p.loads[name]
        if p.coupling == "kinematic":
            F[dm.ref_dofs, k] = v
        else:
            f = np.zeros((p.n_nodes, 3))
            f[p.coupling_nodes] = distributing_forces(p.nodes[p.coupling_nodes], p.coupling_weights,
                                                      p.ref_point, v[:3], v[3:])
            F[:, k] = dm.T.T @ f.ravel()
    return F


def _reduced_stiffness(p: Problem, dm: DofMap, times: dict) -> list:
    """[T^T K T] in a list, so that the caller can hand over its only reference."""
    t = time.perf_counter()
    K = assemble_problem_blocks(p).tocsr()
    times["assembly_s"] = time.perf_counter() - t
    return [(dm.T.T @ K @ dm.T).tocsr()]


def _reduced_blocks(p: Problem, dm: DofMap, times: dict) -> list:
    """[T^T K T] as node blocks (distributing coupling: T is one 3x3 frame per node)."""
    t = time.perf_counter()
    K = assemble_problem_blocks(p)
    times["assembly_s"] = time.perf_counter() - t
    framed = np.unique(np.concatenate([p.contact_nodes, p.spring_nodes]))
    rr = (3 * framed[:, None, None] + np.arange(3)[None, :, None]).repeat(3, axis=2)
    cc = np.swapaxes(rr, 1, 2)
    R = np.asarray(dm.T[rr.ravel(), cc.ravel()]).reshape(-1, 3, 3)   # u_global = R u_local
    rotate_blocks(K, framed, R)
    return [K]


def check_mechanism(p: Problem) -> None:
    """Raise when a rigid-body motion moves no contact normal and strains no spring."""
    if p.n_contacts == 0:
        raise ReferenceSolverError("no contact possible: the problem has no slave nodes")
    L = p.length_scale()
    modes = rigid_modes(p.nodes, p.ref_point, L)                    # (6, n, 3)
    A = np.einsum("mjk,jk->jm", modes[:, p.contact_nodes], p.contact_normals)
    kref = p.E * L
    if p.n_springs:
        B = np.einsum("mjk,jk->jm", modes[:, p.spring_nodes], p.spring_dirs)
        A = np.vstack([A, np.sqrt(p.spring_k / kref)[:, None] * B])
    sv, vt = np.linalg.svd(A, full_matrices=False)[1:]
    null = vt[sv <= 1e-8 * sv.max()]
    if null.size:
        names = ["translation x", "translation y", "translation z", "rotation x", "rotation y", "rotation z"]
        weight = np.linalg.norm(null, axis=0)          # share of each canonical motion in the null space
        free = [names[m] for m in np.flatnonzero(weight > 0.5)] or [names[int(np.argmax(weight))]]
        raise ReferenceSolverError(
            f"mechanism: nothing restrains the rigid-body {', '.join(free)} "
            "(add the radial stop or tangential springs)")


def condense(p: Problem, cases: tuple[str, ...] | None = None, factorize: Factorize | None = None,
             schur: str = "auto", threads: int | None = None) -> CondensedSystem:
    """Assemble K, apply frames and couplings, condense onto contact and spring dofs.

    ``factorize``: sparse factorisation (default CHOLMOD, else SuperLU); ``schur``: 'trailing'
    (CHOLMOD, r ordered last), 'rhs' (blocked solves with ``factorize``) or 'auto' (trailing when
    CHOLMOD is available and ``factorize`` is not given). With a distributing coupling 'trailing'
    works on the node blocks (trailing.py); a kinematic coupling goes through the sparse T^T K T.
    ``threads``: BLAS threads for the condensation (None: threads.default_threads()).
    """
    with blas_threads(threads):
        return _condense(p, cases, factorize, schur)


def _condense(p: Problem, cases, factorize, schur) -> CondensedSystem:
    check_mechanism(p)
    names = tuple(p.loads) if cases is None else tuple(cases)
    if schur == "auto":
        schur = "trailing" if (HAVE_CHOLMOD and factorize is None) else "rhs"
    if schur not in ("trailing", "rhs"):
        raise ReferenceSolverError(f"schur = {schur!r}: must be auto, trailing or rhs")
    t0 = time.perf_counter()
    dm = build_dofmap(p)
    F = load_vectors(p, dm, names)
    r = np.concatenate([dm.contact_dofs, dm.spring_dofs])
    times: dict = {}
    # the reduced stiffness is only referenced by the Schur call, which releases it early
    if schur == "trailing" and dm.ref_dofs is None and dm.n_reduced == 3 * p.n_nodes:
        Kq = _reduced_blocks(p, dm, times)
        mark("assembly")
        t2 = time.perf_counter()
        sc = schur_blocks(Kq, r, F)
    else:
        Kq = _reduced_stiffness(p, dm, times)
        mark("assembly")
        t2 = time.perf_counter()
        sc = (schur_trailing(Kq.pop(), r, F) if schur == "trailing"
              else schur_rhs(Kq.pop(), r, F, factorize or default_factorize()))
    t3 = time.perf_counter()
    t1 = t0 + times["assembly_s"]
    nc, ns = p.n_contacts, p.n_springs
    sc.add_diagonal(np.arange(nc, nc + ns), p.spring_k)    # S with the springs: the Schur's own array, no copy
    S = sc.S
    if not (np.all(np.isfinite(S)) and np.all(np.isfinite(sc.fhat))):
        raise ReferenceSolverError("non-finite numbers in the condensed stiffness (check E, nu and the mesh)")
    if ns:
        cf = cholesky_dense(S[nc:, nc:])
        if cf is None:
            raise ReferenceSolverError("mechanism: the spring dofs are not restrained with the contacts held")
        Gs = sla.cho_solve(cf, S[nc:, :nc])
        us0 = sla.cho_solve(cf, sc.fhat[nc:])
        del cf
    else:
        Gs = np.zeros((0, nc))
        us0 = np.zeros((0, len(names)))
    Sc = contact_operator(S, nc, Gs)
    fc = sc.fhat[:nc] - S[:nc, nc:] @ us0
    t4 = time.perf_counter()
    mark("dense")
    info = {"dofs": dm.n_reduced, "retained": int(r.size), "schur": sc.method,
            "assembly_s": t1 - t0, "transform_s": t2 - t1, "condense_s": t3 - t2,
            "dense_s": t4 - t3, **{f"schur_{k}": v for k, v in sc.timings.items()}}
    return CondensedSystem(problem=p, dofmap=dm, case_names=names, S=S, fhat=sc.fhat, Sc=Sc, fc=fc,
                           Gs=Gs, us0=us0, schur=sc, info=info)
