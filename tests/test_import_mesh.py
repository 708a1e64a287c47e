"""Imported meshes (issue 15) against independent truths.

An independent skirt mesh made with the Gmsh Python API (tests/gmsh_skirt.py: structured transfinite
hexahedra, Gmsh's own node order and numbering) imported from .msh, .inp and .bdf; measured (48 x 6 x 1,
2-core dev box): full-contact sigma_N within 0.30 % of -N/(2 pi R t) (the 48-gon's area is 0.29 % short
of the circle's), kinematic-top liftoff 0.6707 against beam theory 0.675 (0.64 %).
"""

import numpy as np
import pytest

from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.solve import solve_model

from gmsh_skirt import gmsh_skirt, write_inp

KIN = ["load_introduction=kinematic", "loads.T=0", "contact.stop.side=none"]
SETS = {"msh": "{base: BASE, top: TOP}", "inp": "{base: BASE, top: TOP}", "bdf": "{base: '1', top: '2'}"}


@pytest.fixture(scope="module")
def gm(tmp_path_factory):
    pytest.importorskip("gmsh")   # in the 'test' extra
    return gmsh_skirt(tmp_path_factory.mktemp("gmsh"))


def _step1(df):
    s1 = df[df.step == 1]
    return s1[s1.increment == s1.increment.max()]


@pytest.mark.parametrize("fmt", ["msh", "inp", "bdf"])
def test_gmsh_skirt_full_contact_and_liftoff_against_beam_theory(gm, fmt):
    m = load(None, [f"mesh.file={gm[fmt]}", f"mesh.sets={SETS[fmt]}"] + KIN)
    me = build_mesh(m)
    assert me.table.nodes.size == 96 and me.hexes.shape == (288, 8)
    df, summary = solve_model(m, "penalty", recover=False)
    g = m.geometry
    sig = _step1(df).sigma_n_pa.to_numpy()
    np.testing.assert_allclose(sig, -m.loads.N / (2 * np.pi * g.radius * g.thickness), rtol=0.005)
    assert summary["liftoff_load_factor"] == pytest.approx(m.loads.N * g.radius / (2 * m.loads.M), rel=0.01)
    if fmt != "msh":   # .inp and .bdf keep Gmsh's node ids (meshio renumbers .msh points)
        assert set(df.node) <= set(gm["node_ids"].tolist())


def _export(mesh, path, node_ids, elem_ids, order_n, order_e):
    """Write ``mesh`` as an .inp with the given ids, nodes and elements in the given orders."""
    conn = node_ids[mesh.hexes]
    sets = {"BASE": node_ids[mesh.table.nodes], "TOP": node_ids[mesh.top_nodes]}
    return write_inp(path, node_ids[order_n], mesh.nodes[order_n], elem_ids[order_e], conn[order_e], sets)


def _renumbered(mesh, path, seed, node_ids, elem_ids):
    """Write ``mesh`` as an .inp with shuffled ids (permutation x step + first, ``node_ids`` and ``elem_ids``
    each (step, first)) and nodes and elements in a shuffled file order; returns (path, node ids, element
    ids, node order, element order)."""
    rng = np.random.default_rng(seed)
    nid = rng.permutation(mesh.n_nodes) * node_ids[0] + node_ids[1]
    eid = rng.permutation(mesh.hexes.shape[0]) * elem_ids[0] + elem_ids[1]
    on, oe = rng.permutation(mesh.n_nodes), rng.permutation(mesh.hexes.shape[0])
    return _export(mesh, path, nid, eid, on, oe), nid, eid, on, oe


def test_default_jar_written_out_and_imported_back_gives_the_same_sigma(tmp_path):
    ref_model = load(None, ["steps.increments=2"])   # the default JAR mesh; a short load path
    me = build_mesh(ref_model)
    ref, _ = solve_model(ref_model, "lagrange", recover=False)
    n, ne = me.n_nodes, me.hexes.shape[0]
    rng = np.random.default_rng(15)
    nid, eid = rng.permutation(n) * 7 + 100001, rng.permutation(ne) * 3 + 5000
    # (ids, orders, tolerance of the peak). Shuffling the file's node/element order changes the
    # solver's summation order (issue 16's node-block assembly, CHOLMOD ordering): measured 2.5e-9 to
    # 5.5e-9 of the peak over 3 seeds (element order alone as much), round-off; ids alone: 5.7e-12.
    cases = {"same": (np.arange(1, n + 1), np.arange(1, ne + 1), np.arange(n), np.arange(ne), 1e-9),
             "renumbered": (nid, eid, np.arange(n), np.arange(ne), 1e-9),
             "renumbered and shuffled": (nid, eid, rng.permutation(n), rng.permutation(ne), 2e-8)}
    for name, (nid, eid, on, oe, tol) in cases.items():
        f = _export(me, tmp_path / f"{name}.inp", nid, eid, on, oe)
        m = load(None, [f"mesh.file={f}", "mesh.sets={base: BASE, top: TOP}", "steps.increments=2"])
        got, _ = solve_model(m, "lagrange", recover=False)
        back = dict(zip(nid.tolist(), range(1, n + 1)))
        got = got.assign(node=got.node.map(back))
        j = ref.merge(got, on=["step", "increment", "node", "surface"], suffixes=("_r", "_i"))
        assert len(j) == len(ref)
        scale = np.abs(j.sigma_n_pa_r).max()
        assert np.abs(j.sigma_n_pa_r - j.sigma_n_pa_i).max() <= tol * scale, name


def test_renumbered_mesh_decks_carry_the_user_ids(tmp_path):
    from pyNastran.bdf.bdf import BDF

    from deckbridge.importers.inp_mesh import read_inp_mesh
    from deckbridge.render import render_all

    small = ["mesh.n_theta=24", "mesh.n_z=4", "mesh.n_r=1"]
    me = build_mesh(load(None, small))
    rng = np.random.default_rng(7)
    nid = rng.permutation(me.n_nodes) * 5 + 70001
    eid = rng.permutation(me.hexes.shape[0]) * 2 + 901
    f = _export(me, tmp_path / "r.inp", nid, eid, rng.permutation(me.n_nodes), rng.permutation(me.hexes.shape[0]))
    m = load(None, small + [f"mesh.file={f}", "mesh.sets={base: BASE, top: TOP}", "name=RENUM"])
    render_all(m, tmp_path / "decks")
    want = {int(e): set(nid[h].tolist()) for e, h in zip(eid, me.hexes)}   # element id -> its node ids
    for deck in ("RENUM_lagrange.inp", "RENUM_ccx_penalty.inp", "RENUM_ccx_lagrange.inp"):
        got = read_inp_mesh(tmp_path / "decks" / deck)
        ids, conn = got.elements["C3D8I"]
        assert {int(e): set(c.tolist()) for e, c in zip(ids, conn)} == want, deck
        assert set(nid.tolist()) <= set(got.node_ids.tolist())
    for deck in ("RENUM_penalty.bdf", "RENUM_mystran.bdf"):
        bdf = BDF(debug=None)
        bdf.read_bdf(str(tmp_path / "decks" / deck), xref=False)
        hexa = {e: set(el.node_ids) for e, el in bdf.elements.items() if el.type == "CHEXA"}
        assert hexa == want, deck
        for i in rng.choice(me.n_nodes, 20):   # the user's node at its own place
            np.testing.assert_allclose(bdf.nodes[int(nid[i])].xyz, me.nodes[i], atol=1e-12)


def test_imported_gmsh_mesh_reference_matches_ccx_penalty(tmp_path):
    """The whole job on an imported mesh: ccx reads back through the user ids (kinematic top)."""
    from deckbridge.readers import read
    from job_tables import run_job_tables

    pytest.importorskip("gmsh")
    g = gmsh_skirt(tmp_path / "mesh", n_theta=24, n_z=6)
    m = load(None, [f"mesh.file={g['inp']}", "mesh.sets={base: BASE, top: TOP}", "load_introduction=kinematic"])
    run_job_tables(m, tmp_path / "run", with_ccx=True, echo=lambda s: None)
    ref = read(tmp_path / "run" / "reference_penalty", model=m)
    ccx = read(tmp_path / "run" / "ccx", model=m)
    ccx = ccx[ccx.method == "penalty"]
    j = ref[ref.surface == "table"].merge(ccx[ccx.surface == "table"], on=["step", "increment", "node"],
                                          suffixes=("_r", "_c"))
    assert len(j) == 11 * 48 and set(j.node) <= set(g["node_ids"].tolist())
    for _, s in j.groupby(["step", "increment"]):
        assert np.abs(s.sigma_n_pa_r - s.sigma_n_pa_c).max() < 0.02 * np.abs(s.sigma_n_pa_r).max()


def test_units_axis_cp_frames_and_id_list_files_give_the_same_sigma(tmp_path):
    """The same small mesh in mm, shifted off the origin (mesh.axis), with GRIDs in a cylindrical CP
    frame and sets as node-id list files (.bdf): sigma_N identical to the plain import."""
    small = ["mesh.n_theta=24", "mesh.n_z=4", "mesh.n_r=1", "contact.stop.side=none"]
    me = build_mesh(load(None, small))
    nid, eid = np.arange(1, me.n_nodes + 1), np.arange(1, me.hexes.shape[0] + 1)
    plain = _export(me, tmp_path / "plain.inp", nid, eid, np.arange(me.n_nodes), np.arange(len(eid)))
    ref, _ = solve_model(load(None, small + [f"mesh.file={plain}", "mesh.sets={base: BASE, top: TOP}"]),
                         "penalty", recover=False)
    o = np.array([3.0, -2.0, 5.0])
    shifted = write_inp(tmp_path / "mm.inp", nid, (me.nodes + o) * 1000.0, eid, nid[me.hexes],
                        {"BASE": nid[me.table.nodes], "TOP": nid[me.top_nodes]})
    m = load(None, small + [f"mesh.file={shifted}", "mesh.sets={base: BASE, top: TOP}", "mesh.units=mm",
                            f"mesh.axis=[{o[0] * 1000}, {o[1] * 1000}, {o[2] * 1000}, 0, 0, 1]"])
    got, _ = solve_model(m, "penalty", recover=False)
    # mm, a 6 m offset or cylindrical coordinates cost round-off: measured <= 2.8e-8 of the peak (3 of 576 rows)
    np.testing.assert_allclose(got.sigma_n_pa, ref.sigma_n_pa, rtol=0, atol=1e-7 * np.abs(ref.sigma_n_pa).max())
    # Nastran: GRIDs in a cylindrical frame (CORD2C about z), sets as node-id list files
    r = np.hypot(me.nodes[:, 0], me.nodes[:, 1])
    th = np.degrees(np.arctan2(me.nodes[:, 1], me.nodes[:, 0]))
    lines = ["SOL 101", "CEND", "BEGIN BULK", "CORD2C,7,,0.,0.,0.,0.,0.,1.", ",1.,0.,0."]
    lines += [f"GRID*,{i},7,{a!r},{b!r}\n*,{c!r}" for i, a, b, c in zip(nid, r, th, me.nodes[:, 2])]
    lines += [f"CHEXA,{e},1,{','.join(map(str, c[:6]))}\n,{c[6]},{c[7]}" for e, c in zip(eid, nid[me.hexes])]
    lines += ["PSOLID,1,1", "MAT1,1,2.1e11,,0.3", "ENDDATA"]
    (tmp_path / "cyl.bdf").write_text("\n".join(lines) + "\n")
    (tmp_path / "base.txt").write_text("\n".join(map(str, nid[me.table.nodes])))
    (tmp_path / "top.txt").write_text(" ".join(map(str, nid[me.top_nodes])))
    m = load(None, small + [f"mesh.file={tmp_path / 'cyl.bdf'}", "mesh.sets={base: base.txt, top: top.txt}"])
    got, _ = solve_model(m, "penalty", recover=False)
    np.testing.assert_allclose(got.sigma_n_pa, ref.sigma_n_pa, rtol=0, atol=1e-7 * np.abs(ref.sigma_n_pa).max())
