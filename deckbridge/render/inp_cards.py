"""Shared pieces of the Abaqus-style decks (Abaqus/Standard and CalculiX): numbering, rings, card lines.

Numbering: skirt node id = mesh index + 1, skirt element id = hex index + 1 (see :mod:`deckbridge.mesh`).
Extra nodes (reference node, fixed master rings, grounded gap nodes) and extra elements follow the skirt
ids. Hexahedron faces use the C3D8 labels shared by both codes: S1 = 1-2-3-4 (base, outward -z),
S2 = 5-8-7-6 (top, +z), S4 = 2-6-7-3 (outer wall, +r), S6 = 4-8-5-1 (inner wall, -r).

Master surfaces are element faces of fixed rings of C3D8 elements (no analytical rigid surfaces, so that
the same deck geometry reads in Abaqus and CalculiX): the table is the top face (S2, normal +z) of a ring
below z = 0 that overhangs both wall faces by one wall thickness and uses the skirt's azimuths; the stop
is the wall face of a ring at the stop radius, facing the skirt (S4 = +r for an inner stop, S6 = -r for
an outer stop), spanning z in [-h1/2, +h1/2] with h1 the first-row height, so that only the base nodes
of the skirt project onto it (the neutral model's stop slaves: lower half of the first-row wall faces).

Reals are written with an exponent everywhere (CalculiX misreads some integer-looking reals).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..mesh import SkirtMesh, node_index
from ..model import Model

FACE_BASE, FACE_TOP, FACE_OUTER, FACE_INNER = "S1", "S2", "S4", "S6"
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


def node_block(mesh_nodes, ref_node: int, ref_xyz, groups) -> dict:
    """One ``*NODE`` block for the whole deck (meshio and others read only one) and its node sets.

    ``groups``: (set name, ids, xyz) of the extra nodes after the skirt and the reference node.
    Returns ``nodes`` (data lines) and ``node_sets`` (name, first id, last id) for ``*NSET, GENERATE``.
    """
    n = mesh_nodes.shape[0]
    lines = [node_lines(np.arange(1, n + 1), mesh_nodes), f"{ref_node}, {reals(ref_xyz)}"]
    sets = [("NSKIRT", 1, n), ("NREF", ref_node, ref_node)]
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


@dataclass(frozen=True)
class Ring:
    """A ring of hexahedra: node ids/coordinates, element ids/connectivity, the contact face label."""
    node_ids: np.ndarray
    nodes: np.ndarray
    elem_ids: np.ndarray
    conn: np.ndarray          # node ids, C3D8 order
    face: str


def ring(radii, zs, n_theta: int, first_node: int, first_elem: int, face: str) -> Ring:
    """Hexahedra between ``radii`` (2 values) and ``zs`` (2 values) at the skirt's azimuths."""
    theta = 2.0 * np.pi * np.arange(n_theta) / n_theta
    pts = [(r * np.cos(t), r * np.sin(t), z) for z in zs for r in radii for t in theta]
    nodes = np.array(pts, float)
    ids = first_node + np.arange(nodes.shape[0])
    j = np.arange(n_theta)
    ix = lambda k, i, jj: node_index(k, i, jj, 1, n_theta)  # noqa: E731
    conn = np.stack([ix(0, 0, j), ix(0, 1, j), ix(0, 1, j + 1), ix(0, 0, j + 1),
                     ix(1, 0, j), ix(1, 1, j), ix(1, 1, j + 1), ix(1, 0, j + 1)], axis=1)
    return Ring(node_ids=ids, nodes=nodes, elem_ids=first_elem + j, conn=ids[conn], face=face)


@dataclass(frozen=True)
class Layout:
    """Ids, sets and surfaces of one Abaqus-style deck of ``model`` (shared by both dialects)."""
    model: Model
    mesh: SkirtMesh
    ref_node: int
    ref_xyz: np.ndarray
    table_master: Ring | None
    stop_master: Ring | None
    next_node: int                   # first free node id after the rings
    next_elem: int                   # first free element id after the rings
    base_elems: np.ndarray           # first-row element ids (table slave faces S1)
    stop_elems: np.ndarray           # first-row element ids on the stop side (faces S6 inner / S4 outer)
    stop_face: str
    top_elems: np.ndarray            # top-row element ids (coupling faces S2)
    loads: dict = field(default_factory=dict)

    @property
    def first_row_height(self) -> float:
        z = self.mesh.nodes[:, 2]
        return float(np.min(z[z > 1e-12 * self.model.geometry.height]))

    @property
    def master_node_ids(self) -> np.ndarray:
        parts = [r.node_ids for r in (self.table_master, self.stop_master) if r is not None]
        return np.concatenate(parts) if parts else np.zeros(0, int)


def layout(model: Model, mesh: SkirtMesh, *, masters: tuple[str, ...] = ()) -> Layout:
    """Number the deck: skirt, reference node, and the fixed master rings named in ``masters``
    (``"table"``, ``"stop"``; the stop ring only when the model has a stop)."""
    g = model.geometry
    n_nodes, n_elems = mesh.n_nodes, mesh.hexes.shape[0]
    nt, nr, nz = mesh.n_theta, mesh.n_r, mesh.n_z
    ref_node = n_nodes + 1
    next_node, next_elem = ref_node + 1, n_elems + 1
    t = g.thickness
    r_in, r_out = g.radius - t / 2, g.radius + t / 2
    h1 = float(mesh.nodes[node_index(1, 0, 0, nr, nt), 2])   # first-row height at the inner face
    table_master = stop_master = None
    if "table" in masters:
        table_master = ring([r_in - t, r_out + t], [-t, 0.0], nt, next_node, next_elem, FACE_TOP)
        next_node += table_master.node_ids.size
        next_elem += table_master.elem_ids.size
    if "stop" in masters and mesh.stop is not None:
        inner = model.contact.stop.side == "inner"
        r_stop = float(np.mean(mesh.stop.r - mesh.stop.clearance if inner else mesh.stop.r + mesh.stop.clearance))
        if inner:
            radii, face = [r_stop - t, r_stop], FACE_OUTER
        else:
            radii, face = [r_stop, r_stop + t], FACE_INNER
        stop_master = ring(radii, [-h1 / 2, h1 / 2], nt, next_node, next_elem, face)
        next_node += stop_master.node_ids.size
        next_elem += stop_master.elem_ids.size
    # element index e = (k * n_r + i) * n_theta + j  (k along z, i through the wall, j around)
    j = np.arange(nt)
    base = np.concatenate([(0 * nr + i) * nt + j for i in range(nr)]) + 1
    side = model.contact.stop.side
    if side == "outer":
        stop_elems, stop_face = ((nr - 1) * nt + j) + 1, FACE_OUTER
    else:
        stop_elems, stop_face = j + 1, FACE_INNER
    top = np.concatenate([((nz - 1) * nr + i) * nt + j for i in range(nr)]) + 1
    return Layout(model=model, mesh=mesh, ref_node=ref_node, ref_xyz=np.asarray(mesh.ref_point, float),
                  table_master=table_master, stop_master=stop_master, next_node=next_node,
                  next_elem=next_elem, base_elems=base, stop_elems=stop_elems, stop_face=stop_face,
                  top_elems=top, loads=model.load_vectors())


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


@dataclass(frozen=True)
class InpMesh:
    """Nodes and elements read back from an Abaqus-style deck."""
    node_ids: np.ndarray
    nodes: np.ndarray
    elements: dict          # element type -> (ids (m,), connectivity (m, k) of node ids)


def shared_context(model: Model, lay: "Layout", inc_limit: int) -> dict:
    """Template values both Abaqus-style dialects share: skirt elements, springs, loads, increments.

    Step 1 applies N at the reference node; step 2 repeats N and adds lambda_max (T, M), as totals.
    """
    mesh, lv, s = lay.mesh, lay.loads, model.steps
    springs = spring_groups(mesh.k_tangent, mesh.table.nodes + 1, lay.next_elem)
    step2 = {1: lv["T_force"][0] * s.lambda_max, 2: lv["T_force"][1] * s.lambda_max, 3: lv["N_force"][2],
             4: lv["M_moment"][0] * s.lambda_max, 5: lv["M_moment"][1] * s.lambda_max}
    return {
        "title": model.title, "name": model.name,
        "skirt_elems": element_lines(np.arange(1, mesh.hexes.shape[0] + 1), mesh.hexes + 1),
        "ref_node": lay.ref_node,
        "table_nodes": id_lines(mesh.table.nodes + 1),
        "stop_nodes": id_lines(mesh.stop.nodes + 1) if mesh.stop is not None else "",
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


def read_inp_mesh(path) -> InpMesh:
    """Read ``*NODE`` and ``*ELEMENT`` blocks of an Abaqus/CalculiX deck; every other card is skipped.

    meshio 5.3 cannot read the decks: it keeps only the last ``*NODE`` block and stops at element types
    it does not know (SPRING1, GAPUNI). Element data lines ending with ',' continue on the next line.
    """
    from ..errors import DeckbridgeError
    ids, xyz, elems = [], [], {}
    mode, etype, pending = None, None, []
    try:
        text = Path(path).read_text(errors="replace")
    except OSError as exc:
        raise DeckbridgeError(f"{str(path)!r}: cannot read ({exc.strerror})") from None
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("**"):
            continue
        if line.startswith("*"):
            head = [p.strip().upper() for p in line[1:].split(",")]
            mode = head[0] if head[0] in ("NODE", "ELEMENT") else None
            if mode == "ELEMENT":
                etype = next((p.split("=", 1)[1].strip() for p in head[1:] if p.startswith("TYPE=")), None)
                if etype is None:
                    raise DeckbridgeError(f"{str(path)!r}: line {lineno}: *ELEMENT without TYPE")
            pending = []
            continue
        if mode is None:
            continue
        try:
            fields = [f for f in line.split(",")]
            if mode == "NODE":
                ids.append(int(fields[0]))
                xyz.append([float(v) for v in fields[1:4]])
            else:
                pending += [int(f) for f in fields if f.strip()]
                if line.endswith(","):
                    continue
                e_ids, conn = elems.setdefault(etype, ([], []))
                e_ids.append(pending[0])
                conn.append(pending[1:])
                pending = []
        except (ValueError, IndexError):
            raise DeckbridgeError(f"{str(path)!r}: line {lineno}: unreadable {mode} data {line[:60]!r}") from None
    return InpMesh(node_ids=np.array(ids, dtype=np.int64), nodes=np.array(xyz, float).reshape(-1, 3),
                   elements={t: (np.array(i, dtype=np.int64), np.array(c, dtype=np.int64)) for t, (i, c) in
                             elems.items()})
