"""The load path with Coulomb friction: path-dependent increments along a list of load-factor targets.

Step 1 applies ``base`` in one increment from the unloaded state; step 2 follows ``base + lambda * ramp``
from lambda = 0 through each target of ``targets`` in turn (up or down), ``increments`` equal
increments per leg. Every increment starts from the previous converged state (tangential forces and
slip history), so loading to lambda = 1 and back to 0 leaves a residual tangential state where slip
occurred. The liftoff onset is bracketed by the increments and bisected (sub-increments from the last
converged state); the onset of gross slip (the load slides the body) likewise. The Lagrange iterates of
an increment start from a linear estimate of its displacements (through the last two increments; in
the liftoff bisection, through the last two states on the closed side); the increment itself (from
the last converged state) is unchanged, and so is its solution.
"""

from __future__ import annotations

import time
from typing import Callable, Mapping, Sequence

import numpy as np

from .contact import Unbounded
from .errors import ReferenceSolverError, no_equilibrium
from .friction import CORNER_RULE, FrictionSystem, GrossSlip, NotConverged, Runaway, State, solve_increment
from .solution import Solution

QUICK_DEPTH = 2           # Lagrange: cutbacks tried with the direct Newton alone before its fallbacks
CUTBACKS = 5             # an increment that does not converge is halved up to this many times
SLIDE_TOL = 1.0e-4        # bisection tolerance of the gross-slip and liftoff onsets, relative to the largest
                          # load factor (each step is a sub-increment; liftoff_tol applies when coarser)
RHO_FACTOR = 100.0        # augmented-Lagrangian rho = RHO_FACTOR * diag(S) on the normal dofs [N/m]


def _secant(r0, r1, lam: float) -> np.ndarray | None:
    """Linear estimate of x at ``lam`` through two converged path rows (step 2 only), else None."""
    if r0[0] != 2 or r1[0] != 2 or r0[2] == r1[2]:
        return None
    return r1[4].x + (lam - r1[2]) / (r1[2] - r0[2]) * (r1[4].x - r0[4].x)


def _outputs(sysf: FrictionSystem, method, states, kt):
    """Per-increment arrays: tangential force and slip increment (global, [N], [m]), status, dissipation."""
    p = sysf.problem
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
        if method == "penalty":
            d = d + (st.t - t0) / kt[:, None]          # minus the elastic part: the slip (plastic) increment
        d = np.where(st.active[fr][:, None], d, 0.0)
        dslip[i, fr] = np.einsum("fa,fak->fk", d, sysf.tdir)
        diss[i] = float(-np.sum(st.t * d))
        status[i, fr] = np.where(st.active[fr], np.where(st.slip, "slip", "stick"), "open")
        prev = st
    return ft, dslip, status.astype(str), diss


def solve_friction_path(sysf: FrictionSystem, method: str = "penalty", k_factor: float = 1.0, *,
                        base: Mapping[str, float] | None = None, ramp: Mapping[str, float] | None = None,
                        lambda_max: float = 1.0, increments: int = 10, targets: Sequence[float] | None = None,
                        algorithm: str | None = None, liftoff_surface: str | None = "table",
                        liftoff_tol: float = 1e-6, onset: str = "auto", recover: bool = True,
                        on_increment: Callable[[int, int, float], None] | None = None,
                        on_gross_slip: str = "raise", corner: str | None = None):
    """Run step 1 and step 2 with friction; returns a :class:`reference_solver.path.Solution`.

    ``targets``: load factors visited in order in step 2 (default ``[lambda_max]``), ``increments``
    per leg. ``on_gross_slip``: 'raise' (:class:`GrossSlip`, one line, with the bisected onset as
    ``err.load_factor``) or 'stop' (the solution ends at the last converged increment and holds the
    onset in ``gross_slip_load_factor``). ``algorithm`` is 'newton' (penalty) or 'augmented-lagrangian'.
    ``onset`` is accepted for the frictionless signature; friction onsets are always bisected.
    """
    t0 = time.perf_counter()
    p = sysf.problem
    if method not in ("penalty", "lagrange"):
        raise ReferenceSolverError(f"method = {method!r}: must be penalty or lagrange")
    algo = "newton" if method == "penalty" else "augmented-lagrangian"
    offers = (algo,)
    if algorithm not in (None, *offers):
        raise ReferenceSolverError(f"algorithm = {algorithm!r}: {method} with friction offers {', '.join(offers)}")
    if not (np.isfinite(k_factor) and k_factor > 0):
        raise ReferenceSolverError(f"k_factor = {k_factor!r}: must be > 0")
    if on_gross_slip not in ("raise", "stop"):
        raise ReferenceSolverError(f"on_gross_slip = {on_gross_slip!r}: must be raise or stop")
    sysf = sysf.with_corner(corner or CORNER_RULE[method])
    targets = [float(lambda_max)] if targets is None else [float(v) for v in targets]
    if increments < 1 or not targets or not all(np.isfinite(targets)):
        raise ReferenceSolverError("increments must be >= 1 and targets finite load factors")
    base = {"N": 1.0} if base is None else dict(base)
    ramp = {"T": 1.0, "M": 1.0} if ramp is None else dict(ramp)
    cb, cr = sysf.coeffs(base), sysf.coeffs(ramp)
    fr = sysf.rows
    kf = k_factor if method == "penalty" else 1.0
    k = kf * p.contact_k
    k_open = p.k_open_ratio * k
    kt = (kf if p.kt_follows_k else 1.0) * p.contact_kt[fr]
    rho = RHO_FACTOR * np.diag(sysf.S)[:p.n_contacts]
    max_disp = p.max_displacement or p.length_scale()
    watch = np.ones(p.n_contacts, bool) if liftoff_surface is None else p.contact_surface == liftoff_surface
    lam_scale = max(abs(v) for v in targets + [lambda_max])

    def solve(prev: State, lam: float | None, lam_prev: float, depth: int, guess=None) -> State:
        """One increment; cut back into halves (up to CUTBACKS times) when it does not converge.
        ``guess``: an estimate of x at ``lam`` (Lagrange: the semi-smooth Newton's first start)."""
        co = cb if lam is None else cb + lam * cr
        try:
            return solve_increment(sysf, method, sysf.fhat @ co, prev, k, k_open, kt, p.friction, max_disp, rho,
                                   quick=lam is not None and depth < QUICK_DEPTH, guess=guess)
        except NotConverged:
            if depth >= CUTBACKS:
                raise
            mid = None if lam is None else 0.5 * (lam_prev + lam)
            if lam is None:                                  # step 1: ramp the base load in halves
                half = solve_increment(sysf, method, sysf.fhat @ (0.5 * cb), prev, k, k_open, kt, p.friction,
                                       max_disp, rho)
                return solve_increment(sysf, method, sysf.fhat @ cb, half, k, k_open, kt, p.friction, max_disp, rho)
            half = None if guess is None else 0.5 * (prev.x + guess)
            return solve(solve(prev, mid, lam_prev, depth + 1, half), lam, mid, depth + 1, guess)

    def run(prev: State, lam: float | None, step: int, lam_prev: float | None = None, guess=None) -> State:
        try:
            return solve(prev, lam, lam if lam_prev is None else lam_prev, 0 if lam_prev is not None else CUTBACKS,
                         guess)
        except GrossSlip:
            raise
        except Unbounded:
            raise no_equilibrium(step, lam) from None

    def reach(a_st: State, a: float, lam: float, guess=None) -> tuple[State, float | None]:
        """Sub-steps from (a_st, a) to lam: (state at lam, None), or (last state, gross-slip onset)."""
        b, why = lam, None
        for _ in range(8):
            try:
                return run(a_st, lam, 2, a, guess), None
            except (GrossSlip, NotConverged) as exc:
                b, why = lam, exc
            while abs(b - a) > SLIDE_TOL * lam_scale:        # bisect, sub-steps from a
                mid = 0.5 * (a + b)
                try:
                    a_st, a = run(a_st, mid, 2, a), mid
                except (GrossSlip, NotConverged) as exc:
                    b, why = mid, exc
            try:
                a_st, a = run(a_st, b, 2, a), b              # the last small step
            except (GrossSlip, NotConverged) as exc:
                why = exc
                break
        if isinstance(why, Runaway):
            raise no_equilibrium(2, b) from None             # no bounded equilibrium past a: tipping over
        if isinstance(why, NotConverged):
            raise NotConverged(f"step 2, load factor {b:.6g}: the friction iterations do not converge "
                               f"({why}); the last converged load factor is {a:.6g}") from None
        return a_st, b

    nr, nf = sysf.S.shape[0], fr.size
    zero = State(x=np.zeros(nr), p=np.zeros(p.n_contacts), t=np.zeros((nf, 2)),
                 active=p.contact_clearance <= 0, slip=np.zeros(nf, bool))
    rows = [(1, 1, 0.0, cb, run(zero, None, 1))]
    if on_increment:
        on_increment(1, 1, 0.0)
    rows.append((2, 0, 0.0, cb, rows[0][4]))
    if on_increment:
        on_increment(2, 0, 0.0)
    is_open = lambda st: bool(np.any(watch & (p.contact_clearance + st.x[:p.n_contacts] > 0) & ~st.active))  # noqa: E731
    lift_lf = lift_row = slide_lf = None
    if is_open(rows[0][4]):
        g = p.contact_clearance + rows[0][4].x[:p.n_contacts]
        cand = np.flatnonzero(watch & ~rows[0][4].active)
        lift_lf, lift_row = 0.0, int(cand[np.argmax(g[cand])])
    lam_prev, j = 0.0, 0
    for target in targets:
        for m in range(1, increments + 1):
            lam = lam_prev + (target - lam_prev) * m / increments if m < increments else target
            lo_lam, lo_st = rows[-1][2], rows[-1][4]
            st, onset_lf = reach(lo_st, lo_lam, lam, _secant(rows[-2], rows[-1], lam))
            if onset_lf is not None:
                slide_lf = onset_lf
                if on_gross_slip == "raise":
                    err = GrossSlip(f"step 2, load factor {lam:.6g}: the load slides the body (gross slip from "
                                    f"load factor {onset_lf:.6g}; friction cannot carry the tangential load)")
                    err.load_factor = onset_lf
                    raise err from None
                break
            if method == "penalty" and watch.any() and not np.any(st.active & watch):
                raise ReferenceSolverError(
                    f"step 2, load factor {lam:.6g}: the load tips the body over (every {liftoff_surface} contact is open)")
            if lift_lf is None and is_open(st):
                a, b, a_st, b_st = lo_lam, lam, lo_st, st
                back = (rows[-2][2], rows[-2][4].x) if rows[-2][0] == 2 and rows[-2][2] != lo_lam else None
                while abs(b - a) > max(liftoff_tol, SLIDE_TOL) * lam_scale:
                    mid = 0.5 * (a + b)
                    if back is not None:                 # along the closed branch: its last two states
                        guess = a_st.x + (mid - a) / (a - back[0]) * (a_st.x - back[1])
                    else:
                        guess = a_st.x + (mid - a) / (b - a) * (b_st.x - a_st.x)
                    mst = run(a_st, mid, 2, guess=guess)
                    if is_open(mst):
                        b, b_st = mid, mst
                    else:
                        back = (a, a_st.x)
                        a, a_st = mid, mst
                g = p.contact_clearance + b_st.x[:p.n_contacts]
                cand = np.flatnonzero(watch & ~b_st.active)
                lift_lf, lift_row = b, int(cand[np.argmax(g[cand])])
            j += 1
            rows.append((2, j, lam, cb + lam * cr, st))
            if on_increment:
                on_increment(2, j, lam)
        else:
            lam_prev = target
            continue
        break

    states = [r[4] for r in rows]
    X = np.array([st.x for st in states])
    U = X[:, :p.n_contacts]
    act = np.array([st.active for st in states])
    if method == "penalty":
        F = np.array([st.p for st in states])
        closed = p.contact_clearance + U <= 0
    else:
        F = np.where(act, np.array([st.p for st in states]), 0.0)
        closed = act
    ft, dslip, status, diss = _outputs(sysf, method, states, kt)
    C = np.array([r[3] for r in rows])
    step = np.array([r[0] for r in rows])
    ns = p.n_springs
    us = X[:, p.n_contacts:p.n_contacts + ns]
    sol = Solution(
        method=method, algorithm=algo, k_factor=k_factor if method == "penalty" else None,
        penalty_k=k if method == "penalty" else None, step=step, increment=np.array([r[1] for r in rows]),
        load_factor=np.array([r[2] for r in rows]), coeffs=C, u=U, gap=p.contact_clearance + U, force=F,
        sigma_n=0.0 - F / p.contact_area, closed=closed, spring_u=us, spring_force=-p.spring_k * us,
        iterations=np.array([st.iterations for st in states]), liftoff_load_factor=lift_lf,
        liftoff_row=lift_row, liftoff_method="bisection" if lift_lf is not None else None,
        tangential="friction", tangential_force=ft, slip_increment=dslip, stick_status=status,
        dissipation=diss, gross_slip_load_factor=slide_lf, retained_u=X)
    if recover:
        sol.recover_step_ends(sysf, X)
    sol.wall_time_s = time.perf_counter() - t0
    return sol
