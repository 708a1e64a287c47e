"""Tangential springs of a condensed system: re-bind their stiffness without condensing again.

The circumferential springs (``contact.tangential: springs``) are added to the condensed stiffness
after the sparse Schur complement (reference_solver.condense): S = S_schur + diag(0, k_t), then the
contact operator Sc = S_cc - S_cs S_ss^-1 S_sc. Changing k_t therefore only needs the small dense
algebra on the retained dofs, not a new factorisation.

``follow_springs(system, method, k_factor)`` gives the system whose springs honour
``contact.penalty.k_tangent``: when k_t follows k_n (``null``/``follow``: problem.kt_follows_k), a
penalty solve at k-factor f uses k_t = f x k_c of each node (the paper's eq. 3 with the same alpha);
a fixed k_t [N/m] and every exact solve (Lagrange, augmented: ``deckbridge.methods``) keep the springs
as built. A system already bound to a factor is returned as it is for that factor (no second solve). At f = 1 the system is returned
unchanged (same object), so default results do not move.

``follow_springs(..., limit=True)`` gives the limit f -> infinity of those penalty systems for a Lagrange
solve, the reference of a penalty sweep (:mod:`deckbridge.studies`): when k_t follows k_n the springs
become rigid (the circumferential displacement of every table node held at 0, as Lagrange holds the
normal gap exactly; k_t = ``RIGID`` x the largest diagonal entry of the contact operator's block, which
leaves sigma_N within ~1e-11 of the peak of the exact constraint), and a fixed k_t is kept, since
the penalty cases keep it too. The system remembers the choice (``info['spring_limit']``), so a later
``follow_springs`` on it without ``limit`` keeps it.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import scipy.linalg as sla

import reference_solver as rs

from .methods import METHODS

RIGID = 1.0e12       # rigid springs: k_t / max diag of the condensed contact block [-]


def spring_scale(problem: rs.Problem, method: str, k_factor: float, limit: bool = False) -> float:
    """Factor on the springs as built: k_factor for penalty when k_t follows k_n, infinity for the
    Lagrange ``limit`` of such penalty cases (rigid springs), else 1."""
    if not (problem.kt_follows_k and problem.n_springs):
        return 1.0
    if METHODS[method].springs_follow_k:
        return float(k_factor)
    return math.inf if limit else 1.0


def rebind(system: rs.CondensedSystem, problem: rs.Problem, scale: float = 1.0) -> rs.CondensedSystem:
    """``system`` with ``problem`` (same nodes, contacts and spring nodes) and springs problem.spring_k x scale.

    Without springs (a friction system, or none built) only the problem is swapped. Else the springs of
    ``system.problem`` at the scale it was built with (``info['spring_scale']``) are taken out of S first.
    Returns ``system`` itself when nothing changes.
    """
    old = system.problem.spring_k * system.info.get("spring_scale", 1.0)
    new = problem.spring_k * scale
    if problem is system.problem and np.array_equal(old, new):
        return system
    if old.shape != new.shape:
        raise rs.ReferenceSolverError("rebind: the spring nodes differ from the condensed system's")
    nc, ns = system.problem.n_contacts, old.size
    if ns == 0:        # no springs (a friction system: k_t lives in its law): S, Sc, fc do not hold k
        return _with_problem(system, dataclasses.replace(problem, spring_k=new))
    if system.S.shape[0] != nc + ns:
        raise rs.ReferenceSolverError("rebind: the condensed system was stripped of S")
    S = system.S.copy()
    idx = np.arange(nc, nc + ns)
    S[idx, idx] += new - old
    if ns:
        cf = sla.cho_factor(S[nc:, nc:])
        Gs = sla.cho_solve(cf, S[nc:, :nc])
        us0 = sla.cho_solve(cf, system.fhat[nc:])
    else:
        Gs, us0 = system.Gs, system.us0
    Sc = S[:nc, :nc] - S[:nc, nc:] @ Gs
    Sc = 0.5 * (Sc + Sc.T)
    fc = system.fhat[:nc] - S[:nc, nc:] @ us0
    info = {**system.info, "spring_scale": 1.0}
    return dataclasses.replace(system, problem=dataclasses.replace(problem, spring_k=new), S=S, Sc=Sc, fc=fc,
                               Gs=Gs, us0=us0, info=info)


def _with_problem(system, problem: rs.Problem):
    """``system`` solving ``problem`` (same nodes, contacts, condensation): the contact stiffness and the
    friction law's k_t are read from the problem at solve time. A :class:`reference_solver.FrictionSystem`
    drops its views under the other corner rule (they hold the old problem); its H0^-1 cache is keyed by
    the stiffness values, so it is shared."""
    if isinstance(system, rs.FrictionSystem):
        return dataclasses.replace(system, problem=problem, views={})
    return dataclasses.replace(system, problem=problem)


def follow_springs(system: rs.CondensedSystem, method: str, k_factor: float,
                   limit: bool | None = None) -> rs.CondensedSystem:
    """The system a solve with ``method`` at ``k_factor`` runs on (see the module docstring);
    ``limit``: the Lagrange reference of penalty cases (rigid following springs); None = as ``system``."""
    if limit is None:
        limit = bool(system.info.get("spring_limit", False))
    base = system.info.get("spring_base")
    if base is None:                      # the springs as built (before any follow scaling)
        base = system.problem
    s = spring_scale(base, method, k_factor, limit)
    if s == 1.0 and base is system.problem:
        return system
    if system.info.get("spring_base") is base and system.info.get("spring_factor") == s:
        return system                     # already bound to this factor: no second dense solve
    if math.isinf(s) and system.info.get("spring_limit"):
        return system
    if math.isinf(s):                     # rigid: one stiffness far above the body's, at every spring
        nc = base.n_contacts
        k_rigid = RIGID * float(np.abs(np.diag(system.S)[:nc]).max(initial=0.0) or 1.0)
        out = rebind(system, dataclasses.replace(base, spring_k=np.full(base.n_springs, k_rigid)))
    else:
        out = rebind(system, base, s)
    out.info["spring_base"] = base
    out.info["spring_factor"] = s
    out.info["spring_limit"] = bool(limit and math.isinf(s))
    return out
