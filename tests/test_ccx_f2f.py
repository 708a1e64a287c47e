"""The CalculiX face-to-face penalty deck ``<name>_ccx_f2f.inp`` (issue 24): ``SURFACE TO SURFACE`` contact,
LINEAR slope per face from the model's nodal k_c / A, read from the RF of a master that matches the slave mesh.

Checked against: the closed form of the slope (alpha K_bulk / h1 for the model's own penalty), the applied load
(force balance of the read forces), the reference solver's nodal penalty at the same k_c (equal while every
table node is closed; the consistent spreading at the contact edge past liftoff, docs/ccx_f2f.md), and the
reference Lagrange solution as the slope grows.
"""

import shutil

import numpy as np
import pytest

from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.readers import read
from deckbridge.dialects.calculix.render import f2f_context, f2f_face_slopes
from deckbridge.solve import solve_model

SMALL = ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1"]
HELD_OUT = ["geometry.radius=1.3", "geometry.height=1.8", "geometry.thickness=0.015", "mesh.n_theta=32",
            "mesh.n_z=6", "mesh.n_r=2"]
needs_ccx = pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX ccx not installed")


def _through_wall(df, lam, step):
    """Through-wall resultant sigma_N per azimuth [Pa] (sum of forces / sum of areas) of the table at a state."""
    g = df[(df.surface == "table") & (df.step == step) & np.isclose(df.load_factor, lam)]
    a = g.groupby(np.round(g.theta_deg.to_numpy(float), 6))[["force_n", "area_m2"]].sum()
    return -(a.force_n / a.area_m2)


@pytest.mark.parametrize("overrides", [SMALL, HELD_OUT], ids=["small", "held_out"])
def test_f2f_slope_gives_every_node_its_k_c_under_a_uniform_penetration(overrides):
    """sum over a node's faces of K_face x (its nodal area share) = k_c of the node (to 1e-12), and K_face =
    alpha K_bulk / h1 on a parametric mesh (k_c = alpha A^2 K / V per face, V = A h1); the master's top nodes
    sit on the table slave nodes."""
    model = load(None, overrides)
    mesh = build_mesh(model)
    from deckbridge.mesh_data import quad_nodal_areas
    k = f2f_face_slopes(mesh)
    faces = mesh.hexes[mesh.base_elems][:, :4]
    a = quad_nodal_areas(mesh.nodes[faces])
    force = np.zeros(mesh.n_nodes)
    np.add.at(force, faces.ravel(), (k[:, None] * a).ravel())
    np.testing.assert_allclose(force[mesh.table.nodes], mesh.table.k, rtol=1e-12)
    h1 = model.geometry.height / model.mesh.n_z
    np.testing.assert_allclose(k, model.contact.penalty.alpha * model.material.bulk_modulus / h1, rtol=1e-12)
    ctx = f2f_context(model, mesh)
    assert len(ctx["f2f_groups"]) == 1
    assert ctx["f2f_groups"][0]["line"].startswith(f"{k[0]:.12e}")
    pairs = [ln.split()[-2:] for ln in ctx["meta"] if ln.startswith("** deckbridge-f2f-master ")][1:]
    assert len(pairs) == mesh.table.nodes.size


def _f2f_run(model, folder):
    from ccx_job import ccx_job
    return read(ccx_job(model, folder, "f2f").with_suffix(".frd"), fmt="calculix", model=model)


@needs_ccx
@pytest.mark.parametrize("overrides", [SMALL, HELD_OUT], ids=["small", "held_out"])
def test_ccx_f2f_balances_the_load_and_equals_the_reference_penalty_while_the_base_is_closed(overrides, tmp_path):
    """Every state: the read table forces carry N (1e-6 N relative). While no table node of the reference has
    lifted: through-wall sigma_N within 0.1 % of the peak and node by node within 2.5 % (measured 0.005 % and
    0.4 % small, 0.006 % and 1.8 % held out: the consistent spreading through the wall). Past liftoff inside
    the small-strain range (lift / R <= 0.01) the contact-edge azimuths differ (docs/ccx_f2f.md): through-wall
    within 10 % (measured 1.4 / 6.5 % small at lambda 0.7 / 0.8, 0.6-8.0 % held out)."""
    model = load(None, overrides)
    ccx = _f2f_run(model, tmp_path)
    ref, _ = solve_model(model, "penalty", recover=False)
    n_closed = n_lifted = 0
    for (step, inc), g in ref[ref.surface == "table"].groupby(["step", "increment"]):
        lam = float(g.load_factor.iloc[0])
        c = ccx[(ccx.step == step) & np.isclose(ccx.load_factor, lam) & (ccx.surface == "table")]
        if c.empty:
            continue                                       # ccx prints step 2 from its first increment
        assert abs(c.force_n.sum() - model.loads.N) <= 1e-6 * model.loads.N, (step, lam)
        lift = max(float(g.gap_m.max()), 0.0) / model.geometry.radius
        if lift > 0.01:
            continue
        peak = float(np.abs(g.sigma_n_pa).max())
        tw = float(np.abs(_through_wall(ref, lam, step) - _through_wall(ccx, lam, step)).max()) / peak
        j = g.merge(c, on="node", suffixes=("_r", "_c"))
        node = float(np.abs(j.sigma_n_pa_r - j.sigma_n_pa_c).max()) / peak
        if float(g.gap_m.max()) <= 0.0:
            assert tw <= 1e-3 and node <= 0.025, (lam, tw, node)
            n_closed += 1
        else:
            assert tw <= 0.10, (lam, tw)
            n_lifted += 1
    assert n_closed >= 5 and n_lifted >= 1


@needs_ccx
def test_ccx_f2f_and_the_reference_penalty_approach_lagrange_as_the_slope_grows(tmp_path):
    """alpha 0.1, 1, 10 (slope x 1, 10, 100): max |sigma_N - sigma_N,Lagrange| / peak (the reference Lagrange of
    the same model: its circumferential springs follow k_c) falls at every lambda
    with lift / R <= 0.01 past onset (0.6, 0.7, 0.8) for both the face-to-face deck and the nodal reference
    penalty. Measured at lambda 0.8: f2f 58.8 / 51.0 / 33.9 %, nodal 53.6 / 35.5 / 22.3 %: the face-to-face
    penalty nears the nodal Lagrange solution more slowly (docs/ccx_f2f.md)."""
    errs = {"f2f": [], "penalty": []}
    for alpha in (0.1, 1.0, 10.0):
        model = load(None, SMALL + [f"contact.penalty.alpha={alpha}"])
        lag, _ = solve_model(model, "lagrange", recover=False)   # its springs follow k_c too (k_tangent: follow)
        lags = lag[(lag.surface == "table") & (lag.step == 2)]
        tables = {"f2f": _f2f_run(model, tmp_path / f"a{alpha}"), "penalty": solve_model(model, "penalty",
                                                                                           recover=False)[0]}
        for name, df in tables.items():
            row = []
            for lam in (0.6, 0.7, 0.8):
                r = lags[np.isclose(lags.load_factor, lam)]
                c = df[(df.surface == "table") & (df.step == 2) & np.isclose(df.load_factor, lam)]
                j = r.merge(c, on="node", suffixes=("_r", "_c"))
                assert len(j) == len(r)
                row.append(float(np.abs(j.sigma_n_pa_r - j.sigma_n_pa_c).max() / np.abs(r.sigma_n_pa).max()))
            errs[name].append(row)
    for name, e in errs.items():
        e = np.array(e)
        assert np.all(np.diff(e, axis=0) < 0), (name, e)
    assert errs["f2f"][2][2] > errs["penalty"][2][2]
