"""Exact liftoff onset inside a load-factor bracket by following the piecewise-linear path.

Between contact-state changes both methods are linear in lambda (fixed states), so the path from
the solution at ``lo`` can be followed event by event: the first row that changes state is found
in closed form, its state is flipped and the next piece follows. The onset is the first event that
opens a watched row. Returns None when an event cannot be found in the bracket (the caller then
bisects).
"""

from __future__ import annotations

import numpy as np

from .shifted import ShiftedSolver, SubsetSolver


def _first(t: np.ndarray) -> int:
    return int(np.argmin(t))


def track_penalty(S, fr, k, k_open, c0, lo, hi, u_lo, watch, max_events=None, solver=None):
    """Onset (lambda, row) for bilinear gap springs; ``fr`` = d f / d lambda on the contact dofs.

    ``solver``: shifted.ShiftedSolver of ``S`` (each event changes one row of the diagonal)."""
    solver = ShiftedSolver(S) if solver is None else solver
    g = c0 + u_lo
    closed = g <= 0
    lam = lo
    for _ in range(max_events or 4 * g.size + 10):
        dg = solver.solve(np.where(closed, k, k_open), fr)
        if dg is None:
            return None
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where((closed & (dg > 0)) | (~closed & (dg < 0)), -g / dg, np.inf)
        t = np.maximum(t, 0.0)
        i = _first(t)
        if not np.isfinite(t[i]) or lam + t[i] > hi:
            return None
        g = g + t[i] * dg
        lam += t[i]
        if closed[i] and watch[i]:
            return lam, i
        closed[i] = ~closed[i]
        g[i] = 0.0
    return None


def track_lagrange(S, fr, lo, hi, g_lo, w_lo, closed_lo, watch, max_events=None, solver=None):
    """Onset (lambda, row) for the LCP: closed rows (g = 0, w >= 0), open rows (w = 0, g >= 0).

    ``solver``: shifted.SubsetSolver of ``S`` (each event opens or closes one row)."""
    solver = SubsetSolver(S) if solver is None else solver
    A = closed_lo.copy()
    g = np.where(A, 0.0, g_lo)
    w = np.where(A, w_lo, 0.0)
    lam = lo
    for _ in range(max_events or 4 * g.size + 10):
        I = np.flatnonzero(~A)
        dg = np.zeros_like(g)
        if I.size:
            dI = solver.solve(I, fr[I])
            if dI is None:
                return None
            dg[I] = dI
        dw = np.where(A, S @ dg - fr, 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(A & (dw < 0), -w / dw, np.where(~A & (dg < 0), -g / dg, np.inf))
        t = np.maximum(t, 0.0)
        i = _first(t)
        if not np.isfinite(t[i]) or lam + t[i] > hi:
            return None
        g = g + t[i] * dg
        w = w + t[i] * dw
        lam += t[i]
        if A[i] and watch[i]:
            return lam, i
        if A[i]:
            A[i], w[i] = False, 0.0
        else:
            A[i], g[i] = True, 0.0
    return None
