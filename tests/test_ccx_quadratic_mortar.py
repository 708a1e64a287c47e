"""CalculiX mortar deck on quadratic skirts (issue 23, deckbridge/deck_elements.py): ccx 2.20 runs the C3D20R /
C3D20 / C3D10 / C3D15 deck and its face-weighted (mortar) contact carries uniform compression without opening a
corner node, and with the default moment it runs to lambda 1 (its circumferential springs on the corner nodes:
`corner_spring_k`). The truths here are the closed form sigma_N = -N / (2 pi R t) (a thin ring in uniform
compression), the force balance, and the reference solver's face-weighted Lagrange on the same mesh.

Through-wall sigma_N per azimuth = sum F / sum a over the azimuth's table nodes, F the consistent node force
(ccx: RF_z of the slave node; reference: ``Solution.force`` = D^T lambda) and a = int N_i dA (the consistent
share, the same for both), so a pressure constant through the wall is read exactly on 8- and 6-node faces."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import reference_solver as rs
from ccx_job import ccx_job
from deckbridge.model import load
from deckbridge.dialects.calculix.result_files import _dat_blocks, _frd_blocks
from deckbridge.numbering.skirt import mesh_node_ids
from reference_solver.elements import element_type
from reference_solver.face_weights import face_shares, surface_faces

TOL = 0.02                      # of the reference's peak |sigma_N| (issue 23)
SMALL_STRAIN = 0.01             # lift / (R + t/2)
MOMENT_MESH = ["mesh.n_theta=24", "mesh.n_z=3", "mesh.n_r=1", "contact.stop.side=none", "steps.increments=5"]


@pytest.mark.parametrize("element", ["hex20r", "tet10", "wedge15"])
def test_mortar_deck_uniform_compression(tmp_path, element):
    m = load(None, [f"mesh.element={element}", "mesh.n_theta=24", "mesh.n_z=3", "mesh.n_r=1",
                    "contact.stop.side=none", "loads.M=0", "loads.T=0", "steps.increments=1"])
    inp = ccx_job(m, tmp_path, "lagrange")
    assert f"TYPE={element.upper().replace('HEX', 'C3D').replace('TET', 'C3D').replace('WEDGE', 'C3D')}" \
        in inp.read_text()
    _, blocks = _frd_blocks(inp.with_suffix(".frd"))
    contact = next(b for b in blocks if b["name"] == "CONTACT" and b["step"] == 1)
    cpress = np.array([v[3] for v in contact["values"].values()])
    exact = m.loads.N / (2 * math.pi * m.geometry.radius * m.geometry.thickness)
    assert cpress.size == build_table_size(m)                   # every table node, corners included, pressed
    assert np.abs(cpress / exact - 1).max() < 5e-3
    forces = next(b for b in _dat_blocks(inp.with_suffix(".dat")) if b["kind"] == "forces" and b["time"] == 1.0)
    rz = sum(v[2] for v in forces["values"].values())
    assert rz == pytest.approx(m.loads.N, rel=1e-6)


def build_table_size(model) -> int:
    from deckbridge.mesh import build_mesh
    return int(build_mesh(model).table.nodes.size)


_RUNS: dict = {}


def moment_run(element: str, folder) -> dict:
    """ccx mortar and the reference Lagrange on one 24 x 3 x 1 ``element`` skirt under the default loads (N, then
    T and M to lambda 1 in 5 increments), once per module: per state (lambda, lift / (R + t/2) of the reference,
    reference peak |sigma_N| [Pa], through-wall sigma_N per azimuth [Pa] of both, ccx sum RF_z [N])."""
    if element in _RUNS:
        return _RUNS[element]
    from deckbridge.solve import condense_model, solve_system
    model = load(None, [f"mesh.element={element}"] + MOMENT_MESH)
    inp = ccx_job(model, folder, "lagrange")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")              # the quadratic-mesh 'unverified' warning
        mesh, system = condense_model(model)
        _, _, sol = solve_system(model, mesh, system, "lagrange")
    p = system.problem
    tab = p.contact_surface == "table"
    nodes = p.contact_nodes[tab]
    on = np.zeros(mesh.n_nodes, bool)
    on[nodes] = True
    share = np.zeros(mesh.n_nodes)
    for ftype, conn in surface_faces((rs.ElementBlock(element_type(mesh.element), mesh.hexes),), on):
        np.add.at(share, conn.ravel(), face_shares(ftype, mesh.nodes[conn]).ravel())
    theta = np.round(np.degrees(np.arctan2(mesh.nodes[nodes, 1], mesh.nodes[nodes, 0])) % 360.0, 6)
    _, column = np.unique(theta, return_inverse=True)
    area = np.bincount(column, share[nodes])
    ids = mesh_node_ids(mesh, nodes)
    printed = [b for b in _dat_blocks(inp.with_suffix(".dat")) if b["kind"] == "forces" and b["set"] == "NTABLE"]
    radius = model.geometry.radius + model.geometry.thickness / 2
    states = []
    for n, b in enumerate(printed):
        step, lam = (1, 0.0) if n == 0 else (2, round((b["time"] - 1.0) * model.steps.lambda_max, 9))
        k = [i for i in range(sol.load_factor.size) if sol.step[i] == step and abs(sol.load_factor[i] - lam) < 1e-9]
        fc = np.array([b["values"][int(i)][2] for i in ids])     # RF_z: the table's push, > 0 compressive
        fr = sol.force[k[-1], tab]
        states.append({"lam": lam, "lift": max(float(sol.gap[k[-1], tab].max()), 0.0) / radius,
                       "closed": bool(sol.closed[k[-1], tab].all()),
                       "peak": float(np.abs(sol.sigma_n[k[-1], tab]).max()), "rz": float(fc.sum()),
                       "ref": -np.bincount(column, fr) / area, "ccx": -np.bincount(column, fc) / area})
    _RUNS[element] = {"model": model, "states": states}
    return _RUNS[element]


def _errors(run, opened: bool) -> list[tuple[float, float]]:
    """(lambda, max |d sigma_N through the wall| / reference peak) at the small-strain states, full contact
    (every reference table node closed) or past liftoff (some open, lift / R <= 0.01)."""
    out = []
    for s in run["states"]:
        if s["lift"] <= SMALL_STRAIN and s["closed"] != opened:
            out.append((s["lam"], float(np.abs(s["ref"] - s["ccx"]).max() / s["peak"])))
    return out


@pytest.mark.parametrize("element", ["hex20r", "hex20", "tet10"])
def test_mortar_deck_with_the_moment_runs_to_lambda_1(tmp_path_factory, element):
    """With the default moment ccx's mortar runs to lambda 1 (before: residual stuck on the mid-side springs,
    too many cutbacks); the table carries N at every state; under N alone the through-wall sigma_N is the thin
    ring's -N / (2 pi R t) at every azimuth (measured: within 0.11 % on hex20r, hex20, tet10)."""
    run = moment_run(element, tmp_path_factory.mktemp(element))
    m = run["model"]
    assert [s["lam"] for s in run["states"]] == pytest.approx([0.0, 0.2, 0.4, 0.6, 0.8, 1.0])
    for s in run["states"]:
        assert s["rz"] == pytest.approx(m.loads.N, rel=1e-6)
    exact = -m.loads.N / (2 * math.pi * m.geometry.radius * m.geometry.thickness)
    assert np.abs(run["states"][0]["ccx"] / exact - 1).max() < 5e-3


@pytest.mark.parametrize("element", [
    "hex20", "tet10",
    pytest.param("hex20r", marks=pytest.mark.xfail(strict=True, reason=(
        "one-element-thick C3D20R: the reference's through-wall sigma_N alternates between corner and mid-side "
        "azimuths already under N alone (a checkerboard of the reduced-integration element on long cells, "
        "docs/elements.md); measured with the hat basis and hat areas: 2.21 % of the peak at lambda 0, 2.10 % "
        "at 0.4")))])
def test_mortar_deck_matches_the_reference_lagrange_in_full_contact(tmp_path_factory, element):
    """Through-wall sigma_N of ccx mortar within 2 % of the reference Lagrange's peak at every state of full
    contact (measured on 24 x 3 x 1, hat basis and areas: hex20 <= 1.41 %, tet10 <= 0.86 %; before them tet10 with the reference's springs moved
    to the corners as in the deck: 0.013 % to lambda 0.5, so the rest is the spring relocation)."""
    run = moment_run(element, tmp_path_factory.mktemp(element))
    errors = _errors(run, opened=False)
    assert len(errors) >= 3                               # lambda 0 .. 0.4 (0.6: onset)
    assert max(e for _, e in errors) <= TOL, errors


@pytest.mark.parametrize("element", ["hex20r", "hex20", "tet10"])
@pytest.mark.xfail(strict=True, reason=(
    "past liftoff at lambda 0.8 (lift/R <= 0.01) ccx mortar vs the reference face-weighted Lagrange through the "
    "wall: 7.5 % (hex20), 7.7 % (tet10), 9.9 % (hex20r) of the reference peak on 24 x 3 x 1, all of it in the two "
    "contact-edge cells (elsewhere <= 0.9 %; at lambda 0.6 <= 2.1 %); ccx's edge forces are not of the form "
    "D^T lambda, lambda >= 0 (open-gap tension up to 42 % of the peak when projected), while the reference "
    "agrees with a fine hex8i skirt (tests/test_face_weighted_liftoff.py)"))
def test_mortar_deck_matches_the_reference_lagrange_past_liftoff(tmp_path_factory, element):
    run = moment_run(element, tmp_path_factory.mktemp(element))
    errors = _errors(run, opened=True)
    assert errors, "no small-strain state past liftoff"
    assert max(e for _, e in errors) <= TOL, errors


# --- face-to-face penalty deck (<name>_ccx_f2f.inp) on quadratic faces -------------------------------------------
def _cpress(frd, ids) -> list[tuple[int, float, np.ndarray]]:
    """(step, time, CPRESS [Pa] at the table nodes ``ids``, 0 where ccx printed none) per .frd CONTACT block."""
    _, blocks = _frd_blocks(frd)
    return [(b["step"], b["time"], np.array([b["values"].get(int(i), np.zeros(4))[3] for i in ids]))
            for b in blocks if b["name"] == "CONTACT"]


@pytest.mark.parametrize("element", ["hex20r", "tet10"])
def test_f2f_deck_uniform_compression(tmp_path, element):
    """Under N alone the face-to-face deck's base settles p / K (p = N / (2 pi R t), K its LINEAR slope) and its
    pressure is p at every table node, corners included, to 0.5 % (measured: settlement 1 - 6e-8 (hex20r) and
    1 + 8e-6 (tet10) of p / K; a matching C3D20 master instead of the ring gave 2.07 p / K)."""
    from deckbridge.mesh import build_mesh
    m = load(None, [f"mesh.element={element}", "mesh.n_theta=24", "mesh.n_z=3", "mesh.n_r=1",
                    "contact.stop.side=none", "loads.M=0", "loads.T=0", "steps.increments=1"])
    inp = ccx_job(m, tmp_path, "f2f")
    text = inp.read_text()
    behaviour = "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n"
    assert text.count(behaviour) == 1                   # one slope: the model's k_c / A is the same on every node
    slope = float(text.split(behaviour)[1].split(",")[0])
    mesh = build_mesh(m)
    assert slope == pytest.approx(float(np.mean(mesh.table.k / mesh.table.area)), rel=1e-9)
    ids = mesh_node_ids(mesh, mesh.table.nodes)
    p = m.loads.N / (2 * math.pi * m.geometry.radius * m.geometry.thickness)
    dat = _dat_blocks(inp.with_suffix(".dat"))
    u = next(b for b in dat if b["kind"] == "displacements" and b["set"] == "NTABLE" and b["time"] == 1.0)
    uz = np.array([u["values"][int(i)][2] for i in ids])
    assert np.abs(uz / (-p / slope) - 1).max() < 1e-3
    _, _, cpress = _cpress(inp.with_suffix(".frd"), ids)[0]
    assert np.abs(cpress / p - 1).max() < 5e-3
    rf = next(b for b in dat if b["kind"] == "forces" and b["set"] == "NMTOP" and b["time"] == 1.0)
    assert sum(v[2] for v in rf["values"].values()) == pytest.approx(m.loads.N, rel=1e-6)


def test_f2f_deck_with_the_moment_matches_the_reference_lagrange_in_full_contact(tmp_path):
    """tet10 24 x 3 x 1, default loads: the face-to-face deck runs to lambda 1 and its through-wall sigma_N (CPRESS
    made consistent node forces with the face matrices int N_i N_j dA) is within 2 % of the reference Lagrange's
    peak at every state of full contact (measured <= 0.31 %; 0.53 % at lambda 0.6, onset). The reference's own
    penalty on quadratic faces is not there yet (solve refuses it), so this is the penalty deck against the
    Lagrange path it tends to: alpha 0.1 is stiff enough here."""
    from deckbridge.solve import condense_model, solve_system
    from reference_solver.face_weights import face_mass
    model = load(None, ["mesh.element=tet10"] + MOMENT_MESH)
    inp = ccx_job(model, tmp_path, "f2f")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mesh, system = condense_model(model)
        _, _, sol = solve_system(model, mesh, system, "lagrange")
    p = system.problem
    tab = p.contact_surface == "table"
    nodes = p.contact_nodes[tab]
    on = np.zeros(mesh.n_nodes, bool)
    on[nodes] = True
    faces = surface_faces((rs.ElementBlock(element_type(mesh.element), mesh.hexes),), on)
    share = np.zeros(mesh.n_nodes)
    for ftype, conn in faces:
        np.add.at(share, conn.ravel(), face_shares(ftype, mesh.nodes[conn]).ravel())
    theta = np.round(np.degrees(np.arctan2(mesh.nodes[nodes, 1], mesh.nodes[nodes, 0])) % 360.0, 6)
    _, column = np.unique(theta, return_inverse=True)
    area = np.bincount(column, share[nodes])
    states = _cpress(inp.with_suffix(".frd"), mesh_node_ids(mesh, nodes))
    assert [round(t, 9) for _, t, _ in states] == [1.0, 1.2, 1.4, 1.6, 1.8, 2.0]     # ran to lambda 1
    compared = 0
    for step, time, cpress in states:
        lam = 0.0 if step == 1 else round(time - 1.0, 9)
        k = [i for i in range(sol.load_factor.size) if sol.step[i] == step and abs(sol.load_factor[i] - lam) < 1e-9][-1]
        if not sol.closed[k, tab].all():
            continue
        field = np.zeros(mesh.n_nodes)
        field[nodes] = cpress
        force = np.zeros(mesh.n_nodes)
        for ftype, conn in faces:
            consistent = np.einsum("fab,fb->fa", face_mass(ftype, mesh.nodes[conn]), field[conn])
            np.add.at(force, conn.ravel(), consistent.ravel())
        assert force[nodes].sum() == pytest.approx(model.loads.N, rel=1e-3)
        d = np.bincount(column, force[nodes]) / area - np.bincount(column, sol.force[k, tab]) / area
        assert np.abs(d).max() <= TOL * np.abs(sol.sigma_n[k, tab]).max(), lam
        compared += 1
    assert compared >= 3
