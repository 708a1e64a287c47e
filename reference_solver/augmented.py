"""The augmented Lagrangian (method of multipliers) as a frictionless contact law ('augmented').

On the condensed system S u = f + r, gaps g = c0 + u (> 0 open), r >= 0 compressive [N]. For fixed
multipliers lambda (nc,) [N] the inner problem is the penalty law at epsilon = k_factor x contact_k
[N/m] with the multipliers as pre-loads, r = max(0, lambda - epsilon g): a convex bilinear spring
problem with the shifted clearance c0 - lambda / epsilon, solved by the penalty Newton
(:func:`reference_solver.contact.penalty_solve`, open stiffness ``OPEN`` x epsilon, its factor shared
along the path).
Then lambda <- max(0, lambda - epsilon g) (Anderson-accelerated, depth ``ANDERSON``, projected on
lambda >= 0, restarted when the active set changes; an extrapolation whose inner problem has no bounded
solution falls back on the plain update). A fixed point is exactly the complementarity g >= 0, lambda >= 0, lambda g = 0, so the
converged answer does not depend on epsilon (the Lagrange answer); epsilon sets the cost.

Stops when both hold: the largest penetration max(-g) <= ``PENETRATION`` x the characteristic face size
h = sqrt(median contact area) [m], and the largest multiplier change <= ``MULTIPLIER`` x the largest
multiplier [N]. Warm-started across augmentations (u) and increments (u and lambda of the previous
increment). Each state records its augmentations and its final penetration [m].
"""

from __future__ import annotations

import numpy as np

from .contact import Unbounded, lcp_active_set, penalty_solve
from .errors import ReferenceSolverError
from .laws import ContactLaw, register
from .onset import track_lagrange
from .shifted import ShiftedSolver, SubsetSolver

PENETRATION = 1.0e-10     # penetration tolerance, times the characteristic face size [-]
MULTIPLIER = 1.0e-10      # multiplier-change tolerance, times the largest multiplier [-]
ANDERSON = 40             # depth of the Anderson acceleration of the multiplier updates (0: plain updates);
                          # measured on a 24 x 6 x 1 JAR (72 rows) at k x 0.1: 0.8 s with 40, 2.7 s with 8
MAX_AUGMENTATIONS = 2000
OPEN_GUARD = 1.0e-6       # the guard solve's open stiffness, times epsilon (penalty's default open ratio)
OPEN = 0.0                # the inner problem's open stiffness, times epsilon (0: the exact fixed point; an
                          # open row carries OPEN eps g: 1e-9 gave 1.7e-6 of the peak sigma_n on 24 x 6 x 1)


@register
class AugmentedLaw(ContactLaw):
    """Augmented-Lagrangian unilateral contact, epsilon from the penalty stiffness (see the module docstring)."""
    name, algorithms, uses_k = "augmented", ("multipliers",), True

    def __init__(self, system, k_factor=1.0, algorithm=None):
        super().__init__(system, k_factor, algorithm)
        p = self.problem
        self.eps = self.k_factor * p.contact_k
        self.k_open = OPEN * self.eps
        self.face = float(np.sqrt(np.median(p.contact_area)))
        self.solver = ShiftedSolver(system.Sc)
        self.exact = SubsetSolver(system.Sc)                   # onset tracking on the exact LCP

    @property
    def penalty_k(self):
        return self.eps

    @property
    def tolerance(self) -> float:
        """The penetration tolerance [m]."""
        return PENETRATION * self.face

    def _inner(self, f, lam, u0):
        """The penalty problem at epsilon with the pre-loads ``lam``, from ``u0``; (u, Newton iterations). A
        Newton iterate whose closed rows do not hold the body (S + D singular) is passed by a first solve with
        the open stiffness ``OPEN_GUARD`` x epsilon, then polished without it from there."""
        c = self.c0 - lam / self.eps

        def solve(k_open, start):
            return penalty_solve(self.system.Sc, f, self.eps, k_open, c, start, solver=self.solver)
        try:
            try:
                u, its = solve(self.k_open, u0)
            except ReferenceSolverError:
                v, its = solve(OPEN_GUARD * self.eps, u0)
                u, n = solve(self.k_open, v)
                its += n
        except ReferenceSolverError:
            raise Unbounded("the augmented inner problem has no stiffness (the load lifts the body off)") from None
        if not np.all(np.isfinite(u)) or np.abs(u).max() > self.max_disp:
            raise Unbounded("augmented displacements beyond the sane limit")
        return u, its

    def increment(self, prev, coeffs, guess=None, depth=0):
        f = self.load(coeffs)
        lam = np.maximum(prev.p, 0.0)
        u = self.warm(prev)
        its = 0
        hist_l, hist_g = [], []
        plain = None                                           # the last plain (not extrapolated) update
        for aug in range(1, MAX_AUGMENTATIONS + 1):
            try:
                u, n = self._inner(f, lam, u)
            except Unbounded:
                if plain is None or np.array_equal(plain, lam):
                    raise
                lam, hist_l, hist_g = plain, [], []            # the extrapolation pushed the body off: plain step
                u, n = self._inner(f, lam, u)
            its += n
            g = self.c0 + u
            new = np.maximum(lam - self.eps * g, 0.0)
            change = np.abs(new - lam).max(initial=0.0)
            pen = float(np.maximum(-g, 0.0).max(initial=0.0))
            if pen <= self.tolerance and change <= MULTIPLIER * max(np.abs(new).max(initial=0.0), 1e-300):
                return self.checked(u, new, new > 0, its, augmentations=aug, penetration=pen)
            nxt = plain = new
            if hist_l and not np.array_equal(new > 0, hist_g[-1] > 0):
                hist_l, hist_g = [], []                        # a new active set: the map changed, restart
            if ANDERSON:
                hist_l.append(lam)
                hist_g.append(new)
                del hist_l[:-ANDERSON - 1], hist_g[:-ANDERSON - 1]
                if len(hist_l) > 1:
                    G = np.array(hist_g)
                    F = G - np.array(hist_l)                   # residuals of the fixed point
                    gamma = np.linalg.lstsq(np.diff(F, axis=0).T, F[-1], rcond=None)[0]
                    nxt = np.maximum(new - np.diff(G, axis=0).T @ gamma, 0.0)
            lam = nxt
        raise ReferenceSolverError(f"augmented Lagrangian: the multipliers did not settle in {MAX_AUGMENTATIONS} "
                                   f"augmentations (penetration {pen:.3g} m, tolerance {self.tolerance:.3g} m)")

    def track(self, lo, lam_lo, lam_hi, dcoeffs, watch):
        """The exact (Lagrange) path from the converged state ``lo``: the same complementarity problem."""
        return track_lagrange(self.system.Sc, self.load(dcoeffs), lam_lo, lam_hi, np.maximum(self.c0 + lo.x, 0.0),
                              lo.p, lo.active, watch, solver=self.exact)

    def onset_check(self, lo, coeffs):
        """The exact state (of the LCP this law converges to) at ``coeffs``, warm from ``lo``: the states just
        below and above a tracked onset, which the augmented ones resolve only to the tolerance."""
        S = self.system.Sc
        q = -(self.load(coeffs) + S @ self.c0)
        g, its = lcp_active_set(S, q, np.maximum(self.c0 + lo.x, 0.0), max_gap=self.max_disp, solver=self.exact)
        return self.checked(g - self.c0, np.where(g <= 0, S @ g + q, 0.0), g <= 0, its)

    def arrays(self, states, coeffs):
        out = super().arrays(states, coeffs)
        out["augmentations"] = np.array([st.augmentations for st in states])
        out["penetration"] = np.array([st.penetration for st in states])
        out["penetration_tol"] = self.tolerance
        return out
