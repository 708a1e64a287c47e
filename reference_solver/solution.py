"""The result of a load path: contact results per increment and contact row (see :class:`Solution`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


def _cone_check(ft: np.ndarray, fn: np.ndarray, mu: float, rtol: float) -> dict:
    """Tangential forces ``ft`` [N] against mu x the compressive normal forces ``fn`` [N] (same shape,
    increments x rows): violations above mu fn (1 + rtol) plus a floor of 1e-9 of the largest force,
    tangential or normal. Round-off scales with the forces in equilibrium: with mu = 1e-12 every |ft| is
    round-off (<= 1e-6 N against normal forces of 1e5 N on the default JAR), and a floor on the largest
    ft alone counted 1958 such rows as violations, open rows as |ft| / fn = inf (issue 26)."""
    floor = 1e-9 * max(ft.max() if ft.size else 0.0, fn.max() if fn.size else 0.0)
    viol = ft > mu * fn * (1 + rtol) + floor
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(fn > 0, ft / fn, np.where(ft > floor, np.inf, 0.0))
    return {"mu": mu, "violations": int(viol.sum()),
            "violations_last_increment": int(viol[-1].sum()) if viol.size else 0,
            "max_ratio_ft_fn": float(ratio.max()) if ratio.size else 0.0}


@dataclass
class Solution:
    """Contact results per increment (rows) and contact row / spring (columns).

    ``force``: normal force of the master on the node [N], > 0 compressive; ``sigma_n`` = -force /
    area [Pa] (< 0 compression); ``gap`` [m] (> 0 open); ``closed``: gap <= 0 (penalty) or in the
    active set (Lagrange). ``spring_force``: force of each spring on its node along its direction [N].
    ``fields[step]``: global displacements (n, 3) [m] at the end of each step when recovered.
    With friction (``tangential == 'friction'``): ``tangential_force`` is the tangential force of the
    master on the node (global xyz) [N]; it opposes the slip, so in stick its sum is minus the applied
    shear; ``slip_increment`` the slip of the node over the increment [m]; ``dissipation`` = -sum t.slip
    over the increment [J] (>= 0).
    """
    method: str
    algorithm: str
    k_factor: float | None
    penalty_k: np.ndarray | None
    step: np.ndarray
    increment: np.ndarray
    load_factor: np.ndarray
    coeffs: np.ndarray            # (ni, ncase) load-case coefficients of each increment
    u: np.ndarray                 # (ni, nc) normal displacement of the contact dofs [m]
    gap: np.ndarray
    force: np.ndarray
    sigma_n: np.ndarray
    closed: np.ndarray
    spring_u: np.ndarray          # (ni, ns) [m]
    spring_force: np.ndarray      # (ni, ns) [N]
    iterations: np.ndarray
    liftoff_load_factor: float | None
    liftoff_row: int | None
    liftoff_method: str | None = None   # 'path-following' (exact) or 'bisection'
    fields: dict = field(default_factory=dict)
    wall_time_s: float = 0.0
    # with tangential = 'friction' (None otherwise):
    tangential: str = "springs"
    tangential_force: np.ndarray | None = None    # (ni, nc, 3) force of the master on the node [N], global
    slip_increment: np.ndarray | None = None      # (ni, nc, 3) slip over the increment [m] (penalty: plastic part)
    stick_status: np.ndarray | None = None        # (ni, nc) 'open' | 'stick' | 'slip' | 'frictionless'
    dissipation: np.ndarray | None = None         # (ni,) friction work dissipated in the increment [J], >= 0
    gross_slip_load_factor: float | None = None   # onset of gross slip (the load slides the body)
    retained_u: np.ndarray | None = None          # (ni, nr) retained displacements [m]
    tangential_traction: np.ndarray | None = None  # (ni, nc, 3) face-weighted friction: the tangential multipliers
                                                  # lambda_t [Pa] (global), Coulomb's |lambda_t| <= mu (-sigma_n)
    # with method = 'augmented' (None otherwise):
    augmentations: np.ndarray | None = None       # (ni,) multiplier updates of each increment
    penetration: np.ndarray | None = None         # (ni,) largest penetration max(0, -gap) at its end [m]
    penetration_tol: float | None = None          # the penetration tolerance it stopped at [m]
    # a path-dependent law (friction): each step-2 increment's (load factor, converged law State), which the
    # whole-section onset (:func:`reference_solver.path.section_onset`) restarts from; None otherwise
    path_states: list | None = field(default=None, repr=False)

    def friction_check(self, problem, mu: float) -> dict:
        """Compare each spring (tangential) force with mu times the normal force at its node.

        The normal force sums every contact row of the node (table and stop). A node without
        compression and a tangential force above 1e-9 of the largest counts as a violation.
        With friction modelled (``tangential == 'friction'``) each contact row's tangential force is
        compared with mu times its own normal force instead; on face-weighted rows (``tangential_traction``)
        its tangential multiplier with mu times its pressure -sigma_n (the nodal forces of 8-/6-node faces
        are consistent shares, <= 0 at corners: reference_solver/friction_face.py).
        """
        if self.tangential_traction is not None:     # face-weighted rows: Coulomb holds on the multipliers
            return {**_cone_check(np.linalg.norm(self.tangential_traction, axis=2), np.maximum(-self.sigma_n, 0.0),
                                  mu, rtol=1e-9),
                    "slipping_last_increment": int(np.sum(self.stick_status[-1] == "slip"))}
        if self.tangential_force is not None:
            return {**_cone_check(np.linalg.norm(self.tangential_force, axis=2), np.maximum(self.force, 0.0), mu,
                                  rtol=1e-9),
                    "slipping_last_increment": int(np.sum(self.stick_status[-1] == "slip"))}
        fn = np.zeros((self.force.shape[0], problem.n_nodes))
        np.add.at(fn.T, problem.contact_nodes, self.force.T)
        return _cone_check(np.abs(self.spring_force), np.maximum(fn[:, problem.spring_nodes], 0.0), mu, rtol=1e-12)

    def recover_step_ends(self, system, retained: np.ndarray) -> None:
        """Global displacements (n, 3) [m] at the end of steps 1 and 2 into ``fields``, by one
        ``system.recover`` of the retained displacements ``retained`` (ni, nr) of those rows."""
        ends = [int(np.flatnonzero(self.step == s)[-1]) for s in (1, 2)]
        for s, u in zip((1, 2), system.recover(retained[ends], self.coeffs[ends])):
            self.fields[s] = u

