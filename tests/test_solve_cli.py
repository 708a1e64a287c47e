"""``deckbridge solve``: files, schema, statics of the written results, options and bad input."""

import json

import meshio
import numpy as np

import pandas as pd
import pytest
from click.testing import CliRunner

from deckbridge.cli import main
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.outdir import TEMPORARY_PREFIXES
from deckbridge.results import COLUMNS, conform

SMALL = ["--set", "mesh.n_theta=24", "--set", "mesh.n_z=6", "--set", "mesh.n_r=1",
         "--set", "steps.increments=4"]


def _run(args):
    return CliRunner().invoke(main, ["solve", *args])


@pytest.mark.parametrize("method", ["penalty", "lagrange"])
def test_solve_writes_table_summary_and_vtu(tmp_path, method):
    out = tmp_path / "out"
    res = _run(["--method", method, *SMALL, "-o", str(out)])
    assert res.exit_code == 0, res.output
    assert "increments" in res.stderr                     # tqdm progress
    model = load(None, [s for s in SMALL if s != "--set"])
    mesh = build_mesh(model)

    df = pd.read_csv(out / "contact.csv")
    assert list(df.columns) == COLUMNS
    df = conform(df)
    n_rows = mesh.table.nodes.size + mesh.stop.nodes.size
    assert len(df) == (model.steps.increments + 2) * n_rows
    assert set(df["source"]) == {"reference"} and set(df["method"]) == {method}
    # the table's normal forces balance N at the end of step 1 (force = -sigma_n * area)
    s1 = df[(df.step == 1) & (df.surface == "table")].set_index("node")
    area = pd.Series(mesh.table.area, index=mesh.table.nodes + 1)
    assert (-s1["sigma_n_pa"] * area[s1.index]).sum() == pytest.approx(model.loads.N, rel=1e-8)
    assert np.allclose(np.unique(s1["theta_deg"].round(9)), np.arange(24) * 15.0)

    summary = json.loads((out / "summary.json").read_text())
    assert summary["method"] == method and summary["dofs"] == 3 * mesh.n_nodes
    np.testing.assert_allclose(summary["reaction_force_n"]["1"], [0, 0, model.loads.N], atol=1e-8 * model.loads.N)
    np.testing.assert_allclose(summary["reaction_force_n"]["2"], [model.loads.T, 0, model.loads.N],
                               atol=1e-8 * model.loads.N)
    assert 0 < summary["liftoff_load_factor"] < 1 and summary["liftoff_theta_deg"] == pytest.approx(0.0)
    assert summary["min_sigma_n_pa"] == pytest.approx(df["sigma_n_pa"].min())
    assert (summary["penalty_k"] is None) == (method == "lagrange")
    assert summary["wall_time_s"] > 0 and summary["solver"]["sparse"]

    vtu = meshio.read(out / "result.vtu")
    assert vtu.points.shape == mesh.nodes.shape and vtu.cells[0].data.shape == mesh.hexes.shape
    for s in (1, 2):
        assert vtu.point_data[f"displacement_step{s}_m"].shape == mesh.nodes.shape
        assert np.all(vtu.cell_data[f"von_mises_step{s}_pa"][0] >= 0)
    p = vtu.point_data["table_contact_pressure_step1_pa"][mesh.table.nodes]
    assert (p * mesh.table.area).sum() == pytest.approx(model.loads.N, rel=1e-8)
    # base nodes that are closed did not move vertically (Lagrange) / moved by -force/k (penalty)
    u1 = vtu.point_data["displacement_step1_m"]
    uz = u1[mesh.table.nodes, 2]
    if method == "lagrange":
        assert np.abs(uz).max() <= 1e-12 * np.abs(u1).max()
    else:
        np.testing.assert_allclose(uz, -p * mesh.table.area / mesh.table.k, rtol=1e-8)
    assert not [q for q in out.iterdir() if q.name.startswith(TEMPORARY_PREFIXES)]   # no temporary left


def test_liftoff_follows_the_load_azimuth(tmp_path):
    res = _run(["--method", "penalty", *SMALL, "--set", "loads.azimuth=90", "-o", str(tmp_path)])
    assert res.exit_code == 0, res.output
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["liftoff_theta_deg"] == pytest.approx(90.0)


def test_alpha_rescales_the_penalty_stiffness(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    assert _run(["--method", "penalty", *SMALL, "-o", str(a)]).exit_code == 0
    assert _run(["--method", "penalty", *SMALL, "--alpha", "1.0", "-o", str(b)]).exit_code == 0
    ka = json.loads((a / "summary.json").read_text())["penalty_k"]
    kb = json.loads((b / "summary.json").read_text())["penalty_k"]
    assert kb["table"]["mean"] == pytest.approx(10 * ka["table"]["mean"], rel=1e-12)   # default alpha 0.1
    assert kb["k_factor"] == pytest.approx(10.0) and kb["alpha"] == pytest.approx(1.0)


@pytest.mark.parametrize("args, message, code", [
    (["--method", "penalty", "--alpha", "1", "--k-factor", "2"], "give one or the other", 2),
    (["--method", "lagrange", "--k-factor", "2"], "only for --method penalty", 2),
    (["--method", "penalty", "--k-factor", "-1"], "--k-factor = -1.0", 2),
    (["--method", "lagrange", "--set", "contact.stop.side=none", "--set", "contact.penalty.k_tangent=1e-300"],
     "mechanism: nothing restrains the rigid-body translation x, translation y, rotation z", 2),
    (["--method", "lagrange", "--set", "loads.M=2.0e7"], "the load tips the body over", 1),   # a run failure
    (["--method", "penalty", "--set", "loads.N=0"], "the load tips the body over", 1),
    (["--method", "penalty", "--set", "contact.penalty.k_normal=1.0e+8", "--alpha", "0.2"], "k_normal", 2),
])
def test_bad_input_ends_with_one_line_and_writes_nothing(tmp_path, args, message, code):
    out = tmp_path / "out"
    res = _run([*args, *SMALL, "-o", str(out)])
    assert res.exit_code == code
    err = res.stderr.strip().splitlines()[-1].split("\r")[-1].strip()
    assert err.startswith("deckbridge: error:") and message in err, res.stderr
    assert "Traceback" not in res.output
    assert not out.exists() or not any(out.iterdir())


def test_contact_rows_are_the_solver_rows_and_cover_the_base():
    """One contact-row table: the solver's rows in order (table, then stop), the table's tributary areas
    summing to the annulus of the polygonal base, each row's azimuth that of its node."""
    from deckbridge.solve import build_problem
    m = load(None, ["mesh.n_theta=24", "mesh.n_z=3", "mesh.n_r=2"])
    mesh = build_mesh(m)
    rows, p = mesh.contact_rows, build_problem(m, mesh)
    np.testing.assert_array_equal(p.contact_nodes, rows.nodes)
    np.testing.assert_array_equal(p.contact_surface, rows.surface)
    n_table = mesh.table.nodes.size
    assert list(rows.surface[:n_table]) == ["table"] * n_table and set(rows.surface[n_table:]) == {"stop"}
    g, n = m.geometry, m.mesh.n_theta
    annulus = 0.5 * n * np.sin(2 * np.pi / n) * ((g.radius + g.thickness / 2) ** 2 - (g.radius - g.thickness / 2) ** 2)
    assert rows.area[:n_table].sum() == pytest.approx(annulus, rel=1e-12)
    xyz = mesh.nodes[rows.nodes]
    np.testing.assert_allclose(rows.theta, np.degrees(np.arctan2(xyz[:, 1], xyz[:, 0])) % 360.0, atol=1e-9)


def test_beam_theory_liftoff_is_n_r_over_twice_the_base_moment():
    m = load(None, ["loads.N=2.0e6", "loads.M=1.0e6", "loads.T=1.0e5", "geometry.height=2.0"])
    assert m.beam_theory_liftoff() == pytest.approx(2.0e6 * m.geometry.radius / (2 * (1.0e6 + 1.0e5 * 2.0)))
    assert load(None, ["loads.M=0", "loads.T=0"]).beam_theory_liftoff() is None


def test_run_builds_one_mesh_for_decks_and_solver(tmp_path, monkeypatch):
    import deckbridge.job
    import deckbridge.mesh
    import deckbridge.render
    import deckbridge.solve
    calls = []
    real = deckbridge.mesh.build_mesh
    def counted(model):
        calls.append(model.name)
        return real(model)
    for mod in (deckbridge.mesh, deckbridge.job, deckbridge.render, deckbridge.solve):
        monkeypatch.setattr(mod, "build_mesh", counted)
    deckbridge.job.run_job(load(None, ["mesh.n_theta=12", "mesh.n_z=3", "mesh.n_r=1", "steps.increments=2"]),
                           tmp_path / "run", echo=lambda s: None)
    assert len(calls) == 1
    assert (tmp_path / "run" / "report.html").is_file()
