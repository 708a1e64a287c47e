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

from ..deck_elements import CCX_TYPE, ccx_element_lines, face_label_lines
from ..model import Model
from ..numbering.inp import Layout
from ..numbering.skirt import bottom_row_index, elem_ids, mesh_node_ids
from ..units import UNIT_LABEL, Units, scale

PER_LINE = 8   # ids per data line of *NSET / *ELSET (both codes accept up to 16)


def real(x: float, digits: int = 13) -> str:
    """A real with an exponent and ``digits`` significant digits, e.g. ``1.500000000000e+00`` (no -0)."""
    x = float(x)
    return f"{x + 0.0 if x != 0 else 0.0:.{digits - 1}e}"


def clean(v, scale_of: float = 1.0, rel: float = 1e-13):
    """``v`` with round-off residues (|x| < rel * scale_of, e.g. 6.123e-17 of a unit vector) set to 0."""
    a = np.array(v, float)
    a[np.abs(a) < rel * scale_of] = 0.0
    return a


def reals(values, digits: int = 13) -> str:
    return ", ".join(real(v, digits) for v in values)


def id_lines(ids, per_line: int = PER_LINE) -> str:
    """Integer ids, ``per_line`` per line, comma separated (set data lines)."""
    ids = [int(i) for i in ids]
    return "\n".join(", ".join(str(i) for i in ids[k:k + per_line]) for k in range(0, len(ids), per_line))


def node_lines(ids, xyz, length: float = 1.0) -> str:
    """``*NODE`` data lines ``id, x, y, z`` (coordinates [m] times ``length``, round-off residues cleaned)."""
    xyz = np.asarray(xyz, float)
    xyz = clean(xyz, float(np.abs(xyz).max()) if xyz.size else 1.0) * length
    return "\n".join(f"{int(i)}, {real(p[0])}, {real(p[1])}, {real(p[2])}" for i, p in zip(ids, xyz))


def node_block(mesh_nodes, ref_node: int, ref_xyz, groups, length: float = 1.0, skirt_ids=None) -> dict:
    """One ``*NODE`` block for the whole deck (meshio and others read only one) and its node sets.

    ``groups``: (set name, ids, xyz) of the extra nodes after the skirt and the reference node;
    ``skirt_ids``: the skirt's node ids (None: 1..n; an imported mesh: the user's ids, numbering/skirt.py).
    Returns ``nodes`` (data lines) and ``node_sets`` (name, first id, last id) for ``*NSET, GENERATE``.
    """
    n = mesh_nodes.shape[0]
    ids = np.arange(1, n + 1) if skirt_ids is None else np.asarray(skirt_ids)
    lines = [node_lines(ids, mesh_nodes, length), node_lines([ref_node], [ref_xyz], length)]
    sets = []
    for name, ids, xyz in groups:
        if len(ids):
            lines.append(node_lines(ids, xyz, length))
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


def inc_limit(model: Model) -> int:
    """``*STEP, INC=``: the cap on increments, above the step's (10 x increments, at least 1000)."""
    return max(1000, 10 * model.steps.increments)


def time_points(model: Model) -> list[str]:
    """Step-2 output times (step period 1): j / increments, j = 1..increments (lambda_j = j lambda_max / n)."""
    n = model.steps.increments
    return [real(j / n) for j in range(1, n + 1)]


def stiffness_note(model: Model, mesh) -> list[str]:
    """Comment lines: alpha, the k_c range [N/m] and KA / (E A / h1) of the base row (the paper's subject)."""
    z = mesh.nodes[:, 2]
    h1 = float(np.min(z[z > 1e-12 * model.geometry.height]))
    ratio = mesh.table.k / (model.material.E * mesh.table.area / h1)
    pen = model.contact.penalty
    how = f"alpha = {pen.alpha:g}" if pen.k_normal is None else f"explicit k_normal = {pen.k_normal:g} N/m"
    lines = [f"Penalty: {how}; k_c = alpha A^2 K / V per slave node (SI, whatever the deck units):",
             f"  table k_c from {mesh.table.k.min():.4g} to {mesh.table.k.max():.4g} N/m"]
    if mesh.stop is not None:
        lines.append(f"  radial stop k_c from {mesh.stop.k.min():.4g} to {mesh.stop.k.max():.4g} N/m")
    lines += [f"KA / (E A / h1) = {ratio.min():.3g} .. {ratio.max():.3g}: k_c over the axial stiffness of the base "
              f"element above the node (h1 = {h1:.4g} m);",
              f"  the usual Nastran guidance (KA ~ 1e3 x that stiffness) is ~{1e3 / max(ratio.mean(), 1e-300):.0e} "
              "times stiffer."]
    return lines


def shared_context(model: Model, lay: Layout, inc_limit_: int | None = None) -> dict:
    """Template values both Abaqus-style dialects share: skirt elements, springs, loads, increments,
    units (every number scaled to the deck units), NLGEOM, the EBASE stress set.

    Step 1 applies N at the reference node; step 2 repeats N and adds lambda_max (T, M), as totals.
    """
    mesh, lv, s = lay.mesh, lay.loads, model.steps
    u: Units = scale(model.units)
    springs = ([] if model.contact.tangential == "friction"          # friction carries T, no springs
               else spring_groups(mesh.k_tangent, mesh_node_ids(mesh, mesh.table.nodes), lay.next_elem))
    f, m = u.force, u.moment
    step2 = {1: lv["T_force"][0] * s.lambda_max * f, 2: lv["T_force"][1] * s.lambda_max * f, 3: lv["N_force"][2] * f,
             4: lv["M_moment"][0] * s.lambda_max * m, 5: lv["M_moment"][1] * s.lambda_max * m}
    step2 = dict(zip(step2, clean(list(step2.values()), max(abs(v) for v in step2.values()))))
    n = s.increments
    el = getattr(mesh, "element", "c3d8i")
    eids = elem_ids(mesh, np.arange(mesh.hexes.shape[0]))
    blocks = getattr(mesh, "blocks", ())              # a mixed mesh: one *ELEMENT and element set per type
    return {
        "skirt_type": CCX_TYPE.get(el, ""),
        "skirt_elems": ("" if blocks else
                        element_lines(eids, mesh_node_ids(mesh, mesh.hexes)) if el in ("c3d8i", "c3d8") else
                        ccx_element_lines(eids, mesh_node_ids(mesh, mesh.hexes))),
        "skirt_blocks": mixed_blocks(mesh, eids),
        "top_faces": (face_lines(lay.top_elems, "S2") if el in ("c3d8i", "c3d8") else
                      face_label_lines(mesh, mesh.top_elems, elem_ids(mesh, mesh.top_elems), model.geometry.height)),
        "units": u, "unit_label": UNIT_LABEL[u.name], "nlgeom": model.analysis.nlgeom,
        "base_elems": id_lines(elem_ids(mesh, bottom_row_index(mesh))),   # EBASE: the whole row, pads or not
        "time_points": time_points(model),
        "stiffness_note": stiffness_note(model, mesh),
        "title": model.title, "name": model.name,
        "ref_node": lay.ref_node,
        "table_nodes": id_lines(mesh_node_ids(mesh, mesh.table.nodes)),
        "stop_nodes": id_lines(mesh_node_ids(mesh, mesh.stop.nodes)) if mesh.stop is not None else "",
        "springs": [{**g, "elems": element_lines(g["elem_ids"], g["node_ids"][:, None]),
                     "k_str": real(g["k"] * u.stiffness)} for g in springs],
        "E": real(model.material.E * u.stress), "nu": real(model.material.nu),
        "kinematic": model.load_introduction == "kinematic",
        "step1_loads": [(3, real(lv["N_force"][2] * f))],
        "step2_loads": [(dof, real(v)) for dof, v in step2.items()],
        # initial increment, step period, minimum and maximum increment (automatic incrementation,
        # the maximum increment = the compared load-factor spacing, output at the time points)
        "step1_inc": reals([1.0, 1.0, 1.0e-5, 1.0]),
        "step2_inc": reals([1.0 / n, 1.0, 1.0e-5 / n, 1.0 / n]),
        "increments": n, "inc_limit": inc_limit_ or inc_limit(model),
    }


def mixed_blocks(mesh, eids: np.ndarray) -> list[dict]:
    """``*ELEMENT`` blocks of a mixed mesh (``mesh.blocks``, cells numbered block by block; deck ids ``eids``):
    {'type': CalculiX name, 'elset': ESKIRT_<name>, 'elems': data lines}; [] for a mesh of one type."""
    out, start = [], 0
    for name, cells in getattr(mesh, "blocks", ()):
        m = cells.shape[0]
        out.append({"type": CCX_TYPE[name], "elset": f"ESKIRT_{CCX_TYPE[name]}",
                    "elems": ccx_element_lines(eids[start:start + m], mesh_node_ids(mesh, cells))})
        start += m
    return out
