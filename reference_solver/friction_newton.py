"""The inner solve of one friction increment for a frozen slip threshold (Tresca): Newton on a convex energy.

Used by the penalty law and, with the multipliers as pre-loads, by the augmented-Lagrangian last resort of
the Lagrange method (:func:`reference_solver.friction.solve_increment`). Contact laws, units and signs as in
:mod:`reference_solver.friction`: x the retained displacements [m], p >= 0 the normal forces [N], t (nf, 2)
the tangential forces [N] opposing the slip. Newton steps are low-rank (Woodbury) updates of one inverse
of S + k (+ k_t) per (k, k_t), cached on the system; an energy line search keeps the descent.
``sysf`` is a :class:`reference_solver.friction.FrictionSystem` (not imported: no cycle).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from .contact import Unbounded
from .friction_state import GrossSlip, NotConverged, State
from .linalg import cholesky_dense

WOODBURY = True           # Newton steps as low-rank updates of one inverse per (k, k_t) (False: Cholesky)
ROUNDOFF = 16.0           # a residual within ROUNDOFF x its evaluation error is converged [-] (friction_ssn's)


def roundoff_floor(sysf, f, x):
    """ROUNDOFF x the evaluation error eps (|S| |x| + |f|) of the residual S x - f - R, per retained dof [N].
    On face-weighted friction rows (friction_face.py; hex20r 16 x 2 x 1, dual basis, k-factor 1000) |S| |x| reaches
    ~4e6 |f|: the residual cannot fall below ~1e-9 |f|, under ``tol`` 1e-10 |f|, so every Newton ran its 60 steps
    and the penalty's threshold updates (friction.solve_increment) never settled to 1e-11 (>400 s, then cut back)."""
    return ROUNDOFF * np.finfo(float).eps * (np.abs(sysf.S) @ np.abs(x) + np.abs(f))


def _laws(x, sysf, k, k_open, kt, cap, p0, t0, s_ref):
    """Contact forces at ``x`` for a given slip threshold ``cap`` (N) and the pieces of their derivative."""
    pr = sysf.problem
    g = pr.contact_clearance + x[:pr.n_contacts]
    z = p0 - k * g
    active = z >= 0                                           # closed (g <= 0 without pre-load)
    p = np.where(active, z, -k_open * g)
    dp = np.where(active, k, k_open)                          # -dp/dg
    w = np.where(sysf.tmask, x[sysf.tdofs] - s_ref - t0 / kt[:, None], 0.0)   # t_trial = -kt w
    norm = kt * np.linalg.norm(w, axis=1)
    slip = norm > cap
    nd = np.divide(w, np.linalg.norm(w, axis=1)[:, None], out=np.zeros_like(w), where=norm[:, None] > 0)
    c = np.where(slip, cap, 0.0)                              # finite where used (cap may be inf)
    t = np.where(slip[:, None], -c[:, None] * nd, -kt[:, None] * w)
    energy_n = np.where(active, z * z / (2 * k), 0.5 * k_open * g * g)
    energy_t = np.where(slip, c * norm / kt - c * c / (2 * kt), 0.5 * norm * norm / kt)
    return p, dp, active, t, nd, norm, slip, (energy_n, energy_t)


def _residual(sysf, f, x, p, t):
    R = np.zeros_like(x)
    R[:sysf.problem.n_contacts] += p
    np.add.at(R, sysf.tdofs, t)
    return sysf.S @ x - f - R


def _blocks(kt, cap, nd, norm, slip, along=0.0, k_along=None, mask=None):
    """(nf, 2, 2) tangential Hessian blocks; ``along`` > 0 adds along * kt n n' on slipping rows
    (a stiffer, safe descent model)."""
    c = np.where(slip, np.where(slip, cap, 0.0) * kt / np.where(norm > 0, norm, 1.0), kt)
    blocks = c[:, None, None] * np.eye(2)
    ka = along * (kt if k_along is None else k_along)
    blocks[slip] -= (c[slip] - ka[slip])[:, None, None] * nd[slip, :, None] * nd[slip, None, :]
    return blocks if mask is None else blocks * mask[:, :, None] * mask[:, None, :]


def _hessian(sysf, dp, blocks):
    nc = sysf.problem.n_contacts
    H = sysf.S.copy()
    H[np.arange(nc), np.arange(nc)] += dp
    b = sysf.tdofs
    np.add.at(H, (b[:, :, None], b[:, None, :]), blocks)
    return H


def _base_inverse(sysf, k, kt):
    """Inverse of H0 = S + k on the normal dofs + kt on the tangential ones (every row closed, stuck)."""
    key = (k.tobytes(), kt.tobytes())
    if key not in sysf.cache:
        if len(sysf.cache) > 3:
            sysf.cache.clear()
        m = sysf.tmask
        H0 = _hessian(sysf, k, kt[:, None, None] * np.eye(2) * m[:, :, None] * m[:, None, :])
        cf = cholesky_dense(H0)
        sysf.cache[key] = None if cf is None else sla.cho_solve(cf, np.eye(H0.shape[0]), check_finite=False)
    return sysf.cache[key]


def _step(sysf, r, k, kt, dp, blocks):
    """Newton step -H^-1 r as a low-rank (Woodbury) update of H0^-1: only open and slipping rows differ."""
    H0inv = _base_inverse(sysf, k, kt)
    b = sysf.tdofs
    dev_n = dp - k
    m = sysf.tmask
    dev_t = blocks - kt[:, None, None] * np.eye(2) * m[:, :, None] * m[:, None, :]
    rn = np.flatnonzero(dev_n != 0)
    rt = np.flatnonzero(np.abs(dev_t).reshape(-1, 4).max(axis=1) > 0)
    idx = np.unique(np.concatenate([rn, b[rt].ravel()]))
    if H0inv is None or idx.size > 0.5 * r.size:
        return None
    pos = np.full(r.size, -1)
    pos[idx] = np.arange(idx.size)
    C = np.zeros((idx.size, idx.size))
    C[pos[rn], pos[rn]] += dev_n[rn]
    bt = pos[b[rt]]
    np.add.at(C, (bt[:, :, None], bt[:, None, :]), dev_t[rt])
    y = H0inv @ r
    if idx.size == 0:
        return -y
    try:
        z = np.linalg.solve(np.eye(idx.size) + C @ H0inv[np.ix_(idx, idx)], C @ y[idx])
    except np.linalg.LinAlgError:
        return None
    return -(y - H0inv[:, idx] @ z)


def newton(sysf, f, k, k_open, kt, cap, p0, t0, s_ref, x0, max_disp, maxit=60, tol=1e-10,
           k_along=None):
    """Newton with an energy line search for a fixed slip threshold ``cap`` (Tresca); returns State.

    The energy 1/2 x'Sx - f'x + normal spring + tangential (quadratic, then linear beyond ``cap``)
    is convex, so the iterates descend; when it has no minimum (the load slides or lifts the body)
    they run beyond ``max_disp``: :class:`GrossSlip` when every closed friction row slips and the load
    slides the body (:meth:`FrictionSystem.slides`; NotConverged when it does not), else
    :class:`Unbounded`.
    """
    x = np.array(x0, float)
    fscale = np.abs(f).max() + 1e-300
    def change(v, d, new, old):                     # E(v + d) - E(v), without cancellation of E itself
        return (d @ (sysf.S @ v - f) + 0.5 * d @ (sysf.S @ d)
                + np.sum(new[-1][0] - old[-1][0]) + np.sum(new[-1][1] - old[-1][1]))
    out = _laws(x, sysf, k, k_open, kt, cap, p0, t0, s_ref)
    allslip = 0
    for it in range(1, maxit + 1):
        p, dp, active, t, nd, norm, slip, _ = out
        r = _residual(sysf, f, x, p, t)
        if it > 1 and np.all(np.abs(r) <= np.maximum(tol * fscale, roundoff_floor(sysf, f, x))):
            return State(x=x, p=p, t=t, active=active, slip=slip & active[sysf.rows], iterations=it - 1)
        rmax = np.abs(r).max()
        for along in (0.0, 1.0):                             # exact Hessian, then the safe model
            blocks = _blocks(kt, cap, nd, norm, slip, along, k_along, sysf.tmask)
            with np.errstate(all="ignore"):
                dx = _step(sysf, r, k, kt, dp, blocks) if WOODBURY else None
                if dx is None or not np.all(np.isfinite(dx)):
                    H = _hessian(sysf, dp, blocks)
                    cf = cholesky_dense(H)
                    dx = (-sla.cho_solve(cf, r, check_finite=False) if cf is not None
                          else -np.linalg.lstsq(H, r, rcond=None)[0])
            if along == 0.0 and (not np.all(np.isfinite(dx)) or np.abs(x + dx).max() > max_disp):
                continue                                     # no minimum along the exact model
            slope, step = r @ dx, 1.0
            while step > 1e-3:
                new = _laws(x + step * dx, sysf, k, k_open, kt, cap, p0, t0, s_ref)
                de = change(x, step * dx, new, out)
                if de <= 1e-4 * step * slope or (            # Armijo; at round-off, the residual decides
                        de <= 1e-14 * (abs(f @ x) + 1e-300)
                        and np.abs(_residual(sysf, f, x + step * dx, new[0], new[3])).max() <= 0.5 * rmax):
                    break
                step *= 0.5
            if step > 1e-3:
                break
        if np.abs(r).max() <= 1e3 * tol * fscale and step <= 1e-3:      # round-off floor
            return State(x=x, p=p, t=t, active=active, slip=slip & active[sysf.rows], iterations=it)
        if not np.all(np.isfinite(dx)) or np.abs(x + step * dx).max() > max_disp:
            _unbounded(sysf, p, active, slip, f)
        if step <= 1e-3:                                     # no descent: sliding on, or stuck in a kink
            _unbounded(sysf, p, active, slip, f, strict=True)
        x, out = x + step * dx, new
        fa = active[sysf.rows]
        allslip = allslip + 1 if (fa.any() and np.all(slip[fa])) else 0
        if allslip > 25:                                     # sliding on: no minimum in sight
            _unbounded(sysf, p, active, slip, f)
    p, dp, active, t, nd, norm, slip, _ = out
    r = _residual(sysf, f, x, p, t)
    if np.abs(r).max() <= 1e3 * tol * fscale:                   # round-off floor reached
        return State(x=x, p=p, t=t, active=active, slip=slip & active[sysf.rows], iterations=maxit)
    _unbounded(sysf, p, active, slip, f, strict=True)
    raise NotConverged(f"friction Newton did not converge in {maxit} iterations")


def _unbounded(sysf, p, active, slip, f, strict=False):
    """Raise why the iterates stop: where every closed friction row slips, GrossSlip if the load slides the body
    at the normal forces ``p`` (:meth:`FrictionSystem.slides`), else NotConverged (an artefact of the iterates:
    a thin base's rows all slip radially under N); otherwise Unbounded (NotConverged: ``strict``)."""
    fr_active = active[sysf.rows]
    if fr_active.any() and np.all(slip[fr_active]):
        if sysf.slides(f, p, active):
            raise GrossSlip("the load slides the body (gross slip: friction cannot carry the tangential load)")
        raise NotConverged("friction Newton: every closed row slips, the load does not slide the body, and the "
                           "iterates do not settle")       # the path cuts the increment back, as it did on GrossSlip
    if strict:
        raise NotConverged("friction Newton did not converge")
    raise Unbounded("no bounded equilibrium")
