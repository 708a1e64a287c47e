"""CalculiX node-to-surface penalty deck at stiff penalties: its residual tolerance R_n follows the round-off residual
of the stiffest contact spring (render.n2f_residual_tol), so that ccx converges where it stopped before with
'increment size smaller than minimum' (alpha >= 10 on a 24 x 4 x 1 skirt, R 1.2 m, t 12 mm), and the decks at the
model's own alpha keep R_n = 1e-7."""

from __future__ import annotations

import numpy as np
import pytest

from deckbridge.dialects.calculix.render import RESIDUAL_TOL, ROUNDOFF_MARGIN, n2f_residual_tol
from deckbridge.mesh import build_mesh
from deckbridge.model import load

THIN = ["mesh.n_theta=24", "mesh.n_z=4", "mesh.n_r=1", "steps.increments=7", "steps.lambda_max=0.7",
        "geometry.radius=1.2", "geometry.thickness=0.012", "geometry.height=1.5", "contact.penalty.k_tangent=2e8"]


@pytest.mark.parametrize("sets", [[], THIN], ids=["default", "thin"])
def test_residual_tolerance_is_unchanged_at_the_model_alpha_and_grows_with_the_stiffest_spring(sets):
    model = load(None, sets)
    assert n2f_residual_tol(model, build_mesh(model)) == RESIDUAL_TOL
    stiff = model.with_overrides({"contact.penalty.alpha": 50.0})
    mesh = build_mesh(stiff)
    k_max = max(mesh.table.k.max(), mesh.stop.k.max())
    length = np.abs(mesh.nodes[np.concatenate([mesh.table.nodes, mesh.stop.nodes])]).max()
    expected = ROUNDOFF_MARGIN * np.finfo(float).eps * k_max * length / (stiff.loads.N / mesh.table.nodes.size)
    assert expected > RESIDUAL_TOL
    assert n2f_residual_tol(stiff, mesh) == pytest.approx(expected, rel=1e-12)


@pytest.mark.ccx
@pytest.mark.parametrize("alpha", [10.0, 500.0])
def test_ccx_runs_the_stiff_penalty_deck_and_balances_n(alpha, tmp_path):
    """ccx completes both steps; step 1 (N alone, base closed): sum of the table contact forces = N within 2e-4, as
    at the model's own alpha 0.1 (measured 1.06e-4 there, 1.08e-4 at 10, 0.95e-4 at 500: ccx's node area A_ccx
    follows the motion, not the iteration tolerance)."""
    from ccx_job import ccx_penalty_job

    from deckbridge.readers import read

    model = load(None, THIN + [f"contact.penalty.alpha={alpha}"])
    inp = ccx_penalty_job(model, tmp_path)
    table = read(inp.with_suffix(".frd"), fmt="calculix", model=model)
    step1 = table[(table.step == 1) & (table.surface == "table")]
    assert step1.force_n.sum() == pytest.approx(model.loads.N, rel=2e-4)
    assert (table.step == 2).any() and np.isclose(table[table.step == 2].load_factor.max(), 0.7)
