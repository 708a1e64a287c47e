"""A mesh file read as it is: user ids, coordinates, elements by type, node sets by name."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

HEX8 = {"C3D8", "C3D8I", "C3D8R", "C3D8H", "CHEXA", "CHEXA8", "HEXAHEDRON"}


@dataclass
class RawMesh:
    """``nodes`` (n, 3) in the file's unit, ``node_ids`` (n,); ``elements``: type -> (ids (m,), conn
    (m, k) of node ids); ``sets``: name -> node ids."""
    path: str
    node_ids: np.ndarray
    nodes: np.ndarray
    elements: dict
    sets: dict = field(default_factory=dict)
