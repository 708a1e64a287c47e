"""A Gmsh-written quadratic skirt (C3D20 .inp) through ``run`` (reference Lagrange, face-weighted): the ParaView
series holds the file's 20-node cells (VTK_QUADRATIC_HEXAHEDRON, read back with meshio) and the table's sigma_N of
the contact table; and pads on 10-/15-/20-node skirts, parametric or imported, are refused in one line (issue 23:
the pad faces of a quadratic base are not built yet).

Pads were tried on the parametric skirts (each table face standing for its coarse cell's 8-node base face in
``supports.pad_face_mask``; 48 x 6 x 1, 4 pads of 30 deg, kinematic top, N alone, Lagrange): each pad's reaction is
N / 4 to 2e-12, but the face-weighted law (hat basis) lifts 36 of 92 (hex20, hex20r), 64 of 108 (tet10) and
60 of 108 (wedge15) pad nodes by 2-4 um where the 8-node skirt keeps every pad node pressed
(tests/test_pads.py), so pads stay refused on these faces."""

from __future__ import annotations

import warnings

import meshio
import numpy as np
import pandas as pd
import pytest

from gmsh_skirt import gmsh_quadratic

from deckbridge.api import run
from deckbridge.errors import ModelError
from deckbridge.mesh import build_mesh
from deckbridge.model import load

PADS = "contact.pads={count: 4, width_deg: 30, first_deg: 45}"


def _imported(files, *extra):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load(None, [f"mesh.file={files['inp']}", f"mesh.sets={files['sets']['inp']}", *extra])


def test_run_on_gmsh_hex20_writes_quadratic_cells_and_the_table_sigma(tmp_path):
    files = gmsh_quadratic(tmp_path / "mesh", "hex20", n_theta=48, n_z=3, n_r=1)
    m = _imported(files, "contact.stop.side=none", "steps.lambda_max=0.4", "steps.increments=2")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run(m, tmp_path / "out", methods=("lagrange",))
    ref = tmp_path / "out" / "reference_lagrange"
    table = pd.read_csv(ref / "contact.csv")
    tab = table[table.surface == "table"]
    step, inc = max(zip(tab.step, tab.increment))
    last = tab[(tab.step == step) & (tab.increment == inc)]
    assert (last.sigma_n_pa < 0).any() and len(last) == build_mesh(m).table.nodes.size
    series = sorted(ref.glob("result_*.vtu"))
    v = meshio.read(series[-1])
    assert [(c.type, len(c.data)) for c in v.cells] == [("hexahedron20", files["n_elements"])]
    from deckbridge.importers.node_order import node_order_problem
    assert node_order_problem(np.asarray(v.points), v.cells[0].data, "c3d20") is None
    ids = np.asarray(v.point_data["node_id"], np.int64)
    at = {int(n): i for i, n in enumerate(ids)}
    mesh = build_mesh(m)
    node_ids = mesh.node_ids[last.node.to_numpy() - 1] if last.node.max() <= mesh.n_nodes else last.node.to_numpy()
    s_vtu = np.asarray(v.point_data["table_sigma_n_pa"])[[at[int(n)] for n in node_ids]]
    np.testing.assert_allclose(s_vtu, last.sigma_n_pa.to_numpy(), rtol=1e-9, atol=1e-6)


@pytest.mark.parametrize("element", ["hex20", "hex20r", "tet10", "wedge15"])
def test_pads_on_parametric_quadratic_skirts_are_refused_in_one_line(element):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = load(None, [f"mesh.element={element}", "mesh.n_theta=24", "mesh.n_z=2", "mesh.n_r=1", PADS])
    with pytest.raises(ModelError, match=rf"^contact.pads = 'set': needs mesh.element hex8i or hex8 \(not {element}\)") as err:
        build_mesh(m)
    assert "\n" not in str(err.value)


def test_import_cli_on_gmsh_tet10_and_its_pads_refused_in_one_line(tmp_path):
    """``deckbridge import`` of a Gmsh C3D10 skirt writes the model and measures it (it stopped after writing it,
    in the Nastran surface deck's layer builder, which takes 8-node hexahedra only); pads are refused."""
    from click.testing import CliRunner
    from deckbridge.cli import main
    files = gmsh_quadratic(tmp_path, "tet10", n_theta=96, n_z=2, n_r=1)   # not 24: there the curvature
    # (sagitta of a 15 deg edge, 13 mm) exceeds the 20 mm wall's half and Gmsh's curved tetrahedra invert
    r = CliRunner().invoke(main, ["import", str(files["inp"]), "-o", str(tmp_path / "m.yaml"), "--base", "BASE",
                                  "--top", "TOP"])
    assert r.exit_code == 0, r.output
    assert "R = 1.5 m, t = 0.02 m, H = 2 m" in r.output
    assert build_mesh(load(str(tmp_path / "m.yaml"))).element == "c3d10"
    with pytest.raises(ModelError, match=r"^contact.pads = 'set': needs 8-node hexahedra in an imported mesh "
                                         r"\(not C3D10\)") as err:
        build_mesh(_imported(files, PADS))
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("element, vtk, per_cell", [("hex20r", "hexahedron20", 1), ("tet10", "tetra10", 6)])
def test_run_on_parametric_quadratic_skirts(tmp_path, element, vtk, per_cell):
    """``run`` on hex20r and tet10 skirts (48 x 3 x 1; it stopped at 'base nodes do not form the same
    through-wall row' before the wall was reduced at the corner nodes): the ParaView series' cells (meshio),
    the wall table's base areas summing to the section 2 pi R t (measured 6e-7) and, in step 1 (N alone),
    Sum szz_mean x area = -N (measured 1.5e-7 hex20r, 4.6e-6 tet10)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = load(None, [f"mesh.element={element}", "mesh.n_theta=48", "mesh.n_z=3", "mesh.n_r=1",
                        "steps.lambda_max=0.3", "steps.increments=1"])
        run(m, tmp_path / "out", methods=("lagrange",))
    ref = tmp_path / "out" / "reference_lagrange"
    v = meshio.read(sorted(ref.glob("result_*.vtu"))[-1])
    assert [(c.type, len(c.data)) for c in v.cells] == [(vtk, per_cell * 48 * 3)]
    from deckbridge.importers.node_order import node_order_problem    # VTK's quadratic order is CalculiX's:
    assert node_order_problem(np.asarray(v.points), v.cells[0].data, element) is None   # mid-sides mid-edge, J > 0
    wall = pd.read_csv(ref / "wall_stress.csv")
    section = 2 * np.pi * m.geometry.radius * m.geometry.thickness
    for (step, _), d in wall.groupby(["step", "increment"]):
        assert d.area_m2.sum() == pytest.approx(section, rel=1e-5)
        if step == 1:
            assert (d.szz_mean_pa * d.area_m2).sum() == pytest.approx(-m.loads.N, rel=1e-4)
    assert (tmp_path / "out" / "report.html").stat().st_size > 0


@pytest.mark.ccx
def test_run_with_ccx_on_gmsh_hex20_under_n(tmp_path):
    """``run --with-ccx`` on the Gmsh-written C3D20 skirt (48 x 3 x 1), N alone (the moment case is ccx's mortar
    on quadratic faces, another piece of work), no radial stop (its GAPUNI gaps are node-based): ccx's mortar
    pressure (as the ccx reader reads it on quadratic faces) is uniform at -N / (2 pi R t) within 5e-4, in the
    comparison and in its ParaView series with the file's 20-node cells. Before, every corner node read as tension
    (RF / A on a corner that carries -1/12 of a pressure) and the ccx wall reader stopped the run."""
    import json
    files = gmsh_quadratic(tmp_path / "mesh", "hex20", n_theta=48, n_z=3, n_r=1)
    m = _imported(files, "contact.stop.side=none", "loads.M=0", "loads.T=0", "steps.increments=1")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run(m, tmp_path / "out", with_ccx=True, methods=("lagrange",))
    exact = -m.loads.N / (2 * np.pi * m.geometry.radius * m.geometry.thickness)
    ccx = json.loads((tmp_path / "out" / "summary.json").read_text())["sources"]["ccx/mortar"]
    assert ccx["peak_compression_pa"] == pytest.approx(exact, rel=5e-4)
    assert ccx["peak_node_sigma_n_pa"] == pytest.approx(exact, rel=5e-4)
    v = meshio.read(sorted((tmp_path / "out" / "ccx").glob("*_ccx_lagrange_*.vtu"))[-1])
    assert [(c.type, len(c.data)) for c in v.cells] == [("hexahedron20", files["n_elements"])]
    s = np.asarray(v.point_data["table_sigma_n_pa"])[np.asarray(v.point_data["table_slave"]) > 0]
    assert np.allclose(s, exact, rtol=5e-4)
