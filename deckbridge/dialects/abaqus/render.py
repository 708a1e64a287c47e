"""Abaqus/Standard Lagrange deck ``<name>_lagrange.inp`` (renderer "abaqus"; not run here: no Abaqus).

Contact: node-based slave surfaces ``*SURFACE, TYPE=NODE`` (table: every base node; stop: the base nodes
on the stop-side wall face) with each node's tributary area on its data line, so that CPRESS is a
pressure. Masters are element-based surfaces of fixed C3D8 rings (see :mod:`deckbridge.numbering.inp`): Abaqus accepts
them as master surfaces without a rigid-body definition, and the same geometry serves the CalculiX
mortar deck. ``*CONTACT PAIR, TYPE=NODE TO SURFACE`` per pair, ``*SURFACE BEHAVIOR,
PRESSURE-OVERCLOSURE=HARD, DIRECT`` (Lagrange multipliers, written explicitly: the enforcement default
depends on the pair type) and ``*FRICTION`` = contact.friction on the table pair (``LAGRANGE`` stick when
mu > 0), 0 on the stop pair (the radial stop is frictionless, as in the reference solver).

Rest as in the CalculiX decks: C3D8I skirt, circumferential SPRING1 per table node (cylindrical
``*ORIENTATION``, local dof 2, mesh.k_tangent), ``*COUPLING`` + ``*DISTRIBUTING`` (uniform weighting, i.e.
tributary-area weights on the element-based top surface) or ``*KINEMATIC`` from the top-centre reference
node; step 1: N; step 2: N repeated + lambda_max (T, M) with automatic incrementation (``*STATIC`` with
initial, period, minimum and maximum increment = 1/increments, no DIRECT: cutbacks allowed where the contact
state changes) and output at ``*TIME POINTS`` j/increments; ``NLGEOM=YES|NO`` from analysis.nlgeom;
``*STEP, INC=`` from the model. Output: CSTRESS/CDISP field output, ``*CONTACT PRINT`` per pair (surface
names contain TABLE / STOP for the .dat reader) and ``*EL PRINT, ELSET=EBASE`` S. Units: model.units.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from . import RECORD
from ...mesh import SkirtMesh
from ...model import Model
from ...numbering.inp import layout
from ...numbering.skirt import mesh_node_ids
from ...render._env import deck_paths, render
from ...units import scale
from ...render.inp_cards import element_lines, face_lines, node_block, real, shared_context


def context(model: Model, mesh: SkirtMesh) -> dict:
    u = scale(model.units)
    lay = layout(model, mesh, masters=("table", "stop"))
    rings = [r for r in (lay.table_master, lay.stop_master) if r is not None]
    mu = model.contact.friction
    pairs = [{"name": "TABLE", "slave": _node_surface(mesh.table, mesh, u.length),
              "master": face_lines(lay.table_master.elem_ids, lay.table_master.face),
              "friction": real(mu), "lagrange_friction": mu > 0}]
    if lay.stop_master is not None:     # the radial stop is frictionless (docs/friction.md)
        pairs.append({"name": "STOP", "slave": _node_surface(mesh.stop, mesh, u.length),
                      "master": face_lines(lay.stop_master.elem_ids, lay.stop_master.face),
                      "friction": real(0.0), "lagrange_friction": False})
    return {
        **shared_context(model, lay),
        **node_block(mesh.nodes, lay.ref_node, lay.ref_xyz,
                     [("NMASTER", np.concatenate([r.node_ids for r in rings]),
                       np.vstack([r.nodes for r in rings]))], u.length, mesh.node_ids),
        "master_elems": "\n".join(element_lines(r.elem_ids, r.conn) for r in rings),
        "pairs": pairs,
    }


def _node_surface(ss, ss_mesh, length: float = 1.0) -> str:
    """``node, tributary area`` data lines of a node-based slave surface (user node ids, area in deck units)."""
    return "\n".join(f"{int(n)}, {real(a * length ** 2)}"
                     for n, a in zip(mesh_node_ids(ss_mesh, ss.nodes), ss.area))


def write(model: Model, mesh: SkirtMesh, outdir: Path) -> list[Path]:
    """Write the Abaqus/Standard Lagrange deck into ``outdir``."""
    (p,) = deck_paths(RECORD, model.name, outdir)
    p.write_text(render(RECORD.templates, "lagrange.inp.j2", **context(model, mesh)))
    return [p]
