"""Whole-section liftoff onset: the first load factor at which every contact row of one group (e.g.
the through-wall nodes of one azimuth) is open.

Uses only the public path API (:func:`reference_solver.solve_path`): the contact state at a load
factor does not depend on the path (penalty: convex bilinear springs; Lagrange: LCP with a positive
definite operator), so the state at lambda is one ``solve_path`` with a single increment. The onset is
bracketed by the increments of a solution, then located as the first root of

    phi(lambda) = max over groups of (min over the group's rows of m_i),  m_i = gap_i - force_i / S_ii

(a closed Lagrange row has gap 0 and force > 0; a penalty row's gap is negative while closed), which is
continuous and piecewise linear in lambda: Illinois regula falsi, exact once the bracket lies in one
linear piece, with bisection steps as fallback, to ``tol`` on lambda or |phi| < 1e-12 of its scale.
Rows are open when their gap is > 0 and they are not closed (the test of the first-node onset).
"""

from __future__ import annotations

from typing import Mapping

import numpy as np

from .condense import CondensedSystem
from .path import Solution, solve_path

NO_WATCH = "__no_onset__"       # a surface name no row has: solve_path then locates no first-node onset


def group_open(gap: np.ndarray, closed: np.ndarray, groups: list[np.ndarray]) -> np.ndarray:
    """(n_groups,) True where every row of the group is open (gap > 0 and not closed)."""
    is_open = (np.asarray(gap) > 0) & ~np.asarray(closed, bool)
    return np.array([bool(is_open[g].all()) for g in groups])


def section_onset(sysm: CondensedSystem, sol: Solution, groups: list[np.ndarray], *,
                  base: Mapping[str, float] | None = None, ramp: Mapping[str, float] | None = None,
                  tol: float = 1e-9) -> tuple[float | None, int | None]:
    """(lambda, group index) of the first load factor of step 2 at which a whole group is open, or
    (None, None) when none opens along ``sol``. ``groups``: row indices (into the contact rows) of each
    group; ``sol`` the solved path (its method, penalty factor, load factors); ``base``/``ramp`` as given
    to :func:`solve_path` (defaults the same)."""
    rows2 = np.flatnonzero(sol.step == 2)
    hit = [j for j in rows2 if group_open(sol.gap[j], sol.closed[j], groups).any()]
    if not hit:
        return None, None
    j = hit[0]
    hi = float(sol.load_factor[j])
    before = [i for i in rows2 if i < j]
    if not before:
        return hi, int(np.flatnonzero(group_open(sol.gap[j], sol.closed[j], groups))[0])
    lo = float(sol.load_factor[before[-1]])
    kf = sol.k_factor if sol.method == "penalty" else 1.0

    # the normal dofs' condensed stiffness (a friction system retains them first in S)
    diag = (np.diag(sysm.Sc) if hasattr(sysm, "Sc") else np.diag(sysm.S)[:sysm.n_contacts]).copy()

    def measure(gap, force, closed):
        m = np.where(closed, gap - force / diag, gap)
        return np.array([m[g].min() for g in groups])

    def state(lam: float):
        s = solve_path(sysm, sol.method, kf, base=base, ramp=ramp, lambda_max=lam, increments=1,
                       algorithm=sol.algorithm, liftoff_surface=NO_WATCH, recover=False)
        return measure(s.gap[-1], s.force[-1], s.closed[-1]), group_open(s.gap[-1], s.closed[-1], groups)

    i_lo = before[-1]
    f_lo = float(measure(sol.gap[i_lo], sol.force[i_lo], sol.closed[i_lo]).max())
    m_hi = measure(sol.gap[j], sol.force[j], sol.closed[j])
    f_hi, up_hi = float(m_hi.max()), group_open(sol.gap[j], sol.closed[j], groups)
    scale = max(abs(f_lo), abs(f_hi), 1e-300)
    side = 0
    for _ in range(200):
        if hi - lo <= tol:
            break
        x = lo - f_lo * (hi - lo) / (f_hi - f_lo) if f_hi != f_lo else 0.5 * (lo + hi)
        if not (lo < x < hi):
            x = 0.5 * (lo + hi)
        m, up = state(x)
        fx = float(m.max())
        if up.any() or fx > 0:
            hi, f_hi, up_hi = x, fx, up if up.any() else up_hi
            if side == 1:
                f_lo *= 0.5                  # Illinois: the stale end's value halves
            side = 1
        else:
            lo, f_lo = x, fx
            if side == -1:
                f_hi *= 0.5
            side = -1
        if abs(fx) <= 1e-12 * scale:
            return x, int(np.argmax(m))          # the root itself (phi linear around it)
    return hi, int(np.flatnonzero(up_hi)[0]) if up_hi.any() else int(np.argmax(m_hi))
