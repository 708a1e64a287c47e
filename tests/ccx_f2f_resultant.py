"""Test helper: the exact contact resultant of a CalculiX face-to-face job on 8-/6-node faces per load factor.

ccx prints no nodal force of those slave nodes (the table's force_n is NaN); the clamped master ring's reaction is
the resultant (:func:`deckbridge.dialects.calculix.result_files.f2f_master_resultant`, keyed by ccx time).
"""

from pathlib import Path


def load_factor(t: float, lam_max: float) -> float:
    """Load factor of a ccx total time t [s] of the decks' two steps of period 1 (N, then N + lambda (T, M))."""
    return 0.0 if t <= 1.0 + 1e-9 else lam_max * (t - 1.0)


def f2f_resultants(deck: Path, lam_max: float) -> dict:
    """{load factor: (force (3,) [N], moment (3,) [N m] about the origin)} of the table on the skirt, SI."""
    from deckbridge.dialects.calculix.result_files import f2f_master_resultant
    return {load_factor(t, lam_max): fm for t, fm in f2f_master_resultant(deck).items()}


def ring_resultant(ccx_dir: Path, label: str, table, lam_max: float) -> dict | None:
    """Per load factor of ``table`` (source ``label``, e.g. 'ccx/f2f') (Fz [N], Mx, My [N m]) of the job in
    ``ccx_dir`` whose table rows have no nodal force (f2f on 8-/6-node faces); None where they have one."""
    import numpy as np
    if not label.startswith("ccx/") or np.isfinite(table[table.surface == "table"].force_n.to_numpy(float)).any():
        return None
    got = f2f_resultants(next(Path(ccx_dir).glob(f"*_ccx_{label.split('/')[1]}.inp")), lam_max)
    near = {float(k): got[min(got, key=lambda x: abs(x - k))] for k in table.load_factor.unique()}
    return {k: (F[2], M[0], M[1]) for k, (F, M) in near.items()}


def ring_line_pairs(run) -> list[tuple[float, "np.ndarray", "np.ndarray"]]:
    """(load factor, reference, ccx) per common state of a quadratic run's face-to-face pair: the contact force
    [N] on each azimuth line of the deck's master ring, the reference's from its reference/f2f gaps
    (:func:`deckbridge.reference_f2f.ring_line_forces`), ccx's from the ring's RF
    (:func:`deckbridge.dialects.calculix.result_files.f2f_master_lines`): both exact, no nodal extrapolation."""
    import numpy as np
    from deckbridge.dialects.calculix.result_files import f2f_master_lines
    from deckbridge.mesh import build_mesh
    from deckbridge.numbering.skirt import mesh_node_ids
    from deckbridge.reference_f2f import ring_line_forces
    from deckbridge.solve import build_problem
    mesh = build_mesh(run.model)
    p = build_problem(run.model, mesh)
    rows = dict(zip(zip(mesh_node_ids(mesh, p.contact_nodes), p.contact_surface), range(p.n_contacts)))
    deck = next((Path(run.out) / "ccx").glob("*_ccx_f2f.inp"))
    got = {load_factor(t, run.model.steps.lambda_max): f for t, f in f2f_master_lines(deck, mesh.n_theta).items()}
    out = []
    for (step, inc), g in run.tables["reference/f2f"].groupby(["step", "increment"], sort=True):
        lam = float(g.load_factor.iloc[0])
        near = min(got, key=lambda x: abs(x - lam))
        if abs(near - lam) > 1e-6 or (step == 2 and inc == 0):
            continue
        gap = np.zeros(p.n_contacts)
        gap[[rows[(n, s)] for n, s in zip(g.node, g.surface)]] = g.gap_m.to_numpy(float)
        out.append((lam, ring_line_forces(p, gap, mesh.n_theta)[0], got[near]))
    return out
