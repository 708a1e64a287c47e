"""Nastran ``.bdf`` mesh through pyNastran: GRID (CP frames resolved to basic coordinates by
pyNastran's cross-reference), solid elements, node sets from SET1 (name = its id) or a node-id list
file (name = a path relative to the mesh file: ids separated by blanks, commas or new lines)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from .raw import RawMesh


def read_bdf(path: Path) -> RawMesh:
    from pyNastran.bdf.bdf import BDF
    from ..model import ModelError
    bdf = BDF(debug=None, log=None, mode="msc")
    try:
        bdf.read_bdf(str(path), xref=True, punch=_is_punch(path), validate=False)
    except Exception as exc:   # pyNastran raises many kinds on bad decks
        raise ModelError("mesh.file", str(path), f"unreadable Nastran file ({type(exc).__name__}: {exc})") from None
    nids = np.array(sorted(bdf.nodes), np.int64)
    xyz = np.array([bdf.nodes[int(n)].get_position() for n in nids], float).reshape(-1, 3)
    elements: dict = {}
    for eid in sorted(bdf.elements):
        e = bdf.elements[eid]
        t = e.type if e.type != "CHEXA" else ("CHEXA8" if len(e.node_ids) == 8 else f"CHEXA{len(e.node_ids)}")
        ids, conn = elements.setdefault(t, ([], []))
        ids.append(eid)
        conn.append([int(n) if n else 0 for n in e.node_ids])
    sets = {str(sid): np.array(sorted(int(i) for i in s.ids), np.int64) for sid, s in bdf.sets.items()}
    return RawMesh(path=str(path), node_ids=nids, nodes=xyz,
                   elements={t: (np.array(i, np.int64), np.array(c, np.int64)) for t, (i, c) in elements.items()},
                   sets=sets)


def _is_punch(path: Path) -> bool:
    head = Path(path).read_text(errors="replace")[:20000].upper()
    return "BEGIN BULK" not in head and "SOL " not in head and "CEND" not in head


def node_list_file(mesh_path: str, name: str) -> np.ndarray | None:
    """Node ids of the list file ``name`` next to the mesh, None when there is no such file."""
    p = Path(mesh_path).parent / name
    if not p.is_file():
        return None
    return np.array([int(v) for v in re.split(r"[\s,]+", p.read_text()) if v], np.int64)
