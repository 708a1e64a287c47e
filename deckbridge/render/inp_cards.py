"""Shared card lines of the inp-family decks (Abaqus/Standard and CalculiX).

The ids (skirt, reference node, master rings, springs, gaps) and the face labels are in
:mod:`deckbridge.numbering.inp`. Master surfaces are element faces of fixed rings of C3D8 elements (no
analytical rigid surfaces, so that the same deck geometry reads in Abaqus and CalculiX); only the base
nodes of the skirt project onto the stop ring (the neutral model's stop slaves: lower half of the
first-row wall faces).

Reals are written with an exponent everywhere (CalculiX misreads some integer-looking reals).
"""

from __future__ import annotations


import numpy as np

from ..model import Model
from ..numbering.inp import Layout
from ..numbering.skirt import elem_ids, mesh_node_ids

PER_LINE = 8   # ids per data line of *NSET / *ELSET (both codes accept up to 16)


def real(x: float, digits: int = 13) -> str:
    """A real with an exponent and ``digits`` significant digits, e.g. ``1.500000000000e+00`` (no -0)."""
    x = float(x)
    return f"{x + 0.0 if x != 0 else 0.0:.{digits - 1}e}"


def reals(values, digits: int = 13) -> str:
    return ", ".join(real(v, digits) for v in values)


def id_lines(ids, per_line: int = PER_LINE) -> str:
    """Integer ids, ``per_line`` per line, comma separated (set data lines)."""
    ids = [int(i) for i in ids]
    return "\n".join(", ".join(str(i) for i in ids[k:k + per_line]) for k in range(0, len(ids), per_line))


def node_lines(ids, xyz) -> str:
    """``*NODE`` data lines ``id, x, y, z``."""
    return "\n".join(f"{int(i)}, {real(p[0])}, {real(p[1])}, {real(p[2])}" for i, p in zip(ids, xyz))


def node_block(mesh_nodes, ref_node: int, ref_xyz, groups, skirt_ids=None) -> dict:
    """One ``*NODE`` block for the whole deck (meshio and others read only one) and its node sets.

    ``groups``: (set name, ids, xyz) of the extra nodes after the skirt and the reference node;
    ``skirt_ids``: the skirt's node ids (None: 1..n); NSKIRT is written only when they run 1..n.
    Returns ``nodes`` (data lines) and ``node_sets`` (name, first id, last id) for ``*NSET, GENERATE``.
    """
    n = mesh_nodes.shape[0]
    ids = np.arange(1, n + 1) if skirt_ids is None else np.asarray(skirt_ids)
    lines = [node_lines(ids, mesh_nodes), f"{ref_node}, {reals(ref_xyz)}"]
    sets = ([("NSKIRT", 1, n)] if np.array_equal(ids, np.arange(1, n + 1)) else []) + [("NREF", ref_node, ref_node)]
    for name, ids, xyz in groups:
        if len(ids):
            lines.append(node_lines(ids, xyz))
            sets.append((name, int(ids[0]), int(ids[-1])))
    return {"nodes": "\n".join(lines), "node_sets": sets}


def element_lines(ids, conn) -> str:
    """``*ELEMENT`` data lines ``id, n1, ..., nk`` (node ids, 1-based)."""
    return "\n".join(f"{int(e)}, " + ", ".join(str(int(n)) for n in c) for e, c in zip(ids, conn))


def face_lines(elems, label: str) -> str:
    """Element-based ``*SURFACE`` data lines ``element, Sx``."""
    return "\n".join(f"{int(e)}, {label}" for e in elems)


def spring_groups(k: np.ndarray, node_ids: np.ndarray, first_elem: int):
    """SPRING1 elements, one per node, grouped by equal stiffness (relative 1e-12).

    Returns a list of dicts: ``name``, ``k``, ``elem_ids``, ``node_ids``.
    """
    k = np.asarray(k, float)
    order = np.argsort(k, kind="stable")
    groups: list[list[int]] = []
    for idx in order:
        if groups and abs(k[idx] - k[groups[-1][0]]) <= 1e-12 * abs(k[groups[-1][0]]):
            groups[-1].append(int(idx))
        else:
            groups.append([int(idx)])
    out, eid = [], first_elem
    for n, g in enumerate(groups, start=1):
        g = sorted(g)
        ids = np.arange(eid, eid + len(g))
        eid += len(g)
        out.append({"name": f"KTAN{n}", "k": float(np.mean(k[g])), "elem_ids": ids,
                    "node_ids": np.asarray(node_ids)[g]})
    return out


def shared_context(model: Model, lay: Layout, inc_limit: int) -> dict:
    """Template values both Abaqus-style dialects share: skirt elements, springs, loads, increments.

    Step 1 applies N at the reference node; step 2 repeats N and adds lambda_max (T, M), as totals.
    """
    mesh, lv, s = lay.mesh, lay.loads, model.steps
    springs = spring_groups(mesh.k_tangent, mesh_node_ids(mesh, mesh.table.nodes), lay.next_elem)
    step2 = {1: lv["T_force"][0] * s.lambda_max, 2: lv["T_force"][1] * s.lambda_max, 3: lv["N_force"][2],
             4: lv["M_moment"][0] * s.lambda_max, 5: lv["M_moment"][1] * s.lambda_max}
    return {
        "title": model.title, "name": model.name,
        "skirt_elems": element_lines(elem_ids(mesh, np.arange(mesh.hexes.shape[0])), mesh_node_ids(mesh, mesh.hexes)),
        "ref_node": lay.ref_node,
        "table_nodes": id_lines(mesh_node_ids(mesh, mesh.table.nodes)),
        "stop_nodes": id_lines(mesh_node_ids(mesh, mesh.stop.nodes)) if mesh.stop is not None else "",
        "top_faces": face_lines(lay.top_elems, "S2"),
        "springs": [{**g, "elems": element_lines(g["elem_ids"], g["node_ids"][:, None]), "k_str": real(g["k"])}
                    for g in springs],
        "E": real(model.material.E), "nu": real(model.material.nu),
        "kinematic": model.load_introduction == "kinematic",
        "step1_loads": [(3, real(lv["N_force"][2]))],
        "step2_loads": [(dof, real(v)) for dof, v in step2.items()],
        # initial increment, step period, minimum and maximum increment (all equal: fixed increments)
        "step1_inc": reals([1.0, 1.0, 1.0, 1.0]),
        "step2_inc": reals([1.0 / s.increments, 1.0, 1.0 / s.increments, 1.0 / s.increments]),
        "increments": s.increments, "inc_limit": inc_limit,
    }
