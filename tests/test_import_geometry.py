"""The imported mesh is the geometry (issue 26): with ``mesh.file`` the ``geometry`` keys are measured on
the mesh at load; a key the user sets to another value is refused naming both values. Main accepted
geometry.radius = 3.0 m on a 1.5 m mesh and printed beam theory 1.19 instead of 0.596. Reference:
beam theory N R / (2 M_b) with the generating mesh's R, and the reference solver's liftoff on the mesh."""

import json

import pytest
from click.testing import CliRunner

from deckbridge.cli import main
from deckbridge.model import ModelError, load
from gmsh_skirt import gmsh_written


@pytest.fixture(scope="module")
def msh(tmp_path_factory):
    pytest.importorskip("gmsh")
    return gmsh_written(tmp_path_factory.mktemp("geo"), R=1.5, t=0.02, H=2.0, n_theta=16, n_z=2)["msh"]


def test_a_geometry_key_contradicting_the_mesh_is_refused_naming_both(msh, tmp_path):
    f = tmp_path / "m.yaml"
    f.write_text(f"mesh:\n  file: {msh}\n  sets: {{base: BASE, top: TOP}}\ngeometry:\n  radius: 3.0\n")
    with pytest.raises(ModelError, match=r"geometry.radius = 3.0: contradicts the imported mesh .*skirt.msh, which "
                                         r"measures radius = 1.5 m") as err:
        load(f)
    assert "\n" not in str(err.value)
    with pytest.raises(ModelError, match=r"geometry.height = 5.0: contradicts .* height = 2 m"):
        load(None, [f"mesh.file={msh}", "mesh.sets={base: BASE, top: TOP}", "geometry.height=5.0"])


def test_the_mesh_gives_the_geometry_and_the_beam_theory_liftoff(msh, tmp_path):
    """A model naming the mesh and no geometry (the default file's geometry is the default JAR's, here
    overridden only through mesh.file): R, t, H are the mesh's; a 3 m default would print 1.19 (the
    issue's number for R = 3 m); beam theory N R / (2 (M + T H)) = 0.5956 with R = 1.5 m."""
    f = tmp_path / "m.yaml"
    f.write_text(f"mesh:\n  file: {msh}\n  sets: {{base: BASE, top: TOP}}\ngeometry:\n  radius: 1.5\n")
    m = load(f, ["geometry.thickness=0.02"])                 # the mesh's own values are accepted
    assert (m.geometry.radius, m.geometry.thickness, m.geometry.height) == (1.5, 0.02, 2.0)
    m = load(None, [f"mesh.file={msh}", "mesh.sets={base: BASE, top: TOP}", "loads.N=2.7e6", "loads.M=3e6",
                    "loads.T=2e5"])
    assert m.beam_theory_liftoff() == pytest.approx(2.7e6 * 1.5 / (2 * (3e6 + 2e5 * 2.0)), rel=1e-9)
    r = CliRunner().invoke(main, ["solve", "--method", "penalty", "--set", f"mesh.file={msh}", "--set", "mesh.sets={base: BASE, top: TOP}",
                                  "--set", "geometry.radius=3.0", "-o", str(tmp_path / "s")])
    assert r.exit_code == 2 and "geometry.radius = 3.0: contradicts the imported mesh" in r.output
    assert not (tmp_path / "s").exists()


def test_a_small_mesh_with_default_geometry_keys_takes_the_mesh_values(tmp_path):
    """A ring R = 1 m, t = 0.1 m, H = 1 m (test_import_checks) loaded with the default model: the geometry
    is the ring's, not the default JAR's 1.5 / 0.02 / 2 m."""
    from gmsh_skirt import write_inp
    from test_import_checks import N, _ring
    ids, xyz, eids, conn = _ring()
    f = write_inp(tmp_path / "ring.inp", ids, xyz, eids, conn, {"BASE": ids[: 2 * N], "TOP": ids[2 * N:]})
    g = load(None, [f"mesh.file={f}", "mesh.sets={base: BASE, top: TOP}"]).geometry
    assert g.radius == pytest.approx(1.0) and g.thickness == pytest.approx(0.1) and g.height == pytest.approx(1.0)
