"""Contact laws: what one load increment means on a condensed system, behind one interface.

A law is bound to a condensed system (``law = LAWS[method](system, k_factor, algorithm)``) and answers:

- ``start()`` the unloaded :class:`State`;
- ``increment(prev, coeffs, guess=None, depth=0)`` the converged state at the load ``coeffs`` (load-case
  coefficients) reached from ``prev`` (path-dependent laws) or warm-started from it (path-independent
  ones); raises :class:`Unbounded` (no bounded equilibrium), ``NotConverged`` (the driver cuts the
  increment back; ``depth`` = cutbacks so far) or ``GrossSlip``;
- ``track(lo, lam_lo, lam_hi, dcoeffs, watch)`` the exact onset ``(lambda, row)`` inside a bracket by
  following the piecewise-linear path (:mod:`reference_solver.onset`), or None (the driver bisects);
- ``onset_watch(watch)`` the watched rows whose opening is a liftoff (default: all of ``watch``), ``lifted(state,
  watch)`` (optional) which of them are lifted in a state (default: gap > 0 and not closed, onset.lifted_rows);
- ``arrays(states)`` the per-increment arrays of :class:`reference_solver.solution.Solution`;
- ``retained(states)`` the retained displacements that ``system.recover`` turns into fields.

Class attributes: ``name`` (the method), ``algorithms`` (first = default), ``uses_k`` (the k-factor
scales its penalty), ``stateful`` (path-dependent: onsets bisected by sub-increments from the last
converged state, never tracked), ``tips_open`` (an all-open watched surface is a tip-over: the law stays
bounded without contact, penalty's open stiffness), ``onset_floor`` (the least bisection tolerance on
lambda, relative).

Units and signs: u / x [m], gaps g = clearance + u [m] (> 0 open), forces p [N] (> 0 compressive).
The registry :data:`LAWS` lists the frictionless laws; :func:`make_law` picks the friction law for a
friction system (:mod:`reference_solver.friction_law`; on face-weighted rows :mod:`reference_solver.friction_face`). "Add a contact law" in ARCHITECTURE.md.
"""

from __future__ import annotations

import numpy as np

from .contact import Unbounded, lcp_active_set, lcp_pgs, penalty_solve
from .errors import ReferenceSolverError
from .friction_state import State
from .onset import track_lagrange, track_penalty
from .shifted import ShiftedSolver, SubsetSolver


class ContactLaw:
    """A frictionless law on a :class:`reference_solver.condense.CondensedSystem` (contact dofs only)."""
    name = ""
    algorithms: tuple[str, ...] = ()
    uses_k = False
    stateful = False
    tips_open = False
    onset_floor = 0.0

    def __init__(self, system, k_factor: float = 1.0, algorithm: str | None = None):
        p = system.problem
        self.system, self.problem = system, p
        self.k_factor = float(k_factor)
        self.algorithm = algorithm or self.algorithms[0]
        if self.algorithm not in self.algorithms:
            raise ReferenceSolverError(f"algorithm = {algorithm!r}: {self.name} offers {', '.join(self.algorithms)}")
        self.max_disp = p.max_displacement or p.length_scale()
        self.c0 = p.contact_clearance
        self._zero = State(x=np.zeros(p.n_contacts), p=np.zeros(p.n_contacts), t=np.zeros((0, 2)),
                           active=self.c0 <= 0, slip=np.zeros(0, bool))

    @property
    def penalty_k(self) -> np.ndarray | None:
        """The penalty stiffness of each contact row [N/m], None for an exact law."""
        return None

    def start(self) -> State:
        return self._zero

    def warm(self, prev: State) -> np.ndarray | None:
        """The displacements an increment starts from (None from the unloaded state)."""
        return None if prev is self._zero else prev.x

    def load(self, coeffs: np.ndarray) -> np.ndarray:
        return self.system.fc @ coeffs

    def increment(self, prev: State, coeffs: np.ndarray, guess=None, depth: int = 0) -> State:
        raise NotImplementedError

    def track(self, lo: State, lam_lo: float, lam_hi: float, dcoeffs: np.ndarray, watch: np.ndarray):
        return None

    def onset_watch(self, watch: np.ndarray) -> np.ndarray:
        """The rows of ``watch`` (bool per contact row) whose opening is a liftoff: all of them."""
        return watch

    def checked(self, u, force, closed, its, **extra) -> State:
        if not (np.all(np.isfinite(u)) and np.all(np.isfinite(force))):
            raise ReferenceSolverError("non-finite contact results")
        return State(x=u, p=force, t=self._zero.t, active=closed, slip=self._zero.slip, iterations=its, **extra)

    def arrays(self, states: list[State], coeffs: np.ndarray) -> dict:
        p = self.problem
        U = np.array([st.x for st in states])
        us = np.array([self.system.spring_displacement(u, c) for u, c in zip(U, coeffs)]).reshape(len(U), -1)
        return {"u": U, "gap": self.c0 + U, "force": np.array([st.p for st in states]),
                "closed": np.array([st.active for st in states]), "spring_u": us, "spring_force": -p.spring_k * us,
                "iterations": np.array([st.iterations for st in states])}

    def retained(self, states: list[State]) -> np.ndarray:
        return np.array([st.x for st in states])

    def sigma_n(self, force: np.ndarray) -> np.ndarray:
        """sigma_N [Pa] (< 0 compression) of the per-increment row forces (ni, nc) [N]: -force / area."""
        return 0.0 - force / self.problem.contact_area


class PenaltyLaw(ContactLaw):
    """Bilinear gap springs (CGAP/PGAP): k = k_factor x contact_k closed, k_open_ratio x k open."""
    name, algorithms, uses_k, tips_open = "penalty", ("newton",), True, True

    def __init__(self, system, k_factor=1.0, algorithm=None):
        super().__init__(system, k_factor, algorithm)
        self.k = self.k_factor * self.problem.contact_k
        self.k_open = self.problem.k_open_ratio * self.k
        self.solver = ShiftedSolver(system.Sc)                 # shared along the path

    @property
    def penalty_k(self):
        return self.k

    def increment(self, prev, coeffs, guess=None, depth=0):
        u, its = penalty_solve(self.system.Sc, self.load(coeffs), self.k, self.k_open, self.c0, self.warm(prev),
                               solver=self.solver)
        if not np.all(np.isfinite(u)) or np.abs(u).max() > self.max_disp:
            raise Unbounded("penalty displacements beyond the sane limit")
        g = self.c0 + u
        return self.checked(u, -np.where(g <= 0, self.k, self.k_open) * g, g <= 0, its)

    def track(self, lo, lam_lo, lam_hi, dcoeffs, watch):
        return track_penalty(self.system.Sc, self.load(dcoeffs), self.k, self.k_open, self.c0, lam_lo, lam_hi,
                             lo.x, watch, solver=self.solver)


class LagrangeLaw(ContactLaw):
    """Exact unilateral contact: the LCP w = S g + q >= 0, g >= 0, g.w = 0 (q = -(f + S c0))."""
    name, algorithms = "lagrange", ("active-set", "gauss-seidel")

    def __init__(self, system, k_factor=1.0, algorithm=None):
        super().__init__(system, k_factor, algorithm)
        self.weighted = None                                   # face_law.FaceWeighting, or nodal rows
        if self.problem.contact_weighting != "nodal":
            from .face_law import FaceWeighting
            self.weighted = FaceWeighting(self.problem, system.Sc)
        self.solver = SubsetSolver(system.Sc if self.weighted is None else self.weighted.S)

    def increment(self, prev, coeffs, guess=None, depth=0):
        if self.weighted is not None:
            return self._weighted_increment(prev, coeffs)
        S = self.system.Sc
        q = -(self.load(coeffs) + S @ self.c0)
        warm = self.warm(prev)
        g0 = None if warm is None else self.c0 + warm
        if self.algorithm == "gauss-seidel":
            g, its = lcp_pgs(S, q, g0)
        else:
            g, its = lcp_active_set(S, q, g0, max_gap=self.max_disp, solver=self.solver)
        if np.abs(g).max() > self.max_disp:
            raise Unbounded("gaps beyond the sane limit")
        closed = g <= 0
        return self.checked(g - self.c0, np.where(closed, S @ g + q, 0.0), closed, its)

    def _weighted_increment(self, prev, coeffs):
        """The LCP in weighted gaps g~ = D g and pressures lambda (face_law.py); forces r = D^T lambda [N]."""
        W = self.weighted
        q = W.to_pressure(-(self.load(coeffs) + self.system.Sc @ self.c0))
        warm = self.warm(prev)
        g0 = None if warm is None else W.weigh(self.c0 + warm)
        if self.algorithm == "gauss-seidel":
            gw, its = lcp_pgs(W.S, q, g0)
        else:
            gw, its = lcp_active_set(W.S, q, g0, solver=self.solver)
        g = W.to_gap(gw)
        if np.abs(g).max() > self.max_disp:
            raise Unbounded("gaps beyond the sane limit")
        closed = gw <= 0
        lam = np.where(closed, W.S @ gw + q, 0.0)
        return self.checked(g - self.c0, W.to_force(lam), closed, its,
                            penetration=float(max(0.0, -g.min(initial=0.0))))

    def onset_watch(self, watch):
        """The watched rows whose opening is a liftoff onset: every one (face-weighted with the hat basis a row's
        pressure is its own multiplier, face_law.py)."""
        return watch

    def lifted(self, st, watch):
        """Bool per row: watched and lifted. Face-weighted: an :meth:`onset_watch` row that is open (lambda = 0,
        weighted gap > 0): the pressure field is 0 at its node; its nodal gap D^-1 g~ may still be <= 0 by
        the weak condition's ~1e-3 of the open gaps. Nodal: gap > 0 and not closed."""
        if self.weighted is None:
            return watch & (self.c0 + st.x[:self.c0.size] > 0) & ~st.active
        return self.onset_watch(watch) & ~st.active

    def sigma_n(self, force):
        """Face-weighted: the pressure field's nodal values -lambda, lambda = D^-T r (face_law.py)."""
        if self.weighted is None:
            return super().sigma_n(force)
        return 0.0 - self.weighted.to_pressure(np.asarray(force, float).T).T

    def track(self, lo, lam_lo, lam_hi, dcoeffs, watch):
        """Exact onset: the piecewise-linear path of the LCP; face-weighted, in its own variables (weighted gaps
        g~ = D (c0 + x), multipliers lambda = D^-T r, load rate D^-T f'), whose rows open when lambda hits 0."""
        if self.weighted is not None:
            W = self.weighted
            return track_lagrange(W.S, W.to_pressure(self.load(dcoeffs)), lam_lo, lam_hi, W.weigh(self.c0 + lo.x),
                                  W.to_pressure(lo.p), lo.active, watch, solver=self.solver)
        return track_lagrange(self.system.Sc, self.load(dcoeffs), lam_lo, lam_hi, self.c0 + lo.x, lo.p, lo.active,
                              watch, solver=self.solver)


LAWS: dict[str, type[ContactLaw]] = {"penalty": PenaltyLaw, "lagrange": LagrangeLaw}


# Laws that replace a method's own on a weighted problem, by (contact_weighting, method); filled by their modules
# (face_penalty.py: ('face', 'penalty'), imported by the package). LagrangeLaw weighs its own rows (face_law.py).
WEIGHTED_LAWS: dict[tuple[str, str], type[ContactLaw]] = {}


def register(law: type[ContactLaw]) -> type[ContactLaw]:
    """Add a frictionless law to :data:`LAWS` under its ``name`` (usable as a class decorator)."""
    LAWS[law.name] = law
    return law


def make_law(system, method: str, k_factor: float = 1.0, algorithm: str | None = None, **options):
    """The law ``method`` bound to ``system``: a friction system gets the friction law of that method."""
    if not (np.isfinite(k_factor) and k_factor > 0):
        raise ReferenceSolverError(f"k_factor = {k_factor!r}: must be > 0")
    if hasattr(system, "tdofs"):                               # a FrictionSystem
        if system.problem.contact_weighting != "nodal":              # Coulomb on the multipliers
            from .friction_face import FaceFrictionLaw
            return FaceFrictionLaw(system, method, k_factor, algorithm, **options)
        from .friction_law import FrictionLaw
        return FrictionLaw(system, method, k_factor, algorithm, **options)
    if options:
        raise ReferenceSolverError(f"{', '.join(options)}: only with a friction system (tangential = 'friction')")
    if method not in LAWS:
        raise ReferenceSolverError(f"method = {method!r}: must be one of {', '.join(LAWS)}")
    weighting = system.problem.contact_weighting
    if (weighting, method) in WEIGHTED_LAWS:                   # e.g. ('face', 'penalty'): face_penalty.py
        return WEIGHTED_LAWS[weighting, method](system, k_factor, algorithm)
    if weighting != "nodal" and method != "lagrange":
        raise ReferenceSolverError(f"contact_weighting = {weighting!r}: only the lagrange method has a "
                                   f"{weighting}-weighted law (not {method}); use lagrange"
                                   + (" (or 'face' for penalty)" if method == "penalty" else ""))
    return LAWS[method](system, k_factor, algorithm)
