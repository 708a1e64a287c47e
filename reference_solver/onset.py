"""Every onset the solver locates, in one module.

- ``track_penalty`` / ``track_lagrange``: exact onset inside a load-factor bracket by following the
  piecewise-linear path. Between contact-state changes a path-independent law is linear in lambda (fixed
  states), so the path from the solution at ``lo`` is followed event by event: the first row that changes
  state is found in closed form, its state flipped and the next piece followed. The onset is the first
  event that opens a watched row; None when none is found in the bracket (the caller bisects).
- :func:`first_opening`: the first-node onset of a law along a bracket (the law's exact ``track``,
  checked by two full solves just below and above it; else bisection on lambda, by sub-increments from the
  last converged state for a path-dependent law).
- :func:`reach`: sub-steps to a load factor, bisecting the onset of a failure that ends the path (gross
  slip, an increment that does not converge).
- :func:`section_onset`: the first load factor at which every row of one group is open (a whole section).
Rows are open when their gap is > 0 and they are not closed.
"""

from __future__ import annotations

from typing import Callable, NamedTuple

import numpy as np

from .friction_state import GrossSlip, NotConverged, Runaway, State
from .shifted import ShiftedSolver, SubsetSolver

SLIDE_TOL = 1.0e-4        # bisection tolerance of failure onsets (gross slip), relative to the largest load factor


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


def lifted_rows(st: State, c0: np.ndarray, watch: np.ndarray, law=None) -> np.ndarray:
    """Bool per row: watched and lifted in ``st``: ``law.lifted(st, watch)`` where the law defines its own lift
    (the face-weighted Lagrange law: the pressure field is 0 there), else gap > 0 and not closed."""
    own = getattr(law, "lifted", None)
    if own is not None:
        return own(st, watch)
    return watch & (c0 + st.x[:c0.size] > 0) & ~st.active


def is_open(st: State, c0: np.ndarray, watch: np.ndarray, law=None) -> bool:
    """Whether a watched row of ``st`` is open (:func:`lifted_rows`)."""
    return bool(np.any(lifted_rows(st, c0, watch, law)))


def widest_open(st: State, c0: np.ndarray, watch: np.ndarray, law=None) -> int:
    """The watched open row with the largest gap (the onset row of a bisected onset)."""
    cand = np.flatnonzero(lifted_rows(st, c0, watch, law) if hasattr(law, "lifted") else watch & ~st.active)
    return int(cand[np.argmax((c0 + st.x[:c0.size])[cand])])


def first_opening(law, run: Callable, lo: tuple, hi: tuple, back: tuple | None, co: Callable,
                  dcoeffs: np.ndarray, watch: np.ndarray, *, tol: float, scale: float,
                  exact: bool = True) -> tuple[float, int, str]:
    """(lambda, row, how) of the first opening of a ``watch`` row between the converged increments
    ``lo`` = (lambda, state), closed, and ``hi``, open. ``run(state, lam, guess)`` solves the state at
    ``lam`` from ``state``; ``back`` the increment before ``lo`` (its secant guides the guesses of a
    path-dependent law); ``co(lam)`` the load coefficients at ``lam``, ``dcoeffs`` their rate. ``tol`` on
    lambda relative to ``scale``; ``exact``: try ``law.track`` first (checked by ``law.onset_check(state,
    coeffs)`` where the law has one, else by ``run``)."""
    c0 = law.problem.contact_clearance
    (a, a_st), (b, b_st) = lo, hi
    if exact and not law.stateful:
        check = getattr(law, "onset_check", None)            # a law whose states are the exact ones only to a
        ev = law.track(a_st if check is None else check(a_st, co(a)), a, b, dcoeffs, watch)   # tolerance: tracks
        delta = min(1e-7, 0.1 * tol) * scale                  # and checks on the exact problem it solves
        if ev is not None and a < ev[0] - delta and ev[0] + delta < b:
            if check is not None:
                below, above = check(a_st, co(ev[0] - delta)), check(a_st, co(ev[0] + delta))
            else:
                below, above = run(a_st, ev[0] - delta, None), run(a_st, ev[0] + delta, None)
            if not is_open(below, c0, watch, law) and is_open(above, c0, watch, law):
                return float(ev[0]), int(ev[1]), "path-following"
    while abs(b - a) > max(tol, law.onset_floor) * scale:
        mid = 0.5 * (a + b)
        if back is not None:                                  # along the closed branch: its last two states
            guess = a_st.x + (mid - a) / (a - back[0]) * (a_st.x - back[1].x)
        else:
            guess = a_st.x + (mid - a) / (b - a) * (b_st.x - a_st.x)
        mst = run(a_st, mid, guess)
        if is_open(mst, c0, watch, law):
            b, b_st = mid, mst
        else:
            back = (a, a_st)
            a, a_st = mid, mst
    return b, widest_open(b_st, c0, watch, law), "bisection"


def reach(run: Callable, a_st: State, a: float, lam: float, guess, scale: float, tips: Callable):
    """Sub-steps from (a_st, a) to ``lam``: (state at lam, None), or (last state, onset of the failure)
    when an increment slides the body (GrossSlip) or does not converge; the onset bisected to SLIDE_TOL x
    ``scale``. ``run(state, lam, lam_prev, guess)``; ``tips(lam)`` the error of a runaway (tipping)."""
    b, why = lam, None
    for _ in range(8):
        try:
            return run(a_st, lam, a, guess), None
        except (GrossSlip, NotConverged) as exc:
            b, why = lam, exc
        while abs(b - a) > SLIDE_TOL * scale:                 # bisect, sub-steps from a
            mid = 0.5 * (a + b)
            try:
                a_st, a = run(a_st, mid, a, None), mid
            except (GrossSlip, NotConverged) as exc:
                b, why = mid, exc
        try:
            a_st, a = run(a_st, b, a, None), b                # the last small step
        except (GrossSlip, NotConverged) as exc:
            why = exc
            break
    if isinstance(why, Runaway):
        raise tips(b) from None                               # no bounded equilibrium past a: tipping over
    if isinstance(why, NotConverged):
        raise NotConverged(f"step 2, load factor {b:.6g}: the iterations do not converge "
                           f"({why}); the last converged load factor is {a:.6g}") from None
    return a_st, b


def group_open(gap: np.ndarray, closed: np.ndarray, groups: list[np.ndarray]) -> np.ndarray:
    """(n_groups,) True where every row of the group is open (gap > 0 and not closed)."""
    opened = (np.asarray(gap) > 0) & ~np.asarray(closed, bool)
    return np.array([bool(opened[g].all()) for g in groups])


class _Rows(NamedTuple):
    """The per-increment rows :func:`section_onset` reads (in the law's own variables)."""
    step: np.ndarray
    load_factor: np.ndarray
    gap: np.ndarray
    force: np.ndarray
    closed: np.ndarray


def _law_rows(system, sol) -> tuple[Callable, np.ndarray]:
    """(map (gap, force, closed) -> the same in the law's own variables, diag of the law's condensed matrix) for
    :func:`section_onset`. The nodal laws: the rows as they are, diag S. The face-weighted Lagrange
    (``contact_weighting`` not 'nodal', face_law.py): weighted gaps g~ = D g and multipliers lambda = D^-T r, diag
    of S~ = D^-T S D^-1: its rows are open where lambda = 0 and g~ > 0 and pressed where lambda > 0, while the
    nodal forces D^T lambda of a pressed 8-node corner are negative (-1/12 of a uniform pressure) and the nodal
    gap of an open row may be <= 0 by the weak condition's ~1e-3, so the nodal measure read closed pressed
    corners as open (the hex20r cone 16 x 4 x 2 of the quadratic matrix: whole section 0.400, the bracket's lower
    end, where the law's own variables give 0.58; hex8i 64 x 16 x 6: 0.5906)."""
    p = system.problem
    S = system.Sc if hasattr(system, "Sc") else system.S
    if getattr(p, "contact_weighting", "nodal") == "nodal" or sol.method != "lagrange":
        return (lambda gap, force, closed: (gap, force, closed)), np.diag(S)[:system.n_contacts].copy()
    from .face_law import FaceWeighting
    nc = system.n_contacts                   # friction (friction_face.py): S~'s normal block is D^-T S_nn D^-1
    W = FaceWeighting(p, np.asarray(S)[:nc, :nc])
    return (lambda gap, force, closed: (W.weigh(np.asarray(gap, float)), W.to_pressure(force), closed)), np.diag(W.S).copy()


def section_onset(system, sol, groups: list[np.ndarray], state_at: Callable[[float], tuple],
                  tol: float = 1e-9, bisect: bool = False) -> tuple[float | None, int | None]:
    """(lambda, group index) of the first load factor of step 2 at which a whole group is open, or
    (None, None) when none opens along ``sol``. ``groups``: row indices (into the contact rows) of each
    group; ``sol`` the solved path; ``state_at(lam)`` the (gap, force, closed) rows of the state at ``lam``
    (the driver's one-increment path: :func:`reference_solver.path.section_onset`).

    The onset is the first root of phi(lambda) = max over groups of (min over the group's rows of m_i),
    m_i = gap_i - force_i / S_ii (a closed exact row has gap 0 and force > 0; a penalty row's gap is
    negative while closed; the face-weighted Lagrange in its own variables, :func:`_law_rows`), continuous and piecewise linear in lambda: Illinois regula falsi, exact once
    the bracket lies in one linear piece, bisection steps as fallback, to ``tol`` on lambda or |phi| <
    1e-12 of its scale. ``bisect``: bisection steps only (a path-dependent law: phi is curved and each state
    costs a friction increment; regula falsi crept from one end, 60 states on the 24 x 6 x 3 friction skirt,
    where bisection needs log2(bracket / tol), 10 for the 0.1 bracket to 1e-4)."""
    law_rows, diag = _law_rows(system, sol)
    raw_state_at = state_at
    state_at = lambda lam: law_rows(*raw_state_at(lam))        # noqa: E731
    gaps, forces = zip(*(law_rows(g, f, c)[:2] for g, f, c in zip(sol.gap, sol.force, sol.closed)))
    sol = _Rows(sol.step, sol.load_factor, np.array(gaps), np.array(forces), sol.closed)
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

    def measure(gap, force, closed):
        m = np.where(closed, gap - force / diag, gap)
        return np.array([m[g].min() for g in groups])

    def state(lam: float):
        gap, force, closed = state_at(lam)
        return measure(gap, force, closed), group_open(gap, closed, groups)

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
        if not (lo < x < hi) or bisect:
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
