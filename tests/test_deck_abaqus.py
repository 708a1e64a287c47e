"""Abaqus-style Lagrange deck: mesh read back, contact cards, areas and loads against the model."""

import re

import numpy as np
import pytest

from deckbridge.errors import DeckUnsupported
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from reference_solver.elements import element_type
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
    assert sorted(p.name for p in written) == ["JAR_augmented.inp", "JAR_ccx_f2f.inp", "JAR_ccx_lagrange.inp",
                                               "JAR_ccx_penalty.inp", "JAR_lagrange.inp"]
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


# --- issue 24: the augmented-Lagrange deck; issue 23: surface to surface on 8-/6-node faces -----------------

NUM = re.compile(r"^[-+]?\d\.\d{12}e[-+]\d{2}$")


def _pairs(text):
    """{pair name: (slave surface data lines, *SURFACE BEHAVIOR line, its data line or None, pair type)}."""
    out = {}
    for m in re.finditer(r"\*SURFACE BEHAVIOR, (.*)\n(?:([^*].*)\n)?\*FRICTION.*\n.*\n\*CONTACT PAIR, "
                         r"INTERACTION=INTER_(\w+), TYPE=(.*)\n", text):
        behaviour, line, name, kind = m.groups()
        out[name] = (_block(text, f"*SURFACE, TYPE={'ELEMENT' if 'SURFACE TO' in kind else 'NODE'}, "
                                  f"NAME=SLAVE_{name}\n"[:-1]), behaviour, line, kind)
    return out


def _sans(text, words):
    """The deck's card lines without comments and without lines holding any of ``words``."""
    return [ln for ln in text.splitlines() if not ln.startswith("**") and not any(w in ln for w in words)]


@pytest.mark.parametrize("overrides", [[], ["contact.penalty.k_normal=2.5e8", "contact.stop.side=outer"],
                                       ["units=mm", "contact.penalty.alpha=10"]])
def test_augmented_deck_slope_is_each_nodes_k_c_over_its_area(tmp_path, overrides):
    """*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=HARD, AUGMENTED LAGRANGE with the data line K, 0, 1 (every field a
    number): K x (the area written on the node's line) = the model's k_c of that node (the reference solver's
    augmented epsilon at k-factor 1), in deck units; an explicit k_normal on unequal areas splits the slaves into
    pairs of equal K. Everything else is the Lagrange deck's."""
    model = load(None, SMALL + list(overrides))
    mesh = build_mesh(model)
    lag, aug = abaqus.write(model, mesh, tmp_path)
    assert (lag.name, aug.name) == ("JAR_lagrange.inp", "JAR_augmented.inp")
    text = aug.read_text()
    u = {"SI": (1.0, 1.0), "mm": (1e3, 1e-3)}[model.units]            # length, force / length factors
    k_of = {(ss.surface, int(n) + 1): k for ss in (mesh.table, mesh.stop) if ss is not None
            for n, k in zip(ss.nodes, ss.k)}
    pairs = _pairs(text)
    seen = []
    for name, (slave, behaviour, line, kind) in pairs.items():
        assert behaviour == "PRESSURE-OVERCLOSURE=HARD, AUGMENTED LAGRANGE" and kind == "NODE TO SURFACE"
        fields = [f.strip() for f in line.split(",")]
        assert len(fields) == 3 and all(NUM.match(f) for f in fields), line
        slope, clearance, factor = map(float, fields)
        assert (clearance, factor) == (0.0, 1.0)
        for ln in slave:
            key = ("stop" if name.startswith("STOP") else "table", int(ln.split(",")[0]))
            assert slope * float(ln.split(",")[1]) == pytest.approx(k_of[key] * u[1], rel=1e-11), (name, key)
            seen.append(key)
    assert sorted(seen) == sorted(k_of)                                  # every slave node once
    if "contact.penalty.k_normal=2.5e8" in overrides:
        assert len(pairs) > 2                                            # unequal areas: several groups
    else:
        assert sorted(pairs) == ["STOP", "TABLE"]
    if len(pairs) == 2:
        data = {p[2] for p in pairs.values()}
        assert [ln for ln in _sans(text, ("*SURFACE BEHAVIOR", "*CONTACT CONTROLS")) if ln not in data] == \
            _sans(lag.read_text(), ("*SURFACE BEHAVIOR",))
    assert "AUGMENTED" not in lag.read_text()


def test_augmented_deck_penetration_tolerance_in_every_step(tmp_path):
    """*CONTACT CONTROLS, MASTER=, SLAVE=, ABSOLUTE PENETRATION TOLERANCE=d per pair in both steps, d = 1e-4 x
    sigma_0 x h1 / E: computed here from the deck's own numbers (table areas, E, the first-row height from the
    node coordinates) with sigma_0 = max(N / A_table, lambda_max M_b / (pi R^2 t)) (the ring's bending stress of the
    base moment M_b = M + T H is the larger in the default model)."""
    model, mesh, _, _ = _deck(tmp_path)
    text = (tmp_path / "JAR_augmented.inp").read_text()
    controls = re.findall(r"\*CONTACT CONTROLS, MASTER=MASTER_(\w+), SLAVE=SLAVE_(\w+), ABSOLUTE PENETRATION "
                          r"TOLERANCE=(\S+)\n", text)
    assert [(m, s) for m, s, _ in controls] == [("TABLE", "TABLE"), ("STOP", "STOP")] * 2
    assert all(NUM.match(d) for _, _, d in controls)
    area = sum(float(ln.split(",")[1]) for ln in _block(text, "*SURFACE, TYPE=NODE, NAME=SLAVE_TABLE"))
    e_mod = float(_block(text, "*ELASTIC")[0].split(",")[0])
    z = sorted({round(float(ln.split(",")[3]), 9) for ln in _block(text, "*NODE")[:mesh.n_nodes]})
    g = model.geometry
    ring = model.steps.lambda_max * model.base_moment / (np.pi * g.radius ** 2 * g.thickness)
    assert ring > model.loads.N / area
    assert float(controls[0][2]) == pytest.approx(1e-4 * ring * z[1] / e_mod, rel=1e-11)
    # the stops of the steps are the Lagrange deck's: the controls sit between *STATIC's line and the loads
    for step in text.split("*STEP")[1:]:
        assert re.search(r"\*STATIC\n.+\n(\*CONTACT CONTROLS.*\n){2}\*CLOAD\n", step)


@pytest.mark.parametrize("element", ["hex20r", "tet10", "wedge15"])
def test_quadratic_faces_get_a_surface_to_surface_pair(tmp_path, element):
    """On 8-/6-node faces: C3D20R / C3D10 / C3D15 cards (read back by the project's inp parser: the mesh's
    connectivity), the table pair TYPE=SURFACE TO SURFACE on element faces whose nodes are exactly the table's
    slave nodes, each face lying on z = 0 with its element above it; both decks (DIRECT, AUGMENTED LAGRANGE)."""
    model = load(None, SMALL + [f"mesh.element={element}", "contact.stop.side=none"])
    mesh = build_mesh(model)
    lag, aug = render_all(model, tmp_path, names=["abaqus"])
    et = element_type(mesh.element)
    ccx = {"c3d20r": "C3D20R", "c3d10": "C3D10", "c3d15": "C3D15"}[mesh.element]
    inp = read_inp_mesh(lag)
    ids, conn = inp.elements[ccx]
    assert np.array_equal(ids, np.arange(1, mesh.hexes.shape[0] + 1)) and np.array_equal(conn, mesh.hexes + 1)
    for path, how in ((lag, "DIRECT"), (aug, "AUGMENTED LAGRANGE")):
        text = path.read_text()
        ((slave, behaviour, line, kind),) = _pairs(text).values()
        assert kind == "SURFACE TO SURFACE" and behaviour == f"PRESSURE-OVERCLOSURE=HARD, {how}"
        assert (line is None) == (how == "DIRECT")
        covered = set()
        for ln in slave:
            e, label = (v.strip() for v in ln.split(","))
            cell = mesh.hexes[int(e) - 1]
            face = cell[list(et.faces[int(label[1:]) - 1])]
            np.testing.assert_allclose(mesh.nodes[face, 2], 0.0, atol=1e-12)
            assert mesh.nodes[cell, 2].mean() > 0.0
            covered |= set(face.tolist())
        assert covered == set(mesh.table.nodes.tolist())
        assert "TYPE=NODE" not in text and "NODE TO SURFACE" not in text


def test_quadratic_face_cards_equal_the_calculix_mortar_decks(tmp_path):
    """The skirt's C3D10 cards and the table's slave face labels are the CalculiX mortar deck's (ccx runs that
    deck: tests/test_ccx_quadratic_mortar.py): the same lines."""
    model = load(None, SMALL + ["mesh.element=tet10", "contact.stop.side=none"])
    (ccx,) = [p for p in render_all(model, tmp_path / "c", names=["calculix"]) if p.name.endswith("_ccx_lagrange.inp")]
    lag = render_all(model, tmp_path / "a", names=["abaqus"])[0]
    a, c = lag.read_text(), ccx.read_text()
    assert _block(a, "*ELEMENT, TYPE=C3D10, ELSET=ESKIRT") == _block(c, "*ELEMENT, TYPE=C3D10, ELSET=ESKIRT")
    assert _block(a, "*SURFACE, TYPE=ELEMENT, NAME=SLAVE_TABLE") == _block(c, "*SURFACE, NAME=SLAVE_TABLE")


def test_quadratic_faces_with_the_radial_stop_are_refused_in_one_line(tmp_path):
    model = load(None, SMALL + ["mesh.element=hex20"])
    with pytest.raises(DeckUnsupported, match=r"mesh.element = hex20: the radial stop's slaves are base nodes .*"
                                              r"contact.stop.side: none for the Abaqus surface-to-surface deck"):
        render_all(model, tmp_path, names=["abaqus"])
    assert not any(tmp_path.glob("*.inp"))


def test_dat_beside_the_augmented_deck_reads_as_augmented(tmp_path, small_model):
    from test_readers_misc import ABAQUS_DAT

    from deckbridge import readers
    mesh = build_mesh(small_model)
    for method in ("lagrange", "augmented"):
        folder = tmp_path / method
        folder.mkdir()
        deck = dict(zip(("lagrange", "augmented"), abaqus.write(small_model, mesh, folder)))[method]
        (folder / deck.with_suffix(".dat").name).write_text(ABAQUS_DAT)
        df = readers.read(deck.with_suffix(".dat"), model=small_model)
        assert set(df["method"]) == {method} and len(df) == 13


def _as_ccx_penalty(text: str) -> str:
    """The Abaqus deck's step 1 as a CalculiX 2.20 job: the Abaqus-only cards replaced (AUGMENTED LAGRANGE by
    ccx's face-to-face PRESSURE-OVERCLOSURE=LINEAR with the same K; *DISTRIBUTING without WEIGHTING METHOD;
    ENCASTRE by dofs 1-3; no *FRICTION / *CONTACT CONTROLS / *CONTACT PRINT / *OUTPUT; no Abaqus rotation line of
    the cylindrical *ORIENTATION) and ccx's contact print; the model's cards as written."""
    k = re.search(r"AUGMENTED LAGRANGE\n(\S+), ", text).group(1)
    s = re.sub(r"\*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=HARD, AUGMENTED LAGRANGE\n.*\n",
               f"*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n{k}, 1.0e+03\n", text)
    s = s.replace("*DISTRIBUTING, WEIGHTING METHOD=UNIFORM", "*DISTRIBUTING").replace("NMASTER, ENCASTRE", "NMASTER, 1, 3")
    s = re.sub(r"\*FRICTION\n\S+\n|\*CONTACT PRINT.*\n.*\n|\*CONTACT CONTROLS.*\n|\*TIME POINTS, NAME=TP1\n.*\n", "", s)
    s = re.sub(r"\*OUTPUT, FIELD.*\n\*NODE OUTPUT\n.*\n\*CONTACT OUTPUT\n.*\n", "*CONTACT PRINT\nCSTR\n", s)
    s = s.replace("*NODE PRINT, NSET=NMASTER, TOTALS=YES, SUMMARY=NO", "*NODE PRINT, NSET=NMASTER, TOTALS=YES")
    s = s.replace("1.0e+00\n1, 0.0e+00\n", "1.0e+00\n")
    return s[:s.index("*STEP, NAME=STEP2")]


@pytest.mark.parametrize("element", ["hex20r", "tet10", "wedge15"])
def test_quadratic_surface_to_surface_geometry_run_by_ccx_gives_N_over_A(tmp_path, element):
    """The augmented deck's model (skirt cards, slave faces, master ring, coupling) run by ccx 2.20 under N alone,
    its enforcement swapped for ccx's face-to-face penalty of the same K (_as_ccx_penalty): the contact pressure at
    every slave integration point is N / A_table (the base annulus, closed form 2 pi R t; measured within 2e-4),
    and the master ring carries N. Before the ring's outer edge was pushed out on quadratic skirts, a strip of
    the true-cylinder faces saw no master at 16 azimuths: the mean pressure came out 32 % high (tet10)."""
    from deckbridge.dialects import DIALECTS

    model = load(None, SMALL + [f"mesh.element={element}", "contact.stop.side=none"])
    aug = render_all(model, tmp_path / "decks", names=["abaqus"])[1]
    inp = tmp_path / "ccx" / "job.inp"
    inp.parent.mkdir()
    inp.write_text(_as_ccx_penalty(aug.read_text()))
    DIALECTS["calculix"].run(inp, timeout_s=300)
    dat = inp.with_suffix(".dat").read_text()
    press = [float(ln.split()[2]) for ln in dat.split("contact stress")[1].splitlines()[2:] if len(ln.split()) == 5]
    g = model.geometry
    p0 = model.loads.N / (2 * np.pi * g.radius * g.thickness)
    assert len(press) > 10 * model.mesh.n_theta
    assert np.abs(np.array(press) / p0 - 1).max() < 5e-4
    total = dat.split("total force (fx,fy,fz) for set NMASTER")[1].splitlines()[2].split()
    assert float(total[2]) == pytest.approx(model.loads.N, rel=1e-6)
