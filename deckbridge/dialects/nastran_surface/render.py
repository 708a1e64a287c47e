"""Simcenter Nastran surface-contact deck ``<name>_surface.bdf``: SOL 101 linear contact, two subcases.

Laid out after the real Simcenter (Femap 2020.1) SOL 101 contact model of ``../shared/data/nx_surface_contact``:
source and target regions are ``BSURFS`` (solid element id + three grids of the face) each with a
``BCRPARA`` (CRID, OFFSET 0.0, SURF and TYPE blank, as Femap writes it), one ``BCTSET`` pairs them, the case
control selects it with ``BCSET`` and asks ``BCRESULTS(TRACTION,FORCE,SEPDIS) = ALL``.

- Region 1 (source): the skirt's base faces (the table slaves' faces); region 2 (target): the top faces of the
  table, a clamped solid layer (one CHEXA under each base face, its own grids ``clearance`` below the base,
  one first-row height thick, SPC1 123456 on every grid). With a radial stop: region 3 (source) the skirt's
  stop-side wall faces of the first element row, region 4 (target) the faces of a clamped stop layer at the
  stop radius, one first-row height thick away from the skirt.
- ``BCTSET``: pairs (1, 2) and (3, 4); FRIC = ``contact.friction`` on the table with
  ``contact.tangential = friction`` (then no circumferential springs), else 0 and the circumferential CELAS2
  of the CGAP deck carry T; the stop is frictionless as in every other deck. MAXD = the largest clearance + one
  first-row height (deck units); MIND blank, as in the Femap deck.
- **No BCTPARM**: the penalty factors (PENN, PENT), their units (PENTYP) and the other parameters
  (CTOL, INIPENE, SHLTHK, ...) are named in pyNastran's parser, but their meaning, units and defaults could not
  be confirmed from Simcenter's documentation (not available here): nothing is written, Simcenter's defaults
  apply, and the header says so. The Femap deck writes ``BCTPARM 108 PENTYP 1 INIPENE 0``.
- No ``BCTADD`` (one BCTSET holds both pairs; pyNastran 1.4.1's ``add_bctadd`` drops its CSID).
- Quadratic skirts (hex20, hex20r, tet10, wedge15; issue 23): CHEXA (20 grids), CTETRA (10), CPENTA (15) in
  Nastran's grid order (:func:`nastran_order`); the table layer is one 20-node CHEXA (quad8 faces) or 15-node
  CPENTA (tri6 faces) under each base face, built on the face's own corner and mid-side positions
  (:func:`_extrude_quadratic`), so that the curved edges of source and target coincide; BSURFS name each face by
  three corner grids. The radial stop's source faces are the first row's 8-node wall faces (hex20, hex20r, wedge15);
  on tet10 skirts the stop is refused (:func:`deckbridge.deck_elements.element_problem`).
- Subcase 1: N; subcase 2: the totals N + lambda_max (T, M) (SOL 101 solves each subcase on its own).

Ids: skirt grids and CHEXAs as in the other Nastran-family decks (:mod:`deckbridge.numbering.nastran`), the
reference node and RBE there too; the layers' grids from ``node_offset + 1`` and CHEXAs from
``elem_offset + 1`` (the CGAP deck's gap slots, unused here); circumferential CELAS2 as in the CGAP deck.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pyNastran.bdf.field_writer_8 import print_card_8

from ...deck_elements import cell_types
from ...errors import DeckbridgeError
from ...importers.node_order import NASTRAN_TO_CCX
from ...mesh import SkirtMesh
from ...mesh_data import element_key
from ...model import Model
from ...numbering.nastran import clean_xyz, ground_distance, numbering
from ...numbering.skirt import elem_ids, max_elem_id, max_node_id, mesh_node_ids
from ...outdir import write_text
from ...units import UNIT_LABEL, scale
from ...render import nastran_cards as nc
from ...render._env import deck_paths, render
from . import RECORD

PID_LAYER = 2
BCSET_ID = 1
REGION_TABLE_SOURCE, REGION_TABLE_TARGET, REGION_STOP_SOURCE, REGION_STOP_TARGET = 1, 2, 3, 4
SKIRT_CARDS = {"c3d20": "CHEXA, 20 grids", "c3d20r": "CHEXA, 20 grids", "c3d10": "CTETRA, 10 grids",
               "c3d15": "CPENTA, 15 grids"}
LAYER_CARDS = {8: "CHEXA (20 grids)", 6: "CPENTA (15 grids)"}     # the table layer's cell under a quad8 / tri6 face
HEX_FACES = ((0, 1, 2, 3), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7))


@dataclass
class Layer:
    """A clamped target layer: its grids (0-based rows of ``xyz``) and cells, and the source / target faces.

    ``source``: (element index of the skirt, the face's skirt node indices: 4, or 8 / 6 on quadratic faces,
    corners first) per face; ``target``: (layer element index, the layer node indices of the face it sees).
    ``hexes``: the layer cells (8-node CHEXA; on quadratic faces 20-node CHEXA or 15-node CPENTA, a mixed mesh both,
    in CalculiX node order, :func:`nastran_order` writes them). ``xyz`` [m]."""
    xyz: np.ndarray
    hexes: np.ndarray | list      # a list of cells on quadratic faces (20 and 15 grids on a mixed mesh)
    source: list[tuple[int, tuple[int, ...]]]
    target: list[tuple[int, tuple[int, ...]]]


def _extrude(mesh: SkirtMesh, elems: np.ndarray, faces: np.ndarray, offset: np.ndarray,
             thick: np.ndarray) -> Layer:
    """A layer of CHEXAs under skirt ``faces`` (n, 4 node indices): near grids at node + offset, far grids at
    node + offset + thick (per skirt node, [m]); hex = (near face, far face) ordered for a positive volume."""
    nodes = np.unique(faces)
    pos = {int(n): i for i, n in enumerate(nodes)}
    x0 = mesh.nodes[nodes]
    near = x0 + offset[nodes]
    far = near + thick[nodes]
    xyz = np.vstack([near, far])
    hexes, target = [], []
    for k, f in enumerate(faces):
        a = [pos[int(n)] for n in f]
        h = np.array(a + [i + nodes.size for i in a])
        v = xyz[h]
        d = (v[4:].mean(0) - v[:4].mean(0))
        if np.cross(v[1] - v[0], v[3] - v[0]) @ d < 0:      # CHEXA: G1-G4 counter-clockwise seen from G5-G8
            h = h[[0, 3, 2, 1, 4, 7, 6, 5]]
        hexes.append(h)
        target.append((k, tuple(a)))
    return Layer(xyz, np.array(hexes), [(int(e), tuple(int(n) for n in f)) for e, f in zip(elems, faces)], target)


def _faces_on(mesh: SkirtMesh, elems: np.ndarray, slaves: np.ndarray, horizontal: bool) -> np.ndarray:
    """For each element, its face holding its slave nodes whose normal is vertical (table) or horizontal (stop)."""
    slave = set(slaves.tolist())
    out = []
    for e in elems:
        h = mesh.hexes[e]
        hit = []
        for f in HEX_FACES:
            q = h[list(f)]
            n = np.cross(mesh.nodes[q[2]] - mesh.nodes[q[0]], mesh.nodes[q[3]] - mesh.nodes[q[1]])
            flat = abs(n[2]) < 0.5 * np.linalg.norm(n)
            if flat == horizontal and sum(int(i) in slave for i in q) >= 2:
                hit.append(q)
        if len(hit) != 1:
            raise DeckbridgeError(f"mesh: element {e} has {len(hit)} candidate contact faces (needs one)")
        out.append(hit[0])
    return np.array(out, np.int64).reshape(-1, 4)


def layers(mesh: SkirtMesh) -> tuple[Layer, Layer | None]:
    """The table layer and the stop layer (None without a stop)."""
    h = layer_thickness(mesh)
    tab = mesh.table
    elems = np.asarray(mesh.base_elems, np.int64)
    n = mesh.n_nodes
    normal = np.zeros((n, 3))
    clear = np.zeros(n)
    normal[tab.nodes] = tab.normal
    clear[tab.nodes] = tab.clearance
    quadratic = getattr(mesh, "quadratic_faces", False)      # issue 23
    if quadratic:
        table = _extrude_quadratic(mesh, elems, _quadratic_faces(mesh, elems, tab.nodes),
                                   -normal * clear[:, None], -normal * h)
    else:
        faces = _faces_on(mesh, elems, tab.nodes, horizontal=False)
        table = _extrude(mesh, elems, faces, -normal * clear[:, None], -normal * h)
    if mesh.stop is None:
        return table, None
    st = mesh.stop
    selems = np.asarray(mesh.stop_elems, np.int64)
    sfaces = (_quadratic_wall_faces(mesh, selems, st.nodes) if quadratic else
              _faces_on(mesh, selems, st.nodes, horizontal=True))
    theta = np.arctan2(mesh.nodes[:, 1], mesh.nodes[:, 0])
    side = float(np.sign(st.normal[0] @ [np.cos(np.radians(st.theta_deg[0])), np.sin(np.radians(st.theta_deg[0])), 0.0]))
    radial = side * np.stack([np.cos(theta), np.sin(theta), np.zeros(n)], axis=1)   # master normal at every node
    sclear = np.full(n, float(np.max(st.clearance)) if st.clearance.size else 0.0)
    sclear[st.nodes] = st.clearance
    extrude = _extrude_quadratic if quadratic else _extrude
    return table, extrude(mesh, selems, sfaces, -radial * sclear[:, None], -radial * h)


def layer_thickness(mesh: SkirtMesh) -> float:
    """The target layers' thickness [m]: one first-row height (:func:`numbering.nastran.ground_distance`); on
    quadratic meshes the median axial extent of the table faces' cells (their lowest node layer above z = 0 is a
    mid-side layer, which ``ground_distance`` would take)."""
    if not getattr(mesh, "quadratic_faces", False):
        return ground_distance(mesh)
    z = mesh.nodes[:, 2]
    cells = mesh.hexes[np.asarray(mesh.base_elems, np.int64)]
    cells = np.where(cells < 0, cells[:, :1], cells)       # a mixed mesh's padded cells (-1): their first node
    return float(np.median(np.ptp(z[cells], axis=1)))


def nastran_order(conn) -> list[int]:
    """Grid list of a cell (CalculiX order) as Nastran's CHEXA / CPENTA / CTETRA wants it: corners, then the mid-side
    grids of the G1-G4 (G1-G3) face's edges, of the vertical edges, of the opposite face's edges
    (:data:`deckbridge.importers.node_order.NASTRAN_TO_CCX`, its own inverse); CTETRA's order is CalculiX's."""
    conn = [int(n) for n in conn]
    perm = NASTRAN_TO_CCX.get(len(conn))
    return conn if perm is None else [conn[i] for i in perm]


def _reverse(face: np.ndarray, n_corners: int) -> np.ndarray:
    """A quadratic face (corners cyclic, then the mid-side of edge k between corners k and k + 1) turned the other
    way round: corners c0, c_{n-1}, .., c1 and mid-sides reversed."""
    c, m = list(face[:n_corners]), list(face[n_corners:])
    return np.array([c[0]] + c[1:][::-1] + m[::-1], np.int64)


def _quadratic_faces(mesh: SkirtMesh, elems: np.ndarray, slaves: np.ndarray) -> list[np.ndarray]:
    """For each element, its one face whose every node is a slave (the table faces of a quadratic skirt), in the
    element's face order (corners cyclic, then mid-sides); a list (a mixed mesh's faces: 8 and 6 nodes)."""
    types = cell_types(mesh)                               # a mixed mesh: each cell's own faces
    slave = np.zeros(mesh.n_nodes, bool)
    slave[slaves] = True
    out = []
    for e in elems:
        hit = [mesh.hexes[e, list(f)] for f in types[e].faces if slave[mesh.hexes[e, list(f)]].all()]
        if len(hit) != 1:
            raise DeckbridgeError(f"mesh: element {e} has {len(hit)} faces made of slave nodes (needs one)")
        out.append(hit[0])
    return out


def _quadratic_wall_faces(mesh: SkirtMesh, elems: np.ndarray, slaves: np.ndarray) -> np.ndarray:
    """For each element, its one 8-node face with a horizontal normal (from its corners) holding two or more slave
    nodes: the stop-side wall face of a first-row 20-node hexahedron or 15-node wedge (a mixed mesh: either)."""
    types = cell_types(mesh)
    slave = np.zeros(mesh.n_nodes, bool)
    slave[slaves] = True
    out = []
    for e in elems:
        hit = []
        for f in types[e].faces:
            q = mesh.hexes[e, list(f)]
            if len(q) != 8:
                continue
            c = mesh.nodes[q[:4]]
            n = np.cross(c[2] - c[0], c[3] - c[1])
            if abs(n[2]) < 0.5 * np.linalg.norm(n) and slave[q].sum() >= 2:
                hit.append(q)
        if len(hit) != 1:
            raise DeckbridgeError(f"mesh: element {e} has {len(hit)} candidate stop faces (needs one)")
        out.append(hit[0])
    return np.array(out, np.int64)


def _extrude_quadratic(mesh: SkirtMesh, elems: np.ndarray, faces, offset: np.ndarray,
                       thick: np.ndarray) -> Layer:
    """A layer of quadratic cells under quadratic ``faces`` (each 8 nodes: quad8 -> 20-node CHEXA, or 6: tri6 ->
    15-node CPENTA; a mixed mesh has both): near grids at node + offset, far grids at node + offset + thick (every
    face node, [m]), and a vertical mid-side grid at node + offset + thick / 2 of every corner; the near face turned
    so that the cell's volume is positive (G1-G4 counter-clockwise seen from the far face, as the 8-node layer)."""
    faces = [np.asarray(f, np.int64) for f in faces]
    nodes = np.unique(np.concatenate(faces))
    corners = np.unique(np.concatenate([f[:len(f) // 2] for f in faces]))
    pos = {int(n): i for i, n in enumerate(nodes)}
    vpos = {int(n): 2 * nodes.size + i for i, n in enumerate(corners)}
    x0 = mesh.nodes[nodes]
    near = x0 + offset[nodes]
    far = near + thick[nodes]
    xc = mesh.nodes[corners] + offset[corners] + 0.5 * thick[corners]
    xyz = np.vstack([near, far, xc])
    cells, target = [], []
    for k, f in enumerate(faces):
        nc = len(f) // 2
        v = xyz[[pos[int(n)] for n in f[:nc]]]
        d = thick[f[0]]
        turn = np.cross(v[1] - v[0], v[-1] - v[0]) @ d
        g = _reverse(f, nc) if turn < 0 else f
        a = [pos[int(n)] for n in g]
        b = [i + nodes.size for i in a]
        vert = [vpos[int(n)] for n in g[:nc]]
        cells.append(np.array(a[:nc] + b[:nc] + a[nc:] + b[nc:] + vert))     # CalculiX C3D20 / C3D15 order
        target.append((k, tuple(a)))
    src = [(int(e), tuple(int(n) for n in f)) for e, f in zip(elems, faces)]
    return Layer(xyz, cells, src, target)


def largest_id(mesh: SkirtMesh) -> int:
    """The largest grid or element id the deck writes."""
    num = numbering(mesh)
    table, stop = layers(mesh)
    n_grid = table.xyz.shape[0] + (0 if stop is None else stop.xyz.shape[0])
    n_hex = len(table.hexes) + (0 if stop is None else len(stop.hexes))
    return max(num.node_offset + n_grid, num.elem_offset + n_hex, num.spring_base + mesh.table.nodes.size,
               num.rigid_eid, max_node_id(mesh), max_elem_id(mesh))


def _solid(bdf, eid: int, pid: int, conn):
    """CHEXA (8 or 20 grids), CPENTA (15) or CTETRA (10) of a cell given in CalculiX order (grid ids)."""
    nids = nastran_order(conn)
    add = {8: bdf.add_chexa, 20: bdf.add_chexa, 15: bdf.add_cpenta, 10: bdf.add_ctetra}[len(nids)]
    return add(eid, pid=pid, nids=nids)


def _bcrpara(crid: int) -> str:
    """BCRPARA as Femap writes it: CRID, SURF blank, OFFSET 0.0, TYPE blank (solver defaults)."""
    return print_card_8(["BCRPARA", crid, None, 0.0, None])


def surface_bulk(model: Model, mesh: SkirtMesh) -> tuple[nc.Bulk, dict]:
    """Bulk data of the surface-contact deck and the numbers its header states."""
    u, b = scale(model.units), nc.Bulk()
    bdf = b.bdf
    num = numbering(mesh)
    b.put("params", bdf.add_param("POST", [-1]))
    b.put("params", bdf.add_param("AUTOSPC", ["YES"]))
    b.put("cord", bdf.add_cord2c(nc.CID_CYL, origin=[0.0, 0.0, 0.0], zaxis=[0.0, 0.0, 1.0],
                                 xzplane=[1.0, 0.0, 0.0], rid=0))
    b.put("material", bdf.add_psolid(nc.PID_SOLID, mid=nc.MID, cordm=0, integ=None))
    b.put("material", bdf.add_psolid(PID_LAYER, mid=nc.MID, cordm=0, integ=None))
    b.put("material", bdf.add_mat1(nc.MID, E=model.material.E * u.stress, G=None, nu=model.material.nu))
    cd = np.zeros(mesh.n_nodes, int)
    cd[mesh.table.nodes] = nc.CID_CYL
    ids = mesh_node_ids(mesh, np.arange(mesh.n_nodes))
    for i, xyz in enumerate(clean_xyz(mesh.nodes)):
        b.put("grids", bdf.add_grid(int(ids[i]), xyz=[float(c) * u.length for c in xyz], cp=0, cd=int(cd[i])))
    b.put("ref_grid", bdf.add_grid(num.ref_node, xyz=nc.clean(np.asarray(mesh.ref_point) * u.length), cp=0, cd=0))
    eids = elem_ids(mesh, np.arange(mesh.hexes.shape[0]))
    used = mesh.hexes >= 0                                 # a mixed mesh's cells are padded with -1
    for e, h, keep in zip(eids, mesh_node_ids(mesh, np.where(used, mesh.hexes, 0)), used):
        b.put("hexas", _solid(bdf, int(e), nc.PID_SOLID, h[keep]))

    table, stop = layers(mesh)
    next_grid, next_elem = num.node_offset + 1, num.elem_offset + 1
    pairs, maxd = [], []
    h = layer_thickness(mesh)
    for lay, src, tgt, sset in ((table, REGION_TABLE_SOURCE, REGION_TABLE_TARGET, mesh.table),
                                (stop, REGION_STOP_SOURCE, REGION_STOP_TARGET, mesh.stop)):
        if lay is None:
            continue
        gid = next_grid + np.arange(lay.xyz.shape[0])
        hid = next_elem + np.arange(len(lay.hexes))
        next_grid, next_elem = int(gid[-1]) + 1, int(hid[-1]) + 1
        for g, xyz in zip(gid, clean_xyz(lay.xyz)):
            b.put("layer_grids", bdf.add_grid(int(g), xyz=[float(c) * u.length for c in xyz], cp=0, cd=0))
        for e, hx in zip(hid, lay.hexes):
            b.put("layer_hexas", _solid(bdf, int(e), PID_LAYER, gid[hx]))
        b.put("layer_spc", bdf.add_spc1(nc.SPC_SID, components="123456", nodes=[int(g) for g in gid]))
        se = [int(eids[e]) for e, _ in lay.source]
        sg = [[int(x) for x in mesh_node_ids(mesh, np.array(f[:3]))] for _, f in lay.source]
        tg = [[int(gid[i]) for i in f[:3]] for _, f in lay.target]
        b.put("regions", _bcrpara(src))
        b.put("regions", bdf.add_bsurfs(src, se, *[list(c) for c in zip(*sg)]))
        b.put("regions", _bcrpara(tgt))
        b.put("regions", bdf.add_bsurfs(tgt, [int(hid[k]) for k, _ in lay.target], *[list(c) for c in zip(*tg)]))
        pairs.append((src, tgt, float(model.contact.friction) if (sset.surface == "table" and nc.tangential(model)
                                                                   == "friction") else 0.0))
        maxd.append((float(np.max(sset.clearance)) + h) * u.length)
    if next_elem > num.spring_base:
        raise DeckbridgeError(f"mesh: {next_elem - num.elem_offset} layer elements overrun the spring ids "
                              f"({num.spring_base})")
    b.put("bctset", bdf.add_bctset(BCSET_ID, sids=[p[0] for p in pairs], tids=[p[1] for p in pairs],
                                   frictions=[p[2] for p in pairs], min_distances=[None] * len(pairs),
                                   max_distances=maxd))
    if nc.tangential(model) != "friction":
        nc.add_circumferential_springs(b, mesh, u, grounded=True)
    nc.add_coupling(b, model, mesh, u)
    nc.add_loads(b, model, mesh, u, (nc.LOAD_STEP1, nc.LOAD_LINEAR))
    facts = {"n_table_faces": len(table.source),
             "layer_faces": sorted({len(f) for _, f in table.source}, reverse=True),
             "n_stop_faces": 0 if stop is None else len(stop.source),
             "maxd": [f"{m:.6g}" for m in maxd], "h": f"{h * u.length:.6g}",
             "stop_side": model.contact.stop.side}
    return b, facts


def _text(b: nc.Bulk, group: str) -> str:
    return "".join(c if isinstance(c, str) else nc.write_card(c) for c in b.groups.get(group, []))


def deck_text(model: Model, mesh: SkirtMesh) -> str:
    """The whole surface-contact deck as text."""
    b, facts = surface_bulk(model, mesh)
    return render(
        "nastran_surface", "surface.bdf.j2", name=model.name, title=model.title,
        units_tag=f"deckbridge-units: {model.units}", unit_label=UNIT_LABEL[model.units],
        length_unit="m" if model.units == "SI" else "mm", lambda_max=f"{model.steps.lambda_max:g}",
        friction=f"{model.contact.friction:g}", tangential=nc.tangential(model), spc_sid=nc.SPC_SID,
        bcset=BCSET_ID, load_step1=nc.LOAD_STEP1, load_step2=nc.LOAD_LINEAR, cid_cyl=nc.CID_CYL,
        n_grids=mesh.n_nodes, n_hexa=mesh.hexes.shape[0], load_introduction=model.load_introduction,
        quadratic=getattr(mesh, "quadratic_faces", False), element=" = ".join(element_key(model, mesh)),
        skirt_cards=" + ".join(SKIRT_CARDS.get(t, "") for t in getattr(mesh, "element", "").split("+")),
        layer_cell=("CHEXA" if not getattr(mesh, "quadratic_faces", False) else
                    " or ".join(LAYER_CARDS.get(n, "CHEXA").split()[0] for n in facts["layer_faces"])),
        layer_cards=" and ".join(LAYER_CARDS.get(n, "CHEXA (8 grids)") for n in facts["layer_faces"]),
        cards={g: _text(b, g) for g in b.groups}, **facts)


def write(model: Model, mesh: SkirtMesh, outdir: Path) -> list[Path]:
    """Write ``<name>_surface.bdf`` into ``outdir``."""
    (path,) = deck_paths(RECORD, model.name, outdir)
    return [write_text(path, deck_text(model, mesh))]
