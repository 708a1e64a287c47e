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
    (:func:`deckbridge.reference_f2f.table_ring_lines`), ccx's from the ring's RF (the calculix record's line
    reader, :func:`deckbridge.dialects.calculix.result_files.f2f_ring_lines`), paired as the job pairs them
    (:func:`deckbridge.compare.ring_lines.ring_line_pairs`): both exact, no nodal extrapolation."""
    from deckbridge.compare.ring_lines import ring_line_pairs as pairs
    from deckbridge.dialects.calculix.result_files import f2f_ring_lines
    from deckbridge.mesh import build_mesh
    from deckbridge.reference_f2f import table_ring_lines
    from deckbridge.solve import build_problem
    mesh = build_mesh(run.model)
    p = build_problem(run.model, mesh)
    deck = next((Path(run.out) / "ccx").glob("*_ccx_f2f.inp"))
    return pairs(table_ring_lines(p, mesh, run.tables["reference/f2f"]), f2f_ring_lines(deck, run.model, mesh))
