"""A mesh file read as it is: user ids, coordinates, elements by type, node sets by name."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

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


def read_mesh_file(path: str | Path) -> RawMesh:
    """Read ``path`` by its extension: .inp (Abaqus/CalculiX), .msh (Gmsh), .bdf/.dat/.nas (Nastran)."""
    from ..model import ModelError
    p = Path(path)
    if not p.is_file():
        raise ModelError("mesh.file", str(path), "no such file")
    ext = p.suffix.lower()
    if ext == ".inp":
        from .inp_file import read_inp
        return read_inp(p)
    if ext == ".msh":
        from .msh_file import read_msh
        return read_msh(p)
    if ext in (".bdf", ".dat", ".nas", ".blk"):
        from .bdf_file import read_bdf
        return read_bdf(p)
    raise ModelError("mesh.file", str(path), "unknown mesh format (.inp, .msh, .bdf)")
