"""Abaqus/Standard decks (renderer "abaqus"; not run here: no Abaqus): ``<name>_lagrange.inp`` (Lagrange
multipliers, ``*SURFACE BEHAVIOR, ..., DIRECT``) and ``<name>_augmented.inp`` (the augmented Lagrange
enforcement of ``--method augmented``, ``*SURFACE BEHAVIOR, ..., AUGMENTED LAGRANGE``), the same model otherwise.

Contact on 4-node faces (hex8i, hex8): node-based slave surfaces ``*SURFACE, TYPE=NODE`` (table: every base
node; stop: the base nodes on the stop-side wall face) with each node's tributary area on its data line, so that
CPRESS is a pressure; ``*CONTACT PAIR, TYPE=NODE TO SURFACE`` per pair. On 8-/6-node faces (hex20, hex20r,
tet10, wedge15; issue 23) a node-based law opens the corner nodes at zero load (they carry -1/12 or 0 of a
uniform pressure), so the table pair is ``*CONTACT PAIR, TYPE=SURFACE TO SURFACE`` with an element-based slave
surface (the skirt's base faces, labels S1.. in the element's face order, :func:`deck_elements.face_label_lines`)
and the skirt cards C3D20 / C3D20R / C3D10 / C3D15 (20-node lines continued after 16 entries); the radial stop
(its slaves are base nodes, node-based) is refused there by :func:`deckbridge.deck_elements.element_problem`.
Masters are element-based surfaces of fixed C3D8 rings (see :mod:`deckbridge.numbering.inp`): Abaqus accepts
them as master surfaces without a rigid-body definition, and the same geometry serves the CalculiX mortar deck.
``PRESSURE-OVERCLOSURE=HARD`` with the enforcement written explicitly (its default depends on the pair type);
``*FRICTION`` = contact.friction on the table pair (``LAGRANGE`` stick when mu > 0), 0 on the stop pair (the
radial stop is frictionless, as in the reference solver).

Augmented deck (docs/abaqus.md): the data line of ``*SURFACE BEHAVIOR, AUGMENTED LAGRANGE`` is the penalty
stiffness K = k_c / A [pressure / length] (the model's nodal k_c over the node's tributary area; one interaction
per group of equal K), the clearance at which the pressure is zero (0) and the scale factor (1); each step
carries ``*CONTACT CONTROLS, MASTER=, SLAVE=, ABSOLUTE PENETRATION TOLERANCE=`` per pair (:func:`penetration_tol`).

Rest as in the CalculiX decks: circumferential SPRING1 per table node (cylindrical ``*ORIENTATION``, local dof 2,
mesh.k_tangent), ``*COUPLING`` + ``*DISTRIBUTING`` (uniform weighting, i.e. tributary-area weights on the
element-based top surface) or ``*KINEMATIC`` from the top-centre reference node; step 1: N; step 2: N repeated +
lambda_max (T, M) with automatic incrementation (``*STATIC`` with initial, period, minimum and maximum increment =
1/increments, no DIRECT: cutbacks allowed where the contact state changes) and output at ``*TIME POINTS``
j/increments; ``NLGEOM=YES|NO`` from analysis.nlgeom; ``*STEP, INC=`` from the model. Output: CSTRESS/CDISP
field output, ``*CONTACT PRINT`` per pair (surface names contain TABLE / STOP for the .dat reader) and
``*EL PRINT, ELSET=EBASE`` S. Units: model.units.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from . import RECORD
from ...deck_elements import face_label_lines
from ...mesh import SkirtMesh
from ...methods import AUGMENTED, LAGRANGE
from ...model import Model
from ...numbering.inp import layout
from ...numbering.skirt import elem_ids, mesh_node_ids
from ...render._env import deck_paths, render
from ...units import scale
from ...render.inp_cards import element_lines, face_lines, node_block, real, shared_context

# Augmented deck: the allowed penetration is the one that the first-row element's axial stiffness E / h1 turns
# into PRESSURE_SHARE of the base stress scale (see penetration_tol).
PRESSURE_SHARE = 1.0e-4
SAME_SLOPE = 1.0e-9          # penalty stiffnesses K within this relative difference share one interaction


def penetration_tol(model: Model, mesh: SkirtMesh, h1: float) -> float:
    """The augmented deck's ABSOLUTE PENETRATION TOLERANCE [m]: PRESSURE_SHARE x sigma_0 x h1 / E, with sigma_0
    the base stress scale max(N / A_table, lambda_max M_b / (pi R^2 t)) [Pa] (the mean compression under N, the
    thin-ring bending stress of the base moment): a penetration d changes the pressure under a node by about
    E d / h1 through the first-row element (h1 [m]), so this d is PRESSURE_SHARE of sigma_0. Without any load,
    sigma_0 = 1e-6 E."""
    g = model.geometry
    s0 = max(model.loads.N / float(np.sum(mesh.table.area)),
             model.steps.lambda_max * max(model.base_moment, 0.0) / (np.pi * g.radius ** 2 * g.thickness))
    s0 = s0 if s0 > 0 else 1.0e-6 * model.material.E
    return PRESSURE_SHARE * s0 * h1 / model.material.E


def base_cell_height(mesh: SkirtMesh) -> float:
    """h1 [m]: the median axial extent of the cells carrying a table face (the first-row height of the structured
    skirt whatever its element type; the lowest node layer above z = 0 is a mid-side layer on quadratic meshes)."""
    z = mesh.nodes[:, 2]
    if mesh.base_elems is None or not len(mesh.base_elems):
        return float(np.min(z[z > 0.0]))
    cells = mesh.hexes[np.asarray(mesh.base_elems, np.int64)]
    cells = np.where(cells < 0, cells[:, :1], cells)       # a mixed mesh's padded cells (-1): their first node
    return float(np.median(np.ptp(z[cells], axis=1)))


def _groups(values: np.ndarray) -> list[np.ndarray]:
    """Indices of ``values`` grouped by equal value (relative SAME_SLOPE), in order of first appearance."""
    left, out = np.ones(values.size, bool), []
    while left.any():
        i0 = np.flatnonzero(left)[0]
        same = left & (np.abs(values - values[i0]) <= SAME_SLOPE * abs(values[i0]))
        out.append(np.flatnonzero(same))
        left &= ~same
    return out


def _node_pairs(name: str, ss, mesh: SkirtMesh, master: str, length: float, augmented: bool) -> list[dict]:
    """Node-to-surface pair(s) of slave set ``ss``: one, or with ``augmented`` one per group of equal k_c / A."""
    slope = ss.k / ss.area
    groups = _groups(slope) if augmented else [np.arange(ss.nodes.size)]
    out = []
    for n, rows in enumerate(groups, start=1):
        label = name if len(groups) == 1 else f"{name}{n}"
        out.append({"name": label, "slave_type": "NODE", "pair_type": "NODE TO SURFACE", "master": master,
                    "slave": _node_surface(ss, mesh, length, rows), "slope": float(slope[rows[0]])})
    return out


def _face_pairs(mesh: SkirtMesh, master: str, augmented: bool) -> list[dict]:
    """Surface-to-surface table pair(s) on the skirt's base faces; with ``augmented`` one per group of faces of
    equal mean k_c / A over their table nodes."""
    tab = mesh.table
    row = np.full(mesh.n_nodes, -1)
    row[tab.nodes] = np.arange(tab.nodes.size)
    base = np.asarray(mesh.base_elems, np.int64)
    slope_node = tab.k / tab.area
    rows = [row[c[c >= 0]] for c in mesh.hexes[base]]           # a mixed mesh's cells are padded with -1
    slope = np.array([slope_node[r[r >= 0]].mean() for r in rows])
    groups = _groups(slope) if augmented else [np.arange(base.size)]
    out = []
    for n, rows in enumerate(groups, start=1):
        label = "TABLE" if len(groups) == 1 else f"TABLE{n}"
        out.append({"name": label, "slave_type": "ELEMENT", "pair_type": "SURFACE TO SURFACE", "master": master,
                    "slave": face_label_lines(mesh, base[rows], elem_ids(mesh, base[rows]), 0.0),
                    "slope": float(slope[rows[0]])})
    return out


def context(model: Model, mesh: SkirtMesh, method: str = LAGRANGE) -> dict:
    """Template values of the deck of ``method`` ('lagrange': DIRECT; 'augmented': AUGMENTED LAGRANGE)."""
    u = scale(model.units)
    augmented = method == AUGMENTED
    lay = layout(model, mesh, masters=("table", "stop"))
    rings = [r for r in (lay.table_master, lay.stop_master) if r is not None]
    mu = model.contact.friction
    table_master = face_lines(lay.table_master.elem_ids, lay.table_master.face)
    if mesh.quadratic_faces:
        pairs = _face_pairs(mesh, table_master, augmented)
    else:
        pairs = _node_pairs("TABLE", mesh.table, mesh, table_master, u.length, augmented)
    for p in pairs:
        p.update(friction=real(mu), lagrange_friction=mu > 0)
    if lay.stop_master is not None:     # the radial stop is frictionless (docs/friction.md)
        for p in _node_pairs("STOP", mesh.stop, mesh, face_lines(lay.stop_master.elem_ids, lay.stop_master.face),
                             u.length, augmented):
            pairs.append({**p, "friction": real(0.0), "lagrange_friction": False})
    h1 = base_cell_height(mesh)
    tol = penetration_tol(model, mesh, h1)
    for p in pairs:
        p["behavior"] = "AUGMENTED LAGRANGE" if augmented else "DIRECT"
        p["behavior_line"] = f"{real(p['slope'] * u.stress / u.length)}, {real(0.0)}, {real(1.0)}" if augmented else ""
    return {
        **shared_context(model, lay),
        **node_block(mesh.nodes, lay.ref_node, lay.ref_xyz,
                     [("NMASTER", np.concatenate([r.node_ids for r in rings]),
                       np.vstack([r.nodes for r in rings]))], u.length, mesh.node_ids),
        "master_elems": "\n".join(element_lines(r.elem_ids, r.conn) for r in rings),
        "pairs": pairs, "augmented": augmented, "surface_to_surface": mesh.quadratic_faces,
        "penetration_tol": real(tol * u.length), "pressure_share": real(PRESSURE_SHARE),
        "h1": real(h1 * u.length),
    }


def _node_surface(ss, ss_mesh, length: float = 1.0, rows=None) -> str:
    """``node, tributary area`` data lines of a node-based slave surface (user node ids, area in deck units)."""
    rows = np.arange(ss.nodes.size) if rows is None else rows
    return "\n".join(f"{int(n)}, {real(a * length ** 2)}"
                     for n, a in zip(mesh_node_ids(ss_mesh, ss.nodes[rows]), ss.area[rows]))


DECKS = (LAGRANGE, AUGMENTED)        # in the order of the dialect record's deck names


def write(model: Model, mesh: SkirtMesh, outdir: Path) -> list[Path]:
    """Write the Abaqus/Standard Lagrange and augmented-Lagrange decks into ``outdir``."""
    out = []
    for method, p in zip(DECKS, deck_paths(RECORD, model.name, outdir)):
        p.write_text(render(RECORD.templates, "lagrange.inp.j2", **context(model, mesh, method)))
        out.append(p)
    return out
