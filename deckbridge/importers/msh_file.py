"""Gmsh ``.msh`` mesh through meshio: points, hexahedra, node sets from named physical groups.

meshio renumbers: node id = point index + 1, element id = the hexahedron's rank + 1 (all cell blocks
in file order). A physical group of any dimension (points, lines, quads, volumes) gives the node set
of its cells' nodes: in a 4.1 file through meshio's ``cell_sets``; in a 2.2 file (as meshio and older
tools write it, where meshio builds no ``cell_sets``) through each cell's ``gmsh:physical`` tag and
the names of ``$PhysicalNames``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .raw import RawMesh

MESHIO_TO_TYPE = {"hexahedron": "C3D8", "tetra": "C3D4", "tetra10": "C3D10", "hexahedron20": "C3D20",
                  "hexahedron27": "C3D27", "wedge": "C3D6", "pyramid": "C3D5"}
SURFACE_OR_LOWER = {"vertex", "line", "line3", "triangle", "triangle6", "quad", "quad8", "quad9"}


def read_msh(path: Path) -> RawMesh:
    import meshio
    from ..errors import ModelError
    try:
        m = meshio.read(str(path), file_format="gmsh")
    except KeyError as exc:    # an element type meshio's Gmsh reader has no node order for (15-node prisms)
        raise ModelError("mesh.file", str(path), f"meshio cannot read Gmsh elements of type {exc}: write the mesh as "
                         ".inp or .bdf (gmsh.write('skirt.inp'))") from None
    except Exception as exc:   # meshio raises plain exceptions of many kinds on bad files
        raise ModelError("mesh.file", str(path), f"unreadable Gmsh file ({type(exc).__name__}: {exc})") from None
    elements: dict = {}
    next_id = 1
    for block in m.cells:
        if block.type in SURFACE_OR_LOWER:
            continue
        t = MESHIO_TO_TYPE.get(block.type, block.type.upper())
        n = len(block.data)
        ids, conn = elements.get(t, (np.zeros(0, np.int64), np.zeros((0, block.data.shape[1]), np.int64)))
        elements[t] = (np.concatenate([ids, next_id + np.arange(n)]), np.vstack([conn, block.data + 1]))
        next_id += n
    sets = _physical_sets(m)
    for name, per_block in m.cell_sets.items():
        if name.startswith("gmsh:"):
            continue
        nodes = [m.cells[b].data[np.asarray(idx, np.int64)].ravel() for b, idx in enumerate(per_block)
                 if idx is not None and len(idx)]
        sets[name] = np.unique(np.concatenate(nodes)) + 1 if nodes else np.zeros(0, np.int64)
    return RawMesh(path=str(path), node_ids=np.arange(1, len(m.points) + 1, dtype=np.int64),
                   nodes=np.asarray(m.points, float)[:, :3], elements=elements, sets=sets)


def _physical_sets(m) -> dict:
    """Node sets (name -> node ids, 1-based) of the named physical groups from the cells' ``gmsh:physical``
    tags (a Gmsh 2.2 file); empty when the file has no such tags or names."""
    phys = m.cell_data.get("gmsh:physical")
    if not phys or not m.field_data:
        return {}
    sets = {}
    for name, (tag, dim) in ((k, np.asarray(v).ravel()[:2]) for k, v in m.field_data.items()):
        nodes = [b.data[np.asarray(p) == tag].ravel() for b, p in zip(m.cells, phys) if b.dim == dim]
        nodes = [n for n in nodes if n.size]
        if nodes:
            sets[str(name)] = np.unique(np.concatenate(nodes)) + 1
    return sets
