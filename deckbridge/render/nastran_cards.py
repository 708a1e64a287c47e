"""Bulk-data cards shared by the Nastran penalty deck and the MYSTRAN linear deck.

Cards are built as field lists and laid out by pyNastran's field writers (8 or 16 characters a
field), so every value fits its column. The ids (skirt, reference node, grounded gap nodes, gap and
spring elements, RBE) and the gap convention are in :mod:`deckbridge.numbering.nastran`, which the
readers (:mod:`deckbridge.readers.nastran_op2`, :mod:`deckbridge.readers.mystran_f06`) use too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pyNastran.bdf.field_writer_16 import print_card_16
from pyNastran.bdf.field_writer_8 import print_card_8

from ..errors import DeckbridgeError
from ..mesh import SkirtMesh
from ..model import Model
from ..numbering.nastran import clean_xyz, gap_layout, numbering
from ..numbering.skirt import elem_ids, mesh_node_ids

PID_SOLID = 1
MID = 1
CID_CYL = 1          # CORD2C about z: displacement system (R, theta, Z) of the base nodes
SPC_SID = 1
SID_N, SID_T, SID_M = 11, 12, 13
LOAD_STEP1, LOAD_STEP2, LOAD_LINEAR = 101, 102, 103
NLPARM_STEP1, NLPARM_STEP2 = 1, 2

# Cylindrical components of the base nodes: 1 = radial, 2 = theta, 3 = z.
COMP_RADIAL, COMP_THETA, COMP_Z = 1, 2, 3


# --- field layout --------------------------------------------------------------------------------
def card8(fields: list) -> str:
    return print_card_8(fields)


def card16(fields: list) -> str:
    return print_card_16(fields)


def _f(x) -> float:
    """A plain Python float (numpy scalars print the same, but keep the writers' input simple)."""
    return float(x)


def model_context(model: Model, mesh: SkirtMesh) -> dict:
    """Template values both Nastran-family decks share: skirt, reference and grounded grids, material,
    coupling and loads; ``n_contacts`` = number of contact elements (CGAP or CELAS2)."""
    lay = gap_layout(mesh)
    return {
        "name": model.name, "title": model.title, "lambda_max": f"{model.steps.lambda_max:g}",
        "spc_sid": SPC_SID, "cid_cyl": CID_CYL, "cord": [cord2c_card()], "material": material_cards(model),
        "grids": grid_cards(mesh), "n_grids": mesh.n_nodes, "ref_grid": reference_grid_card(mesh),
        "hexas": hexa_cards(mesh), "n_hexa": mesh.hexes.shape[0],
        "ground_grids": ground_grid_cards(mesh), "spcs": spc_ground_cards(lay.ground), "n_contacts": len(lay),
        "coupling": coupling_cards(mesh, model), "loads": load_cards(mesh, model),
    }


# --- model cards ---------------------------------------------------------------------------------
def grid_cards(mesh: SkirtMesh) -> list[str]:
    """Skirt GRIDs in the basic system; base (table) nodes get CD = the cylindrical system."""
    cd = np.zeros(mesh.n_nodes, int)
    cd[mesh.table.nodes] = CID_CYL
    xyz = clean_xyz(mesh.nodes)
    ids = mesh_node_ids(mesh, np.arange(mesh.n_nodes))
    return [card16(["GRID", int(ids[i]), None, _f(x), _f(y), _f(z), int(cd[i]) or None])
            for i, (x, y, z) in enumerate(xyz)]


def hexa_cards(mesh: SkirtMesh) -> list[str]:
    eids, conn = elem_ids(mesh, np.arange(mesh.hexes.shape[0])), mesh_node_ids(mesh, mesh.hexes)
    return [card8(["CHEXA", int(e), PID_SOLID] + [int(n) for n in h]) for e, h in zip(eids, conn)]


def material_cards(model: Model) -> list[str]:
    """PSOLID (IN = 2: 2x2x2 Gauss points, required by MYSTRAN) and MAT1 with E, G and nu all
    written (G = E / (2 (1 + nu)), consistent)."""
    m = model.material
    g = m.E / (2.0 * (1.0 + m.nu))
    return [card8(["PSOLID", PID_SOLID, MID, 0, 2]),
            card16(["MAT1", MID, _f(m.E), _f(g), _f(m.nu)])]


def cord2c_card() -> str:
    """CORD2C about the basic z axis: A = origin, B on +z, C on +x (theta = 0 along +x)."""
    return card8(["CORD2C", CID_CYL, 0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0])


def reference_grid_card(mesh: SkirtMesh) -> str:
    x, y, z = mesh.ref_point
    return card16(["GRID", numbering(mesh).ref_node, None, _f(x), _f(y), _f(z)])


def ground_grid_cards(mesh: SkirtMesh) -> list[str]:
    lay = gap_layout(mesh)
    return [card16(["GRID", int(g), None, _f(x), _f(y), _f(z)]) for g, (x, y, z) in zip(lay.ground, lay.ground_xyz)]


def spc_ground_cards(ids) -> list[str]:
    """SPC1 123456 on grounded nodes, THRU ranges when the ids are consecutive."""
    ids = np.asarray(ids, int)
    if ids.size and np.all(np.diff(ids) == 1):
        return [card8(["SPC1", SPC_SID, 123456, int(ids[0]), "THRU", int(ids[-1])])]
    return [card8(["SPC1", SPC_SID, 123456] + [int(i) for i in ids])]


def gap_cards(mesh: SkirtMesh, model: Model) -> list[str]:
    """CGAP GA=skirt node, GB=grounded node, orientation vector normal to the gap axis; one PGAP each.

    PGAP: U0 = clearance, F0 = 0, KA = k_c, KB = open_ratio * KA, KT = tangent stiffness,
    MU1 = MU2 = friction; continuation TMAX = 0 (no adaptive penalty), MAR and TRMIN written too.
    """
    lay = gap_layout(mesh)
    mu = _f(model.contact.friction)
    cards = []
    for i in range(len(lay)):
        ax = lay.axis[i]
        # orientation vector: radial for vertical gaps, +z for horizontal ones
        if abs(ax[2]) > 0.5:
            t = math.radians(lay.theta_deg[i])
            v = [math.cos(t), math.sin(t), 0.0]
        else:
            v = [0.0, 0.0, 1.0]
        eid = int(lay.eid[i])
        cards.append(card8(["CGAP", eid, eid, int(lay.node[i]), int(lay.ground[i])] + v))
        ka = _f(lay.k[i])
        cards.append(card16(["PGAP", eid, _f(lay.u0[i]), 0.0, ka, _f(mesh.k_open_ratio * ka), _f(lay.k_t[i]),
                             mu, mu, 0.0, 100.0, 0.001]))
    return cards


def contact_spring_cards(mesh: SkirtMesh) -> list[str]:
    """Linear deck: each gap replaced by a CELAS2 of stiffness KA from the base node to its grounded node.

    Table gaps act on cylindrical component 3 (z), stop gaps on component 1 (radial); both
    through the base nodes' CD = CORD2C. Element ids are the gap ids. MYSTRAN 18 refuses a
    CELAS2 with a blank second grid/component (error 1133), hence the grounded nodes
    (SPC 123456) of the penalty deck as second grid; their component is immaterial.
    """
    lay = gap_layout(mesh)
    comp = np.where(lay.surface == "table", COMP_Z, COMP_RADIAL)
    return [card16(["CELAS2", int(e), _f(k), int(n), int(c), int(g), int(c)])
            for e, k, n, c, g in zip(lay.eid, lay.k, lay.node, comp, lay.ground)]


def circumferential_spring_cards(mesh: SkirtMesh, grounded: bool = True) -> list[str]:
    """CELAS2 on the theta component of every table node, stiffness mesh.k_tangent.

    ``grounded``: second grid blank (Nastran); otherwise tied to the node's table-gap grounded
    node (MYSTRAN, which refuses grounded CELAS2).
    """
    base = numbering(mesh).spring_base
    lay = gap_layout(mesh)
    ground = dict(zip(lay.node[lay.surface == "table"].tolist(), lay.ground[lay.surface == "table"].tolist()))
    cards = []
    for i, (n, k) in enumerate(zip(mesh_node_ids(mesh, mesh.table.nodes), mesh.k_tangent)):
        tail = [] if grounded else [ground[int(n)], COMP_THETA]
        cards.append(card16(["CELAS2", base + i, _f(k), int(n), COMP_THETA] + tail))
    return cards


def _weight_groups(nodes: np.ndarray, weights: np.ndarray) -> list[tuple[float, list[int]]]:
    """Top nodes (deck ids) grouped by equal weight (equal to 1e-10 relative), in order of first appearance."""
    key = np.round(weights / weights.max(), 10)
    groups: dict[float, list[int]] = {}
    for k, n in zip(key.tolist(), nodes.tolist()):
        groups.setdefault(k, []).append(int(n))
    out = []
    for k, ids in groups.items():
        w = float(np.mean(weights[np.isin(nodes, ids)]))
        out.append((w, ids))
    return out


def coupling_cards(mesh: SkirtMesh, model: Model, kind: str | None = None) -> list[str]:
    """Load introduction at the top face: RBE3 (distributing) or RBE2 (kinematic)."""
    num = numbering(mesh)
    kind = kind or model.load_introduction
    if kind == "distributing":
        fields = ["RBE3", num.rigid_eid, None, num.ref_node, 123456]
        for w, ids in _weight_groups(mesh_node_ids(mesh, mesh.top_nodes), mesh.top_weights):
            fields += [w, 123] + ids
        return [card16(fields)]
    if kind == "kinematic":
        return [card8(["RBE2", num.rigid_eid, num.ref_node, 123456] + [int(n) for n in mesh_node_ids(mesh, mesh.top_nodes)])]
    raise DeckbridgeError(f"load_introduction = {kind!r}: unknown")


def load_cards(mesh: SkirtMesh, model: Model) -> list[str]:
    """FORCE (N, T) and MOMENT (M) at the reference node, unit direction and magnitude, and the LOADs.

    LOAD 101 = N (step 1); LOAD 102 = N + lambda_max (T, M) (totals, step 2 of SOL 106);
    LOAD 103 = the same combination for the linear deck.
    """
    ref = numbering(mesh).ref_node
    ld = model.loads
    a = math.radians(ld.azimuth)
    c, s = math.cos(a), math.sin(a)
    lam = _f(model.steps.lambda_max)
    return [
        card16(["FORCE", SID_N, ref, 0, _f(ld.N), 0.0, 0.0, -1.0]),
        card16(["FORCE", SID_T, ref, 0, _f(ld.T), -c, -s, 0.0]),
        card16(["MOMENT", SID_M, ref, 0, _f(ld.M), s, -c, 0.0]),
        card16(["LOAD", LOAD_STEP1, 1.0, 1.0, SID_N]),
        card16(["LOAD", LOAD_STEP2, 1.0, 1.0, SID_N, lam, SID_T, lam, SID_M]),
        card16(["LOAD", LOAD_LINEAR, 1.0, 1.0, SID_N, lam, SID_T, lam, SID_M]),
    ]


@dataclass(frozen=True)
class NlparmSettings:
    """Every NLPARM field the decks write (no solver defaults)."""
    kmethod: str = "ITER"   # full Newton with KSTEP = 1
    kstep: int = 1
    maxiter: int = 25
    conv: str = "UPW"
    intout: str = "YES"
    epsu: float = 1.0e-3
    epsp: float = 1.0e-3
    epsw: float = 1.0e-7
    maxdiv: int = 3
    maxqn: int = 0          # no quasi-Newton updates
    maxls: int = 4
    fstress: float = 0.2
    lstol: float = 0.5
    maxbis: int = 5


NLPARM = NlparmSettings()


def nlparm_cards(model: Model, s: NlparmSettings = NLPARM) -> list[str]:
    """NLPARM 1 (step 1, NINC = 1) and NLPARM 2 (step 2, NINC = steps.increments), DT = 0."""
    out = []
    for nid, ninc in ((NLPARM_STEP1, 1), (NLPARM_STEP2, model.steps.increments)):
        out.append(card8(["NLPARM", nid, int(ninc), 0.0, s.kmethod, s.kstep, s.maxiter, s.conv, s.intout,
                          s.epsu, s.epsp, s.epsw, s.maxdiv, s.maxqn, s.maxls, s.fstress, s.lstol,
                          s.maxbis]))
    return out
