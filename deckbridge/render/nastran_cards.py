"""Bulk data of the Nastran penalty deck and the MYSTRAN linear deck, built as pyNastran cards.

Every card is made by a ``pyNastran.bdf.bdf.BDF.add_*`` call with keyword arguments (every field
named) on one ``BDF`` per deck, then laid out by pyNastran's field writers in the width of
:data:`WIDTH` (16 characters where precision matters: coordinates, stiffnesses, moduli, loads,
weights; 8 for ids and flags). Cards in :data:`EXPLICIT` are written with all their fields
(``raw_fields``: no field left blank for a solver default); the others with pyNastran's
``repr_fields`` (defaults blank), which is what leaves MAT1 G and the SOL 106 PSOLID IN blank.

Values are converted from the SI model to the deck's units (:func:`deckbridge.units.scale`).
Ids and the gap convention are in :mod:`deckbridge.numbering.nastran`, which the readers use too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from pyNastran.bdf.bdf import BDF
from pyNastran.bdf.field_writer_16 import print_card_16
from pyNastran.bdf.field_writer_8 import print_card_8

from ..errors import DeckbridgeError
from ..mesh import SkirtMesh
from ..model import Model
from ..numbering.nastran import clean_xyz, gap_layout, numbering
from ..numbering.skirt import elem_ids, mesh_node_ids
from ..units import Units, scale

PID_SOLID = 1
MID = 1
CID_CYL = 1          # CORD2C about z: displacement system (R, theta, Z) of the base nodes
SPC_SID = 1
SID_N, SID_T, SID_M = 11, 12, 13
LOAD_STEP1, LOAD_STEP2, LOAD_LINEAR = 101, 102, 103
NLPARM_STEP1, NLPARM_STEP2 = 1, 2

# Cylindrical components of the base nodes: 1 = radial, 2 = theta, 3 = z.
COMP_RADIAL, COMP_THETA, COMP_Z = 1, 2, 3

# CGAP orientation vectors, components in the CD of GA (= CORD2C 1 for every base node):
X_TABLE = (1.0, 0.0, 0.0)    # radial: (R, theta, Z) = (1, 0, 0) at the node's own azimuth
X_STOP = (0.0, 0.0, 1.0)     # axial Z (the stop gap's axis is radial)

WIDTH = {"GRID": 16, "MAT1": 16, "PGAP": 16, "CELAS2": 16, "RBE3": 16, "FORCE": 16, "MOMENT": 16,
         "LOAD": 16}                               # every other card: 8
EXPLICIT = {"PGAP", "NLPARM"}                      # every field written, none left to a default


def write_card(card) -> str:
    """One card as deck text (pyNastran field writers, width per :data:`WIDTH`), after its comment lines if any."""
    fields = card.raw_fields() if card.type in EXPLICIT else card.repr_fields()
    return card.comment + (print_card_16 if WIDTH.get(card.type, 8) == 16 else print_card_8)(fields)


def clean(v, rel: float = 1e-12) -> list[float]:
    """Components as floats with round-off residues (|v_i| < rel * max |v|) set to 0."""
    a = np.asarray(v, float)
    a = np.where(np.abs(a) < rel * max(float(np.abs(a).max()), 1e-300), 0.0, a)
    return [float(x) + 0.0 for x in a]


@dataclass
class Bulk:
    """The deck's pyNastran model and its cards grouped in deck order (group name -> cards)."""
    bdf: BDF = field(default_factory=lambda: BDF(debug=None))
    groups: dict[str, list] = field(default_factory=dict)

    def put(self, group: str, card) -> None:
        self.groups.setdefault(group, []).append(card)

    def text(self, group: str) -> str:
        return "".join(write_card(c) for c in self.groups.get(group, []))


def tangential(model: Model) -> str:
    """What carries the tangential (circumferential) load at the base: 'springs' (grounded CELAS2,
    PGAP KT = 0) or 'friction' (PGAP KT and MU, no CELAS2; ``contact.tangential`` of issue 14)."""
    return str(getattr(model.contact, "tangential", "springs"))


# --- cards of both decks ---------------------------------------------------------------------------
def add_model(b: Bulk, model: Model, mesh: SkirtMesh, u: Units, integ: int | None) -> None:
    """CORD2C, PSOLID (IN = ``integ``; None = blank), MAT1 (E, nu; G blank), skirt and reference
    GRIDs (base nodes CD = the cylindrical system), CHEXAs, grounded gap GRIDs and their SPC1."""
    bdf = b.bdf
    # A = origin, B on +z, C on +x: theta = 0 along +x
    b.put("cord", bdf.add_cord2c(CID_CYL, origin=[0.0, 0.0, 0.0], zaxis=[0.0, 0.0, 1.0],
                                 xzplane=[1.0, 0.0, 0.0], rid=0))
    b.put("material", bdf.add_psolid(PID_SOLID, mid=MID, cordm=0, integ=integ))
    b.put("material", bdf.add_mat1(MID, E=model.material.E * u.stress, G=None, nu=model.material.nu))
    cd = np.zeros(mesh.n_nodes, int)
    cd[mesh.table.nodes] = CID_CYL
    ids = mesh_node_ids(mesh, np.arange(mesh.n_nodes))   # the user's ids (numbering/skirt.py)
    for i, xyz in enumerate(clean_xyz(mesh.nodes)):
        b.put("grids", bdf.add_grid(int(ids[i]), xyz=[float(c) * u.length for c in xyz], cp=0, cd=int(cd[i])))
    num = numbering(mesh)
    b.put("ref_grid", bdf.add_grid(num.ref_node, xyz=clean(np.asarray(mesh.ref_point) * u.length), cp=0, cd=0))
    eids, conn = elem_ids(mesh, np.arange(mesh.hexes.shape[0])), mesh_node_ids(mesh, mesh.hexes)
    wedge = (mesh.hexes < 0).any(axis=1)          # a mixed mesh's 6-node wedges (padded with -1): CPENTA
    for e, h, w in zip(eids, conn, wedge):
        if w:
            b.put("hexas", bdf.add_cpenta(int(e), pid=PID_SOLID, nids=[int(n) for n in h[:6]]))
        else:
            b.put("hexas", bdf.add_chexa(int(e), pid=PID_SOLID, nids=[int(n) for n in h]))
    lay = gap_layout(mesh)
    for g, xyz in zip(lay.ground, lay.ground_xyz):
        b.put("ground", bdf.add_grid(int(g), xyz=[float(c) * u.length for c in xyz], cp=0, cd=0))
    b.put("ground", bdf.add_spc1(SPC_SID, components="123456", nodes=[int(g) for g in lay.ground]))


def add_gaps(b: Bulk, model: Model, mesh: SkirtMesh, u: Units) -> None:
    """One CGAP (GA = skirt node, GB = grounded node) and one PGAP (PID = EID) per slave node.

    X1-X3 in GA's CD (cylindrical): (1, 0, 0) = radial for the vertical table gaps, (0, 0, 1) = z
    for the radial stop gaps. PGAP: U0 = clearance, F0 = 0, KA = k_c, KB = open_ratio * KA,
    table gaps: KT = 0 with the circumferential springs (they carry T; KT would add a second
    mechanism) or the node's k_t with ``contact.tangential = friction``, MU1 = MU2 = friction;
    stop gaps: KT = MU1 = MU2 = 0 (the radial stop is frictionless, as in the reference solver and
    every other deck); TMAX = 0 (no adaptive penalty), MAR = 100, TRMIN = 0.001.
    """
    lay = gap_layout(mesh)
    friction = tangential(model) == "friction"
    for i in range(len(lay)):
        eid = int(lay.eid[i])
        table = lay.surface[i] == "table"
        x = X_TABLE if table else X_STOP
        b.put("gaps", b.bdf.add_cgap(eid, pid=eid, nids=[int(lay.node[i]), int(lay.ground[i])],
                                     x=list(x), g0=None, cid=None))
        ka = float(lay.k[i]) * u.stiffness
        mu = float(model.contact.friction) if table else 0.0
        kt = float(lay.k_t[i]) * u.stiffness if friction and table else 0.0
        b.put("gaps", b.bdf.add_pgap(eid, u0=float(lay.u0[i]) * u.length, f0=0.0, ka=ka,
                                     kb=mesh.k_open_ratio * ka, kt=kt, mu1=mu, mu2=mu, tmax=0.0,
                                     mar=100.0, trmin=0.001))


def add_contact_springs(b: Bulk, mesh: SkirtMesh, u: Units) -> None:
    """Linear deck: each gap replaced by a CELAS2 of stiffness KA from the base node to its grounded
    node: table gaps on cylindrical component 3 (z), stop gaps on 1 (radial), through the base
    nodes' CD. Element ids = the gap ids. MYSTRAN 18 refuses a CELAS2 with a blank second
    grid/component (error 1133), hence the grounded nodes as second grid."""
    lay = gap_layout(mesh)
    comp = np.where(lay.surface == "table", COMP_Z, COMP_RADIAL)
    for e, k, n, c, g in zip(lay.eid, lay.k, lay.node, comp, lay.ground):
        b.put("contact_springs", b.bdf.add_celas2(int(e), k=float(k) * u.stiffness, nids=[int(n), int(g)],
                                                  c1=int(c), c2=int(c)))


def add_circumferential_springs(b: Bulk, mesh: SkirtMesh, u: Units, grounded: bool) -> None:
    """CELAS2 on the theta component of every table node, stiffness mesh.k_tangent.

    ``grounded``: second grid blank, component 0 (Nastran); otherwise tied to the node's table-gap
    grounded node (MYSTRAN refuses grounded CELAS2).
    """
    base = numbering(mesh).spring_base
    lay = gap_layout(mesh)
    tab = lay.surface == "table"
    ground = dict(zip(lay.node[tab].tolist(), lay.ground[tab].tolist()))
    for i, (n, k) in enumerate(zip(mesh_node_ids(mesh, mesh.table.nodes), mesh.k_tangent)):
        nids, c2 = ([int(n), None], 0) if grounded else ([int(n), ground[int(n)]], COMP_THETA)
        b.put("springs", b.bdf.add_celas2(base + i, k=float(k) * u.stiffness, nids=nids, c1=COMP_THETA, c2=c2))


def _weight_groups(nodes: np.ndarray, weights: np.ndarray) -> list[tuple[float, list[int]]]:
    """Top nodes (deck ids) grouped by equal weight (equal to 1e-10 relative), in order of first appearance."""
    key = np.round(weights / weights.max(), 10)
    groups: dict[float, list[int]] = {}
    for k, n in zip(key.tolist(), nodes.tolist()):
        groups.setdefault(k, []).append(int(n))
    return [(float(np.mean(weights[np.isin(nodes, ids)])), ids) for ids in groups.values()]


# On 8-/6-node top faces the RBE3 weights are the consistent shares int N dA (SkirtMesh.top_weights), <= 0 at the
# corners: what ccx's and Abaqus' *COUPLING, *DISTRIBUTING and the reference use. The Nastran QRGs found (Autodesk
# Nastran, OptiStruct, NASTRAN-CoFE) type WTi as Real with no sign bound; not run in a Nastran here.
RBE3_CONSISTENT = (" RBE3 WTi: the top faces' consistent shares (int N dA; <= 0 at the\n"
                   " corners of 8-/6-node faces), as ccx/Abaqus *DISTRIBUTING and the reference")


def add_coupling(b: Bulk, model: Model, mesh: SkirtMesh, u: Units) -> None:
    """Load introduction at the top face: RBE3 (distributing; weights = ``mesh.top_weights`` in deck units:
    tributary top-face areas, on 8-/6-node faces the consistent shares, commented) or RBE2 (kinematic)."""
    num = numbering(mesh)
    kind = model.load_introduction
    if kind == "distributing":
        groups = _weight_groups(mesh_node_ids(mesh, mesh.top_nodes), mesh.top_weights)
        note = RBE3_CONSISTENT if np.any(mesh.top_weights <= 0) else ""
        b.put("coupling", b.bdf.add_rbe3(num.rigid_eid, refgrid=num.ref_node, refc="123456",
                                         weights=[w * u.length ** 2 for w, _ in groups],
                                         comps=["123"] * len(groups), Gijs=[ids for _, ids in groups],
                                         comment=note))
    elif kind == "kinematic":
        b.put("coupling", b.bdf.add_rbe2(num.rigid_eid, gn=num.ref_node, cm="123456",
                                         Gmi=[int(n) for n in mesh_node_ids(mesh, mesh.top_nodes)]))
    else:
        raise DeckbridgeError(f"load_introduction = {kind!r}: unknown")


def add_loads(b: Bulk, model: Model, mesh: SkirtMesh, u: Units, load_ids: tuple[int, ...]) -> None:
    """FORCE (N, T) and MOMENT (M) at the reference node (unit direction, magnitude), and the LOAD
    combinations of ``load_ids`` only (those the case control uses): 101 = N; 102 and 103 =
    N + lambda_max (T, M) (totals: SOL 106 subcase 2, resp. the linear deck's one subcase)."""
    ref = numbering(mesh).ref_node
    ld = model.loads
    a = math.radians(ld.azimuth)
    c, s = math.cos(a), math.sin(a)
    lam = float(model.steps.lambda_max)
    bdf = b.bdf
    b.put("loads", bdf.add_force(SID_N, node=ref, mag=float(ld.N) * u.force, xyz=[0.0, 0.0, -1.0], cid=0))
    b.put("loads", bdf.add_force(SID_T, node=ref, mag=float(ld.T) * u.force, xyz=clean([-c, -s, 0.0]), cid=0))
    b.put("loads", bdf.add_moment(SID_M, node=ref, mag=float(ld.M) * u.moment, xyz=clean([s, -c, 0.0]), cid=0))
    combos = {LOAD_STEP1: ([1.0], [SID_N]), LOAD_STEP2: ([1.0, lam, lam], [SID_N, SID_T, SID_M]),
              LOAD_LINEAR: ([1.0, lam, lam], [SID_N, SID_T, SID_M])}
    for lid in load_ids:
        factors, ids = combos[lid]
        b.put("loads", bdf.add_load(lid, scale=1.0, scale_factors=factors, load_ids=ids))


@dataclass(frozen=True)
class NlparmSettings:
    """Every NLPARM field the SOL 106 deck writes (no solver defaults)."""
    kmethod: str = "ITER"   # full Newton with KSTEP = 1
    kstep: int = 1
    maxiter: int = 25
    conv: str = "UPW"
    intout: str = "YES"     # output at every increment = the compared load factors
    epsu: float = 1.0e-3
    epsp: float = 1.0e-3
    epsw: float = 1.0e-7
    maxdiv: int = 3
    maxqn: int = 0          # no quasi-Newton updates
    maxls: int = 4
    fstress: float = 0.2
    lstol: float = 0.5
    maxbis: int = 5
    maxr: float = 20.0
    rtolb: float = 20.0


NLPARM = NlparmSettings()


def add_nlparms(b: Bulk, model: Model, s: NlparmSettings = NLPARM) -> None:
    """NLPARM 1 (subcase 1, NINC = 1) and NLPARM 2 (subcase 2, NINC = steps.increments: equal load
    increments, one output each at lambda_max * i / NINC), DT = 0."""
    for nid, ninc in ((NLPARM_STEP1, 1), (NLPARM_STEP2, model.steps.increments)):
        b.put("nlparm", b.bdf.add_nlparm(
            nid, ninc=int(ninc), dt=0.0, kmethod=s.kmethod, kstep=s.kstep, max_iter=s.maxiter, conv=s.conv,
            int_out=s.intout, eps_u=s.epsu, eps_p=s.epsp, eps_w=s.epsw, max_div=s.maxdiv, max_qn=s.maxqn,
            max_ls=s.maxls, fstress=s.fstress, ls_tol=s.lstol, max_bisect=s.maxbis, max_r=s.maxr,
            rtol_b=s.rtolb))


def penalty_bulk(model: Model, mesh: SkirtMesh) -> Bulk:
    """Bulk data of the SOL 106 penalty deck (PSOLID IN blank: MSC's CHEXA8 default, bubble
    functions, the counterpart of C3D8I)."""
    u, b = scale(model.units), Bulk()
    b.put("params", b.bdf.add_param("POST", [-1]))
    b.put("params", b.bdf.add_param("AUTOSPC", ["YES"]))
    b.put("params", b.bdf.add_param("LGDISP", [1 if model.analysis.nlgeom else -1]))
    add_model(b, model, mesh, u, integ=None)
    add_gaps(b, model, mesh, u)
    if tangential(model) != "friction":
        add_circumferential_springs(b, mesh, u, grounded=True)
    add_coupling(b, model, mesh, u)
    add_loads(b, model, mesh, u, (LOAD_STEP1, LOAD_STEP2))
    add_nlparms(b, model)
    return b


def linear_bulk(model: Model, mesh: SkirtMesh) -> Bulk:
    """Bulk data of the MYSTRAN linear deck (PSOLID IN = 2, which MYSTRAN requires)."""
    if tangential(model) == "friction":
        raise DeckbridgeError("contact.tangential = friction: the MYSTRAN linear deck has no friction "
                              "(every gap closed, T through springs); use contact.tangential = springs")
    u, b = scale(model.units), Bulk()
    b.put("params", b.bdf.add_param("AUTOSPC", ["YES"]))
    add_model(b, model, mesh, u, integ=2)
    add_contact_springs(b, mesh, u)
    add_circumferential_springs(b, mesh, u, grounded=False)
    add_coupling(b, model, mesh, u)
    add_loads(b, model, mesh, u, (LOAD_LINEAR,))
    return b
