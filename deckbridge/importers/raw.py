"""A mesh file read as it is: user ids, coordinates, elements by type, node sets by name."""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

HEX8 = {"C3D8", "C3D8I", "C3D8R", "C3D8H", "CHEXA", "CHEXA8", "HEXAHEDRON"}
_SOLID = re.compile(r"^(?:DC3D|C3D|CHEXA|CPENTA|CTETRA|CPYRAM|HEXAHEDRON|TETRA|WEDGE|PYRAMID)")
_SHAPES = {4: "4-node tetrahedra", 5: "5-node pyramids", 6: "6-node wedges", 10: "10-node (quadratic) tetrahedra",
           13: "13-node (quadratic) pyramids", 15: "15-node (quadratic) wedges", 20: "20-node (quadratic) hexahedra",
           27: "27-node (quadratic) hexahedra"}


def is_solid(etype: str) -> bool:
    """True for a 3D solid element type (C3D*, CHEXA, CTETRA, ...); False for the skin, beam, spring
    and mass elements a mesher writes beside the solid (CPS4, S4, CQUAD4, T3D2, ...)."""
    return bool(_SOLID.match(etype.upper()))


def solid_shape(n_nodes: int) -> str:
    """Words for a solid of ``n_nodes`` nodes (``"10-node (quadratic) tetrahedra"``)."""
    return _SHAPES.get(n_nodes, f"{n_nodes}-node solids")


@dataclass
class RawMesh:
    """``nodes`` (n, 3) in the file's unit, ``node_ids`` (n,); ``elements``: type -> (ids (m,), conn
    (m, k) of node ids), every element the file holds (skin elements included); ``sets``: name -> node ids."""
    path: str
    node_ids: np.ndarray
    nodes: np.ndarray
    elements: dict
    sets: dict = field(default_factory=dict)
