"""Read a mesh file by its extension into a :class:`~.raw.RawMesh`."""

from __future__ import annotations

from pathlib import Path

from .bdf_file import read_bdf
from .inp_file import read_inp
from .msh_file import read_msh
from .raw import RawMesh


def read_mesh_file(path: str | Path) -> RawMesh:
    """Read ``path`` by its extension: .inp (Abaqus/CalculiX), .msh (Gmsh), .bdf/.dat/.nas (Nastran)."""
    from ..errors import ModelError
    from .spec import MAX_MESH_BYTES, check_file
    p = Path(path)
    check_file("mesh.file", p, MAX_MESH_BYTES)   # also for models not read by model.load
    ext = p.suffix.lower()
    if ext == ".inp":
        return read_inp(p)
    if ext == ".msh":
        return read_msh(p)
    if ext in (".bdf", ".dat", ".nas", ".blk"):
        return read_bdf(p)
    raise ModelError("mesh.file", str(path), "unknown mesh format (.inp, .msh, .bdf)")
