"""Misleading import messages (issue 26): a NaN coordinate was reported as 'nodes 1 and 2 coincide';
a mesh in mm declared as m was echoed as 'R = 1500 m', one in m declared mm ended in the solver's 'no
contact possible'. Reference: the generating mesh (R = 1.5 m, Gmsh-written .msh in mm and in m)."""

import numpy as np
import pytest
from click.testing import CliRunner

from deckbridge.cli import main
from deckbridge.mesh import build_mesh
from deckbridge.model import ModelError, load
from gmsh_skirt import gmsh_written, write_inp
from test_import_checks import N, _ring


def test_nan_coordinate_is_named_with_its_node_and_value(tmp_path):
    ids, xyz, eids, conn = _ring()
    xyz = xyz.copy()
    xyz[4, 1] = np.nan                                  # node 5, y
    f = write_inp(tmp_path / "nan.inp", ids, xyz, eids, conn, {"BASE": ids[: 2 * N], "TOP": ids[2 * N:]})
    with pytest.raises(ModelError, match=r"node 5: coordinate y = nan is not a finite number") as err:
        build_mesh(load(None, [f"mesh.file={f}", "mesh.sets={base: BASE, top: TOP}"]))
    assert "coincide" not in str(err.value) and "\n" not in str(err.value)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    pytest.importorskip("gmsh")
    base = tmp_path_factory.mktemp("units")
    return {u: gmsh_written(base / u, n_theta=16, n_z=2, scale=s)["msh"] for u, s in (("mm", 1000.0), ("m", 1.0))}


@pytest.mark.parametrize("written,declared", [("mm", "m"), ("m", "mm")])
def test_a_wrong_mesh_unit_is_refused_naming_the_radius_and_the_other_unit(files, written, declared, tmp_path):
    r_out = 1.5 + 0.02 / 2
    out = tmp_path / "m.yaml"
    r = CliRunner().invoke(main, ["import", str(files[written]), "-o", str(out), "--base", "BASE", "--top", "TOP",
                                  "--units", declared])
    assert r.exit_code == 2 and not out.exists()
    line = r.output.strip().splitlines()[-1]
    got = r_out * (1000.0 if written == "mm" else 1e-3)
    assert f"mesh.units = '{declared}': the mesh's largest radius is {got:.6g} m, outside 0.01..100 m" in line
    assert f"(mesh.units = {written}: {r_out:.6g} m)" in line
    r = CliRunner().invoke(main, ["import", str(files[written]), "-o", str(out), "--base", "BASE", "--top", "TOP",
                                  "--units", written])
    assert r.exit_code == 0 and "R = 1.5 m, t = 0.02 m, H = 2 m" in r.output
