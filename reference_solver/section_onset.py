"""Whole-section liftoff onset: the first load factor at which every contact row of one group (e.g.
the through-wall nodes of one azimuth) is open.

Uses only the public path API (:func:`reference_solver.solve_path`): the contact state at a load
factor does not depend on the path (penalty: convex bilinear springs; Lagrange: LCP with a positive
definite operator), so the state at lambda is one ``solve_path`` with a single increment. The onset is
bracketed by the increments of a solution, then bisected to ``tol`` (absolute on lambda). Rows are
open when their gap is > 0 and they are not closed (the test of the first-node onset).
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

    def state(lam: float) -> np.ndarray:
        s = solve_path(sysm, sol.method, kf, base=base, ramp=ramp, lambda_max=lam, increments=1,
                       algorithm=sol.algorithm, liftoff_surface=NO_WATCH, recover=False)
        return group_open(s.gap[-1], s.closed[-1], groups)

    up_hi = group_open(sol.gap[j], sol.closed[j], groups)
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        up = state(mid)
        if up.any():
            hi, up_hi = mid, up
        else:
            lo = mid
    return hi, int(np.flatnonzero(up_hi)[0])
