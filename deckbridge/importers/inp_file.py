"""Abaqus/CalculiX ``.inp`` mesh: nodes and elements through :func:`deckbridge.readers.inp_mesh.read_inp_mesh`
(meshio 5.3 keeps only the last ``*NODE`` block), node sets from ``*NSET`` (lists or GENERATE) and
``*ELSET``-free ``*SURFACE``-free files."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .raw import RawMesh


def _nsets(text: str) -> dict:
    from ..readers.inp_mesh import keyword_blocks
    sets: dict[str, list[int]] = {}
    for key, opts, data in keyword_blocks(text):
        if key != "NSET":
            continue
        name, generate = opts.get("NSET"), "GENERATE" in opts
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


def read_inp(path: Path) -> RawMesh:
    from ..readers.inp_mesh import read_inp_mesh
    m = read_inp_mesh(path)
    return RawMesh(path=str(path), node_ids=m.node_ids, nodes=m.nodes, elements=dict(m.elements),
                   sets=_nsets(Path(path).read_text(errors="replace")))
