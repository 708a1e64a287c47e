"""The load path on a condensed system: step 1 (base load), step 2 (base + lambda * ramp).

Every increment is a small dense problem on the contact dofs. The liftoff onset (first contact row of
``liftoff_surface`` that opens, gap > 0, i.e. sigma_n >= 0) is bracketed by the increments, then located
exactly by following the piecewise-linear path inside the bracket (onset.py), checked by two full solves
just below and above it; when that fails, by bisection on lambda to ``liftoff_tol``.
"""

from __future__ import annotations

import time
from typing import Callable, Mapping

import numpy as np

from .condense import CondensedSystem
from .contact import Unbounded, lcp_active_set, lcp_pgs, penalty_solve
from .errors import ReferenceSolverError, no_equilibrium
from .friction import FrictionSystem
from .friction_path import solve_friction_path
from .onset import track_lagrange, track_penalty
from .shifted import ShiftedSolver, SubsetSolver
from .solution import Solution  # noqa: F401  (re-exported: reference_solver.path.Solution)
from .threads import with_blas_threads

METHODS = ("penalty", "lagrange")
ALGORITHMS = {"penalty": ("newton",), "lagrange": ("active-set", "gauss-seidel")}


def _solve_state(sysm: CondensedSystem, method: str, algorithm: str, coeffs: np.ndarray,
                 k: np.ndarray | None, k_open: np.ndarray | None, warm: np.ndarray | None,
                 max_disp: float, solver=None):
    p = sysm.problem
    f = sysm.fc @ coeffs
    c0 = p.contact_clearance
    if method == "penalty":
        u, its = penalty_solve(sysm.Sc, f, k, k_open, c0, warm, solver=solver)
        if not np.all(np.isfinite(u)) or np.abs(u).max() > max_disp:
            raise Unbounded("penalty displacements beyond the sane limit")
        force = -np.where(c0 + u <= 0, k, k_open) * (c0 + u)
        closed = c0 + u <= 0
    else:
        q = -(f + sysm.Sc @ c0)
        g0 = None if warm is None else c0 + warm
        if algorithm == "gauss-seidel":
            g, its = lcp_pgs(sysm.Sc, q, g0)
        else:
            g, its = lcp_active_set(sysm.Sc, q, g0, max_gap=max_disp, solver=solver)
        if np.abs(g).max() > max_disp:
            raise Unbounded("gaps beyond the sane limit")
        u = g - c0
        force = sysm.Sc @ g + q
        closed = g <= 0
        force = np.where(closed, force, 0.0)
    if not (np.all(np.isfinite(u)) and np.all(np.isfinite(force))):
        raise ReferenceSolverError("non-finite contact results")
    return u, force, closed, its


@with_blas_threads
def solve_path(sysm: CondensedSystem, method: str = "penalty", k_factor: float = 1.0, *,
               base: Mapping[str, float] | None = None, ramp: Mapping[str, float] | None = None,
               lambda_max: float = 1.0, increments: int = 10, algorithm: str | None = None,
               liftoff_surface: str | None = "table", liftoff_tol: float = 1e-6,
               onset: str = "auto", recover: bool = True, on_increment: Callable[[int, int, float], None] | None = None,
               **friction) -> Solution:
    """Run step 1 (``base``) and step 2 (``base + lambda * ramp``, lambda = j lambda_max / increments).

    ``k_factor`` multiplies the problem's penalty stiffness (penalty only). Defaults: base {'N': 1},
    ramp {'T': 1, 'M': 1}. ``liftoff_tol``: bisection tolerance on lambda relative to lambda_max (the
    fallback; the path-following onset is exact to round-off). A :class:`FrictionSystem` runs the
    friction path (:func:`reference_solver.friction_path.solve_friction_path`; ``friction`` keywords
    ``targets``, ``on_gross_slip`` go there).
    """
    if isinstance(sysm, FrictionSystem):
        return solve_friction_path(sysm, method, k_factor, base=base, ramp=ramp, lambda_max=lambda_max,
                                   increments=increments, algorithm=algorithm, liftoff_surface=liftoff_surface,
                                   liftoff_tol=liftoff_tol, onset=onset, recover=recover,
                                   on_increment=on_increment, **friction)
    if friction:
        raise ReferenceSolverError(f"{', '.join(friction)}: only with a friction system (tangential = 'friction')")
    t0 = time.perf_counter()
    p = sysm.problem
    if method not in METHODS:
        raise ReferenceSolverError(f"method = {method!r}: must be penalty or lagrange")
    algorithm = algorithm or ALGORITHMS[method][0]
    if algorithm not in ALGORITHMS[method]:
        raise ReferenceSolverError(f"algorithm = {algorithm!r}: {method} offers {', '.join(ALGORITHMS[method])}")
    if not (np.isfinite(k_factor) and k_factor > 0):
        raise ReferenceSolverError(f"k_factor = {k_factor!r}: must be > 0")
    if onset not in ("auto", "bisection"):
        raise ReferenceSolverError(f"onset = {onset!r}: must be auto or bisection")
    if increments < 1 or not (lambda_max > 0):
        raise ReferenceSolverError("increments must be >= 1 and lambda_max > 0")
    base = {"N": 1.0} if base is None else dict(base)
    ramp = {"T": 1.0, "M": 1.0} if ramp is None else dict(ramp)
    cb, cr = sysm.coeffs(base), sysm.coeffs(ramp)
    k = k_factor * p.contact_k if method == "penalty" else None
    k_open = p.k_open_ratio * k if method == "penalty" else None
    max_disp = p.max_displacement or p.length_scale()
    watch = np.ones(p.n_contacts, bool) if liftoff_surface is None else p.contact_surface == liftoff_surface

    solver = ShiftedSolver(sysm.Sc) if method == "penalty" else SubsetSolver(sysm.Sc)  # shared along the path

    def run(coeffs, warm, step, lam):
        try:
            return _solve_state(sysm, method, algorithm, coeffs, k, k_open, warm, max_disp, solver)
        except Unbounded:
            raise no_equilibrium(step, lam) from None

    rows = []
    u1, f1, c1, it1 = run(cb, None, 1, 0.0)
    rows.append((1, 1, 0.0, cb, u1, f1, c1, it1))
    if on_increment:
        on_increment(1, 1, 0.0)
    warm = u1
    for j in range(increments + 1):
        lam = j * lambda_max / increments
        co = cb + lam * cr
        u, fo, cl, its = (u1, f1, c1, 0) if j == 0 else run(co, warm, 2, lam)
        if method == "penalty" and watch.any() and not np.any(cl & watch):
            raise ReferenceSolverError(
                f"step 2, load factor {lam:.6g}: the load tips the body over (every {liftoff_surface} contact is open)")
        rows.append((2, j, lam, co, u, fo, cl, its))
        warm = u
        if on_increment:
            on_increment(2, j, lam)

    gap_of = lambda u: p.contact_clearance + u  # noqa: E731
    lift_lf, lift_row, lift_how = None, None, None
    opened = [np.any(watch & (gap_of(r[4]) > 0) & ~r[6]) for r in rows[1:]]
    if any(opened):
        j = opened.index(True)
        if j == 0:
            lift_lf = 0.0
            hi_u = rows[1][4]
        else:
            lo, hi = rows[1 + j - 1][2], rows[1 + j][2]
            lo_u, hi_u = rows[1 + j - 1][4], rows[1 + j][4]
            is_open = lambda st: np.any(watch & (gap_of(st[0]) > 0) & ~st[2])  # noqa: E731
            fr = sysm.fc @ cr
            if onset == "bisection":
                ev = None
            elif method == "penalty":
                ev = track_penalty(sysm.Sc, fr, k, k_open, p.contact_clearance, lo, hi, lo_u, watch, solver=solver)
            else:
                prev = rows[1 + j - 1]
                ev = track_lagrange(sysm.Sc, fr, lo, hi, gap_of(prev[4]), prev[5], prev[6], watch, solver=solver)
            delta = min(1e-7, 0.1 * liftoff_tol) * lambda_max
            if ev is not None and lo < ev[0] - delta and ev[0] + delta < hi:
                below = run(cb + (ev[0] - delta) * cr, lo_u, 2, ev[0] - delta)
                above = run(cb + (ev[0] + delta) * cr, lo_u, 2, ev[0] + delta)
                if not is_open(below) and is_open(above):
                    lift_lf, lift_row = float(ev[0]), int(ev[1])
                    lift_how = "path-following"
            if lift_lf is None:                                  # bisection on lambda
                while hi - lo > liftoff_tol * lambda_max:
                    mid = 0.5 * (lo + hi)
                    st = run(cb + mid * cr, lo_u, 2, mid)
                    if is_open(st):
                        hi, hi_u = mid, st[0]
                    else:
                        lo, lo_u = mid, st[0]
                lift_lf = hi
                lift_how = "bisection"
        if lift_row is None:
            cand = np.flatnonzero(watch)
            lift_row = int(cand[np.argmax(gap_of(hi_u)[cand])])

    step = np.array([r[0] for r in rows])
    U = np.array([r[4] for r in rows])
    Fo = np.array([r[5] for r in rows])
    C = np.array([r[3] for r in rows])
    us = np.array([sysm.spring_displacement(r[4], r[3]) for r in rows]).reshape(len(rows), -1)
    sol = Solution(
        method=method, algorithm=algorithm, k_factor=k_factor if method == "penalty" else None,
        penalty_k=k, step=step, increment=np.array([r[1] for r in rows]),
        load_factor=np.array([r[2] for r in rows]), coeffs=C, u=U, gap=gap_of(U), force=Fo,
        sigma_n=0.0 - Fo / p.contact_area, closed=np.array([r[6] for r in rows]), spring_u=us,
        spring_force=-p.spring_k * us, iterations=np.array([r[7] for r in rows]),
        liftoff_load_factor=lift_lf, liftoff_row=lift_row, liftoff_method=lift_how)
    if recover:
        sol.recover_step_ends(sysm, U)
    sol.wall_time_s = time.perf_counter() - t0
    return sol
