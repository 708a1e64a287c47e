"""Nastran ``.bdf`` mesh through pyNastran: GRID (CP frames resolved to basic coordinates by
pyNastran's cross-reference of the coordinate systems and nodes only: element properties and materials
are the model's, so a solid or skin element without its PSOLID / PSHELL, as Gmsh writes them, is read),
every element (the solids, and skin elements such as Gmsh's CQUAD4 of a physical group), node sets from
SET1 (name = its id), else from the skin elements of a property id (name = the PID: with
``Mesh.SaveElementTagType = 2`` Gmsh writes a physical group's tag there), else a node-id list file (name
= a path relative to the mesh file: ids separated by blanks, commas or new lines)."""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

from .raw import RawMesh, is_solid


def read_bdf(path: Path) -> RawMesh:
    from pyNastran.bdf.bdf import BDF
    from ..errors import ModelError
    check_includes(path)
    bdf = BDF(debug=None, log=None, mode="msc")
    try:
        bdf.read_bdf(str(path), xref=False, punch=_is_punch(path), validate=False)
        bdf.cross_reference(xref_nodes=True, xref_elements=False, xref_properties=False, xref_masses=False,
                            xref_materials=False, xref_loads=False, xref_constraints=False, xref_aero=False,
                            xref_sets=False, xref_optimization=False)
    except Exception as exc:   # pyNastran raises many kinds on bad decks
        why = " ".join(str(exc).split("\n")[:1])[:300]
        if "CHEXA20 card" in why:   # Gmsh's second order without Mesh.SecondOrderIncomplete: 27 nodes
            why += ": a CHEXA has at most 20 nodes (Gmsh writes 27-node bricks unless Mesh.SecondOrderIncomplete = 1)"
        raise ModelError("mesh.file", str(path), f"unreadable Nastran file ({type(exc).__name__}: {why})") from None
    nids = np.array(sorted(bdf.nodes), np.int64)
    xyz = np.array([bdf.nodes[int(n)].get_position() for n in nids], float).reshape(-1, 3)
    elements: dict = {}
    by_pid: dict = {}
    for eid in sorted(bdf.elements):
        e = bdf.elements[eid]
        t = e.type if e.type != "CHEXA" else ("CHEXA8" if len(e.node_ids) == 8 else f"CHEXA{len(e.node_ids)}")
        ids, conn = elements.setdefault(t, ([], []))
        ids.append(eid)
        conn.append([int(n) if n else 0 for n in e.node_ids])
        pid = getattr(e, "pid", None)
        if isinstance(pid, (int, np.integer)) and not is_solid(t):
            by_pid.setdefault(str(int(pid)), []).extend(int(n) for n in e.node_ids if n)
    sets = {k: np.unique(np.array(v, np.int64)) for k, v in by_pid.items()}
    sets.update({str(sid): np.array(sorted(int(i) for i in s.ids), np.int64) for sid, s in bdf.sets.items()})
    return RawMesh(path=str(path), node_ids=nids, nodes=xyz,
                   elements={t: (np.array(i, np.int64), np.array(c, np.int64)) for t, (i, c) in elements.items()},
                   sets=sets)


def _is_punch(path: Path) -> bool:
    head = Path(path).read_text(errors="replace")[:20000].upper()
    return "BEGIN BULK" not in head and "SOL " not in head and "CEND" not in head


def node_list_file(mesh_path: str, name: str, key: str = "mesh.sets") -> np.ndarray | None:
    """Node ids of the list file ``name`` in the mesh's folder (or below), None when there is no such file."""
    from ..errors import ModelError
    from .spec import MAX_LIST_BYTES, check_file, inside_folder
    if not os.path.lexists(Path(mesh_path).parent / name):
        return None
    p = inside_folder(key, Path(mesh_path).parent, name)
    check_file(key, p, MAX_LIST_BYTES)
    text = p.read_text(errors="replace")
    try:
        return np.array([int(v) for v in re.split(r"[\s,]+", text) if v], np.int64)
    except ValueError:
        raise ModelError(key, name, "a node-id list file holds integers separated by blanks, commas or "
                         "new lines") from None


def check_includes(path: Path) -> None:
    """Refuse INCLUDEs of a .bdf that lead outside the mesh file's folder (pyNastran would follow them)."""
    from .spec import inside_folder
    for m in re.finditer(r"(?im)^\s*INCLUDE\s+'([^']*)'", Path(path).read_text(errors="replace")):
        inside_folder("mesh.file", Path(path).parent, m.group(1).strip())
