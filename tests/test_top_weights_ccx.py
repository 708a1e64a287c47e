"""The distributing top on 8-/6-node faces (issue 23): ccx 2.20's ``*COUPLING, *DISTRIBUTING`` over a surface of
quadratic faces spreads a force and a moment at its reference node exactly as the reference solver's distributing
coupling (:func:`reference_solver.distributing_forces`: weighted centroid, weighted second moment) with the weights
:func:`deckbridge.mesh_order.top_weights` (the consistent shares int N_a dA: negative at quad8 corners), so the
reference loads a quadratic top as the decks do. The truth is ccx itself: one block, base held, loaded once through
the coupling and once by ``*CLOAD`` of the reference's nodal forces; the displacements must be the same.
"""

from __future__ import annotations

import numpy as np
import pytest

import reference_solver as rs
from deckbridge.dialects import DIALECTS
from deckbridge.dialects.calculix.result_files import _dat_blocks
from deckbridge.face_areas import hrz_areas
from deckbridge.mesh_order import top_weights
from element_meshes import block_mesh
from reference_solver.elements import element_type
from reference_solver.face_weights import surface_faces

LOAD = np.array([1e5, -2e5, -3e6, 4e5, -6e5, 2.5e5])     # Fx, Fy, Fz [N], Mx, My, Mz [N m] at REF
REF = np.array([0.7, 0.3, 1.6])                          # 0.4 m above the top, off its centroid [m]


def _block(name):
    """A graded, plan-sheared 2 x 2 x 2 block (1 x 0.8 x 1.2 m) whose top mid-side nodes are moved in plane by up
    to 4 cm (curved top edges, a flat top), its top faces (ccx element, face number) and the reference's faces."""
    et = element_type(name)
    nodes, cells = block_mesh(name, nx=2, ny=2, nz=2, L=(1.0, 0.8, 1.2), shear=0.3, grade=True)
    on_top = nodes[:, 2] > 1.2 - 1e-12
    mids = np.setdiff1d(np.flatnonzero(on_top), cells[:, :{20: 8, 10: 4}[et.n_nodes]])
    nodes[mids, :2] += 0.04 * np.random.default_rng(1).uniform(-1, 1, (mids.size, 2))
    ccx_faces = [(e, f + 1) for e, c in enumerate(cells) for f, loc in enumerate(et.faces) if on_top[c[list(loc)]].all()]
    return nodes, cells, ccx_faces, tuple(surface_faces((rs.ElementBlock(et, cells),), on_top))


def _ccx_u(folder, job, name, nodes, cells, ccx_faces, cloads):
    """Displacements (n, 3) [m] of the block (base held in x, y, z) under ``cloads`` [(node, dof, value)], with the
    top coupled to the reference node when ``ccx_faces`` is given."""
    n, ref = len(nodes), len(nodes) + 1
    lines = ["*NODE"] + [f"{i + 1}, {x:.12e}, {y:.12e}, {z:.12e}" for i, (x, y, z) in enumerate(nodes)]
    lines += [f"{ref}, {REF[0]:.12e}, {REF[1]:.12e}, {REF[2]:.12e}", f"*ELEMENT, TYPE={name.upper()}, ELSET=EALL"]
    for e, c in enumerate(cells):
        ids = [str(i + 1) for i in c]
        lines += [f"{e + 1}, " + ", ".join(ids[:15]) + ("," if len(ids) > 15 else "")] + \
                 ([", ".join(ids[15:])] if len(ids) > 15 else [])
    lines += ["*NSET, NSET=NBASE"] + [f"{i + 1}," for i in np.flatnonzero(nodes[:, 2] < 1e-12)]
    lines += ["*NSET, NSET=NALL, GENERATE", f"1, {n}", "*MATERIAL, NAME=M", "*ELASTIC", "70e9, 0.3",
              "*SOLID SECTION, ELSET=EALL, MATERIAL=M", "*BOUNDARY", "NBASE, 1, 3"]
    if ccx_faces:
        lines += ["*SURFACE, NAME=TOP, TYPE=ELEMENT"] + [f"{e + 1}, S{f}" for e, f in ccx_faces]
        lines += [f"*COUPLING, REF NODE={ref}, SURFACE=TOP, CONSTRAINT NAME=C1", "*DISTRIBUTING", "1, 6"]
    lines += ["*STEP", "*STATIC", "*CLOAD"] + [f"{node}, {dof}, {v:.12e}" for node, dof, v in cloads]
    lines += ["*NODE PRINT, NSET=NALL", "U", "*END STEP"]
    inp = folder / f"{job}.inp"
    inp.write_text("\n".join(lines) + "\n")
    DIALECTS["calculix"].run(inp, timeout_s=60)
    u = next(b for b in _dat_blocks(inp.with_suffix(".dat")) if b["kind"] == "displacements")["values"]
    return np.array([u[i + 1] for i in range(n)])


@pytest.mark.parametrize("name", ["c3d20", "c3d10"])
def test_ccx_distributing_coupling_spreads_force_and_moment_by_the_top_weights(tmp_path, name):
    """Force and moment together (the moment about a point 0.4 m above the top, off its centroid): ccx's coupling
    and ``*CLOAD`` of distributing_forces(top_weights) give the same displacements to the printed digits (1e-6 of
    the largest; measured equal); with the HRZ areas instead 13 % (c3d20) / 6.6 % (c3d10) apart. On these curved
    edges the tri6 weights need ccx's 3-point rule: the 6-point one is 0.19 % off."""
    nodes, cells, ccx_faces, faces = _block(name)
    coupled = _ccx_u(tmp_path, "coupled", name, nodes, cells, ccx_faces,
                     [(len(nodes) + 1, k + 1, LOAD[k]) for k in range(6)])
    scale = np.abs(coupled).max()

    def cload_u(job, weights_of):
        top, w = weights_of(faces, nodes)
        f = rs.distributing_forces(nodes[top], w, REF, LOAD[:3], LOAD[3:])
        return _ccx_u(tmp_path, job, name, nodes, cells, None,
                      [(int(t) + 1, k + 1, f[i, k]) for i, t in enumerate(top) for k in range(3)])

    top, w = top_weights(faces, nodes)
    assert w.sum() == pytest.approx(hrz_areas(faces, nodes)[1].sum(), rel=1e-12)    # the top's area
    if name == "c3d20":
        assert w.min() < -0.05 * w.max()                          # quad8 corners: about -1/12 of the face
    assert np.abs(cload_u("shares", top_weights) - coupled).max() <= 1e-6 * scale
    assert np.abs(cload_u("hrz", hrz_areas) - coupled).max() >= 0.05 * scale


def test_problem_takes_top_weights_with_a_positive_sum():
    """``Problem`` takes the quad8 top's weights (negative corners; their sum the area) and its distributing forces
    are statically equivalent to the load at REF (force and moment to 1e-9); a non-positive sum is refused in one
    line naming the key."""
    nodes, cells, _, faces = _block("c3d20")
    top, w = top_weights(faces, nodes)
    base = np.flatnonzero(nodes[:, 2] < 1e-12)
    nb = base.size
    kw = dict(nodes=nodes, hexes=cells, element="c3d20", E=70e9, nu=0.3, contact_nodes=base,
              contact_normals=np.tile([0, 0, 1.0], (nb, 1)), contact_area=np.ones(nb), contact_k=np.ones(nb),
              contact_clearance=np.zeros(nb), contact_surface=["table"] * nb, spring_nodes=[],
              spring_dirs=np.zeros((0, 3)), spring_k=[], ref_point=REF, coupling_nodes=top, loads={"L": LOAD})
    p = rs.Problem(coupling_weights=w, **kw)
    f = rs.distributing_forces(nodes[top], p.coupling_weights, REF, LOAD[:3], LOAD[3:])
    np.testing.assert_allclose(f.sum(axis=0), LOAD[:3], rtol=0, atol=1e-9 * np.abs(LOAD).max())
    np.testing.assert_allclose(np.cross(nodes[top] - REF, f).sum(axis=0), LOAD[3:], rtol=0,
                               atol=1e-9 * np.abs(LOAD).max())
    with pytest.raises(rs.ReferenceSolverError, match=r"^coupling_weights: must be finite with a positive sum"):
        rs.Problem(coupling_weights=-w, **kw)


@pytest.mark.parametrize("element", ["hex20", "tet10"])
def test_nastran_rbe3_carries_the_top_weights(tmp_path, element):
    """The surface-contact Nastran deck's RBE3 on a quadratic top: pyNastran reads back WTi = top_weights node by node
    (deck units m^2, 16-character fields: to 1e-9 of the largest), negative at the quad8 corners, with the deck
    comment saying so (the QRGs type WTi as Real, no sign bound; nastran_cards.RBE3_CONSISTENT)."""
    from pyNastran.bdf.bdf import read_bdf

    from deckbridge.mesh import build_mesh
    from deckbridge.model import load
    from deckbridge.numbering.skirt import mesh_node_ids
    from deckbridge.render.nastran_cards import RBE3_CONSISTENT
    model = load(None, [f"mesh.element={element}", "mesh.n_theta=8", "mesh.n_z=1", "mesh.n_r=1",
                        "contact.stop.side=none"])
    mesh = build_mesh(model)
    (path,) = DIALECTS["nastran_surface"].write(model, mesh, tmp_path)
    assert "\n".join("$" + ln for ln in RBE3_CONSISTENT.splitlines()) in path.read_text()
    (rbe,) = read_bdf(str(path), xref=True, debug=None).rigid_elements.values()
    got = {nid: w for w, ids in zip(rbe.weights, rbe.Gijs) for nid in ids}
    want = dict(zip(mesh_node_ids(mesh, mesh.top_nodes).tolist(), mesh.top_weights))
    assert sorted(got) == sorted(want)
    np.testing.assert_allclose([got[n] for n in want], list(want.values()), rtol=0,
                               atol=1e-9 * mesh.top_weights.max())
    assert (min(got.values()) < -0.2 * max(got.values())) == (element == "hex20")
