"""ParaView series (result.pvd + one VTU per increment) of the reference solver and of CalculiX, read
back with meshio and checked against the Solution, the force balance and ccx's own increment list."""

import re
import shutil
import xml.etree.ElementTree as ET

import meshio
import numpy as np

import pytest

from deckbridge.mesh import build_mesh, hex_volumes
from deckbridge.model import load
from deckbridge.outdir import TEMPORARY_PREFIXES
from deckbridge.solve import condense_model, solve_system, write_outputs

SMALL = ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1"]
needs_ccx = pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX ccx not installed")
POINT = ("displacement_m", "node_id", "table_sigma_n_pa", "table_gap_m", "table_status", "stop_sigma_n_pa",
         "stop_gap_m", "stop_status", "table_area_m2", "table_slave", "stop_slave", "top_ring")


def read_pvd(pvd):
    """[(timestep, file, 'step S increment I load_factor L' comment)] of a .pvd, parsed with ElementTree."""
    root = ET.parse(pvd, parser=ET.XMLParser(target=ET.TreeBuilder(insert_comments=True))).getroot()
    assert root.tag == "VTKFile" and root.get("type") == "Collection"
    out, label = [], None
    for el in root.find("Collection"):
        if el.tag is ET.Comment:
            label = el.text.strip()
        else:
            out.append((float(el.get("timestep")), pvd.parent / el.get("file"), label))
    return out


@pytest.fixture(scope="module", params=["penalty", "lagrange"])
def series(request, tmp_path_factory):
    model = load(None, SMALL)
    mesh, system = condense_model(model)
    df, summary, sol = solve_system(model, mesh, system, request.param)
    out = tmp_path_factory.mktemp(request.param)
    paths = write_outputs(out, model, system, sol, df, summary, mesh)
    return model, mesh, system, sol, out, paths


def test_pvd_lists_every_increment_in_order(series):
    model, mesh, _, sol, out, paths = series
    entries = read_pvd(out / "result.pvd")
    assert len(entries) == sol.step.size == model.steps.increments + 2
    assert {p.name for p in paths} >= {"result.pvd", "result.vtu"} | {e[1].name for e in entries}
    times = np.array([e[0] for e in entries])
    assert times[0] == 0.0 and np.all(np.diff(times) > 0) and times[-1] == pytest.approx(2.0)
    for (t, f, label), s, j, lam in zip(entries, sol.step, sol.increment, sol.load_factor):
        step, inc, lf = re.fullmatch(r"step (\d+) increment (\d+) load_factor (\S+)", label).groups()
        assert (int(step), int(inc)) == (s, j) and float(lf) == pytest.approx(lam, abs=1e-12)
        assert t == pytest.approx(0.0 if s == 1 else 1 + lam / model.steps.lambda_max)
    assert not [q for q in out.iterdir() if q.name.startswith(TEMPORARY_PREFIXES)]   # no temporary left


def test_each_vtu_has_status_gap_stress_ids_and_sets(series):
    model, mesh, _, sol, out, _ = series
    for r, (_, f, _) in enumerate(read_pvd(out / "result.pvd")):
        v = meshio.read(f)
        assert v.points.shape == mesh.nodes.shape and v.cells[0].data.shape == mesh.hexes.shape
        for name in POINT:
            assert np.all(np.isfinite(v.point_data[name])), name
        assert v.point_data["stress_nodal_pa"].shape == (mesh.n_nodes, 6)
        assert v.cell_data["stress_pa"][0].shape == (mesh.hexes.shape[0], 6)
        assert np.all(v.cell_data["von_mises_pa"][0] >= 0)
        np.testing.assert_array_equal(v.point_data["node_id"], np.arange(1, mesh.n_nodes + 1))
        np.testing.assert_array_equal(v.cell_data["element_id"][0], np.arange(1, mesh.hexes.shape[0] + 1))
        # named sets: the masks are the mesh's slave sets and top ring, bottom_row the elements on z = 0
        for s in mesh.slave_sets:
            np.testing.assert_array_equal(np.flatnonzero(v.point_data[f"{s.surface}_slave"]), np.sort(s.nodes))
        np.testing.assert_array_equal(np.flatnonzero(v.point_data["top_ring"]), np.sort(mesh.top_nodes))
        bottom = v.cell_data["bottom_row"][0].astype(bool)
        assert bottom.sum() == mesh.n_theta * mesh.n_r
        assert np.all(mesh.nodes[mesh.hexes[bottom]][:, :4, 2] == 0.0)
        # status: 1 closed / 0 open on the slaves as the Solution says, -1 elsewhere
        st = v.point_data["table_status"]
        t_rows = system_rows(sol, mesh, "table")
        np.testing.assert_array_equal(st[mesh.table.nodes], sol.closed[r, t_rows].astype(int))
        assert np.all(np.delete(st, mesh.table.nodes) == -1)
        np.testing.assert_array_equal(v.point_data["table_gap_m"][mesh.table.nodes], sol.gap[r, t_rows])


def system_rows(sol, mesh, surface):
    """Contact-row indices of ``surface`` (table rows first, then stop rows)."""
    return np.flatnonzero(mesh.contact_rows.surface == surface)


def test_table_stress_times_vtu_area_balances_N_at_every_increment(series):
    """Independent of the solver: sum over table slaves of -sigma_N x tributary area (both read from the
    VTU) is the vertical reaction N (T and M add no vertical resultant; springs and stop are horizontal)."""
    model, mesh, _, _, out, _ = series
    for _, f, label in read_pvd(out / "result.pvd"):
        v = meshio.read(f)
        force = -(v.point_data["table_sigma_n_pa"] * v.point_data["table_area_m2"]).sum()
        assert force == pytest.approx(model.loads.N, rel=1e-9), label


def test_vtu_displacement_is_the_solutions_contact_displacement(series):
    """The displacement of every state (recovered in one solve) gives back the Solution's normal
    displacement of every contact row and its spring displacement, to 1e-12 of the largest."""
    model, mesh, system, sol, out, _ = series
    p = system.problem
    for r, (_, f, _) in enumerate(read_pvd(out / "result.pvd")):
        u = meshio.read(f).point_data["displacement_m"]
        scale = np.abs(u).max()
        un = np.einsum("ij,ij->i", u[p.contact_nodes], p.contact_normals)
        assert np.abs(un - sol.u[r]).max() <= 1e-12 * scale
        us = np.einsum("ij,ij->i", u[p.spring_nodes], p.spring_dirs)
        assert np.abs(us - sol.spring_u[r]).max() <= 1e-12 * scale
        # the tangential force is the spring law on that displacement (step 1: round-off, 1e-12 N)
        ft = meshio.read(f).point_data["tangential_force_n"][p.spring_nodes]
        np.testing.assert_allclose(ft, -p.spring_k * us, rtol=1e-9, atol=1e-12 * model.loads.N)
    # the last state is the end of step 2 that result.vtu holds
    np.testing.assert_allclose(u, meshio.read(out / "result.vtu").point_data["displacement_step2_m"],
                               rtol=0, atol=1e-12 * scale)


def test_cell_stress_balances_N_in_every_element_layer(series):
    """Virtual work with v_z linear in z inside one element layer (a field of the mesh): the layer's
    integral of sigma_zz is -N times its height. With the cell stress the element's volume average and the
    volumes of mesh.hex_volumes, sum(sigma_zz V) / h = -N to 1e-9 in every layer at every increment."""
    model, mesh, _, _, out, _ = series
    vol = hex_volumes(mesh.nodes[mesh.hexes])
    h = model.geometry.height / mesh.n_z
    layer = np.arange(mesh.hexes.shape[0]) // (mesh.n_theta * mesh.n_r)
    for _, f, label in read_pvd(out / "result.pvd"):
        szz = meshio.read(f).cell_data["stress_pa"][0][:, 2]
        per_layer = np.bincount(layer, szz * vol) / h
        np.testing.assert_allclose(per_layer, -model.loads.N, rtol=1e-9, err_msg=label)


def test_step1_stress_is_uniaxial_and_nodal_equals_cell(series):
    """Step 1 (N alone, uniform): the extrapolated nodal sigma_zz at the base equals the bottom cells'
    (extrapolation is exact for a uniform field) and von Mises is |sigma_zz| within 5 %."""
    model, mesh, _, _, out, _ = series
    v = meshio.read(read_pvd(out / "result.pvd")[0][1])
    bottom = v.cell_data["bottom_row"][0].astype(bool)
    szz = v.cell_data["stress_pa"][0][bottom, 2]
    assert v.point_data["stress_nodal_pa"][mesh.table.nodes, 2].mean() == pytest.approx(szz.mean(), rel=1e-6)
    np.testing.assert_allclose(v.cell_data["von_mises_pa"][0][bottom], np.abs(szz), rtol=0.05)


@pytest.mark.parametrize("method", ["penalty", "lagrange"])
def test_friction_force_in_the_vtus_balances_the_shear(method, tmp_path):
    """With tangential = friction (no stop, so only friction carries T): in every VTU the friction
    force field summed over the nodes equals minus the applied horizontal load T lambda (the table
    pushes against it) to 1e-9, and the circumferential field is that force's e_theta component."""
    model = load(None, SMALL + ["contact.tangential=friction", "contact.friction=0.3", "contact.stop.side=none"])
    mesh, system = condense_model(model)
    df, summary, sol = solve_system(model, mesh, system, method)
    write_outputs(tmp_path, model, system, sol, df, summary, mesh)
    tx, ty, _ = model.load_vectors()["T_force"]
    for (_, f, label), lam in zip(read_pvd(tmp_path / "result.pvd"), sol.load_factor):
        v = meshio.read(f)
        ff = v.point_data["friction_force_n"]
        assert ff.sum(axis=0)[:2] == pytest.approx([-tx * lam, -ty * lam], abs=1e-9 * abs(tx)), label
        t = np.arctan2(v.points[:, 1], v.points[:, 0])
        np.testing.assert_allclose(v.point_data["tangential_force_n"], -ff[:, 0] * np.sin(t) + ff[:, 1] * np.cos(t),
                                   atol=1e-9 * abs(tx))


def test_no_series_without_outputs_vtu(tmp_path):
    model = load(None, SMALL + ["outputs.vtu=false"])
    mesh, system = condense_model(model)
    df, summary, sol = solve_system(model, mesh, system, "penalty", recover=False)
    write_outputs(tmp_path, model, system, sol, df, summary, mesh)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["contact.csv", "summary.json"]


@pytest.fixture(scope="module")
def ccx_job(tmp_path_factory):
    """``deckbridge run --with-ccx`` on a 16 x 4 x 1 mesh (both ccx decks, past liftoff at lambda = 1)."""
    from job_tables import run_job_tables

    model = load(None, SMALL)
    out = tmp_path_factory.mktemp("job")
    run_job_tables(model, out, with_ccx=True, echo=lambda s: None)
    return model, build_mesh(model), out


@needs_ccx
def test_run_writes_a_series_per_reference_method(ccx_job):
    model, mesh, out = ccx_job
    for method in ("penalty", "lagrange"):
        entries = read_pvd(out / f"reference_{method}" / "result.pvd")
        assert len(entries) == model.steps.increments + 2 and all(f.is_file() for _, f, _ in entries)


@needs_ccx
@pytest.mark.parametrize("deck", ["JAR_ccx_penalty", "JAR_ccx_lagrange"])
def test_ccx_series_lists_every_increment_ccx_printed(ccx_job, deck):
    """The pvd of each ccx job lists every converged increment of its .sta (ccx's own list); each VTU has
    the reader's sigma_N / gap / status at the slaves and ccx's displacement; the table forces balance N
    (to 1e-6: ccx prints 7 digits)."""
    model, mesh, out = ccx_job
    sta = [ln.split() for ln in (out / "ccx" / f"{deck}.sta").read_text().splitlines()]
    printed = [(int(f[0]), int(f[1]), float(f[4])) for f in sta if len(f) == 7 and f[0].isdigit()]
    entries = read_pvd(out / "ccx" / f"{deck}.pvd")
    assert len(entries) == len(printed) == 1 + model.steps.increments
    for (t, f, label), (step, inc, total) in zip(entries, printed):
        s, i, lf = re.fullmatch(r"step (\d+) increment (\d+) load_factor (\S+)", label).groups()
        assert (int(s), int(i)) == (step, inc) and t == pytest.approx(total, rel=1e-6)
        assert float(lf) == pytest.approx(0.0 if step == 1 else total - 1, abs=1e-9)
        v = meshio.read(f)
        for name in POINT:
            assert np.all(np.isfinite(v.point_data[name])), name
        st = v.point_data["table_status"]
        assert set(np.unique(st[mesh.table.nodes])) <= {0, 1} and np.all(np.delete(st, mesh.table.nodes) == -1)
        force = -(v.point_data["table_sigma_n_pa"] * v.point_data["table_area_m2"]).sum()
        # ccx prints 7 digits (mortar: 1e-6); its linear node-to-surface penalty deck balances N only to
        # ~1e-4 (measured 4.6e-5 .. 1.2e-4; tests/test_calculix.py uses the same bound for that deck)
        tol = 2e-4 if "penalty" in deck else 1e-6
        assert force == pytest.approx(model.loads.N, rel=tol), label
        # gap = clearance + u.n of the .frd displacement at the table slaves (z up, zero clearance)
        u = v.point_data["displacement_m"]
        np.testing.assert_allclose(v.point_data["table_gap_m"][mesh.table.nodes], u[mesh.table.nodes, 2],
                                   rtol=1e-4, atol=1e-6 * np.abs(u).max())
    # past liftoff at lambda = 1 the tension side is open and the compression side closed
    last = meshio.read(entries[-1][1]).point_data["table_status"][mesh.table.nodes]
    assert 0 in last and 1 in last


@needs_ccx
def test_ccx_series_carries_frd_stress(tmp_path):
    """The decks write ``*EL FILE`` S, so the .frd's nodal stresses reach the VTU in Voigt order, as the
    reference series' ``stress_nodal_pa``: at step 1 (N alone) sigma_zz at mid-height is the membrane
    stress -N / (layer volume / h) within 1 %, the other components are below 1e-3 of it, and the von
    Mises field is |sigma_zz| there."""
    from deckbridge.dialects.calculix.paraview import write_ccx_series
    from ccx_job import ccx_penalty_job

    model = load(None, SMALL)
    mesh = build_mesh(model)
    paths = write_ccx_series(ccx_penalty_job(model, tmp_path), model, tmp_path / "pv")
    v = meshio.read(paths[1]).point_data
    s = v["stress_nodal_pa"]
    mid = np.flatnonzero(np.isclose(mesh.nodes[:, 2], model.geometry.height / 2))
    h = model.geometry.height / mesh.n_z
    membrane = -model.loads.N / (hex_volumes(mesh.nodes[mesh.hexes]).sum() / mesh.n_z / h)
    np.testing.assert_allclose(s[mid, 2], membrane, rtol=0.01)
    assert np.abs(s[mid][:, [0, 1, 3, 4, 5]]).max() < 1e-3 * abs(membrane)
    np.testing.assert_allclose(v["von_mises_nodal_pa"][mid], -s[mid, 2], rtol=2e-3)


@needs_ccx
def test_ccx_series_equal_in_si_and_mm(tmp_path):
    """The same ccx penalty job written in SI and in mm gives the same series (issue 21 item 5): every point
    field in SI units, to ccx's printed digits (1e-5 of the field's largest value)."""
    from deckbridge.dialects.calculix.paraview import write_ccx_series
    from ccx_job import ccx_penalty_job

    small = ["mesh.n_theta=12", "mesh.n_z=3", "mesh.n_r=1", "steps.increments=2"]
    series = {}
    for units in ("SI", "mm"):
        model = load(None, small + [f"units={units}"])
        paths = write_ccx_series(ccx_penalty_job(model, tmp_path / units), model, tmp_path / units / "pv")
        series[units] = [meshio.read(p) for p in paths[1:]]
    assert len(series["SI"]) == len(series["mm"]) == 3
    for si, mm in zip(series["SI"], series["mm"]):
        np.testing.assert_array_equal(si.points, mm.points)
        assert set(si.point_data) == set(mm.point_data) and "stress_nodal_pa" in si.point_data
        for name, a in si.point_data.items():
            scale = max(float(np.nanmax(np.abs(a))), 1e-300)
            np.testing.assert_allclose(mm.point_data[name], a, rtol=0, atol=1e-5 * scale, err_msg=name)
    u = series["SI"][-1].point_data["displacement_m"]
    assert 1e-5 < np.abs(u).max() < 1e-1          # metres, not millimetres
