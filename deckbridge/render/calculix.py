"""CalculiX 2.20 decks: ``<name>_ccx_penalty.inp`` (GAPUNI gaps) and ``<name>_ccx_lagrange.inp`` (mortar).

Penalty: one GAPUNI element per slave node, from the skirt node to a grounded node at the same place,
with exactly the neutral model's stiffness k_c [N/m] (mesh.table.k, mesh.stop.k) on its ``*GAP`` line, the
direction -n (n = master normal pointing into the skirt) and the clearance. The gap's tension for a wide
opening is written explicitly: f_inf = open_ratio * k_c * t (t = wall thickness; ccx's default 1e-3 N
would be a hidden number). GAPUNI needs ``NLGEOM`` in 2.20 (without it reactions came out doubled).
GAPUNI gaps are frictionless: a model with contact.friction > 0 is refused for this deck.

Lagrange-type: ``*CONTACT PAIR, TYPE=MORTAR`` (dual shape functions) between the skirt's first-row base
faces (slave) and the top faces of a fixed C3D8 ring (master, see :mod:`deckbridge.numbering.inp`). With
MORTAR_HARD (default) the interaction has no ``*SURFACE BEHAVIOR``: ccx 2.20 then enforces hard contact
with Lagrange multipliers (measured penetration ~1e-24 m; a ``PRESSURE-OVERCLOSURE=HARD`` card would be
reduced to a linear penalty with hidden defaults). Otherwise it writes ``PRESSURE-OVERCLOSURE=LINEAR`` with
the explicit slope K_m = MORTAR_FACTOR * E / h1 [Pa/m] (h1 = first-row height; penetration 1/MORTAR_FACTOR
of the first row's elastic shortening under the same pressure). Friction, when mu > 0, has the stick
slope K_m / 100 (ccx's advice). The radial stop is not a second mortar pair: its base nodes are also
table slaves, and ccx 2.20 loses the output (CPRESS 0) of a node on two mortar slave surfaces; it is
GAPUNI gaps with the slope K_m, k = K_m * A per node. The nodal contact force is printed as RF of the
table slaves (the fixed master's RF stays 0 with mortar).

Both decks: C3D8I skirt, circumferential SPRING1 restraint of every table slave node (cylindrical
``*ORIENTATION``, local dof 2, stiffness mesh.k_tangent), ``*COUPLING`` + ``*DISTRIBUTING`` (dofs 1-6) or
``*KINEMATIC`` (dofs 1-3) from the top-centre reference node; step 1 applies N, step 2 repeats N (the
first ``*CLOAD`` on the reference node in a step replaces all earlier ones) and ramps lambda_max (T, M) in
``steps.increments`` fixed increments (``*STATIC, DIRECT``): one ccx increment per model increment.
Comment lines ``** deckbridge-...`` carry the model's slave table for :mod:`deckbridge.readers.calculix`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import DeckbridgeError
from ..mesh import SkirtMesh
from ..model import Model
from ..numbering.inp import GapIds, Layout, ccx_gaps, ccx_layout
from ..numbering.skirt import mesh_node_ids, mesh_node_index
from ._env import deck_paths, render
from .inp_cards import element_lines, face_lines, id_lines, node_block, real, reals, shared_context

MORTAR_HARD = True           # mortar table pair without *SURFACE BEHAVIOR: hard (Lagrange) contact
MORTAR_FACTOR = 1.0e4        # K_m = MORTAR_FACTOR * E / h1 [Pa/m]: stop gaps, stick slope, LINEAR variant
STICK_SLOPE_RATIO = 1.0e-2   # friction stick slope = ratio * normal slope
RESIDUAL_TOL = 1.0e-7        # *CONTROLS FIELD R_n (and R_p): largest residual / mean force
CORRECTION_TOL = 1.0e-6      # *CONTROLS FIELD C_n: largest correction / largest increment of the solution
MAX_ITER = 60                # *CONTROLS TIME INCREMENTATION I_C (I_0 = 20, I_R = I_P = I_L = MAX_ITER)
INC_LIMIT = 1000             # *STEP, INC= (upper bound on increments; DIRECT uses exactly the given ones)


def _common(model: Model, lay: Layout, method: str) -> dict:
    mesh = lay.mesh
    return {
        **shared_context(model, lay, INC_LIMIT),
        "model": model,
        "method": method,
        "r_n": f"{RESIDUAL_TOL:.0e}", "c_n": f"{CORRECTION_TOL:.0e}", "max_iter": MAX_ITER,
        # I_0, I_R, I_P, I_C, I_L, I_G; blank fields keep ccx's defaults for the adaptive force scales
        "time_controls": f"20, {MAX_ITER}, {MAX_ITER}, {MAX_ITER}, {MAX_ITER}, 4",
        "field_controls": f"{real(RESIDUAL_TOL)}, {real(CORRECTION_TOL)}, , , {real(RESIDUAL_TOL)}",
        "meta": _meta_lines(model, mesh, method),
        "next_elem": lay.first_gap_elem,
    }


def _meta_lines(model: Model, mesh: SkirtMesh, method: str) -> list[str]:
    """``** deckbridge-...`` comment lines: what the reader needs without the model."""
    s = model.steps
    lines = [f"** deckbridge-job method={method} n_nodes={mesh.n_nodes} lambda_max={real(s.lambda_max)} "
             f"increments={s.increments}",
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
    k = [k_of(ss) for ss in gap_ids.sets]
    gaps = []
    for s_i, i, slave, node, elem in zip(gap_ids.set_index, gap_ids.row, gap_ids.slave, gap_ids.ground,
                                         gap_ids.elem):
        ss = gap_ids.sets[s_i]
        gaps.append({"elset": f"GAP_{ss.surface.upper()}_{slave}", "id": int(elem),
                     "elem": f"{elem}, {slave}, {node}",
                     # 10 digits: the line must stay within ccx's 132 characters
                     "line": f"{real(ss.clearance[i], 10)}, {reals(-ss.normal[i], 10)}, , {real(k[s_i][i], 10)}, "
                             f"{real(mesh.k_open_ratio * ss.k[i] * t, 10)}"})
    ground_xyz = mesh.nodes[mesh_node_index(mesh, gap_ids.slave)]
    return {"ground": ("NGROUND", np.asarray(gap_ids.ground, int), np.array(ground_xyz, float).reshape(-1, 3)),
            "gaps": gaps,
            "gap_elems": id_lines([g["id"] for g in gaps])}


def penalty_context(model: Model, mesh: SkirtMesh) -> dict:
    if model.contact.friction > 0:
        raise DeckbridgeError(f"contact.friction = {model.contact.friction:g}: the CalculiX penalty deck uses "
                              "GAPUNI gap elements, which are frictionless: set it to 0, or leave out the calculix "
                              "dialect (--dialect)")
    lay = ccx_layout(model, mesh, "penalty")
    ctx = _common(model, lay, "penalty")
    ctx.update(_gaps(model, mesh, ccx_gaps(model, mesh, "penalty", lay), lambda ss: ss.k))
    ctx.update(node_block(mesh.nodes, lay.ref_node, lay.ref_xyz, [ctx["ground"]], mesh.node_ids))
    return ctx


def mortar_slope(model: Model, lay: Layout) -> float:
    """K_m = MORTAR_FACTOR * E / h1 [Pa/m]."""
    return MORTAR_FACTOR * model.material.E / lay.first_row_height


def mortar_context(model: Model, mesh: SkirtMesh) -> dict:
    lay = ccx_layout(model, mesh, "mortar")
    ctx = _common(model, lay, "mortar")
    tm = lay.table_master
    km = mortar_slope(model, lay)
    mu = model.contact.friction
    ctx.update(table_slave=face_lines(lay.base_elems, "S1"), table_master=face_lines(tm.elem_ids, tm.face),
               master_elems=element_lines(tm.elem_ids, tm.conn),
               mortar_k=real(km), mortar_hard=MORTAR_HARD, friction=mu > 0, friction_line=f"{real(mu)}, {real(STICK_SLOPE_RATIO * km)}",
               mortar_factor=real(MORTAR_FACTOR), h1=real(lay.first_row_height))
    ctx.update(_gaps(model, mesh, ccx_gaps(model, mesh, "mortar", lay), lambda ss: km * ss.area))
    ctx.update(node_block(mesh.nodes, lay.ref_node, lay.ref_xyz,
                          [("NMASTER", tm.node_ids, tm.nodes), ctx["ground"]], mesh.node_ids))
    return ctx


def write(model: Model, mesh: SkirtMesh, outdir: Path) -> list[Path]:
    """Write the CalculiX penalty (GAPUNI) and mortar decks into ``outdir``."""
    paths = dict(zip(("penalty", "mortar"), deck_paths("calculix", model.name, outdir)))
    out = []
    for method, ctx_fn, tpl in (("penalty", penalty_context, "penalty.inp.j2"),
                                ("mortar", mortar_context, "mortar.inp.j2")):
        text = render("calculix", tpl, **ctx_fn(model, mesh))
        p = paths[method]
        p.write_text(text)
        out.append(p)
    return out
