"""Quadratic skirts meshed with the Gmsh API as an analyst does it (``gmsh.model.mesh.setOrder(2)``; recombined
hexahedra with ``Mesh.SecondOrderIncomplete`` 1, or tetrahedra), written by ``gmsh.write`` as .msh, .inp and .bdf,
imported and solved by the reference solver (face-weighted Lagrange, issue 23).

96 x 6 x 2 skirt (R 1.5, t 0.02, H 2 m), default loads, lambda = 0.3 (full contact): the through-wall mean
(Simpson over the 5 nodes of a corner azimuth) of sigma_N against thin-ring beam theory, as a fraction of the
peak. Measured: hex20 0.00089 (.msh, .inp), 0.0014 (.bdf), tet10 0.0041 (.msh); the parametric skirt on the same
grid gives hex20 0.0008, tet10 0.0040 (tests/test_face_weighted_skirt.py). The table forces add up to N (2e-13)
and their moment about the axis' normal to the load plane is lambda M (1e-9). The .msh and .inp give the same
sigma_N to 1.8e-10 of the peak (the .inp's 14 significant digits); the .bdf to 3.6e-4, since Gmsh writes
small-field GRID cards (8 characters: radii 1.4999974 m, thickness 0.0199992 m measured); with
``Mesh.BdfFieldFormat = 2`` (GRID*, 8 decimals) to 2.7e-7.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.integrate import simpson

from gmsh_skirt import gmsh_quadratic

from deckbridge.errors import ModelError
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.quantities import beam_theory_sigma
from deckbridge.solve import condense_model, solve_path

N_THETA = 96
EPS = 0.004      # Gmsh's against the parametric hex20 skirt, node by node: measured 0.0024 of the peak


def _model(files, fmt, *extra):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load(None, [f"mesh.file={files[fmt]}", f"mesh.sets={files['sets'][fmt]}", "steps.lambda_max=0.3",
                           "steps.increments=1", "outputs.vtu=false", *extra])


def _solve(files, fmt):
    """(model, mesh, sigma_N of the table rows, forces, table xyz, lambda) at lambda = 0.3."""
    m = _model(files, fmt)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mesh, system = condense_model(m)
        sol = solve_path(m, system, "lagrange")
    p = system.problem
    tab = p.contact_surface == "table"
    assert sol.closed[-1][tab].all()
    return m, mesh, sol.sigma_n[-1][tab], sol.force[-1][tab], p.nodes[p.contact_nodes[tab]], sol.load_factor[-1]


def _beam_error(m, mesh, s, lam) -> tuple[float, int]:
    """Largest |through-wall mean - beam theory| / peak over the corner azimuths, and their count."""
    R, t = m.geometry.radius, m.geometry.thickness
    th, r = mesh.table.theta_deg, mesh.table.r
    peak = abs(beam_theory_sigma(m.loads.N, lam * m.base_moment, R, t, 180.0))
    errs = []
    for a in np.unique(th):
        i = np.flatnonzero(th == a)
        if i.size != 5 or abs((a * N_THETA / 360 + 0.5) % 1 - 0.5) > 1e-4:   # corner azimuths only
            continue
        i = i[np.argsort(r[i])]
        wall = simpson(s[i], x=r[i]) / t
        errs.append(abs(wall - beam_theory_sigma(m.loads.N, lam * m.base_moment, R, t, a - m.loads.azimuth)) / peak)
    return max(errs), len(errs)


def _balance(m, f, xyz, lam):
    assert f.sum() == pytest.approx(m.loads.N, rel=1e-9)                     # Sum F = N
    assert abs((f * xyz[:, 0]).sum()) == pytest.approx(lam * m.base_moment, rel=1e-9)   # moment about y
    assert abs((f * xyz[:, 1]).sum()) < 1e-9 * lam * m.base_moment


@pytest.fixture(scope="module")
def hex20_files(tmp_path_factory):
    return gmsh_quadratic(tmp_path_factory.mktemp("hex20"), "hex20", n_theta=N_THETA, n_z=6, n_r=2)


def test_gmsh_hex20_in_three_formats_against_beam_theory(hex20_files):
    out = {}
    for fmt in ("msh", "inp", "bdf", "bdf_large"):
        m, mesh, s, f, xyz, lam = _solve(hex20_files, fmt)
        assert mesh.element == "c3d20" and mesh.hexes.shape == (hex20_files["n_elements"], 20)
        assert (mesh.n_theta, mesh.n_r, mesh.n_z) == (N_THETA, 2, 6)
        err, n = _beam_error(m, mesh, s, lam)
        assert n == N_THETA and err < (0.002 if fmt == "bdf" else 0.0012), (fmt, err)
        _balance(m, f, xyz, lam)
        out[fmt] = s
    peak = np.abs(out["msh"]).max()
    assert np.abs(out["inp"] - out["msh"]).max() < 1e-8 * peak        # measured 1.8e-10
    assert np.abs(out["bdf"] - out["msh"]).max() < 1e-3 * peak        # 8-character GRID fields: 3.6e-4
    assert np.abs(out["bdf_large"] - out["msh"]).max() < 2e-6 * peak  # GRID* with 8 decimals: 2.7e-7


def test_gmsh_tet10_against_beam_theory(tmp_path):
    files = gmsh_quadratic(tmp_path, "tet10", n_theta=N_THETA, n_z=6, n_r=2)
    m, mesh, s, f, xyz, lam = _solve(files, "msh")
    assert mesh.element == "c3d10" and mesh.hexes.shape == (files["n_elements"], 10)
    err, n = _beam_error(m, mesh, s, lam)
    assert n == N_THETA and err < 0.005, err                           # measured 0.0041
    _balance(m, f, xyz, lam)


def test_gmsh_hex27_is_read_as_hex20_and_its_bdf_refused(tmp_path, hex20_files):
    """Without Mesh.SecondOrderIncomplete Gmsh writes 27-node bricks: read as the same C3D20 mesh (face and
    centre nodes dropped, warned); its .bdf (a 27-node CHEXA, which Nastran has not) is refused in one line."""
    files = gmsh_quadratic(tmp_path, "hex27", n_theta=N_THETA, n_z=6, n_r=2)
    with pytest.warns(UserWarning, match="27-node hexahedra read as 20-node"):
        mesh27 = build_mesh(_model(files, "inp"))
    mesh20 = build_mesh(_model(hex20_files, "inp"))
    assert mesh27.hexes.shape == mesh20.hexes.shape
    np.testing.assert_allclose(mesh27.nodes[mesh27.hexes], mesh20.nodes[mesh20.hexes], atol=1e-12)
    np.testing.assert_allclose(mesh27.table.area.sum(), mesh20.table.area.sum(), rtol=1e-12)
    with pytest.raises(ModelError, match="CHEXA has at most 20 nodes.*SecondOrderIncomplete") as err:
        build_mesh(_model(files, "bdf"))
    assert "\n" not in str(err.value)


def test_permuted_node_order_is_refused_in_one_line(tmp_path, hex20_files):
    """Two mid-side nodes of one C3D20 exchanged in the .inp: refused, naming the element."""
    text = hex20_files["inp"].read_text().splitlines()
    at = next(k for k, ln in enumerate(text) if ln.upper().startswith("*ELEMENT, TYPE=C3D20"))
    row = text[at + 1].rstrip(",").split(",") + text[at + 2].rstrip(",").split(",")
    eid, nodes = row[0], [v.strip() for v in row[1:] if v.strip()]
    nodes[8], nodes[9] = nodes[9], nodes[8]
    text[at + 1] = ", ".join([eid] + nodes[:15]) + ","
    text[at + 2] = ", ".join(nodes[15:])
    bad = tmp_path / "skirt.inp"
    bad.write_text("\n".join(text) + "\n")
    with pytest.raises(ModelError, match=rf"element {eid.strip()} \(C3D20\): node 9 is not near the mid-point") as err:
        build_mesh(_model({"inp": bad, "sets": hex20_files["sets"]}, "inp"))
    assert "\n" not in str(err.value)


def test_gmsh_hex20_equals_the_parametric_hex20_skirt(hex20_files):
    """The same grid meshed by Gmsh (imported .msh) and by deckbridge (mesh.element = hex20). Gmsh puts the
    mid-side nodes of edges inside the volume on the straight chord (the mid-wall ring r = R: 1.499197 m, the
    sagitta 0.8 mm off the parametric skirt's true circle), every other node where the parametric skirt has it;
    the table's sigma_N then agrees node by node (matched by position, 1 mm) to EPS of the peak (measured 0.0024)."""
    m, mesh, s, _, xyz, _ = _solve(hex20_files, "msh")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        p = load(None, ["mesh.element=hex20", f"mesh.n_theta={N_THETA}", "mesh.n_z=6", "mesh.n_r=2",
                        "steps.lambda_max=0.3", "steps.increments=1", "outputs.vtu=false"])
        pmesh, system = condense_model(p)
        sol = solve_path(p, system, "lagrange")
    tab = system.problem.contact_surface == "table"
    pxyz, ps = system.problem.nodes[system.problem.contact_nodes[tab]], sol.sigma_n[-1][tab]
    assert pmesh.hexes.shape == mesh.hexes.shape and ps.size == s.size
    from scipy.spatial import cKDTree
    dist, at = cKDTree(pxyz).query(xyz)
    assert np.unique(at).size == at.size and dist.max() < 1e-3
    chord = dist > 1e-9
    r = np.hypot(xyz[:, 0], xyz[:, 1])
    assert np.allclose(r[chord], m.geometry.radius * np.cos(np.radians(360 / N_THETA / 2)), atol=1e-9)
    err = np.abs(s - ps[at]).max() / np.abs(ps).max()
    assert err < EPS, err


def test_c3d20r_in_the_file_solves_as_hex20r(tmp_path, hex20_files):
    """The .inp's element type names the integration: C3D20R -> the reference's c3d20r (8 Gauss points)."""
    text = hex20_files["inp"].read_text().replace("type=C3D20,", "type=C3D20R,")
    (tmp_path / "skirt.inp").write_text(text)
    mesh = build_mesh(_model({"inp": tmp_path / "skirt.inp", "sets": hex20_files["sets"]}, "inp"))
    assert mesh.element == "c3d20r" and mesh.hexes.shape[1] == 20


@pytest.mark.parametrize("element", ["tet10", "hex20", "wedge15"])
def test_wholly_inverted_elements_are_mirrored_with_a_warning(element):
    """Elements whose every Jacobian is negative (a mesher's mirrored order, all mid-sides mid-edge) are read
    mirrored: the same node sets per element, positive volumes, a warning with their count."""
    from deckbridge.importers.node_order import mirror_order
    from deckbridge.importers.quadratic import check_node_order
    from deckbridge.mesh_order import skirt_cells
    from reference_solver.elements import element_type
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = load(None, [f"mesh.element={element}", "mesh.n_theta=24", "mesh.n_z=2", "mesh.n_r=1"])
    nodes, cells, _ = skirt_cells(m)
    et = element_type(element)
    bad = cells.copy()
    bad[[3, 7]] = cells[[3, 7]][:, mirror_order(et)]
    ids = np.arange(1, len(cells) + 1)
    with pytest.warns(UserWarning, match=rf"2 of {len(cells)} C3D\w+ elements were inverted"):
        fixed = check_node_order(nodes, bad, et.name, ids)
    assert (np.sort(fixed, axis=1) == np.sort(cells, axis=1)).all()
    np.testing.assert_allclose(et.volume_weights(nodes[fixed]).sum(1), et.volume_weights(nodes[cells]).sum(1),
                               rtol=1e-12)


def test_gmsh_wedge15_against_beam_theory_and_its_msh_refused(tmp_path):
    """Triangles revolved into prisms, second order (C3D15 / 15-node CPENTA): the .inp within 0.00065 of the peak
    of beam theory (measured; .bdf 0.0012); meshio has no node order for Gmsh's 15-node prism, so the .msh is
    refused in one line that names the formats that work."""
    files = gmsh_quadratic(tmp_path, "wedge15", n_theta=N_THETA, n_z=6, n_r=2)
    m, mesh, s, f, xyz, lam = _solve(files, "inp")
    assert mesh.element == "c3d15" and mesh.hexes.shape == (files["n_elements"], 15)
    err, n = _beam_error(m, mesh, s, lam)
    assert n == N_THETA and err < 0.001, err
    _balance(m, f, xyz, lam)
    with pytest.raises(ModelError, match=r"meshio cannot read Gmsh elements of type 'wedge15': write the mesh as "
                                         r"\.inp or \.bdf") as exc:
        build_mesh(_model(files, "msh"))
    assert "\n" not in str(exc.value)


def test_gmsh_unstructured_tet10_against_beam_theory(tmp_path):
    """Plain tetrahedra as Gmsh makes them (an OpenCASCADE tube R 0.5, t 0.02, H 0.6 m, size <= 2 t: 8556 C3D10,
    no through-wall rows), N 3e5 N and M 2e4 N m at lambda 0.5 (beam liftoff at 3.75): every table node closed,
    Sum F = N and its moment lambda M (1e-9), and sigma_N node by node within 0.5 % of the peak of thin-ring beam
    theory at the node's azimuth (measured 0.29 %; through-wall variation r / R included in that)."""
    files = gmsh_quadratic(tmp_path, "tet10", R=0.5, t=0.02, H=0.6, unstructured=True, size=0.04)
    m, mesh, s, f, xyz, lam = _solve_loads(files)
    assert mesh.element == "c3d10" and mesh.hexes.shape[0] == files["n_elements"]
    _balance(m, f, xyz, lam)
    th = np.degrees(np.arctan2(xyz[:, 1], xyz[:, 0]))
    beam = np.array([beam_theory_sigma(m.loads.N, lam * m.base_moment, m.geometry.radius, m.geometry.thickness,
                                       a - m.loads.azimuth) for a in th])
    err = np.abs(s - beam).max() / np.abs(beam).max()
    assert err < 0.005, err


def _solve_loads(files):
    """:func:`_solve` of the .msh with N 3e5 N, M 2e4 N m, T 0, lambda 0.5 (a skirt of radius 0.5 m)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = load(None, [f"mesh.file={files['msh']}", f"mesh.sets={files['sets']['msh']}", "loads.N=3e5",
                        "loads.M=2e4", "loads.T=0", "steps.lambda_max=0.5", "steps.increments=1", "outputs.vtu=false"])
        mesh, system = condense_model(m)
        sol = solve_path(m, system, "lagrange")
    p = system.problem
    tab = p.contact_surface == "table"
    assert sol.closed[-1][tab].all()
    return m, mesh, sol.sigma_n[-1][tab], sol.force[-1][tab], p.nodes[p.contact_nodes[tab]], sol.load_factor[-1]
