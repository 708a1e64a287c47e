"""friction.csv of a reference folder: the tangential (friction) state of every contact row and increment.

Written beside contact.csv when the solution models Coulomb friction (``contact.tangential: friction``),
same rows in the same order. Columns: step, increment, load_factor, node, surface, theta_deg, wall (as in
contact.csv); ``fn_x_n``, ``fn_y_n``, ``fn_z_n``: the normal force of the master on the node in global
xyz [N] (force_n times the row's normal into the body; with F_t the whole contact force); ``ft_x_n``, ``ft_y_n``, ``ft_z_n``: the tangential force F_t of the master (table, stop) on
the node in global xyz [N] (it opposes the slip: in stick Sum F_t = -T lambda with no stop in contact);
``ft_theta_n`` = F_t . e_theta with e_theta = (-sin t, cos t, 0) (circumferential, CCW > 0),
``ft_r_n`` = F_t . e_r with e_r = (cos t, sin t, 0) (radial, outwards > 0), ``ft_n`` = |F_t| [N];
``area_m2`` the node's tributary contact area, ``tau_pa`` = |F_t| / area [Pa] (one node; through the
wall see :func:`deckbridge.quantities.tangential_traction`); ``mu_fn_n`` = mu max(force_n, 0) [N], the
Coulomb bound; ``stick_status``: stick | slip | open | frictionless (a surface without friction);
On face-weighted rows (8-/6-node faces, ``Solution.tangential_traction``) F_t is the tangential multiplier [Pa]
times ``area_m2`` and the normal force contact.csv's ``force_n`` (the pressure on that area), not the nodal
consistent shares (<= 0 at the corners of 8-node faces): each row then meets Coulomb on its own, |F_t| <=
mu force_n, and the sums are the resultants (reference_solver/friction_face.py). ``node_fh_r_n``, ``node_fh_theta_n``: the node's whole horizontal contact force (normal + tangential of
every row of the node, summed over table and stop), radial (outwards > 0) and circumferential [N], the same
on each row of the node. At a base node on both table and stop this is the compared quantity: its split
into stop normal and table friction follows the method's corner rule and is not unique in Lagrange
(docs/friction.md).
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd


FRICTION_CSV = "friction.csv"
COLUMNS = ["step", "increment", "load_factor", "node", "surface", "theta_deg", "wall", "fn_x_n", "fn_y_n", "fn_z_n",
           "ft_x_n", "ft_y_n", "ft_z_n", "ft_theta_n", "ft_r_n", "ft_n", "area_m2", "tau_pa", "mu_fn_n", "stick_status",
           "node_fh_r_n", "node_fh_theta_n"]
STATUSES = ("stick", "slip", "open", "frictionless")


def friction_table(contact: pd.DataFrame, sol, mu: float, normals: np.ndarray) -> pd.DataFrame | None:
    """friction.csv of a solution (None without friction); ``contact``: its tidy contact table, whose
    rows are (increment, contact row) in the solution's order; ``normals`` (nc, 3): the contact rows'
    unit normals into the body (the problem's contact_normals)."""
    if getattr(sol, "tangential_force", None) is None:
        return None
    ft = np.asarray(sol.tangential_force, float).reshape(-1, 3)
    if len(contact) != ft.shape[0]:
        raise ValueError(f"friction table: {ft.shape[0]} tangential forces for {len(contact)} contact rows")
    area = contact["area_m2"].to_numpy(float)
    traction = getattr(sol, "tangential_traction", None)
    if traction is not None:       # face-weighted rows: the multipliers on the row's area, as force_n (contact.csv)
        ft = np.asarray(traction, float).reshape(-1, 3) * area[:, None]
        fn = contact["force_n"].to_numpy(float)[:, None] * np.tile(np.asarray(normals, float), (sol.force.shape[0], 1))
    else:
        fn = (np.asarray(sol.force, float)[:, :, None] * np.asarray(normals, float)[None]).reshape(-1, 3)
    t = np.radians(contact["theta_deg"].to_numpy(float))
    e_theta = np.stack([-np.sin(t), np.cos(t), np.zeros_like(t)], axis=1)
    e_r = np.stack([np.cos(t), np.sin(t), np.zeros_like(t)], axis=1)
    mag = np.linalg.norm(ft, axis=1)
    out = contact[["step", "increment", "load_factor", "node", "surface", "theta_deg", "wall"]].reset_index(drop=True)
    out = out.assign(fn_x_n=fn[:, 0], fn_y_n=fn[:, 1], fn_z_n=fn[:, 2], ft_x_n=ft[:, 0], ft_y_n=ft[:, 1], ft_z_n=ft[:, 2],
                     ft_theta_n=np.einsum("ij,ij->i", ft, e_theta), ft_r_n=np.einsum("ij,ij->i", ft, e_r),
                     ft_n=mag, area_m2=area, tau_pa=mag / area,
                     mu_fn_n=mu * np.maximum(contact["force_n"].to_numpy(float), 0.0),
                     stick_status=np.asarray(sol.stick_status).ravel().astype(str))
    whole = pd.DataFrame({"step": out["step"], "increment": out["increment"], "node": out["node"],
                          "r": np.einsum("ij,ij->i", fn + ft, e_r), "t": np.einsum("ij,ij->i", fn + ft, e_theta)})
    node_sum = whole.groupby(["step", "increment", "node"])[["r", "t"]].transform("sum")
    out = out.assign(node_fh_r_n=node_sum["r"].to_numpy(), node_fh_theta_n=node_sum["t"].to_numpy())
    warn_coulomb(out, sol.friction_check(None, mu))
    return out[COLUMNS]


def warn_coulomb(table: pd.DataFrame, check: dict) -> None:
    """Say (UserWarning, shown by the CLI) when the solution breaks its own Coulomb law: ``check`` is the
    solver's count (:meth:`reference_solver.Solution.friction_check`: |F_t| > mu max(F_n, 0) (1 + 1e-9) +
    1e-9 max |F_t|), the worst row is read from ``table`` (friction.csv). Such a row is no 0/0: a row whose
    master pushes it with |F_t| far above mu F_n (issue 26: 8.9 kN of table friction with mu F_n = 6e-8 N
    on a corner node whose stop is open) is not a Coulomb equilibrium, whatever its stick_status says."""
    if not check["violations"]:
        return
    excess = table["ft_n"].to_numpy(float) - table["mu_fn_n"].to_numpy(float)
    w = table.iloc[int(np.argmax(excess))]
    warnings.warn(f"friction: {check['violations']} contact row(s) x increments break the Coulomb law "
                  f"|F_t| <= mu F_n (mu = {check['mu']:g}); worst: node {int(w['node'])} ({w['surface']}, "
                  f"{w['stick_status']}), step {int(w['step'])} increment {int(w['increment'])}: |F_t| = "
                  f"{w['ft_n']:.4g} N against mu F_n = {w['mu_fn_n']:.4g} N (friction.csv): the solution is not "
                  "a Coulomb equilibrium there", stacklevel=2)


def state_rows(df: pd.DataFrame, load_factor: float) -> pd.DataFrame | None:
    """Rows of one state: lambda = 0 the end of step 1, else the last step-2 increment at ``load_factor``
    (to 1e-9 relative); None when the path has no such state (no interpolation)."""
    if load_factor == 0.0:
        s = df[df["step"] == 1]
    else:
        s = df[(df["step"] == 2) & (np.abs(df["load_factor"] - load_factor) <= 1e-9 * max(1.0, abs(load_factor)))]
    if s.empty:
        return None
    return s[s["increment"] == s["increment"].max()]


def states(df: pd.DataFrame):
    """(step, increment, load_factor, rows) of every state in path order."""
    for (step, inc), rows in df.groupby(["step", "increment"], sort=True):
        yield int(step), int(inc), float(rows["load_factor"].iloc[0]), rows
