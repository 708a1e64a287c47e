"""The ``mesh`` keys of an imported mesh: ``file``, ``sets``, ``units``, ``axis`` (validated, hashable).

``file``: the mesh file (``.inp``, ``.msh``, ``.bdf``/``.dat``/``.nas``), relative to the model file.
``sets``: ``{base: NAME, top: NAME, stop: NAME}`` node sets: the slave nodes on the table, the loaded
top (the reference node is created at the top centre), optionally the radial-stop face nodes. In a
``.bdf`` a set is a SET1 id or a file of node ids (one or more per line). ``units``: ``m`` or ``mm``
(the mesh's length unit; the model stays SI). ``axis``: ``[x0, y0, z0, dx, dy, dz]``, the skirt axis
(default z through the origin), pointing from the base to the top.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

MESH_UNITS = {"m": 1.0, "mm": 1.0e-3}


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
    _put(spec, "sets", sets_from(spec.sets, ModelError))
    _put(spec, "axis", axis_from(spec.axis, ModelError, _num))
    _choice("mesh.units", spec.units, tuple(MESH_UNITS))
    if spec.file is not None and spec.sets is None:
        raise ModelError("mesh.sets", None, "an imported mesh (mesh.file) needs sets {base, top}")


def resolve_file(model, model_dir: Path):
    """The model with ``mesh.file`` made absolute against the model file's folder."""
    f = model.mesh.file
    if f is None or Path(f).is_absolute():
        return model
    return model.with_overrides({"mesh.file": str((Path(model_dir) / f).resolve())})
