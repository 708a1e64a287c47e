"""Coulomb friction as a stateful contact law (the interface of :mod:`reference_solver.laws`).

Bound to a :class:`reference_solver.friction.FrictionSystem` (normal, spring and tangential dofs retained).
Every increment starts from the previous converged state (tangential forces and slip history), so the
law is path-dependent (``stateful``): onsets are bisected by sub-increments, never tracked. The
increment itself is :func:`reference_solver.friction.solve_increment` of the method ('penalty':
return mapping; 'lagrange': exact, semi-smooth Newton; 'augmented': the augmented-Lagrangian multiplier
updates with the penalty stiffness as epsilon). Units and signs as in :mod:`reference_solver.friction`.
"""

from __future__ import annotations

import numpy as np

from .errors import ReferenceSolverError
from .friction import CORNER_RULE, RHO_FACTOR, solve_increment
from .friction_state import State
from .onset import SLIDE_TOL


QUICK_DEPTH = 2           # Lagrange: cutbacks tried with the direct Newton alone before its fallbacks
ALGORITHMS = {"penalty": "newton", "lagrange": "semi-smooth-newton", "augmented": "augmented-lagrangian"}


class FrictionLaw:
    """The friction law of ``method`` on ``sysf`` at penalty factor ``k_factor`` (see the module docstring)."""
    stateful, onset_floor = True, SLIDE_TOL

    def __init__(self, sysf, method: str, k_factor: float = 1.0, algorithm: str | None = None,
                 corner: str | None = None):
        if method not in ALGORITHMS:
            raise ReferenceSolverError(f"method = {method!r}: with friction, one of {', '.join(ALGORITHMS)}")
        self.name, self.algorithm = method, ALGORITHMS[method]
        if algorithm not in (None, self.algorithm):
            raise ReferenceSolverError(f"algorithm = {algorithm!r}: {method} with friction offers {self.algorithm}")
        self.uses_k = method != "lagrange"
        self.tips_open = method == "penalty"
        self.sysf = sysf.with_corner(corner or CORNER_RULE[method])
        p = self.problem = sysf.problem
        fr = sysf.rows
        kf = k_factor if self.uses_k else 1.0
        self.k = kf * p.contact_k
        self.k_open = p.k_open_ratio * self.k
        self.kt = (kf if p.kt_follows_k else 1.0) * p.contact_kt[fr]
        self.rho = self.k if method == "augmented" else RHO_FACTOR * np.diag(sysf.S)[:p.n_contacts]
        self.max_disp = p.max_displacement or p.length_scale()

    @property
    def penalty_k(self):
        return self.k if self.uses_k else None

    def start(self) -> State:
        p, nf = self.problem, self.sysf.rows.size
        return State(x=np.zeros(self.sysf.S.shape[0]), p=np.zeros(p.n_contacts), t=np.zeros((nf, 2)),
                     active=p.contact_clearance <= 0, slip=np.zeros(nf, bool))

    def increment(self, prev: State, coeffs, guess=None, depth: int = 0) -> State:
        p = self.problem
        return solve_increment(self.sysf, self.name, self.sysf.fhat @ coeffs, prev, self.k, self.k_open, self.kt,
                               p.friction, self.max_disp, self.rho, quick=depth < QUICK_DEPTH, guess=guess)

    def track(self, *args):
        return None

    def retained(self, states) -> np.ndarray:
        return np.array([st.x for st in states])

    def arrays(self, states, coeffs) -> dict:
        p = self.problem
        X = self.retained(states)
        U = X[:, :p.n_contacts]
        act = np.array([st.active for st in states])
        if self.name == "penalty":
            F, closed = np.array([st.p for st in states]), p.contact_clearance + U <= 0
        else:
            F, closed = np.where(act, np.array([st.p for st in states]), 0.0), act
        ft, dslip, status, diss = self._outputs(states)
        us = X[:, p.n_contacts:p.n_contacts + p.n_springs]
        out = {"u": U, "gap": p.contact_clearance + U, "force": F, "closed": closed, "spring_u": us,
               "spring_force": -p.spring_k * us, "iterations": np.array([st.iterations for st in states]),
               "tangential": "friction", "tangential_force": ft, "slip_increment": dslip, "stick_status": status,
               "dissipation": diss, "retained_u": X}
        if self.name == "augmented":
            out["augmentations"] = np.array([st.augmentations for st in states])
            out["penetration"] = np.maximum(-(p.contact_clearance + U), 0.0).max(axis=1)
        return out

    def _outputs(self, states):
        """Per-increment arrays: tangential force and slip increment (global, [N], [m]), status, dissipation."""
        sysf, p = self.sysf, self.problem
        ni, nc, fr = len(states), p.n_contacts, sysf.rows
        ft = np.zeros((ni, nc, 3))
        dslip = np.zeros((ni, nc, 3))
        status = np.where(np.array([st.active for st in states]), "frictionless", "open").astype(object)
        diss = np.zeros(ni)
        prev = None
        for i, st in enumerate(states):
            ft[i, fr] = np.einsum("fa,fak->fk", st.t, sysf.tdir)
            s = st.x[sysf.tdofs]
            s0 = np.zeros_like(s) if prev is None else prev.x[sysf.tdofs]
            t0 = np.zeros_like(st.t) if prev is None else prev.t
            d = np.where(sysf.axes(st.active), s - s0, 0.0)
            if self.name == "penalty":
                d = d + (st.t - t0) / self.kt[:, None]     # minus the elastic part: the slip (plastic) increment
            d = np.where(st.active[fr][:, None], d, 0.0)
            dslip[i, fr] = np.einsum("fa,fak->fk", d, sysf.tdir)
            diss[i] = float(-np.sum(st.t * d))
            status[i, fr] = np.where(st.active[fr], np.where(st.slip, "slip", "stick"), "open")
            prev = st
        return ft, dslip, status.astype(str), diss
