"""Abaqus/CalculiX ``.inp`` mesh: nodes and elements through :func:`.inp_mesh.read_inp_mesh`
(meshio 5.3 keeps only the last ``*NODE`` block), node sets from ``*NSET`` (lists or GENERATE), and from element sets of skin elements (``*ELSET`` or
``*ELEMENT, ELSET=``: the nodes of their 2D elements, e.g. the CPS4 faces Gmsh writes for a physical
group) under a name no ``*NSET`` uses."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .raw import RawMesh, is_solid


def _nsets(text: str, kind: str = "NSET") -> dict:
    """Sets of ``*NSET`` (``kind`` 'NSET') or ``*ELSET`` (``kind`` 'ELSET'): name -> ids."""
    from .inp_mesh import keyword_blocks
    sets: dict[str, list[int]] = {}
    for key, opts, data in keyword_blocks(text):
        if key != kind:
            continue
        name, generate = opts.get(kind), "GENERATE" in opts
        if name is None:
            continue
        sets.setdefault(name, [])
        for line in data:
            vals = [v.strip() for v in line.split(",") if v.strip()]
            if generate:
                a, b, *st = (int(v) for v in vals)
                sets[name] += list(range(a, b + 1, st[0] if st else 1))
            else:
                for v in vals:   # a member may be another set's name
                    sets[name] += sets.get(v, []) if not v.lstrip("-").isdigit() else [int(v)]
    return {k: np.array(v, np.int64) for k, v in sets.items()}


def _element_node_sets(elsets: dict, elements: dict) -> dict:
    """Node sets (name -> node ids) of element sets of skin elements: the nodes of their non-solid
    elements (element sets of solids are not node sets)."""
    skin = {t: v for t, v in elements.items() if not is_solid(t)}
    ids = np.concatenate([i for i, _ in skin.values()]) if skin else np.zeros(0, np.int64)
    nodes_of = dict(zip(ids.tolist(), [row for _, c in skin.values() for row in c]))
    out = {}
    for name, members in elsets.items():
        rows = [nodes_of[int(e)] for e in members if int(e) in nodes_of]
        if rows:
            out[name] = np.unique(np.concatenate(rows))
    return out


def read_inp(path: Path) -> RawMesh:
    from .inp_mesh import read_inp_mesh
    m = read_inp_mesh(path)
    text = Path(path).read_text(errors="replace")
    elsets = _nsets(text, "ELSET")
    for name, ids in m.elsets.items():
        elsets[name] = np.concatenate([elsets.get(name, np.zeros(0, np.int64)), ids])
    sets = {**_element_node_sets(elsets, m.elements), **_nsets(text)}
    return RawMesh(path=str(path), node_ids=m.node_ids, nodes=m.nodes, elements=dict(m.elements), sets=sets)
