"""The reference solver against CalculiX on the same mesh, elements (C3D8I) and per-node stiffness.

Measured (24 x 6 x 1 mesh, max |d sigma_N| per increment / peak |sigma_N|):
- penalty vs ccx GAPUNI, kinematic top: <= 0.6 % at every increment, past liftoff too;
- penalty vs ccx GAPUNI, distributing top: 0.3 % up to liftoff; past it ccx (NLGEOM, required by GAPUNI)
  parts from the linear reference as the base lifts by centimetres (4-11 %), see the issue note;
- Lagrange vs ccx hard mortar (face-integrated, not node-based): 2.4-5.5 % (kinematic; 5.5 % under N alone), pinned below.
"""

import numpy as np
import pytest

from deckbridge.job import run_job
from deckbridge.model import load
from deckbridge.readers import read

SMALL = ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1"]


def _errors(out, model, ref_method, ccx_method):
    """Per increment: max |sigma_ref - sigma_ccx| / peak |sigma_ref| over the table nodes."""
    ref = read(out / f"reference_{ref_method}", model=model)
    ccx = read(out / "ccx", model=model)
    ccx = ccx[ccx.method == ccx_method]
    j = ref[ref.surface == "table"].merge(ccx[ccx.surface == "table"], on=["step", "increment", "node"],
                                          suffixes=("_r", "_c"))
    assert len(j) == 11 * 2 * 24   # 11 states x 48 table nodes
    res = {}
    for (_, _), g in j.groupby(["step", "increment"]):
        lam = float(g.load_factor_r.iloc[0])
        assert lam == pytest.approx(float(g.load_factor_c.iloc[0]))
        res[lam] = float(np.abs(g.sigma_n_pa_r - g.sigma_n_pa_c).max() / np.abs(g.sigma_n_pa_r).max())
    return res


@pytest.fixture(scope="module")
def kinematic_job(tmp_path_factory):
    model = load(None, SMALL + ["load_introduction=kinematic"])
    out = tmp_path_factory.mktemp("kin")
    run_job(model, out, with_ccx=True, echo=lambda s: None)
    return model, out


def test_penalty_matches_ccx_gapuni_within_2_percent_also_past_liftoff(kinematic_job):
    model, out = kinematic_job
    err = _errors(out, model, "penalty", "penalty")
    assert max(err.values()) < 0.02, err
    # the load path goes past liftoff, so the comparison covers open gaps too
    lifted = read(out / "reference_penalty", model=model)
    assert (lifted[(lifted.load_factor == 1.0) & (lifted.surface == "table")].status == "open").any()


def test_lagrange_against_ccx_mortar_pinned(kinematic_job):
    model, out = kinematic_job
    err = _errors(out, model, "lagrange", "mortar")
    worst = max(err.values())
    assert 0.03 < worst < 0.07, err   # measured 0.055 (step 1: mortar varies across the wall)


def test_penalty_matches_ccx_with_distributing_top_until_liftoff(tmp_path):
    model = load(None, SMALL + ["steps.lambda_max=0.5", "steps.increments=10"])  # liftoff near 0.59
    run_job(model, tmp_path, with_ccx=True, echo=lambda s: None)
    err = _errors(tmp_path, model, "penalty", "penalty")
    assert max(err.values()) < 0.02, err
