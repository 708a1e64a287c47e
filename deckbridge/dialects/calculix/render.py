"""CalculiX 2.20 decks: ``<name>_ccx_penalty.inp`` (penalty), ``<name>_ccx_lagrange.inp`` (mortar) and
``<name>_ccx_f2f.inp`` (face-to-face penalty).

Penalty, ``analysis.nlgeom: false`` (default, the reference solver's small-strain analysis): node-to-surface
contact with ``PRESSURE-OVERCLOSURE=LINEAR``, node-based slave surfaces grouped by equal k_c / A_ccx
(:func:`.numbering.ccx_n2f_groups`), masters the faces of fixed C3D8 rings (table, stop). ccx
gives a node of a node-based slave surface the area A_ccx (a quarter of every free face of the skirt at the
node, measured) and the force K A_ccx d, so the slope K = k_c / A_ccx reproduces the model's k_c per node.
Penalty, ``nlgeom: true``: one GAPUNI element per slave node, from the skirt node to a grounded node at the
same place, stiffness k_c on its ``*GAP`` line, direction -n, the clearance and the tension for a wide
opening f_inf = open_ratio * k_c * t. GAPUNI needs ``NLGEOM`` in 2.20 (without it reactions came out doubled),
so it is the NLGEOM deck only. At stiff penalties the node-to-surface deck's residual tolerance R_n follows the
round-off residual of its stiffest spring (:func:`n2f_residual_tol`). With contact.tangential = friction the
node-to-surface table groups carry ``*FRICTION`` (mu, stick slope k_t / A_ccx [Pa/m]: ccx's tangential spring is
the slope times the node's area) and no circumferential springs; GAPUNI has no friction (:class:`DeckUnsupported`).

Lagrange-type: ``*CONTACT PAIR, TYPE=MORTAR`` (dual shape functions) between the skirt's first-row base
faces (slave) and the top faces of a fixed C3D8 ring (master). With MORTAR_HARD (default) the interaction
has no ``*SURFACE BEHAVIOR``: ccx 2.20 then enforces hard contact with Lagrange multipliers. Otherwise it
writes ``PRESSURE-OVERCLOSURE=LINEAR`` with the slope K_m = MORTAR_FACTOR * E / h1. The radial stop is GAPUNI
gaps with the slope K_m, k = K_m * A per node (a node on two mortar slave surfaces loses its output; a
node-to-surface stop pair beside the mortar pair needs a *SURFACE BEHAVIOR on the table and stalls when stiff).
The deck follows analysis.nlgeom like every other deck: without NLGEOM these near-rigid gaps give the
reference Lagrange path (24 x 6 x 1, inner stop: table sigma_N within 0.063 % of the peak to lambda 0.8,
0.23 % at 1; stop force within 0.1 % to 0.9), where the earlier NLGEOM deck was 10.8 % off at 0.8.

Face-to-face penalty (:func:`f2f_context`, docs/ccx_f2f.md): ``*CONTACT PAIR, TYPE=SURFACE TO SURFACE`` between the
base faces and a fixed master matching them node for node, LINEAR slope per face K = sum a_i (k_c,i / A_i) / a_face
(a uniform penetration d gives every node k_c,i d), *FRICTION with the stick slope of k_t likewise; GAPUNI stop
with the model's k_c; sigma_N from the RF of the master node under each slave node.

Every deck: C3D8I skirt, circumferential SPRING1 restraint of every table slave node, ``*COUPLING`` +
``*DISTRIBUTING`` (dofs 1-6) or ``*KINEMATIC`` (dofs 1-3) from the top-centre reference node; step 1 applies
N, step 2 repeats N and ramps lambda_max (T, M) with automatic incrementation (maximum increment
1/increments) and output at the time points j/increments; ``*EL PRINT, ELSET=EBASE`` S (bottom element row).
Units: model.units ('SI' or 'mm', :mod:`deckbridge.units`); ``** deckbridge-...`` comment lines (SI) carry
the model's slave table for :mod:`.reader`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from . import RECORD
from ...errors import DeckUnsupported
from ...mesh import SkirtMesh
from ...mesh_data import quad_nodal_areas
from ...model import Model
from ...numbering.inp import FACE_TOP, Layout
from .numbering import GapIds, ccx_gaps, ccx_layout, ccx_n2f_groups, ccx_node_slave_areas, ccx_penalty_is_n2f
from ...units import scale
from ...numbering.skirt import elem_ids, mesh_node_ids, mesh_node_index
from ...deck_elements import QUADRATIC_ELEMENTS, base_faces, corner_spring_k, face_label_lines, quadratic_face_slopes
from .quadratic_master import f2f_ring, pair_masters
from ...render._env import deck_paths, render
from ...render.inp_cards import (clean, element_lines, face_lines, id_lines, node_block, real, reals, shared_context,
                                 spring_groups)

MORTAR_HARD = True           # mortar table pair without *SURFACE BEHAVIOR: hard (Lagrange) contact
MORTAR_FACTOR = 1.0e4        # K_m = MORTAR_FACTOR * E / h1 [Pa/m]: stop gaps, stick slope, LINEAR variant
STICK_SLOPE_RATIO = 1.0e-2   # friction stick slope = ratio * normal slope
RESIDUAL_TOL = 1.0e-7        # *CONTROLS FIELD R_n (and R_p): largest residual / mean force
CORRECTION_TOL = 1.0e-6      # *CONTROLS FIELD C_n: largest correction / largest increment of the solution
MAX_ITER = 60                # *CONTROLS TIME INCREMENTATION I_C (I_0 = 20, I_R = I_P = I_L = MAX_ITER)
# Node-to-surface penalty deck: R_n is raised to ROUNDOFF_MARGIN x the round-off residual of its stiffest spring,
# eps k_max L (L = the largest slave coordinate), over the mean contact force N / n_table, where that exceeds
# RESIDUAL_TOL (see :func:`n2f_residual_tol`).
ROUNDOFF_MARGIN = 10.0
# Mortar deck with *FRICTION: ccx's maximum increment in step 2 is 1 / (MORTAR_FRICTION_SUBSTEPS x increments)
# (output still at the time points j / increments). ccx 2.20's mortar friction integrates the slip path
# poorly in large increments: scenario 16 x 4 x 2, pads, no stop, mu 0.3, 5 increments: with 0.2 it lands
# 100 % of the peak off the reference Lagrange at lambda 0.8 (all pad-edge force on the inner nodes, the
# mid nodes free), with 0.1 / 0.02 within 0.17 / 0.20 % at every lambda (the reference itself moves
# <= 0.11 % between 5 and 50 increments).
MORTAR_FRICTION_SUBSTEPS = 10


def _common(model: Model, lay: Layout, method: str) -> dict:
    mesh = lay.mesh
    return {
        **shared_context(model, lay),
        "model": model,
        "method": method,
        "step_nlgeom": model.analysis.nlgeom,
        "r_n": f"{RESIDUAL_TOL:.0e}", "c_n": f"{CORRECTION_TOL:.0e}", "max_iter": MAX_ITER,
        # I_0, I_R, I_P, I_C, I_L, I_G; blank fields keep ccx's defaults for the adaptive force scales
        "time_controls": f"20, {MAX_ITER}, {MAX_ITER}, {MAX_ITER}, {MAX_ITER}, 4",
        "field_controls": f"{real(RESIDUAL_TOL)}, {real(CORRECTION_TOL)}, , , {real(RESIDUAL_TOL)}",
        "meta": _meta_lines(model, mesh, method),
        "next_elem": lay.first_gap_elem,
        "tipping": _tipping_note(model),
        "friction_substeps": 0,
        "roundoff_note": "",
        "corner_springs": False,
    }


def _tipping_note(model: Model) -> str:
    """The header's warning when steps.lambda_max is at or past :meth:`Model.tipping_load_factor`, else ''."""
    tip, lam = model.tipping_load_factor(), model.steps.lambda_max
    if tip is None or lam < tip:
        return ""
    return (f"steps.lambda_max = {real(lam)} is past the tipping load of a compression-only base, lambda = "
            f"N (R + t/2) / (M + T H) = {real(tip)}: no equilibrium beyond it, ccx stops near it")


def _meta_lines(model: Model, mesh: SkirtMesh, method: str) -> list[str]:
    """``** deckbridge-...`` comment lines: what the reader needs without the model."""
    s = model.steps
    lines = [f"** deckbridge-job method={method} n_nodes={mesh.n_nodes} lambda_max={real(s.lambda_max)} "
             f"increments={s.increments} units={model.units}",
             "** deckbridge-slave node surface theta_deg r z area nx ny nz clearance"]
    for ss in (mesh.table, mesh.stop):
        if ss is None:
            continue
        ids = mesh_node_ids(mesh, ss.nodes)
        for i in range(ss.nodes.size):
            lines.append(f"** deckbridge-slave {ids[i]} {ss.surface} {real(ss.theta_deg[i])} "
                         f"{real(ss.r[i])} {real(ss.z[i])} {real(ss.area[i])} {reals(ss.normal[i])} "
                         f"{real(ss.clearance[i])}".replace(",", ""))
    return lines


def _gaps(model: Model, mesh: SkirtMesh, gap_ids: GapIds, k_of) -> dict:
    """GAPUNI elements, one per slave node of ``gap_ids``, to grounded nodes at the same place.

    ``k_of(slave_set)`` gives the stiffness per node [N/m]; the tension for a wide opening is
    f_inf = open_ratio * k_c * t with the model's own penalty k_c (never the stiffer mortar-like one).
    """
    t = model.geometry.thickness
    u = scale(model.units)
    k = [k_of(ss) for ss in gap_ids.sets]
    gaps = []
    for s_i, i, slave, node, elem in zip(gap_ids.set_index, gap_ids.row, gap_ids.slave, gap_ids.ground,
                                         gap_ids.elem):
        ss = gap_ids.sets[s_i]
        gaps.append({"elset": f"GAP_{ss.surface.upper()}_{slave}", "id": int(elem),
                     "elem": f"{elem}, {slave}, {node}",
                     # 10 digits: the line must stay within ccx's 132 characters
                     "line": f"{real(ss.clearance[i] * u.length, 10)}, {reals(clean(-ss.normal[i]), 10)}, , "
                             f"{real(k[s_i][i] * u.stiffness, 10)}, "
                             f"{real(mesh.k_open_ratio * ss.k[i] * t * u.force, 10)}"})
    ground_xyz = mesh.nodes[mesh_node_index(mesh, gap_ids.slave)]
    return {"ground": ("NGROUND", np.asarray(gap_ids.ground, int), np.array(ground_xyz, float).reshape(-1, 3)),
            "gaps": gaps,
            "gap_elems": id_lines([g["id"] for g in gaps])}


def check_supported(model: Model) -> None:
    """Raise :class:`DeckUnsupported` (before anything is written) when the penalty deck cannot carry the model."""
    mu = model.contact.friction
    if mu > 0 and getattr(model.contact, "tangential", "springs") != "friction":
        raise DeckUnsupported("calculix", f"contact.friction = {mu:g} with contact.tangential = springs: the CalculiX "
                              "penalty deck writes *FRICTION only when friction carries the shear (tangential = "
                              "friction); set friction to 0, or leave out the calculix dialect (`dialects`)")
    if mu > 0 and not ccx_penalty_is_n2f(model):
        raise DeckUnsupported("calculix", f"contact.friction = {mu:g} with analysis.nlgeom = true: the CalculiX "
                              "penalty deck is then GAPUNI gaps, which have no friction; set nlgeom to false "
                              "(node-to-surface contact with *FRICTION), or leave out the calculix dialect (`dialects`)")


def _stick_slopes(mesh: SkirtMesh, group, a_ccx: np.ndarray, rel: float = 1e-6) -> float:
    """The *FRICTION stick slope of a table group [Pa/m, SI]: k_t / A_ccx, ccx's tangential spring being
    the slope times the node's area (as the normal one); one value per group, else DeckUnsupported."""
    kt = np.asarray(mesh.k_tangent, float)[group.rows]
    slope = kt / a_ccx[mesh.table.nodes[group.rows]]
    if np.ptp(slope) > rel * np.abs(slope).max():
        raise DeckUnsupported("calculix", f"contact group {group.name}: k_t / A_ccx differs from node to node "
                              "(a fixed contact.penalty.k_tangent on unequal areas); use k_tangent: follow")
    return float(slope.mean())


def _n2f(model: Model, mesh: SkirtMesh, lay: Layout) -> dict:
    """Node-to-surface LINEAR groups, master surfaces and the ``** deckbridge-n2f`` area lines."""
    u = scale(model.units)
    t = model.geometry.thickness
    rings = {"TABLE": lay.table_master, "STOP": lay.stop_master}
    masters = [{"name": n, "faces": face_lines(r.elem_ids, r.face)} for n, r in rings.items() if r is not None]
    a_ccx = ccx_node_slave_areas(mesh)
    mu = model.contact.friction if getattr(model.contact, "tangential", "springs") == "friction" else 0.0
    groups = [{"name": g.name, "master": g.surface.upper(), "nodes": id_lines(g.nodes, 1),   # ccx: one node a line
               "line": f"{real(g.slope * u.stress / u.length)}, "
                       f"{real(mesh.k_open_ratio * g.slope * t * u.stress)}",
               "friction": (f"{real(mu)}, {real(_stick_slopes(mesh, g, a_ccx) * u.stress / u.length)}"
                            if mu > 0 and g.surface == "table" else "")} for g in ccx_n2f_groups(mesh)]
    meta = ["** deckbridge-n2f node surface area_ccx (m^2: ccx's area of the node-based slave node)"]
    for ss in (mesh.table, mesh.stop):
        if ss is not None:
            meta += [f"** deckbridge-n2f {i} {ss.surface} {real(a_ccx[n])}"
                     for i, n in zip(mesh_node_ids(mesh, ss.nodes), ss.nodes)]
    rs = [r for r in rings.values() if r is not None]
    return {"masters": masters, "groups": groups, "n2f_meta": meta,
            "master_elems": "\n".join(element_lines(r.elem_ids, r.conn) for r in rs),
            "master_nodes": ("NMASTER", np.concatenate([r.node_ids for r in rs]), np.vstack([r.nodes for r in rs]))}


def penalty_context(model: Model, mesh: SkirtMesh) -> dict:
    check_supported(model)
    lay = ccx_layout(model, mesh, "penalty")
    ctx = _common(model, lay, "penalty")
    ctx.update(_gaps(model, mesh, ccx_gaps(model, mesh, "penalty", lay), lambda ss: ss.k))
    n2f = ccx_penalty_is_n2f(model)
    ctx["n2f"] = n2f
    groups = [ctx["ground"]]
    if n2f:
        extra = _n2f(model, mesh, lay)
        ctx.update(extra)
        ctx["meta"] = ctx["meta"] + extra["n2f_meta"]
        groups = [extra["master_nodes"]]
        r_n = n2f_residual_tol(model, mesh)
        if r_n > RESIDUAL_TOL:         # stiff penalty: above the round-off residual of its stiffest spring
            ctx.update(r_n=f"{r_n:.1e}", field_controls=f"{real(r_n)}, {real(CORRECTION_TOL)}, , , {real(r_n)}",
                       roundoff_note=f"** R_n (and R_p) raised from {RESIDUAL_TOL:.0e} for this stiff penalty to "
                       f"{ROUNDOFF_MARGIN:g} x eps k_max L / (N / n_table):\n** the residual that round-off of the "
                       "slave positions leaves in the stiffest contact spring; below it ccx iterates on\n** "
                       "round-off until 'increment size smaller than minimum'.")
    ctx.update(node_block(mesh.nodes, lay.ref_node, lay.ref_xyz, groups, scale(model.units).length, mesh.node_ids))
    return ctx


def n2f_residual_tol(model: Model, mesh: SkirtMesh) -> float:
    """R_n of the node-to-surface penalty deck: RESIDUAL_TOL, or ROUNDOFF_MARGIN x eps k_max L / (N / n_table)
    where that is larger (stiff penalties). ccx computes a slave node's penetration from its position X + u (|X|
    up to L, metres); round-off of eps L there gives a spring of stiffness k_max [N/m] a residual force of about
    eps k_max L [N] that no iteration removes. Measured (24 x 4 x 1, R 1.2 m, t 12 mm, zero-clearance inner stop,
    stop k_c = 4.3e13 N/m at alpha 50): the largest residual toggled between 2e-3 and 8e-3 N on the stop nodes at
    theta 0 (eps k_max L = 1.1e-2 N) for 60 iterations, above R_n = 1e-7 x the mean force, until the increment fell
    below the minimum; with R_n 1e-5 the deck ran in 8 increments within 0.8 % of the reference Lagrange peak."""
    k = [float(np.max(ss.k)) for ss in (mesh.table, mesh.stop) if ss is not None and ss.nodes.size]
    slaves = np.concatenate([ss.nodes for ss in (mesh.table, mesh.stop) if ss is not None])
    length = float(np.abs(mesh.nodes[slaves]).max())
    mean_force = abs(model.loads.N) / max(mesh.table.nodes.size, 1)
    if not k or mean_force == 0.0:
        return RESIDUAL_TOL
    floor = ROUNDOFF_MARGIN * np.finfo(float).eps * max(k) * length / mean_force
    return float(max(RESIDUAL_TOL, floor))


def mortar_slope(model: Model, lay: Layout) -> float:
    """K_m = MORTAR_FACTOR * E / h1 [Pa/m]."""
    return MORTAR_FACTOR * model.material.E / lay.first_row_height


def mortar_context(model: Model, mesh: SkirtMesh) -> dict:
    lay = ccx_layout(model, mesh, "mortar")
    ctx = _common(model, lay, "mortar")
    tm = lay.table_master
    km = mortar_slope(model, lay)
    u = scale(model.units)
    km_deck = km * u.stress / u.length
    mu = model.contact.friction
    slave = (face_lines(lay.base_elems, "S1") if mesh.element in ("c3d8i", "c3d8") else   # issue 23: any type
             face_label_lines(mesh, mesh.base_elems, elem_ids(mesh, mesh.base_elems), 0.0))
    ctx.update(table_slave=slave, table_master=face_lines(tm.elem_ids, tm.face),
               master_elems=element_lines(tm.elem_ids, tm.conn),
               mortar_k=real(km_deck), mortar_hard=MORTAR_HARD, friction=mu > 0,
               friction_line=f"{real(mu)}, {real(STICK_SLOPE_RATIO * km_deck)}",
               mortar_factor=real(MORTAR_FACTOR), h1=real(lay.first_row_height * u.length))
    if mu > 0:
        n = model.steps.increments * MORTAR_FRICTION_SUBSTEPS
        ctx.update(step2_inc=reals([1.0 / n, 1.0, 1.0e-5 / n, 1.0 / n]),
                   inc_limit=max(ctx["inc_limit"], 10 * n), friction_substeps=MORTAR_FRICTION_SUBSTEPS)
    if mesh.quadratic_faces and ctx["springs"]:     # no SPRING1 on mid-side slave nodes (deck_elements.py)
        k = corner_spring_k(mesh)
        keep = k > 0
        groups = spring_groups(k[keep], mesh_node_ids(mesh, mesh.table.nodes)[keep], lay.next_elem)
        ctx.update(springs=[{**g, "elems": element_lines(g["elem_ids"], g["node_ids"][:, None]),
                             "k_str": real(g["k"] * u.stiffness)} for g in groups], corner_springs=True)
    ctx.update(_gaps(model, mesh, ccx_gaps(model, mesh, "mortar", lay), lambda ss: km * ss.area))
    ctx.update(node_block(mesh.nodes, lay.ref_node, lay.ref_xyz,
                          [("NMASTER", tm.node_ids, tm.nodes), ctx["ground"]], u.length, mesh.node_ids))
    return ctx


def f2f_face_slopes(mesh: SkirtMesh, k_node: np.ndarray | None = None) -> np.ndarray:
    """Slope K [Pa/m, SI] of each table slave face (``mesh.base_elems`` order) of the face-to-face deck: the
    nodal stiffness k_i [N/m] over the node's tributary area A_i, averaged over the face with its nodal area
    shares a_i, sum a_i k_i / A_i / a_face, so that a uniform penetration (slip) d gives every node k_i d.
    ``k_node``: per table row (default the model's normal k_c; the friction stick slope passes k_t)."""
    tab = mesh.table
    k = tab.k if k_node is None else np.asarray(k_node, float)
    row = np.full(mesh.n_nodes, -1)
    row[tab.nodes] = np.arange(tab.nodes.size)
    faces = mesh.hexes[mesh.base_elems][:, :4]
    a = quad_nodal_areas(mesh.nodes[faces])
    q = (k / tab.area)[row[faces]]
    return (a * q).sum(axis=1) / a.sum(axis=1)


def _f2f_master(mesh: SkirtMesh, first_node: int, first_elem: int, t: float) -> dict:
    """The face-to-face deck's table: one fixed C3D8 under each slave base face, its top face (S2) on the
    face's own nodes' places (z as in the mesh) and its bottom t lower, so that master and slave meshes match
    node for node and the RF of a master top node is the contact force on the slave node above it."""
    tab = mesh.table.nodes
    row = np.full(mesh.n_nodes, -1)
    row[tab] = np.arange(tab.size)
    top_ids = first_node + np.arange(tab.size)
    bot_ids = top_ids + tab.size
    top_xyz = mesh.nodes[tab]
    bot_xyz = top_xyz - np.array([0.0, 0.0, t])
    faces = row[mesh.hexes[mesh.base_elems][:, :4]]           # skirt face 1-2-3-4 (S1, normal -z)
    conn = np.hstack([bot_ids[faces], top_ids[faces]])         # same turn below, then above: S2 is the top
    elems = first_elem + np.arange(faces.shape[0])
    return {"top": ("NMTOP", top_ids, top_xyz), "bottom": ("NMBOT", bot_ids, bot_xyz),
            "master_elems": element_lines(elems, conn), "table_master": face_lines(elems, FACE_TOP), "elems": elems,
            "pairs": [f"** deckbridge-f2f-master {s} {m}" for s, m in zip(mesh_node_ids(mesh, tab), top_ids)]}


def f2f_context(model: Model, mesh: SkirtMesh) -> dict:
    """The face-to-face (``SURFACE TO SURFACE``) penalty deck: table pair(s) of equal face slope on a master
    that matches the slave mesh, GAPUNI stop with the model's k_c."""
    lay = ccx_layout(model, mesh, "f2f")
    ctx = _common(model, lay, "f2f")
    u = scale(model.units)
    t = model.geometry.thickness
    mu = model.contact.friction if getattr(model.contact, "tangential", "springs") == "friction" else 0.0
    quad = mesh.quadratic_faces          # issue 23: 8-/6-node faces on a matching C3D20 / C3D15 master
    faces = base_faces(mesh) if quad else []
    if quad:
        slope = quadratic_face_slopes(mesh, faces, mesh.table.k)
        stick = quadratic_face_slopes(mesh, faces, mesh.k_tangent) if mu > 0 else np.zeros_like(slope)
        labels = np.array([f"{elem_ids(mesh, np.array([e]))[0]}, S{k}" for e, k, _ in faces], dtype=object)
    else:
        slope = f2f_face_slopes(mesh)
        stick = f2f_face_slopes(mesh, mesh.k_tangent) if mu > 0 else np.zeros_like(slope)
    groups, masks, left = [], [], np.ones(slope.size, bool)
    while left.any():              # faces of equal slopes (1e-6) share a surface and an interaction
        i0 = np.flatnonzero(left)[0]
        same = left & (np.abs(slope - slope[i0]) <= 1e-6 * abs(slope[i0])) & (
            np.abs(stick - stick[i0]) <= 1e-6 * abs(stick[i0]))
        k0 = slope[i0]
        groups.append({"name": f"TABLE{len(groups) + 1}",
                       "faces": "\n".join(labels[same]) if quad else face_lines(lay.base_elems[same], "S1"),
                       "line": f"{real(k0 * u.stress / u.length)}, {real(mesh.k_open_ratio * k0 * t * u.stress)}",
                       "friction": f"{real(mu)}, {real(stick[i0] * u.stress / u.length)}" if mu > 0 else ""})
        left &= ~same
        masks.append(same)
    gap_ids = ccx_gaps(model, mesh, "f2f", lay)
    ctx.update(_gaps(model, mesh, gap_ids, lambda ss: ss.k))
    first = (lay.next_node + gap_ids.ground.size, lay.first_gap_elem + gap_ids.elem.size)
    master = f2f_ring(model, mesh, *first) if quad else _f2f_master(mesh, *first, t)
    surfaces, copies, copy_elems = pair_masters(model, mesh, master, masks, quad)   # one master per pair
    for g, (name, lines) in zip(groups, surfaces):
        g.update(master=name, master_faces=lines)
    ctx.update(f2f_groups=groups, table_master=master["table_master"], quadratic=quad, master_copies=copies[1].size,
               master_elems="\n".join(x for x in (master["master_elems"], copy_elems) if x))
    if not quad:
        ctx["meta"] = ctx["meta"] + ["** deckbridge-f2f-master slave master (the master top node under each table "
                                     "slave node: its RF is the slave's contact force)"] + master["pairs"]
    ctx.update(node_block(mesh.nodes, lay.ref_node, lay.ref_xyz, [ctx["ground"], master["top"], master["bottom"],
                                                                   copies], u.length, mesh.node_ids))
    return ctx


DECKS = (("penalty", penalty_context, "penalty.inp.j2"), ("mortar", mortar_context, "mortar.inp.j2"),
         ("f2f", f2f_context, "f2f.inp.j2"))     # in the order of the dialect record's deck names


def write(model: Model, mesh: SkirtMesh, outdir: Path) -> list[Path]:
    """Write the CalculiX penalty (node-to-surface or GAPUNI), mortar and face-to-face decks into ``outdir``.

    The face-to-face deck only for the small-strain analysis (analysis.nlgeom false): with NLGEOM (matrix case
    inp, inner stop, n_r 2, t/R 0.005, pads, cone, kinematic, mm) its top swayed 36 mm at lambda 1 against
    13 mm (nodal penalty, same k_c) and 4 mm (mortar), its moment off the load by 2.3 % of N R; not explained
    (docs/ccx_f2f.md), so it is not written."""
    check_supported(model)
    paths = dict(zip((d[0] for d in DECKS), deck_paths(RECORD, model.name, outdir)))
    out = []
    for method, ctx_fn, tpl in DECKS:
        if method == "f2f" and model.analysis.nlgeom:
            continue
        if method == "penalty" and mesh.quadratic_faces:   # node-to-surface / GAPUNI: node-based (issue 23)
            continue
        if mesh.blocks and method != "mortar" and not (method == "f2f" and mesh.quadratic_faces):
            continue          # a mixed mesh: the mortar deck, and on second order the face-to-face deck too
        if method == "f2f" and not all(t in ("c3d8", "c3d8i", *QUADRATIC_ELEMENTS) for t in mesh.element.split("+")):
            continue
        text = render(RECORD.templates, tpl, **ctx_fn(model, mesh))
        p = paths[method]
        p.write_text(text)
        out.append(p)
    return out
