"""Exact (Lagrange) Coulomb friction: a semi-smooth Newton method on the Alart-Curnier equations.

On the condensed friction system every retained dof carries exactly one contact force: the normal
force p of its own contact row, a tangential force t of a friction row, or nothing (a spring dof or a
free tangential axis). The forces therefore follow from the displacements, ``lam = S x - f`` [N]
(equilibrium holds by construction, to round-off), and the unknowns are the retained displacements x
alone. One equation per retained dof (force units, N):

- normal dof of row j, ``sigma = p - rho_n g`` (g = clearance + x_n, > 0 open):
  ``C = p - max(0, sigma)``, i.e. ``rho_n g`` when closed (sigma > 0), ``p`` when open;
- tangential axes of a closed friction row (the corner rule's axes in the current state, FrictionSystem.axes),
  ``xi = t - rho_t (s - s_ref)``, ``q = mu sigma``: ``C = t - proj_{|.| <= q}(xi)``, i.e.
  ``rho_t (s - s_ref)`` in stick (|xi| <= q) and ``t - q xi / |xi|`` in slip; of an open row ``C = t``;
- any other dof: ``C = lam`` (no force).

A closed row whose tangential increment points along its force (``t . (s - s_ref) > 0``: friction
pushing the motion on) is taken as sticking in the iterates, so its next step returns it to ``s_ref``.
No solution has such a row (stick: s = s_ref; slip: s - s_ref opposes t), so C = 0 is unchanged, except at
s = s_ref to round-off, where the sign of t . (s - s_ref) is noise and the stick equation rho_t (s - s_ref) = 0
holds with any |t|: a root of these iterate equations is accepted only where the plain equations vanish too,
else the iteration goes on with the plain ones (issue 26: 8.9 kN of table friction against mu p = 6e-8 N
was accepted on a corner row with mu = 1e-12, t . ds = +5e-16). Without
it the Newton iterates lock such rows in a wrong-way slip and drift (most increments past liftoff
did not settle and were cut back). Where those iterates run away (the onset of gross slip), the plain
iteration follows and decides as before; ``WRONG_WAY_STICK = False`` keeps only the plain one.

The generalised Jacobian is ``D_lam S + D_x`` with per-node blocks; the dofs whose equation is
``rho (x - x_target)`` (closed normals, sticking axes) are solved outright, so each Newton step
solves a dense system on the open and slipping dofs only. The iterates start from the path's
estimate of the increment (warm start), else from the previous increment. At the solution
g = 0 or p = 0 exactly, and s = s_ref (stick) or |t| = mu p opposing the slip (slip).

Convergence: every |C_i| <= tol max(|f|, |lam|) [N], or within ROUNDOFF times its own evaluation error
eps (|S| |x| + |f|)_i [N] (lam = S x - f cancels). Near tipping the remaining support is almost a
mechanism: x reaches 0.4 m on 36 x 8 x 2 at lambda = 1.153 while S reaches 6e11 N/m, so that error is
~8e-11 |f|, above tol |f| = 1e-11 |f|; the iterates then sit at the floor (same contact set, C from
2e-11 to 9e-11 |f|, by the BLAS's summation order) and were taken as not converged.
"""

from __future__ import annotations

import numpy as np

from .contact import Unbounded
from .friction_state import GrossSlip, NotConverged, Runaway, State

PREDICTOR = 10.0         # the fallback predictor's penalty stiffness, times diag(S) [-]
LINESEARCH = 0           # full (active-set) Newton steps: a line search on |C|^2 stalls at the kinks
DIRECT_MAXIT = 30        # Newton steps per direct attempt (guess, previous increment), wrong-way rows sticking
PLAIN_MAXIT = 12         # Newton steps of the plain iteration from the previous increment, before the predictor
DIRECT_RHO = (1.0, 0.1)  # the direct attempts' rho, times diag(S)
RHO_N = 1.0
RHO_T = 1.0
ROUNDOFF = 16.0         # a residual within ROUNDOFF x its evaluation error eps (|S| |x| + |f|) is converged [-]
WRONG_WAY_STICK = True   # iterates: a closed row slipping along its own force is taken as sticking
                         # (False: the plain iteration alone, as before issue 14's speed work)


def _equations(x, sysf, f, rho_n, rho_t, mu, s_ref, qfix=None, wrong_way_stick=True):
    """Residual C (nr,), the known-dof mask, and the pieces of the Jacobian at ``x``; the friction axes ``m``
    are the corner rule's in this contact state (:meth:`FrictionSystem.axes`)."""
    S, nc, clear, fr, td = sysf.S, sysf.problem.n_contacts, sysf.problem.contact_clearance, sysf.rows, sysf.tdofs
    lam = S @ x - f
    g = clear + x[:nc]
    sig = lam[:nc] - rho_n * g
    act = sig > 0
    m = sysf.axes(act)
    C = lam.copy()
    C[:nc] = np.where(act, rho_n * g, lam[:nc])
    t = lam[td] * m                                           # (nf, 2) tangential forces, free axes only
    ds = (x[td] - s_ref) * m
    xi = t - rho_t * ds
    nxi = np.linalg.norm(xi, axis=1)
    q = np.where(sig[fr] > 0, mu * np.maximum(sig[fr], 0.0) if qfix is None else qfix, 0.0)   # slip threshold [N]
    closed = act[fr]
    wrong_way = np.sum(ds * t, axis=1) > 0 if wrong_way_stick else False   # t pushes along the slip
    stick = closed & ((nxi <= q) | wrong_way)
    slip = closed & ~stick
    nv = np.divide(xi, nxi[:, None], out=np.zeros_like(xi), where=nxi[:, None] > 0)
    ct = np.where(stick[:, None], rho_t * ds, np.where(slip[:, None], t - q[:, None] * nv, t))
    C[td[m]] = ct[m]
    return C, lam, act, stick, slip, nv, nxi, q, t, m


def solve_lagrange_increment(sysf, f, prev, mu, max_disp, tol=1e-11, maxit=60, predictor=None, guess=None):
    """One increment of exact Coulomb friction from the converged state ``prev``.

    The semi-smooth Newton (:func:`_ssn`, wrong-way rows taken as sticking) from ``guess`` (an estimate
    of x from the path, when given), then from the previous increment (``DIRECT_MAXIT`` steps each).
    When none settles (an increment at or past the onset of gross slip or tipping: the iterates run
    away), the plain iteration of the earlier solver: from the previous increment (``PLAIN_MAXIT``
    steps, its active sets can cycle), then from a penalty predictor (the energy-descent penalty solve
    ``predictor(k, k_t)`` with k = PREDICTOR * diag S, which also decides gross slip); NotConverged
    when that fails too (the caller has the augmented-Lagrangian solve as the last resort), Runaway
    where the predictor has no bounded equilibrium or the Newton from it runs away (every closed row
    slipping included: the predictor decided that it is not gross slip); the path bisects to that
    load, the tipping load.
    """
    starts = ([(guess, 1.0)] if guess is not None else []) + [(None, r) for r in DIRECT_RHO]
    for x0, rho in starts if WRONG_WAY_STICK else []:
        try:
            return _ssn(sysf, f, prev, mu, max_disp, tol, DIRECT_MAXIT, x0=x0, rho=rho)
        except (GrossSlip, NotConverged, Unbounded):
            pass
    for rho in DIRECT_RHO:                             # the active sets cycle at some rho and not at others
        try:
            return _ssn(sysf, f, prev, mu, max_disp, tol, PLAIN_MAXIT, rho=rho, wrong_way_stick=False)
        except (GrossSlip, NotConverged, Unbounded):
            pass
    d = np.diag(sysf.S)
    k = PREDICTOR * d[:sysf.problem.n_contacts]
    kt = PREDICTOR * d[sysf.tdofs].mean(axis=1)
    if predictor is None:
        raise NotConverged("Lagrange friction: the semi-smooth Newton did not settle (no predictor given)")
    try:
        pred = predictor(k, kt)
    except Unbounded as exc:                           # no bounded penalty equilibrium either: not gross slip
        raise Runaway(f"Lagrange friction: the penalty predictor ran away ({exc})") from None
    try:
        st = _ssn(sysf, f, prev, mu, max_disp, tol, maxit, x0=pred.x, wrong_way_stick=False)
    except (GrossSlip, Unbounded) as exc:   # the predictor (it decides gross slip) found one: a runaway
        raise Runaway(f"Lagrange friction: the semi-smooth Newton left the penalty predictor ({exc})") from None
    st.iterations += pred.iterations
    return st


def _ssn(sysf, f, prev, mu, max_disp, tol=1e-11, maxit=60, x0=None, qfix=None, rho=1.0, wrong_way_stick=True):
    """One increment of exact Coulomb friction from the converged state ``prev`` (a friction.State).

    Raises :class:`reference_solver.friction.GrossSlip` when the iterates run away with every closed
    friction row slipping and the load slides the body at the iterate's normal forces (
    :meth:`reference_solver.friction.FrictionSystem.slides`; every row slipping radially under N alone is
    not that), :class:`Unbounded` when they run away otherwise,
    :class:`reference_solver.friction.NotConverged` when they do not settle in ``maxit`` steps.
    """
    pr = sysf.problem
    S, nc, nr = sysf.S, pr.n_contacts, sysf.S.shape[0]
    fr, td = sysf.rows, sysf.tdofs
    d = np.diag(S)
    rho_n, rho_t = rho * RHO_N * d[:nc], rho * RHO_T * d[td].mean(axis=1)[:, None]
    s_ref = prev.x[td]
    nf = fr.size
    fi = np.repeat(np.arange(nf), 2).reshape(nf, 2)           # friction row of each tangential axis
    scale = max(np.abs(f).max(), 1e-300)
    absS, absf = np.abs(S), np.abs(f)
    args = (sysf, f, rho_n, rho_t, mu, s_ref, qfix, wrong_way_stick)
    x = np.array(prev.x if x0 is None else x0, float)
    ev = _equations(x, *args)
    allslip = 0

    def settled(C, lam):      # every entry within tol of the scale, or within ROUNDOFF x its own rounding error [N]
        floor = ROUNDOFF * np.finfo(float).eps * (absS @ np.abs(x) + absf)
        return np.all(np.abs(C) <= np.maximum(tol * max(scale, np.abs(lam).max()), floor))

    for it in range(1, maxit + 1):
        C, lam, act, stick, slip, nv, nxi, q, t, m = ev
        tflat, fflat = td[m], fi[m]
        if settled(C, lam) and args[-1]:
            plain = _equations(x, *args[:-1], False)     # wrong-way rows sticking: a root of the plain law too?
            if not settled(plain[0], plain[1]):
                args, ev = (*args[:-1], False), plain    # no (s = s_ref to round-off, |t| > mu p): go on plain
                C, lam, act, stick, slip, nv, nxi, q, t, m = ev
                tflat, fflat = td[m], fi[m]
        if settled(C, lam):
            moving = np.linalg.norm((x[td] - s_ref) * m, axis=1) > 1e-12 * (np.abs(x).max() + 1e-300)
            on_cone = act[fr] & (np.linalg.norm(t, axis=1) >= (1 - 1e-8) * q)
            slipping = on_cone & (moving | prev.slip)        # a zero increment keeps the slip status
            return State(x=x, p=lam[:nc].copy(), t=t, active=act, slip=slipping, iterations=it - 1)
        # the Jacobian: rows of S by default (C = lam), replaced where the law says otherwise
        known = np.zeros(nr, bool)
        known[:nc] = act
        known[tflat] = stick[fflat]
        kdiag = np.zeros(nr)
        kdiag[:nc] = rho_n
        kdiag[tflat] = rho_t[fflat, 0]
        dx = np.zeros(nr)
        dx[known] = -C[known] / kdiag[known]
        U = np.flatnonzero(~known)
        if U.size:
            J = S[U].copy()
            row = np.full(nr, -1)
            row[U] = np.arange(U.size)
            sl = np.flatnonzero(slip)
            if sl.size:                                       # slip: dC = A dt + rho_t c P ds - mu n dq
                c = q[sl] / nxi[sl]
                P = np.eye(2) - nv[sl, :, None] * nv[sl, None, :]
                mm = m[sl]
                A = (np.eye(2) - c[:, None, None] * P) * mm[:, :, None] * mm[:, None, :]
                B = (rho_t[sl, 0] * c)[:, None, None] * P * mm[:, :, None] * mm[:, None, :]
                St = S[td[sl]]                                # (ns, 2, nr)
                jn = fr[sl]
                dq = (0.0 if qfix is not None else mu) * S[jn]   # d sigma / dx = S[j] - rho_n e_j (Tresca: 0)
                dq[np.arange(sl.size), jn] -= (0.0 if qfix is not None else mu) * rho_n[jn]
                Jt = np.einsum("sab,sbk->sak", A, St) - nv[sl, :, None] * mm[:, :, None] * dq[:, None, :]
                Jt[np.arange(sl.size)[:, None], np.arange(2)[None, :], td[sl]] += np.einsum("saa->sa", B)
                Jt[np.arange(sl.size), 0, td[sl, 1]] += B[:, 0, 1]
                Jt[np.arange(sl.size), 1, td[sl, 0]] += B[:, 1, 0]
                for a in (0, 1):
                    keep = mm[:, a]
                    J[row[td[sl[keep], a]]] = Jt[keep, a]
            rhs = -C[U] - J[:, known] @ dx[known]
            with np.errstate(all="ignore"):
                try:
                    dx[U] = np.linalg.solve(J[:, U], rhs)
                except np.linalg.LinAlgError:
                    dx[U] = np.nan
        fa = act[fr]
        allslip_now = bool(fa.any() and np.all(nxi[fa] > q[fa]))   # beyond the cone (wrong-way rows too)
        if not np.all(np.isfinite(dx)) or np.abs(x + dx).max() > max_disp:
            if (allslip_now or allslip) and (not np.all(np.isfinite(dx)) or sysf.slides(f, lam[:nc], act)):
                raise GrossSlip("the load slides the body (gross slip: friction cannot carry the tangential load)")
            if not np.all(np.isfinite(dx)):
                raise NotConverged("Lagrange friction: singular Newton system")
            raise Unbounded("no bounded equilibrium")
        allslip = allslip + 1 if allslip_now else 0
        phi = 0.5 * C @ C
        step, new = 1.0, _equations(x + dx, *args)
        if LINESEARCH and 0.5 * new[0] @ new[0] > phi:          # a few halvings; the best trial, else the full step
            best = (0.5 * new[0] @ new[0], 1.0, new)
            for trial in (0.5, 0.25, 0.125)[:LINESEARCH]:
                cand = _equations(x + trial * dx, *args)
                best = min(best, (0.5 * cand[0] @ cand[0], trial, cand), key=lambda b: b[0])
                if best[0] <= phi:
                    break
            _, step, new = best
        x, ev = x + step * dx, new
    C, lam, act, stick, slip, nv, nxi, q, t, _ = ev
    fa = act[fr]
    if (allslip or (fa.any() and np.all(nxi[fa] > q[fa]))) and sysf.slides(f, lam[:nc], act):
        raise GrossSlip("the load slides the body (gross slip: friction cannot carry the tangential load)")
    raise NotConverged(f"Lagrange friction: the semi-smooth Newton did not settle in {maxit} steps")
