"""One state per ccx time point: the .dat prints a time to 7 significant digits, the .frd to 10
(deckbridge/dialects/calculix/result_files.py ``_on_frd_time``). With 3 increments the step-2 times are 4/3 and 5/3:
keyed apart, a state's forces (.dat) and its displacements or CPRESS (.frd) fell into two half-empty states
(the quadratic face-to-face table read an all-zero state beside each real one; node-based gaps were NaN)."""

from __future__ import annotations

import shutil
import warnings

import numpy as np
import pytest

from deckbridge.dialects.calculix.result_files import _on_frd_time
from deckbridge.model import load

needs_ccx = pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX ccx not installed")
SMALL = ["mesh.n_theta=24", "mesh.n_z=3", "mesh.n_r=1", "contact.stop.side=none", "steps.lambda_max=0.6",
         "steps.increments=3"]


def test_dat_time_snaps_to_the_frd_time():
    frd = np.array([1.0, 1.333333333, 1.666666667, 2.0])
    assert _on_frd_time(1.333333, frd) == 1.333333333
    assert _on_frd_time(1.666667, frd) == 1.666666667
    assert _on_frd_time(1.5, frd) == 1.5                      # no frd point there: kept
    assert _on_frd_time(0.3333333, np.array([])) == 0.3333333


@needs_ccx
@pytest.mark.parametrize("element, method", [("hex20r", "f2f"), ("hex8i", "penalty")])
def test_three_increments_read_as_three_states(element, method, tmp_path):
    """Each step-2 state at lambda 0.2 / 0.4 / 0.6 once, its contact forces carrying N (1e-3) and every gap finite
    (f2f on 8-node faces: the master ring's reaction, result_files.f2f_master_resultant; the table has no nodal force)."""
    from ccx_job import ccx_job
    from deckbridge.dialects.calculix.result_files import f2f_master_resultant
    from deckbridge.readers import read
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = load(None, [f"mesh.element={element}", *SMALL])
        job = ccx_job(model, tmp_path, method)
        df = read(job.with_suffix(".frd"), fmt="calculix", model=model)
    tab = df[(df.surface == "table") & (df.step == 2)]
    lams = tab.groupby("increment").load_factor.first().to_numpy()
    np.testing.assert_allclose(lams, [0.2, 0.4, 0.6], rtol=1e-6)
    for _, g in tab.groupby("increment"):
        if method == "penalty":
            assert g.force_n.sum() == pytest.approx(model.loads.N, rel=1e-3)
        assert np.isfinite(g.gap_m).all()
    if method == "f2f":
        fz = [F[2] for t, (F, _) in sorted(f2f_master_resultant(job).items()) if t > 1.0]
        np.testing.assert_allclose(fz, model.loads.N, rtol=1e-3)
        assert len(fz) == 3
