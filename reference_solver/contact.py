"""Contact on the condensed system S_c u = f + r (r: reaction of the master, > 0 compressive).

Gaps g = c0 + u (c0: clearance, g > 0 open). Two methods:
- penalty (CGAP/PGAP semantics): r = -D(g) g with D = k when closed (g <= 0) and k_open when open;
  the bilinear spring energy is convex, so Newton on the states with an energy line search always ends
  in a consistent state.
- Lagrange (exact): the linear complementarity problem w = S g + q >= 0, g >= 0, g.w = 0 with
  q = -(f + S c0), w = r. Solved exactly by a primal-dual active-set (semi-smooth Newton) method
  with a finite primal active-set fallback, both warm-started, or by the paper's projected
  Gauss-Seidel iteration over the slave nodes (over-relaxed, warm-started; slow past liftoff).
"""

from __future__ import annotations

import numpy as np

from .errors import ReferenceSolverError
from .shifted import ShiftedSolver, SubsetSolver


class Unbounded(ReferenceSolverError):
    """No equilibrium: the free set of the Lagrange problem is not held (tipping / lifting off)."""


def penalty_solve(S: np.ndarray, f: np.ndarray, k: np.ndarray, k_open: np.ndarray, c0: np.ndarray,
                  u0: np.ndarray | None = None, maxit: int = 200,
                  solver: ShiftedSolver | None = None) -> tuple[np.ndarray, int]:
    """Displacements u of the contact dofs with bilinear gap springs; returns (u, Newton iterations).

    Newton on the open/closed states (full steps); when a state repeats, the step is damped by an
    Armijo line search on the convex energy 1/2 u'Su - f'u + sum 1/2 D(g) g^2. The solves with
    S + D go through ``solver`` (shifted.ShiftedSolver of ``S``; pass one to share its factor
    between calls along a load path).
    """
    n = f.size
    u = np.zeros(n) if u0 is None else np.array(u0, float)

    def energy(v):
        g = c0 + v
        return 0.5 * v @ (S @ v) - f @ v + 0.5 * np.sum(np.where(g <= 0, k, k_open) * g * g)

    solver = ShiftedSolver(S) if solver is None else solver
    seen = set()
    for it in range(1, maxit + 1):
        g = c0 + u
        closed = g <= 0
        D = np.where(closed, k, k_open)
        u_new = solver.solve(D, f - D * c0)
        if u_new is None:
            raise ReferenceSolverError("penalty: the contact stiffness S + D is not positive definite")
        g_new = c0 + u_new
        if np.all(np.where(closed, g_new <= 0, g_new > 0)):
            return u_new, it
        key = closed.tobytes()
        d = u_new - u
        if key in seen:                               # cycling: damp the step
            e0 = energy(u)
            slope = (S @ u - f + D * g) @ d
            t = 1.0
            while t > 1e-10 and energy(u + t * d) > e0 + 1e-4 * t * slope:
                t *= 0.5
            u = u + (t if t > 1e-10 else 1.0) * d
        else:
            u = u_new
        seen.add(key)
    raise ReferenceSolverError(f"penalty: open/closed states did not settle in {maxit} iterations")


def lcp_active_set(S: np.ndarray, q: np.ndarray, g0: np.ndarray | None = None,
                   max_gap: float = np.inf, maxit: int = 50,
                   solver: SubsetSolver | None = None) -> tuple[np.ndarray, int]:
    """Exact solution g >= 0 of the LCP (w = S g + q >= 0, g.w = 0); returns (g, iterations).

    Primal-dual active set (semi-smooth Newton on min(g, w) = 0): the closed set A holds g = 0,
    the open set I holds w = 0; A is updated from the signs of w_A and g_I until it repeats.
    Warm-started from ``g0``. When it does not settle in ``maxit`` iterations (it can cycle on
    matrices that are not M-matrices) or meets a singular open set, the finite primal active-set
    method :func:`lcp_primal_active_set` finishes from the best feasible point. The solves with
    S_II go through ``solver`` (shifted.SubsetSolver of ``S``; pass one to share it along a path).
    """
    n = q.size
    solver = SubsetSolver(S) if solver is None else solver
    if n == 0:
        return np.zeros(0), 0
    d = np.diag(S)
    closed = np.ones(n, bool) if g0 is None else np.asarray(g0) <= 0
    seen = set()
    for it in range(1, maxit + 1):
        key = closed.tobytes()
        if key in seen:
            break
        seen.add(key)
        I = np.flatnonzero(~closed)
        g = np.zeros(n)
        if I.size:
            gI = solver.solve(I, -q[I])
            if gI is None:
                break
            g[I] = gI
            if not np.all(np.isfinite(g)) or np.abs(g).max() > max_gap:
                break
        w = S @ g + q
        w[I] = 0.0
        new_closed = w - d * g > 0
        if np.array_equal(new_closed, closed):
            if np.all(g >= 0) and np.all(w >= 0):
                return g, it
            break
        closed = new_closed
    g, extra = lcp_primal_active_set(S, q, None if g0 is None else np.maximum(g0, 0.0), max_gap, solver=solver)
    return g, maxit + extra


def lcp_primal_active_set(S: np.ndarray, q: np.ndarray, g0: np.ndarray | None = None,
                          max_gap: float = np.inf, maxit: int | None = None,
                          solver: SubsetSolver | None = None) -> tuple[np.ndarray, int]:
    """Exact solution of the LCP by a primal active-set method (finite; Lawson-Hanson style).

    Minimises 1/2 g'Sg + q'g over g >= 0: the free set holds the open nodes; the node with the most
    negative reaction opens, and steps are cut back to keep g >= 0. Raises :class:`Unbounded` when
    the free set has no stiffness (the load lifts or tips the body off its supports). The solves with
    S_FF go through ``solver`` (shifted.SubsetSolver: bordered updates of one factor, not a dense
    Cholesky per free set; pass the path's to share it).
    """
    solver = SubsetSolver(S) if solver is None else solver
    n = q.size
    maxit = maxit or 10 * n + 50
    g = np.zeros(n) if g0 is None else np.maximum(np.asarray(g0, float), 0.0)
    free = g > 0
    wscale = np.abs(q).max() + np.abs(S).max() * (np.abs(g).max()) + 1e-300
    last = -1
    for it in range(1, maxit + 1):
        while True:                                   # minimise on the free set, staying feasible
            F = np.flatnonzero(free)
            z = np.zeros(n)
            if F.size:
                zF = solver.solve(F, -q[F])
                if zF is None:
                    raise Unbounded("the open contacts have no stiffness")
                z[F] = zF
                if not np.all(np.isfinite(z)) or np.abs(z).max() > max_gap:
                    raise Unbounded("the gaps grow without bound")
            neg = F[z[F] <= 0]
            if neg.size == 0:
                g = z
                break
            alpha = np.min(g[neg] / (g[neg] - z[neg]))
            g = g + alpha * (z - g)
            g[neg[g[neg] <= 1e-15 * (np.abs(g).max() + 1e-300)]] = 0.0
            g[~free] = 0.0
            free = g > 0
        w = S @ g + q
        B = np.flatnonzero(~free)
        if B.size == 0:
            return g, it
        j = B[np.argmin(w[B])]
        if w[j] >= -1e-12 * wscale or j == last:
            return g, it
        free[j] = True
        last = j
        wscale = max(wscale, np.abs(q).max() + np.abs(S).max() * np.abs(g).max())
    raise ReferenceSolverError(f"Lagrange active set did not converge in {maxit} iterations")


def lcp_pgs(S: np.ndarray, q: np.ndarray, g0: np.ndarray | None = None, omega: float = 1.6,
            tol: float = 1e-13, maxit: int = 200_000) -> tuple[np.ndarray, int]:
    """Projected (successive over-relaxed) Gauss-Seidel over the slave nodes; returns (g, sweeps).

    Node by node: g_i <- max(0, g_i - omega (S g + q)_i / S_ii), with the latest values of the
    other nodes. Stops when a sweep changes no gap by more than ``tol`` times the largest gap (or
    an absolute floor from the data scale) and complementarity holds to the same tolerance.
    """
    n = q.size
    g = np.zeros(n) if g0 is None else np.maximum(np.asarray(g0, float), 0.0)
    d = np.diag(S).copy()
    if np.any(d <= 0):
        raise ReferenceSolverError("Gauss-Seidel: non-positive diagonal in the contact operator")
    rows = [np.ascontiguousarray(S[i]) for i in range(n)]
    floor = tol * np.abs(q).max() / d.max()
    for sweep in range(1, maxit + 1):
        dmax = 0.0
        for i in range(n):
            wi = rows[i] @ g + q[i]
            gi = g[i] - omega * wi / d[i]
            if gi < 0.0:
                gi = 0.0
            dg = abs(gi - g[i])
            if dg > dmax:
                dmax = dg
            g[i] = gi
        if dmax <= tol * np.abs(g).max() + floor:
            return g, sweep
        if not np.isfinite(dmax) or np.abs(g).max() > 1e100:
            raise Unbounded("Gauss-Seidel iterates diverge")
    raise ReferenceSolverError(f"Gauss-Seidel did not converge in {maxit} sweeps (use the active-set algorithm)")
