"""The scaled condensation (node blocks, node-graph ordering, supernodal read) against the plain one.

Reference: ``schur='rhs'`` (K_ii factored on its own, S from solves with the columns of K_ir), a
path this issue did not change. Round-off floor: in the pre-issue-16 code, switching only the
fill-reducing ordering of K_ii from METIS to AMD moved sigma_N of the default model by 2.7e-9 of its
largest value and the onsets by 6e-13, so sigma_N is compared to 1e-8 and onsets to 1e-9.
Measured against the pre-issue-16 results of the default model: sigma_N 1.6e-9 (penalty) and
2.4e-9 (Lagrange) of the largest value, onsets 1.2e-12 and 4.8e-13 relative.
"""

import numpy as np
import pytest

import reference_solver as rs
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.solve import build_problem
from reference_solver.linalg import trailing_block

pytestmark = pytest.mark.skipif(not rs.HAVE_CHOLMOD, reason="needs CHOLMOD")


@pytest.fixture(scope="module")
def default_problem():
    model = load(None, [])
    return model, build_problem(model, build_mesh(model))


def test_default_model_same_sigma_and_onsets_as_the_plain_condensation(default_problem):
    model, p = default_problem
    fast = rs.condense(p)
    plain = rs.condense(p, schur="rhs", factorize=rs.cholmod_factorize)
    assert fast.info["schur"] == "cholmod-trailing-blocks" and plain.info["schur"].startswith("rhs")
    for method in ("penalty", "lagrange"):
        a = rs.solve_path(fast, method, lambda_max=model.steps.lambda_max, increments=model.steps.increments,
                          liftoff_surface="table")
        b = rs.solve_path(plain, method, lambda_max=model.steps.lambda_max, increments=model.steps.increments,
                          liftoff_surface="table")
        np.testing.assert_array_equal(a.closed, b.closed)
        np.testing.assert_allclose(a.sigma_n, b.sigma_n, rtol=0, atol=1e-8 * np.abs(b.sigma_n).max())
        assert a.liftoff_load_factor == pytest.approx(b.liftoff_load_factor, rel=1e-9)
        assert a.liftoff_row == b.liftoff_row
        for s in (1, 2):
            np.testing.assert_allclose(a.fields[s], b.fields[s], rtol=0, atol=1e-8 * np.abs(b.fields[s]).max())


def test_default_model_same_sigma_and_onsets_as_before_issue_16():
    """Against tests/pinned/reference_default_pre16.json, written by the code of commit 7d4235e."""
    import json
    from pathlib import Path
    from deckbridge.solve import solve_model
    pinned = json.loads((Path(__file__).parent / "pinned" / "reference_default_pre16.json").read_text())
    for method in ("penalty", "lagrange"):
        df, summary = solve_model(load(None, []), method, recover=False)
        b = pinned[method]
        assert df["node"].tolist() == b["node"] and df["status"].tolist() == b["status"]
        scale = np.abs(b["sigma_n_pa"]).max()
        np.testing.assert_allclose(df["sigma_n_pa"], b["sigma_n_pa"], rtol=0, atol=1e-8 * scale)
        assert summary["liftoff_load_factor"] == pytest.approx(b["liftoff_load_factor"], rel=1e-9)


def test_supernodal_read_equals_the_factor_copy():
    import scipy.sparse as sp
    from sksparse import cholmod
    rng = np.random.default_rng(3)
    A = sp.random(400, 400, density=0.01, random_state=4)
    A = (A @ A.T + sp.diags(rng.uniform(1, 2, 400)) * 5).tocsc()
    f = cholmod.cholesky(A, ordering_method="natural", mode="supernodal")
    got = trailing_block(f, 400, 60)
    assert got is not None
    L = f.L().toarray()
    np.testing.assert_allclose(got, L[340:, 340:], rtol=0, atol=1e-14 * np.abs(L).max())
    simplicial = cholmod.cholesky(A, ordering_method="natural", mode="simplicial")
    assert trailing_block(simplicial, 400, 60) is None        # not supernodal: refused (caller uses L())


def test_peak_estimate_brackets_the_measured_peak_rss(tmp_path):
    """estimate_peak_bytes against the peak RSS (VmHWM) of a fresh process running the whole path.

    Stated factor: the measured peak lies within [0.5, 1.25] x the estimate (bench/scale.py measured
    0.87-0.90 at 100k-400k dofs). The process is separate so that its peak is its own.
    """
    import json
    import subprocess
    import sys
    code = """
import json, reference_solver as rs
from deckbridge.model import load
from deckbridge.mesh import build_mesh
from deckbridge.solve import build_problem
m = load(None, ["mesh.n_theta=120", "mesh.n_z=50"])
p = build_problem(m, build_mesh(m))
est = rs.estimate_peak_bytes(p.n_nodes, len(p.hexes), p.n_contacts, p.n_springs,
                             factor_entries=rs.factor_entries(p.hexes, p.n_nodes))
s = rs.condense(p)
for method in ("penalty", "lagrange"):
    rs.solve_path(s, method)
hwm = next(int(l.split()[1]) for l in open("/proc/self/status") if l.startswith("VmHWM:")) * 1024
print(json.dumps({"est": est, "hwm": hwm}))
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    r = json.loads(out.stdout.strip().splitlines()[-1])
    assert 0.5 * r["est"] <= r["hwm"] <= 1.25 * r["est"], r


def test_peak_estimate_grows_with_the_mesh():
    small = rs.estimate_peak_bytes(10_000, 6_000, 300, 200)
    big = rs.estimate_peak_bytes(1_000_000, 660_000, 3_000, 2_000)
    assert big > 20 * small > 0
