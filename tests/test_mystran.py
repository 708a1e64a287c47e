"""MYSTRAN runs the linear deck; its base spring forces are checked against beam theory and
against the equilibrium of the applied loads (REFERENCE.md section 3)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from deckbridge.errors import DeckbridgeError
from deckbridge.dialects.mystran import runner as mystran_run
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.readers import detect, read
from deckbridge.dialects.mystran.reader import read_spring_forces
from deckbridge.dialects.mystran.render import write
from deckbridge.numbering.nastran import gap_layout, numbering

pytestmark = pytest.mark.mystran

# lambda_max = 0.5: M_b = 0.5 (M + T H) = 1.7e6 N m < N R / 2 = 2.03e6 N m (no liftoff)
BEAM = ["mesh.n_theta=48", "mesh.n_z=8", "mesh.n_r=1", "steps.lambda_max=0.5", "loads.azimuth=30",
        "contact.stop.side=none"]
STOP = ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1", "steps.lambda_max=0.5", "loads.azimuth=30"]


def _run(overrides, folder):
    model = load(None, overrides)
    mesh = build_mesh(model)
    f06 = mystran_run.run(write(model, mesh, folder)[0])
    return model, mesh, f06


@pytest.fixture(scope="module")
def beam_run(tmp_path_factory):
    return _run(BEAM, tmp_path_factory.mktemp("mystran_beam"))


@pytest.fixture(scope="module")
def stop_run(tmp_path_factory):
    return _run(STOP, tmp_path_factory.mktemp("mystran_stop"))


def test_beam_theory_below_liftoff(beam_run):
    model, mesh, f06 = beam_run
    assert detect(f06) == "mystran_f06"
    df = read(f06, model=model)
    tab = df[df["surface"] == "table"]
    assert len(tab) == mesh.table.nodes.size and (df["status"] == "closed").all()
    assert (df[["source", "method", "step", "increment"]].drop_duplicates().values.tolist()
            == [["mystran", "linear", 2, 1]])
    assert (df["load_factor"] == model.steps.lambda_max).all()
    g, ld = model.geometry, model.loads
    R, t = g.radius, g.thickness
    mb = model.steps.lambda_max * (ld.M + ld.T * g.height)
    assert mb < ld.N * R / 2
    th = np.radians(tab["theta_deg"].to_numpy() - ld.azimuth)
    beam = -ld.N / (2 * np.pi * R * t) + mb * np.cos(th) / (np.pi * R**2 * t)
    err = np.abs(tab["sigma_n_pa"].to_numpy() - beam).max() / np.abs(beam).max()
    assert err < 0.01, f"beam theory error {err:.4%} of the peak"
    # the compressed side is opposite the azimuth (tension side)
    i_min = np.argmin(tab["sigma_n_pa"].to_numpy())
    assert abs(((tab["theta_deg"].iloc[i_min] - ld.azimuth) % 360) - 180) <= 360 / model.mesh.n_theta


def test_vertical_reactions_sum_to_n(beam_run):
    model, mesh, f06 = beam_run
    df = read(f06, model=model)
    lay = gap_layout(mesh)
    area = dict(zip(lay.node[lay.surface == "table"], lay.area[lay.surface == "table"]))
    tab = df[df["surface"] == "table"]
    fz = -(tab["sigma_n_pa"] * tab["node"].map(area)).sum()     # table pushes the skirt up
    assert fz == pytest.approx(model.loads.N, rel=1e-6)
    # gap_m is the displacement along +z: force / k, pressed-in under compression
    assert (np.sign(tab["gap_m"]) == np.sign(tab["sigma_n_pa"])).all()


def test_equilibrium_with_radial_stop(stop_run):
    """Base reactions of all springs (table z, stop radial, circumferential) balance N, lambda T
    and lambda M_b; this checks the sign of the stop and theta springs as read."""
    model, mesh, f06 = stop_run
    lam, ld, g = model.steps.lambda_max, model.loads, model.geometry
    df = read(f06, model=model)
    lay = gap_layout(mesh)
    area = dict(zip(zip(lay.surface, lay.node), lay.area))
    a = df.apply(lambda r: area[(r["surface"], r["node"])], axis=1).to_numpy()
    th = np.radians(df["theta_deg"].to_numpy())
    f_n = -df["sigma_n_pa"].to_numpy() * a                      # force on the skirt along the master normal
    is_t = (df["surface"] == "table").to_numpy()
    assert (~is_t).sum() == model.mesh.n_theta
    force = np.zeros(3)
    force[2] = f_n[is_t].sum()
    # inner stop: master normal = +radial
    force[0] += (f_n[~is_t] * np.cos(th[~is_t])).sum()
    force[1] += (f_n[~is_t] * np.sin(th[~is_t])).sum()
    raw = read_spring_forces(f06).set_index("element")["force_n"]
    first = 2 * numbering(mesh).elem_offset + 1
    tht = np.radians(mesh.table.theta_deg)
    f_t = raw.loc[first + np.arange(mesh.table.nodes.size)].to_numpy()   # on the skirt, along theta
    force[0] += (-f_t * np.sin(tht)).sum()
    force[1] += (f_t * np.cos(tht)).sum()
    v = model.load_vectors()
    applied = np.array(v["N_force"]) + lam * np.array(v["T_force"])
    np.testing.assert_allclose(force, -applied, atol=2e-6 * ld.N)
    # base moment of the vertical reactions about the axis normal to the azimuth
    az = math.radians(ld.azimuth)
    x = mesh.nodes[df["node"].to_numpy()[is_t] - 1]
    lever = x[:, 0] * math.cos(az) + x[:, 1] * math.sin(az)
    mb = lam * (ld.M + ld.T * g.height)
    assert (f_n[is_t] * lever).sum() == pytest.approx(-mb, rel=1e-5)
    # T pushes the base towards azimuth + 180: the stop is pressed on the azimuth side
    stop = df[~is_t]
    near = np.abs(((stop["theta_deg"] - ld.azimuth + 180) % 360) - 180) < 1
    assert (stop.loc[near, "sigma_n_pa"] < 0).all()


def test_read_without_model_uses_the_deck(beam_run):
    model, mesh, f06 = beam_run
    with_model = read(f06, model=model)
    bare = read(f06)          # areas 1: sigma_n holds the force [N]
    lay = gap_layout(mesh)
    area = lay.area[np.searchsorted(lay.node, with_model["node"].to_numpy())]
    np.testing.assert_allclose(bare["sigma_n_pa"].to_numpy(), with_model["sigma_n_pa"].to_numpy() * area,
                               rtol=1e-12)
    assert (bare["node"].to_numpy() == with_model["node"].to_numpy()).all()
    np.testing.assert_allclose(bare["theta_deg"], with_model["theta_deg"], atol=1e-9)


def test_kinematic_coupling_runs(tmp_path):
    model, mesh, f06 = _run(STOP + ["load_introduction=kinematic"], tmp_path)
    assert "RBE2" in (tmp_path / "JAR_mystran.bdf").read_text()
    df = read(f06, model=model)
    assert len(df) == len(gap_layout(mesh))


def test_failure_is_one_line(tmp_path):
    deck = tmp_path / "bad.bdf"
    deck.write_text("SOL 101\nCEND\nBEGIN BULK\nGRID,1,,0.,0.,0.\nCELAS2,5,1.0,1,3\nENDDATA\n")
    with pytest.raises(DeckbridgeError) as exc:
        mystran_run.run(deck)
    msg = str(exc.value)
    assert "\n" not in msg and "bad.bdf" in msg and "MYSTRAN failed" in msg
    assert not list(tmp_path.glob("bad.L1?"))


def test_mm_and_si_decks_give_the_same_results(stop_run, tmp_path):
    """The same model written in N, mm, MPa and run by MYSTRAN: after reading back (by the deck's
    units line) sigma_N, gaps, node positions and every spring reaction equal the SI run's to 1e-6."""
    model, mesh, f06_si = stop_run
    mm_model, _, f06_mm = _run(STOP + ["units=mm"], tmp_path)
    assert mm_model.units == "mm" and "$ deckbridge-units: mm" in (tmp_path / "JAR_mystran.bdf").read_text()
    for m in (model, None):
        a, b = read(f06_si, model=m), read(f06_mm, model=mm_model if m is not None else None)
        assert len(a) == len(b) == len(gap_layout(mesh))
        for col in ("sigma_n_pa", "gap_m", "r", "z", "theta_deg"):
            x, y = a[col].to_numpy(float), b[col].to_numpy(float)
            if np.isnan(x).all():
                assert np.isnan(y).all()
                continue
            np.testing.assert_allclose(y, x, rtol=0, atol=1e-6 * max(np.abs(x).max(), 1e-300), err_msg=col)
    bare = read(f06_mm)                 # positions from the mm deck beside the F06, in metres
    lay = gap_layout(mesh)
    np.testing.assert_allclose(bare["r"], lay.r, rtol=1e-12)
    np.testing.assert_allclose(bare["z"], lay.z, atol=1e-12)
    ra = read_spring_forces(f06_si).set_index("element")["force_n"]
    rb = read_spring_forces(f06_mm).set_index("element")["force_n"]    # N in both systems
    np.testing.assert_allclose(rb.loc[ra.index], ra, rtol=0, atol=1e-6 * ra.abs().max())
