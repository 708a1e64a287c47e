"""Abaqus-style Lagrange deck: mesh read back, contact cards, areas and loads against the model."""

import re

import numpy as np
import pytest

from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.dialects.abaqus import render as abaqus
from deckbridge.render import render_all
from deckbridge.importers.inp_mesh import read_inp_mesh

SMALL = ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1"]


def _deck(tmp_path, overrides=()):
    model = load(None, SMALL + list(overrides))
    mesh = build_mesh(model)
    tmp_path.mkdir(exist_ok=True)
    path = abaqus.write(model, mesh, tmp_path)[0]
    return model, mesh, path, path.read_text()


def _block(text, header):
    """Data lines under the first card line starting with ``header``."""
    lines = text.split("\n")
    k = next(i for i, ln in enumerate(lines) if ln.startswith(header))
    out = []
    for ln in lines[k + 1:]:
        if ln.startswith("*"):
            break
        out.append(ln)
    return out


def _poly_annulus(n, ro, ri):
    return 0.5 * n * np.sin(2 * np.pi / n) * (ro ** 2 - ri ** 2)


def test_mesh_reads_back(tmp_path):
    """meshio 5.3 cannot read the deck (SPRING1 is not one of its types): the project's reader does."""
    model, mesh, path, _ = _deck(tmp_path)
    inp = read_inp_mesh(path)
    nt = model.mesh.n_theta
    # skirt + reference node + table ring + stop ring (2 x 2 x n_theta nodes each)
    assert inp.node_ids.size == mesh.n_nodes + 1 + 2 * 4 * nt
    assert np.array_equal(inp.node_ids, np.arange(1, inp.node_ids.size + 1))
    np.testing.assert_allclose(inp.nodes[:mesh.n_nodes], mesh.nodes, atol=1e-12)
    np.testing.assert_allclose(inp.nodes[mesh.n_nodes], [0.0, 0.0, model.geometry.height])
    ids, conn = inp.elements["C3D8I"]
    assert np.array_equal(ids, np.arange(1, mesh.hexes.shape[0] + 1))
    assert np.array_equal(conn, mesh.hexes + 1)
    assert inp.elements["C3D8"][0].size == 2 * nt
    assert inp.elements["SPRING1"][0].size == mesh.table.nodes.size


def test_title_cannot_inject_cards(tmp_path):
    title = "JAR\n*NODE\n999, 0, 0, 0"
    model, mesh, path, text = _deck(tmp_path, [f"title={title}"])
    plain = read_inp_mesh(_deck(tmp_path / "plain")[2])
    for p in [path] + render_all(model, tmp_path / "ccx", ["calculix"]):
        inp = read_inp_mesh(p)
        assert 999 not in inp.node_ids
        lines = p.read_text().splitlines()
        assert sum(1 for ln in lines if re.match(r"\*NODE\s*(,|$)", ln, re.I)) == 1, p.name
        assert "JAR _NODE 999, 0, 0, 0" in lines
    assert read_inp_mesh(path).node_ids.size == plain.node_ids.size


def test_slave_surfaces_carry_tributary_areas(tmp_path):
    model, mesh, _, text = _deck(tmp_path, ["contact.stop.side=outer"])
    g = model.geometry
    table = [ln.split(",") for ln in _block(text, "*SURFACE, TYPE=NODE, NAME=SLAVE_TABLE")]
    assert [int(n) for n, _ in table] == list(mesh.table.nodes + 1)
    area = sum(float(a) for _, a in table)
    assert area == pytest.approx(_poly_annulus(16, g.radius + g.thickness / 2, g.radius - g.thickness / 2),
                                 rel=1e-12)
    stop = [ln.split(",") for ln in _block(text, "*SURFACE, TYPE=NODE, NAME=SLAVE_STOP")]
    r_out = g.radius + g.thickness / 2
    lower_half_faces = 16 * 2 * r_out * np.sin(np.pi / 16) * (g.height / 4) / 2
    assert sum(float(a) for _, a in stop) == pytest.approx(lower_half_faces, rel=1e-12)


def test_master_faces_are_the_table_plane_and_the_stop_cylinder(tmp_path):
    model, mesh, path, text = _deck(tmp_path, ["contact.stop.radius=1.485"])
    inp = read_inp_mesh(path)
    xyz = dict(zip(inp.node_ids, inp.nodes))
    conn = dict(zip(*inp.elements["C3D8"]))
    faces = {"S2": [4, 5, 6, 7], "S4": [1, 5, 6, 2]}   # 0-based corners of C3D8 faces 5-8-7-6, 2-6-7-3

    def corners(name):
        out = []
        for ln in _block(text, f"*SURFACE, TYPE=ELEMENT, NAME={name}"):
            e, label = (v.strip() for v in ln.split(","))
            out.append(np.array([xyz[conn[int(e)][i]] for i in faces[label]]))
        return np.array(out)

    table = corners("MASTER_TABLE")
    np.testing.assert_allclose(table[:, :, 2], 0.0, atol=1e-15)                      # table plane z = 0
    r = np.hypot(table[..., 0], table[..., 1])
    g = model.geometry
    assert r.min() < g.radius - g.thickness / 2 and r.max() > g.radius + g.thickness / 2  # overhangs the wall
    stop = corners("MASTER_STOP")
    # faces centred on the skirt azimuths: corners at 1.485 / cos(pi / n_theta), every face plane 1.485 from
    # the axis along its mid-azimuth (the stop slaves' radial), so each slave sees a radial normal
    n = model.mesh.n_theta
    np.testing.assert_allclose(np.hypot(stop[..., 0], stop[..., 1]), 1.485 / np.cos(np.pi / n), rtol=1e-12)
    mid = stop.mean(axis=1)
    e_r = mid[:, :2] / np.hypot(mid[:, 0], mid[:, 1])[:, None]
    np.testing.assert_allclose(np.einsum("fkc,fc->fk", stop[..., :2], e_r), 1.485, rtol=1e-12)
    th = np.degrees(np.arctan2(e_r[:, 1], e_r[:, 0])) % 360.0
    assert set(np.round(th, 6) % 360.0) <= set(np.round(np.unique(mesh.stop.theta_deg), 6) % 360.0)
    h1 = g.height / 4
    assert stop[..., 2].min() == pytest.approx(-h1 / 2) and stop[..., 2].max() == pytest.approx(h1 / 2)
    # every slave node lies on its master: base nodes at z = 0 inside the ring, stop slaves at 1.485 + clearance
    np.testing.assert_allclose(mesh.stop.r - mesh.stop.clearance, 1.485, rtol=1e-12)


def test_lagrange_contact_cards(tmp_path):
    _, _, _, text = _deck(tmp_path, ["contact.friction=0.3"])
    pairs = re.findall(r"\*CONTACT PAIR, INTERACTION=(\w+), TYPE=NODE TO SURFACE\n(\w+), (\w+)", text)
    assert pairs == [("INTER_TABLE", "SLAVE_TABLE", "MASTER_TABLE"), ("INTER_STOP", "SLAVE_STOP", "MASTER_STOP")]
    assert text.count("*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=HARD, DIRECT\n") == 2
    # friction at the table only: the radial stop is frictionless (issue 21 item 6)
    assert re.findall(r"\*FRICTION(, LAGRANGE)?\n(\S+)", text) == [(", LAGRANGE", "3.000000000000e-01"),
                                                                     ("", "0.000000000000e+00")]
    assert text.count("*CONTACT PRINT, SLAVE=") == 4          # two pairs, two steps
    assert "CSTRESS, CDISP" in text


def test_load_introduction_and_springs(tmp_path):
    model, mesh, _, text = _deck(tmp_path)
    assert "*DISTRIBUTING, WEIGHTING METHOD=UNIFORM\n1, 6" in text and "*KINEMATIC" not in text
    _, _, _, kin = _deck(tmp_path, ["load_introduction=kinematic"])
    assert "*KINEMATIC\n1, 6" in kin and "*DISTRIBUTING" not in kin
    # circumferential springs: every table node once, stiffness per node = mesh.k_tangent
    k_of = {}
    for elems, k in re.findall(r"\*ELEMENT, TYPE=SPRING1, ELSET=\w+\n([\d,\s]+?)\n\*SPRING, ELSET=\w+, "
                               r"ORIENTATION=OCYL\n2\n(\S+)", text):
        for ln in elems.splitlines():
            k_of[int(ln.split(",")[1])] = float(k)
    assert sorted(k_of) == list(mesh.table.nodes + 1)
    np.testing.assert_allclose([k_of[n + 1] for n in mesh.table.nodes], mesh.k_tangent, rtol=1e-12)


def test_steps_repeat_N_and_ramp_T_M_with_automatic_increments(tmp_path):
    model, mesh, _, text = _deck(tmp_path, ["loads.azimuth=120", "steps.increments=5", "steps.lambda_max=2"])
    steps = text.split("*STEP")[1:]
    assert len(steps) == 2 and all("NLGEOM=NO" in s for s in steps)
    ref = mesh.n_nodes + 1
    loads = [{int(d): float(v) for n, d, v in (ln.split(",") for ln in _block("*" + s, "*CLOAD")) if int(n) == ref}
             for s in steps]
    v = model.load_vectors()
    assert loads[0] == pytest.approx({3: -model.loads.N})
    assert loads[1] == pytest.approx({1: 2 * v["T_force"][0], 2: 2 * v["T_force"][1], 3: -model.loads.N,
                                      4: 2 * v["M_moment"][0], 5: 2 * v["M_moment"][1]})
    inc = [float(x) for x in _block("*" + steps[1], "*STATIC")[0].split(",")]
    assert inc == pytest.approx([0.2, 1.0, 2e-6, 0.2])        # initial, period, minimum, maximum increment
    assert "DIRECT\n" not in text.split("*STEP")[1] and "*STATIC, DIRECT" not in text
    points = [float(x) for x in _block(text, "*TIME POINTS, NAME=TP2")]
    assert points == pytest.approx([0.2, 0.4, 0.6, 0.8, 1.0])    # lambda_j / lambda_max
    assert text.count("*OUTPUT, FIELD, TIME POINTS=TP2") == 1 and text.count("INC=1000") == 2


def test_nlgeom_inc_and_base_stress_request(tmp_path):
    """NLGEOM=YES|NO from analysis.nlgeom; INC above the step's increments; *EL PRINT S on EBASE = the
    bottom element row (ids 1..n_theta n_r) in both steps."""
    model, mesh, _, text = _deck(tmp_path / "a", ["analysis.nlgeom=true", "steps.increments=1500"])
    assert text.count("NLGEOM=YES, INC=15000") == 2 and "NLGEOM=NO" not in text
    ebase = [int(v) for ln in _block(text, "*ELSET, ELSET=EBASE") for v in ln.split(",")]
    assert ebase == list(range(1, mesh.n_theta * mesh.n_r + 1))
    assert text.count("*EL PRINT, ELSET=EBASE, FREQUENCY=1\nS\n") == 2


def test_registered_with_the_calculix_decks(tmp_path):
    model = load(None, SMALL)
    written = render_all(model, tmp_path, ["abaqus", "calculix"])
    assert sorted(p.name for p in written) == ["JAR_ccx_f2f.inp", "JAR_ccx_lagrange.inp", "JAR_ccx_penalty.inp",
                                               "JAR_lagrange.inp"]
    assert all(p.is_file() for p in written)


def test_mm_deck_scales_coordinates_modulus_areas_loads_and_springs(tmp_path):
    """units: mm -> N, mm, MPa: coordinates x 1e3, E x 1e-6, areas x 1e6, forces x 1, moments x 1e3,
    spring stiffness x 1e-3 (N/mm), against the SI deck of the same model."""
    _, mesh, _, si = _deck(tmp_path / "si")
    _, _, _, mm = _deck(tmp_path / "mm", ["units=mm"])
    assert "** deckbridge-units: mm" in mm and "N, mm, MPa" in mm

    def first(text, header, col):
        return float(_block(text, header)[0].split(",")[col])

    assert first(mm, "*NODE", 1) == pytest.approx(1e3 * first(si, "*NODE", 1), rel=1e-12)
    assert first(mm, "*ELASTIC", 0) == pytest.approx(1e-6 * first(si, "*ELASTIC", 0), rel=1e-12)
    assert first(mm, "*SURFACE, TYPE=NODE, NAME=SLAVE_TABLE", 1) == pytest.approx(
        1e6 * first(si, "*SURFACE, TYPE=NODE, NAME=SLAVE_TABLE", 1), rel=1e-12)
    assert float(_block(mm, "*SPRING, ELSET=KTAN1")[1]) == pytest.approx(1e-3 * float(_block(si, "*SPRING, ELSET=KTAN1")[1]))
    step2 = lambda t: {ln.split(",")[1].strip(): float(ln.split(",")[2]) for ln in _block(t.split("*STEP")[2], "*CLOAD")}  # noqa: E731
    a, b = step2(si), step2(mm)
    assert b["3"] == pytest.approx(a["3"]) and b["4"] == pytest.approx(1e3 * a["4"]) and b["5"] == pytest.approx(1e3 * a["5"])
