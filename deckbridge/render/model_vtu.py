"""The model as a VTU beside the decks, ``<name>_model.vtu``: the skirt mesh with its deck ids and sets.

Dialect-free (meshio cannot read every deck: the Abaqus ``SPRING1`` stops it), written once by
:func:`deckbridge.render.render_all`. Coordinates in metres (the model's SI, whatever
``units`` the decks use). Point data: ``node_id`` (the skirt node id of every deck, mesh index + 1)
and 0/1 masks ``table_slave``, ``stop_slave``, ``top_ring`` (the coupled top nodes). Cell data
(8-node hexahedra, the deck element order): ``element_id`` and ``bottom_row`` (the first element
row, the Nastran decks' stress ``SET`` and the inp decks' base element set).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..mesh import SkirtMesh
from ..model import Model
from ..numbering.skirt import bottom_row_index, elem_ids, mesh_node_ids
from ..outdir import safe_filename
from ..paraview import by_block, vtk_blocks

SUFFIX = "_model.vtu"


def model_mesh(mesh: SkirtMesh):
    """meshio Mesh of the skirt with ids and set masks (int32 arrays)."""
    import meshio

    def mask(index) -> np.ndarray:
        out = np.zeros(mesh.n_nodes, np.int32)
        out[np.asarray(index, int)] = 1
        return out

    n_el = mesh.hexes.shape[0]
    bottom = np.zeros(n_el, np.int32)
    bottom[bottom_row_index(mesh)] = 1
    point = {"node_id": mesh_node_ids(mesh, np.arange(mesh.n_nodes)).astype(np.int32),
             "table_slave": mask(mesh.table.nodes),
             "stop_slave": mask(mesh.stop.nodes if mesh.stop is not None else []),
             "top_ring": mask(mesh.top_nodes)}
    blocks = vtk_blocks(mesh.hexes)                 # one block, or a mixed mesh's one per type
    cell = {"element_id": by_block(blocks, elem_ids(mesh, np.arange(n_el)).astype(np.int32)),
            "bottom_row": by_block(blocks, bottom)}
    return meshio.Mesh(np.asarray(mesh.nodes, float), blocks, point_data=point, cell_data=cell)


def write(model: Model, mesh: SkirtMesh, outdir: Path) -> Path:
    """Write ``<name>_model.vtu`` into ``outdir`` and return its path."""
    import meshio

    path = Path(outdir) / safe_filename(model.name + SUFFIX)
    meshio.write(path, model_mesh(mesh), file_format="vtu")
    return path
