"""The ``mesh`` keys of an imported mesh: ``file``, ``sets``, ``units``, ``axis`` (validated, hashable).

``file``: the mesh file (``.inp``, ``.msh``, ``.bdf``/``.dat``/``.nas``), relative to the model file.
``sets``: ``{base: NAME, top: NAME, stop: NAME}`` node sets: the slave nodes on the table, the loaded
top (the reference node is created at the top centre), optionally the radial-stop face nodes. In a
``.bdf`` a set is a SET1 id or a file of node ids (one or more per line). ``units``: ``m`` or ``mm``
(the mesh's length unit; the model stays SI). ``axis``: ``[x0, y0, z0, dx, dy, dz]``, the skirt axis
(default z through the origin), pointing from the base to the top.

Files (issue 13's rules for the model file, applied to the mesh): ``mesh.file`` is taken relative to the
model file's folder (the working folder for the default model), must be a regular file (not a folder,
device, pipe or socket), not empty and at most :data:`MAX_MESH_BYTES`; its text has no control characters.
Nothing beyond the file the user names is read from outside its folder: node-id list files and a
``.bdf``'s INCLUDEs must lie in the mesh file's folder or below (:func:`inside_folder`).
"""

from __future__ import annotations

import os
import stat
from dataclasses import dataclass
from pathlib import Path
from typing import Any

MESH_UNITS = {"m": 1.0, "mm": 1.0e-3}
PLAUSIBLE_RADIUS_M = (0.01, 100.0)   # a skirt's largest radius [m]; outside it mesh.units is refused as wrong
MAX_MESH_BYTES = 1 << 30        # 1 GiB of mesh text (~10^7 nodes); the memory check then bounds the solve
MAX_LIST_BYTES = 64 << 20       # a node-id list file


@dataclass(frozen=True)
class MeshSets:
    """Names of the node sets of an imported mesh."""
    base: str
    top: str
    stop: str | None = None


def sets_from(value: Any, ModelError) -> MeshSets | None:
    if value is None or isinstance(value, MeshSets):
        return value
    if not isinstance(value, dict):
        raise ModelError("mesh.sets", value, "must be a mapping {base: NAME, top: NAME, stop: NAME}")
    for key in value:
        if key not in ("base", "top", "stop"):
            raise ModelError(f"mesh.sets.{key}", value[key], "unknown key (base, top, stop)")
    for key in ("base", "top"):
        if key not in value:
            raise ModelError("mesh.sets", value, f"needs {key}")
    out = {}
    for key, v in value.items():
        if v is None and key == "stop":
            continue
        if isinstance(v, bool) or not isinstance(v, (str, int)) or not str(v).strip() or len(str(v)) > 200:
            raise ModelError(f"mesh.sets.{key}", v, "must be a set name (or a SET1 id)")
        out[key] = str(v)
    return MeshSets(**out)


def axis_from(value: Any, ModelError, _num) -> tuple | None:
    if value is None or value == "z":
        return None
    if not isinstance(value, (list, tuple)) or len(value) != 6:
        raise ModelError("mesh.axis", value, "must be [x0, y0, z0, dx, dy, dz] (or null: z through the origin)")
    v = tuple(_num(f"mesh.axis[{i}]", x) for i, x in enumerate(value))
    if sum(c * c for c in v[3:]) == 0:
        raise ModelError("mesh.axis", value, "direction is zero")
    return v


def check_mesh_keys(spec, ModelError, _num, _text, _choice, _put) -> None:
    """Validate and convert the import keys of a MeshSpec in place (called from its __post_init__ with
    the model's checkers: this module does not import the model)."""
    if spec.file is not None:
        _text("mesh.file", spec.file, max_len=400)
        if not spec.file.strip() or any(ord(c) < 0x20 or 0x7F <= ord(c) < 0xA0 for c in spec.file):
            raise ModelError("mesh.file", spec.file, "must be a file name without control characters")
    _put(spec, "sets", sets_from(spec.sets, ModelError))
    _put(spec, "axis", axis_from(spec.axis, ModelError, _num))
    _choice("mesh.units", spec.units, tuple(MESH_UNITS))
    if spec.file is not None and spec.sets is None:
        raise ModelError("mesh.sets", None, "an imported mesh (mesh.file) needs sets {base, top}")


def resolve_file(model, model_dir: Path):
    """The model with ``mesh.file`` made absolute against ``model_dir`` (the model file's folder) and
    checked by :func:`check_file`."""
    f = model.mesh.file
    if f is None:
        return model
    p = Path(f) if Path(f).is_absolute() else Path(model_dir) / f
    p = Path(os.path.abspath(p))
    check_file("mesh.file", p, MAX_MESH_BYTES)
    return model if str(p) == f else model.with_overrides({"mesh.file": str(p)})


def check_file(key: str, path: Path, max_bytes: int) -> None:
    """One-line ModelError naming ``key`` unless ``path`` is a regular, non-empty file of at most
    ``max_bytes`` (the model file's rules, :func:`deckbridge.safe_yaml.read_model_text`)."""
    from ..errors import ModelError
    try:
        st = os.stat(path)
    except OSError as exc:
        raise ModelError(key, str(path), f"cannot read file ({exc.strerror})") from None
    if stat.S_ISDIR(st.st_mode):
        raise ModelError(key, str(path), "is a folder, not a mesh file")
    if not stat.S_ISREG(st.st_mode):
        raise ModelError(key, str(path), "not a regular file (device, pipe or socket)")
    if st.st_size == 0:
        raise ModelError(key, str(path), "is empty")
    if st.st_size > max_bytes:
        raise ModelError(key, str(path), f"{st.st_size} bytes: at most {max_bytes} bytes")


def inside_folder(key: str, folder: Path, name: str) -> Path:
    """``name`` (relative) resolved in ``folder``; a ModelError when it is absolute or leads outside it."""
    from ..errors import ModelError
    base = Path(os.path.realpath(folder))
    p = Path(os.path.realpath(base / name))
    if Path(name).is_absolute() or not p.is_relative_to(base):
        raise ModelError(key, name, f"must be a file in the mesh file's folder {str(base)!r} or below")
    return p
