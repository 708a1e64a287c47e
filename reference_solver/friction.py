"""Coulomb friction on the condensed system: retained dofs, contact laws and one increment's solve.

Retained dofs r: the normal dof of every contact row (index = row), then the spring dofs, then the two
tangential dofs of every friction row that are not already a normal or a spring dof of that node
(the axes of the node's local frame). The condensed stiffness S (r x r, no rigid-body restraint of
its own) gives the equilibrium of an increment

    S x = f + R(x),   R = sum over rows of p_i n_i (normal dof) + t_i (two tangential dofs),

with x the retained displacements [m], f the condensed load [N], p_i >= 0 the normal force of the
master on the node [N] (compressive, along the normal into the body) and t_i (2,) the tangential
force of the master on the node [N] in the row's tangent axes (global vector: t_i . tdir_i).
Sign convention: t_i opposes the slip, so the table pushes back against the applied shear
(sum of t over the rows = -T in stick).

Laws (``s`` = tangential displacement (2,) [m], ``s_ref`` its value at the previous converged
increment, ``g`` = clearance + x_normal the gap [m], > 0 open):
- penalty (the paper's eq. 3, PGAP-like): p = -k g when closed, -k_open g open; t = proj(t_ref -
  k_t (s - s_ref)) on the disc |t| <= mu max(p, 0) (return mapping, radial);
- Lagrange (exact): the Alart-Curnier equations p = max(0, p - rho g), t = proj(t - rho (s - s_ref))
  solved by a semi-smooth Newton on the displacements alone (:mod:`.friction_ssn`), from the path's
  estimate of the increment (secant of the last two), then from the previous increment, else from a
  penalty predictor; the augmented-Lagrangian multiplier updates below (each
  inner problem the penalty law with the multipliers as pre-loads) are the last resort. At the
  solution g = 0 or p = 0 exactly, and s = s_ref (stick) or t = -mu p (s - s_ref) / |s - s_ref| (slip).
Each inner problem freezes the slip threshold mu p (Tresca) so that it minimises a convex energy:
Newton with an energy line search, its steps low-rank (Woodbury) updates of one inverse of
S + k (+ k_t) per path; the threshold is then updated to mu p (fixed point; for Lagrange together
with the multipliers, Anderson-accelerated) until nothing changes to ``tol``.
Corner nodes (a base node on both the table and the radial stop; docs/friction.md): one tangent axis of
the table row is the stop's normal (the radial), so that dof carries two forces, the stop's normal force
and the table's friction. The rule (``FrictionSystem.corner``, by method :data:`CORNER_RULE`):
- penalty, 'both' (as CalculiX's node-to-surface ``*FRICTION``): the table's friction acts on both tangent
  axes; the split of the radial force is unique, by the stiffnesses (stop k_n, table k_t) and the cone;
- Lagrange, 'stop' (stop first): the radial axis carries no table friction, the stop takes the force along
  it. With both rigid the split is indeterminate (the node does not move radially); what is unique is the
  node's whole horizontal force (stop normal + table friction), to be compared between methods and codes.
  While the stop is open (g > 0, or no compressive force) the table's friction acts on the radial too
  (:meth:`FrictionSystem.axes`, evaluated per Newton iterate by the semi-smooth Newton): the limit of the
  penalty split as k_stop / k_t -> infinity. The augmented-Lagrangian last resort keeps the radial of
  every corner off the table's friction (the static mask ``tmask``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .condense import CondensedSystem, check_mechanism, condense
from .contact import Unbounded
from .errors import ReferenceSolverError
from .friction_newton import newton
from .friction_ssn import solve_lagrange_increment
from .friction_state import GrossSlip, NotConverged, Runaway, State  # noqa: F401  (re-exported)
from .frames import complete_basis
from .problem import Problem

ANDERSON = 5             # depth of the Anderson acceleration of the Lagrange multiplier updates (0: off)
AL_RHO = (1.0, 1.0e-2)    # the augmented Lagrangian's rho, times the path's (RHO_FACTOR diag S), tried in turn:
                          # a thin base's soft modes (ring growth and tilt, ~1e-5 diag S) stall the inner
                          # Newton in the kinks of the stiff one (docs/friction.md, section 5)
AL_SAFE = 100.0           # the safe Newton model of the Lagrange inner solve uses rho / AL_SAFE along the slip
STALL_TOL = 1.0e-7        # penalty: thresholds that stop contracting below this relative change are at their rounding
                          # noise (face-weighted rows: ~2e-9, above tol 1e-11; hex20r 16 x 2 x 1, k-factor 100-1000)
PREDICTOR_TOL = 1.0e-6    # relative settling of the Lagrange predictor's slip thresholds (a predictor only)
RHO_FACTOR = 100.0        # the Lagrange fallback's augmented-Lagrangian rho = RHO_FACTOR * diag(S) on the normal dofs [N/m]
REGULARISER = 1.0e-6      # spring on the added tangential dofs during condensation, times E * L [N/m]
CORNER_RULES = ("stop", "both")
CORNER_RULE = {"penalty": "both", "lagrange": "stop", "augmented": "stop"}   # each method's corner rule (above)


@dataclass
class FrictionSystem:
    """The condensed system of a ``tangential='friction'`` problem (built by :func:`condense_friction`)."""
    problem: Problem
    base: CondensedSystem         # condensation of the problem with the tangential dofs as (removed) springs
    S: np.ndarray                 # (nr, nr) condensed stiffness, the regulariser removed [N/m]
    fhat: np.ndarray              # (nr, ncase) condensed loads [N]
    rows: np.ndarray              # (nf,) contact rows with friction
    tdofs: np.ndarray             # (nf, 2) retained index of each friction row's tangential dofs
    tdir: np.ndarray              # (nf, 2, 3) their global unit directions
    info: dict = field(default_factory=dict)
    cache: dict = field(default_factory=dict, repr=False)   # H0^-1 per (k, k_t), see _base_inverse
    corner: str = "stop"          # corner rule: 'stop' (stop first) or 'both' (table friction on every axis)
    views: dict = field(default_factory=dict, repr=False)   # this system under the other corner rule
    modes: np.ndarray | None = field(default=None, repr=False)   # slide_modes, once built
    dirs: np.ndarray | None = field(default=None, repr=False)    # slides' trial directions, once built

    @property
    def tmask(self) -> np.ndarray:
        """(nf, 2) tangential axes that carry friction. Corner rule 'both': every axis; 'stop': not an
        axis that is the normal of another contact row of the node (the stop's radial normal)."""
        if self.corner == "both":
            return np.ones(self.tdofs.shape, bool)
        return self.tdofs >= self.problem.n_contacts

    def axes(self, active: np.ndarray) -> np.ndarray:
        """(nf, 2) tangential axes that carry friction in the contact state ``active`` (nc,): the corner
        rule 'stop' gives a corner's radial axis back to the table's friction while the stop is open."""
        m = self.tmask
        if self.corner == "stop":
            nc = self.problem.n_contacts
            m = m | ((self.tdofs < nc) & ~np.asarray(active, bool)[np.minimum(self.tdofs, nc - 1)])
        return m

    @property
    def slide_modes(self) -> np.ndarray:
        """(nr, 3) the retained dofs of the body's rigid slides on the table: translations along two
        tangent axes of the table and the rotation about its normal through the friction nodes' centroid
        (unit translation, unit rotation [rad]); the motions that friction alone holds."""
        if self.modes is None:
            p = self.problem
            nr = self.S.shape[0]
            node, dirs = np.zeros(nr, np.int64), np.zeros((nr, 3))
            node[:p.n_contacts], dirs[:p.n_contacts] = p.contact_nodes, p.contact_normals
            ns = p.n_springs
            node[p.n_contacts:p.n_contacts + ns] = p.spring_nodes
            dirs[p.n_contacts:p.n_contacts + ns] = np.asarray(p.spring_dirs).reshape(-1, 3)
            fn = p.contact_nodes[self.rows]
            node[self.tdofs.ravel()] = np.repeat(fn, 2)
            dirs[self.tdofs.ravel()] = self.tdir.reshape(-1, 3)
            n = p.contact_normals[self.rows].mean(axis=0)
            n /= np.linalg.norm(n)
            a, b = _tangent_axes([n])
            r = p.nodes[node] - p.nodes[fn].mean(axis=0)
            B = np.stack([dirs @ a, dirs @ b, np.einsum("ik,ik->i", dirs, np.cross(n, r))], axis=1)
            self.modes = B
        return self.modes

    def slides(self, f: np.ndarray, p: np.ndarray, closed: np.ndarray) -> bool:
        """Whether the load ``f`` (nr,) slides the body on the table at the normal forces ``p`` (nc,) [N]
        (> 0 compressive) of the ``closed`` (nc,) rows: some rigid slide c (:attr:`slide_modes`), into no
        closed contact, along which the load does more work than the table's friction dissipates,
        f . B c > mu sum_i p_i |B_i c| (the friction rows' tangential part). That is gross slip; every closed
        row slipping is not: with no stop the base may slip radially everywhere under N alone (Poisson),
        a growth of the base ring, and the load there has no in-plane resultant (docs/friction.md,
        section 5). Checked on a fixed set of slide directions plus the load's own translation and
        rotation."""
        B = self.slide_modes
        g = f @ B                                                  # the load's in-plane force and torque
        pr = self.problem
        nodes = pr.nodes[pr.contact_nodes[self.rows]]
        L = max(float(np.sqrt(np.mean(np.sum((nodes - nodes.mean(axis=0)) ** 2, axis=1)))), 1e-300)
        gs = g * np.array([1.0, 1.0, 1.0 / L])                     # per unit translation / rotation x L
        if not np.all(np.isfinite(gs)) or np.linalg.norm(gs) <= 1e-12 * np.abs(f).max():
            return False
        if self.dirs is None:
            n = 2000                                              # a Fibonacci sphere of slide directions
            i = np.arange(n) + 0.5
            z = 1 - 2 * i / n
            ph = np.pi * (1 + 5 ** 0.5) * i
            self.dirs = np.stack([np.sqrt(1 - z * z) * np.cos(ph), np.sqrt(1 - z * z) * np.sin(ph), z], axis=1)
        own = [gs / np.linalg.norm(gs), np.r_[gs[:2], 0.0], np.r_[0.0, 0.0, gs[2]]]
        C = np.vstack([self.dirs] + [o / np.linalg.norm(o) for o in own if np.linalg.norm(o) > 0])
        C = C * np.array([1.0, 1.0, 1.0 / L])                      # back to (translation, rotation [rad])
        closed = np.asarray(closed, bool)
        move = C @ B[:pr.n_contacts][closed].T                    # opening (> 0) of the closed rows
        ok = np.all(move >= -1e-9 * np.abs(move).max(initial=0.0), axis=1)
        pn = pr.friction * np.where(closed, np.maximum(p, 0.0), 0.0)[self.rows]
        diss = np.linalg.norm(np.einsum("fak,ck->cfa", B[self.tdofs], C), axis=2) @ pn
        work = C @ g
        return bool(np.any(ok & (work > diss) & (work > 1e-9 * np.linalg.norm(g))))

    def with_corner(self, corner: str) -> "FrictionSystem":
        """This system under the corner rule ``corner`` (shares S and the condensation; one view per rule)."""
        if corner not in CORNER_RULES:
            raise ReferenceSolverError(f"corner = {corner!r}: must be one of {', '.join(CORNER_RULES)}")
        if corner == self.corner:
            return self
        if corner not in self.views:
            self.views[corner] = replace(self, corner=corner, cache={}, views={self.corner: self})
        return self.views[corner]

    @property
    def case_names(self):
        return self.base.case_names

    @property
    def dofs(self) -> int:
        return self.base.dofs

    @property
    def n_contacts(self) -> int:
        return self.problem.n_contacts

    def coeffs(self, combo) -> np.ndarray:
        return self.base.coeffs(combo)

    def recover(self, x: np.ndarray, coeffs: np.ndarray) -> np.ndarray:
        """Global nodal displacements (m, n, 3) [m] from retained displacements ``x`` (m, nr)."""
        xr = np.atleast_2d(x).T
        co = np.atleast_2d(coeffs).T
        q = self.base.schur.recover(xr, co)
        u = (self.base.dofmap.T @ q).T.reshape(xr.shape[1], -1, 3)
        if not np.all(np.isfinite(u)):
            raise ReferenceSolverError("non-finite displacements in the recovered field")
        return u


def _tangent_axes(normals: list[np.ndarray]) -> list[np.ndarray]:
    """Axes completing the given orthonormal directions of one node to an orthonormal basis."""
    return complete_basis(normals)[len(normals):]


def condense_friction(p: Problem, **kw) -> FrictionSystem:
    """Condense a friction problem onto normal, spring and tangential dofs (``kw`` to :func:`condense`)."""
    if p.tangential != "friction":
        raise ReferenceSolverError("condense_friction: the problem has tangential = 'springs'")
    if p.friction <= 0:
        check_mechanism(p)     # without friction nothing carries the tangential load
        raise ReferenceSolverError("friction = 0 with tangential = 'friction': nothing carries the tangential load")
    at_node: dict[int, list[tuple[np.ndarray, int]]] = {}
    for j, (n, v) in enumerate(zip(p.contact_nodes, p.contact_normals)):
        at_node.setdefault(int(n), []).append((v, j))
    for m, (n, v) in enumerate(zip(p.spring_nodes, p.spring_dirs)):
        at_node.setdefault(int(n), []).append((v, p.n_contacts + m))
    rows = np.flatnonzero(np.isin(p.contact_surface, p.friction_surfaces))
    new_nodes, new_dirs = [], []
    for n in np.unique(p.contact_nodes[rows]):
        dirs = [v for v, _ in at_node[int(n)]]
        for a in _tangent_axes(dirs) if len(dirs) < 3 else []:
            at_node[int(n)].append((a, p.n_contacts + p.n_springs + len(new_nodes)))
            new_nodes.append(int(n))
            new_dirs.append(a)
    kreg = REGULARISER * p.E * p.length_scale()
    nn = len(new_nodes)
    aug = Problem(**{**{f: getattr(p, f) for f in p.__dataclass_fields__},
                     "spring_nodes": np.concatenate([p.spring_nodes, np.array(new_nodes, np.int64)]),
                     "spring_dirs": np.vstack([p.spring_dirs.reshape(-1, 3), np.array(new_dirs).reshape(-1, 3)]),
                     "spring_k": np.concatenate([p.spring_k, np.full(nn, kreg)]),
                     "tangential": "springs"})
    base = condense(aug, **kw)
    S = base.S.copy()
    added = np.arange(p.n_contacts + p.n_springs, S.shape[0])
    S[added, added] -= kreg
    tdofs = np.empty((rows.size, 2), np.int64)
    tdir = np.empty((rows.size, 2, 3))
    for i, j in enumerate(rows):
        nvec = p.contact_normals[j]
        others = [(v, r) for v, r in at_node[int(p.contact_nodes[j])] if abs(v @ nvec) < 0.5]
        if len(others) != 2:
            raise ReferenceSolverError(f"node {int(p.contact_nodes[j])}: cannot build its tangent plane")
        tdofs[i] = [r for _, r in others]
        tdir[i] = [v for v, _ in others]
    return FrictionSystem(problem=p, base=base, S=S, fhat=base.fhat, rows=rows, tdofs=tdofs, tdir=tdir,
                          info={**base.info, "retained": int(S.shape[0])})


def solve_increment(sysf: FrictionSystem, method: str, f: np.ndarray, prev: State, k: np.ndarray,
                    k_open: np.ndarray, kt: np.ndarray, mu: float, max_disp: float,
                    rho: np.ndarray | None = None, tol: float = 1e-11, maxit: int = 200,
                    rho_steps: int = 1, rho_growth: float = 10.0, quick: bool = False,
                    guess: np.ndarray | None = None) -> State:
    """One load increment from the converged state ``prev`` to the load ``f`` (penalty, Lagrange or augmented).

    Penalty: fixed point on the slip thresholds mu p around the Tresca Newton solve. Lagrange: the
    semi-smooth Newton (``quick``: its direct attempts only, NotConverged else), then, as the last
    resort, the augmented-Lagrangian multiplier updates with rho = ``rho`` x AL_RHO in turn. Augmented:
    those updates with rho = ``rho`` (the law's epsilon) alone.
    """
    s_ref = prev.x[sysf.tdofs]
    nf, fr = sysf.rows.size, sysf.rows
    x, its = prev.x, 0
    if method == "penalty":
        z0 = np.zeros_like(k)
        cap = mu * np.where(prev.active[fr], np.maximum(prev.p[fr], 0.0), 0.0)
        if not np.any(cap > 0):
            cap = np.full(nf, np.inf)                     # no normal force yet: stick predictor
        last = np.inf
        for outer in range(1, maxit + 1):                    # fixed point on the threshold mu p
            st = newton(sysf, f, k, k_open, kt, cap, z0, prev.t, s_ref, x, max_disp)
            its += st.iterations
            new = mu * np.where(st.active[fr], np.maximum(st.p[fr], 0.0), 0.0)
            x = st.x
            change = np.abs(new - cap).max() / (np.abs(new).max() + 1e-300)
            if change <= tol or (change <= STALL_TOL and change > 0.5 * last):   # settled, or at its rounding
                st.iterations = its                                               # noise (face rows: STALL_TOL)
                return st
            cap, last = new, change
        raise NotConverged(f"penalty friction: the slip thresholds did not settle in {maxit} updates")
    if method == "augmented":
        return augmented_increment(sysf, f, prev, mu, max_disp, rho, tol, maxit, rho_steps, rho_growth, False)
    try:
        return solve_lagrange_increment(sysf, f, prev, mu, max_disp, guess=guess, predictor=None if quick else (
            lambda kp, ktp: solve_increment(sysf.with_corner("both"), "penalty", f, prev, kp, 1e-12 * kp, ktp,
                                            mu, max_disp, tol=PREDICTOR_TOL)))
    except NotConverged as exc:
        if quick:
            raise                                  # the caller cuts the increment back first
        runaway = isinstance(exc, Runaway)         # the augmented Lagrangian below, the last resort
    first = None
    for scale in AL_RHO:                               # the last resort, its rho from stiff to soft
        try:
            return augmented_increment(sysf, f, prev, mu, max_disp, scale * rho, tol, maxit, rho_steps, rho_growth,
                                       runaway)
        except (NotConverged, Unbounded) as exc:       # GrossSlip: the load slides the body, said at once
            first = first or exc
    raise first


def augmented_increment(sysf, f, prev, mu, max_disp, rho, tol, maxit, rho_steps, rho_growth, runaway):
    """The augmented-Lagrangian multiplier updates (p, t and the slip thresholds, Anderson-accelerated), each
    inner problem the penalty law at ``rho`` [N/m] with the multipliers as pre-loads; the augmented
    friction law and the Lagrange law's last resort. Counts its updates in ``State.augmentations``."""
    s_ref = prev.x[sysf.tdofs]
    nf, fr = sysf.rows.size, sysf.rows
    x, its = prev.x, 0
    p0 = np.where(prev.active, np.maximum(prev.p, 0.0), 0.0)
    t0 = prev.t.copy()
    zero = np.zeros_like(rho)
    r = rho / rho_growth ** rho_steps                  # continuation: moderate rho first, then stiffer
    cap = mu * p0[fr] if np.any(p0[fr] > 0) else np.full(nf, np.inf)
    hist_z, hist_g = [], []                            # Anderson acceleration of the multiplier updates
    for outer in range(1, maxit + 1):
        r = np.minimum(r * rho_growth, rho)
        try:
            st = newton(sysf, f, r, zero, r[fr], cap, p0, t0, s_ref, x, max_disp, k_along=r[fr] / AL_SAFE)
        except (NotConverged, Unbounded) as exc:
            if runaway:                                # both ran away, not all slipping (the path decides)
                raise Runaway(str(exc)) from None
            raise
        its += st.iterations
        p = np.where(st.active, st.p, 0.0)
        change = max(np.abs(p - p0).max(), np.abs(st.t - t0).max() if nf else 0.0,
                     np.abs(mu * p[fr] - cap).max() if nf else 0.0)
        z, gz = np.concatenate([p0, t0.ravel()]), np.concatenate([p, st.t.ravel()])
        x = st.x
        if np.all(r >= rho) and ANDERSON:
            hist_z.append(z)
            hist_g.append(gz)
            del hist_z[:-ANDERSON - 1], hist_g[:-ANDERSON - 1]
        if len(hist_z) > 1:
            F = np.array(hist_g) - np.array(hist_z)                    # residuals of the fixed point
            dF, dG = np.diff(F, axis=0).T, np.diff(np.array(hist_g), axis=0).T
            gamma = np.linalg.lstsq(dF, F[-1], rcond=None)[0]
            gz = gz - dG @ gamma
        p0, t0 = np.maximum(gz[:p.size], 0.0), gz[p.size:].reshape(-1, 2)
        cap = mu * p0[fr]
        if change <= tol * (np.abs(p).max() + 1e-300) and np.all(r >= rho):
            break
    else:
        raise NotConverged(f"Lagrange friction: multipliers did not settle in {maxit} updates")
    ds = np.linalg.norm(np.where(sysf.tmask, x[sysf.tdofs] - s_ref, 0.0), axis=1)
    on_cone = np.linalg.norm(st.t, axis=1) >= (1 - 1e-8) * mu * p[fr]        # |t| = mu p and moving
    slip = st.active[fr] & (p[fr] > 0) & on_cone & (ds > 1e-9 * (np.abs(x).max() + 1e-300))
    pen = float(np.maximum(-(sysf.problem.contact_clearance + x[:p.size]), 0.0).max(initial=0.0))
    return State(x=x, p=p, t=st.t, active=st.active, slip=slip, iterations=its, augmentations=outer, penetration=pen)
