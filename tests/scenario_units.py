"""The SI-against-mm invariants of the scenario matrices (:mod:`scenario_checks` lists them in ``CHECKS``): a mm case's
CalculiX penalty job (face-to-face on 8-/6-node faces) against its SI twin, run once, table by table and VTU by VTU.

Tolerances: what deckbridge computes is unit-free to round-off (1e-6); what ccx wrote is rounded to its printed
digits (1e-5). ccx face-to-face's nodal CPRESS on 8-/6-node faces (the table's sigma_N there) is not unit-invariant:
ccx fits the integration points' pressures of each slave face by an unweighted least squares and clamps the corners
to their range (its extrapolatecontact, read, nothing copied), and which points a face gets comes from its clipping
of the slave face by the master faces, which is not unit-invariant. Measured on the hex20r cone (16 x 4 x 2, mm
scenario case): displacements and gaps equal to 1e-16, the master ring's reaction to 1e-16, the same iterations and
1344 contact elements, the slopes exact in both units; CPRESS differs at 48 of 896 nodes by 2.16e-5 (table) /
7.7e-5 (VTU, of the state's largest) in full contact only (later states <= 1.1e-6); with the ring turned half a
cell 4.5e-4, with the whole model turned 5 deg 1.8e-3. Not convergence, not digits, not the deck: the tolerance
:data:`TOL_F2F_CPRESS` is that post-processing's on this deck.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from deckbridge.importers.inp_mesh import read_inp_mesh
from deckbridge.readers import read

from scenarios import Run

TOL_UNITS = 1e-6        # SI against mm: fraction of the largest value of the quantity
TOL_CCX_FILES = 1e-5    # the same, for what ccx wrote: 6 significant digits in the .frd (E12.5), 7 in the .dat
                        # (E13.6); two files rounded apart differ by up to 1e-5 of a value (seen: 3.2e-6)
TOL_F2F_CPRESS = 2e-4   # ccx face-to-face's nodal CPRESS (sigma_N) on 8-/6-node faces: module doc (measured 7.7e-5)


def _si_twin(run: Run):
    """(SI model, its ccx penalty job: f2f on 8-/6-node faces) of a mm case, run once (tests/ccx_job.py)."""
    from ccx_job import ccx_job
    si = run.model.with_overrides({"units": "SI"})
    if run.si_twin is None:
        run.si_twin = ccx_job(si, Path(tempfile.mkdtemp(prefix="si-", dir=run.out.parent)), run.penalty_deck)
    return si, run.si_twin


def paraview_si_equals_mm(run: Run) -> str:
    """The ccx ParaView series (deckbridge.dialects.calculix.paraview) of the mm case's penalty job equals that of its SI
    twin: every point and cell array of every VTU, and the points, to 1e-6 of the array's largest value."""
    import meshio

    from deckbridge.dialects.calculix.paraview import write_ccx_series
    assert run.error is None, run.error
    if run.model.units != "mm":
        return "skipped: SI case"
    si, deck = _si_twin(run)
    mm_job = run.out / "ccx" / deck.name
    a = write_ccx_series(deck, si, Path(tempfile.mkdtemp(prefix="pv-si-", dir=run.out.parent)))[1:]
    b = write_ccx_series(mm_job, run.model, Path(tempfile.mkdtemp(prefix="pv-mm-", dir=run.out.parent)))[1:]
    assert len(a) == len(b) > 0, f"{len(a)} SI and {len(b)} mm VTU files"
    n = 0
    for fa, fb in zip(a, b):
        ma, mb = meshio.read(fa), meshio.read(fb)
        arrays = [("points", ma.points, mb.points)]
        arrays += [(k, v, mb.point_data.get(k)) for k, v in ma.point_data.items()]
        arrays += [(k, v[0], mb.cell_data[k][0] if k in mb.cell_data else None) for k, v in ma.cell_data.items()]
        for key, va, vb in arrays:
            assert vb is not None, f"{fb.name}: no {key}"
            va, vb = np.asarray(va, float), np.asarray(vb, float)
            d = np.abs(va - vb).max(initial=0.0) / max(np.abs(va).max(initial=0.0), 1e-300)
            tol = TOL_F2F_CPRESS if run.quadratic and key.endswith("sigma_n_pa") else TOL_CCX_FILES
            assert d <= tol, f"{fb.name} {key}: SI vs mm differ by {d:.3g} of the largest"
            n += 1
    return f"{n} arrays equal"


def si_equals_mm(run: Run) -> str:
    """Every quantity equal between the SI and the mm run: the mm case's CalculiX penalty deck against the
    same model's SI deck, both run by ccx (contact table, node coordinates of the decks)."""
    assert run.error is None, run.error
    if run.model.units != "mm":
        return "skipped: SI case"
    si, deck = _si_twin(run)
    a = read(deck.with_suffix(".frd"), model=si)
    b = run.tables[f"ccx/{run.penalty_deck}"]
    j = a.merge(b, on=["step", "increment", "node", "surface"], suffixes=("_si", "_mm"))
    assert len(j) == len(a) == len(b), "SI and mm tables differ in rows"
    for col in ("sigma_n_pa", "gap_m", "force_n", "r", "theta_deg", "load_factor"):
        a_, b_ = j[f"{col}_si"].to_numpy(float), j[f"{col}_mm"].to_numpy(float)
        assert (np.isnan(a_) == np.isnan(b_)).all(), f"{col}: known in one unit system only"
        d = np.nanmax(np.abs(a_ - b_), initial=0.0) / max(np.nanmax(np.abs(a_), initial=0.0), 1e-300)
        tol = TOL_F2F_CPRESS if run.quadratic and col == "sigma_n_pa" else TOL_CCX_FILES
        assert d <= tol, f"{col}: SI vs mm differ by {d:.3g} of the largest"
    x_si = read_inp_mesh(deck).nodes
    x_mm = read_inp_mesh(run.out / "ccx" / deck.name).nodes
    assert np.abs(x_mm * 1e-3 - x_si).max() <= TOL_UNITS * np.abs(x_si).max(), "deck coordinates"
    return f"{len(j)} rows equal"
