"""The model of an imported mesh (``deckbridge import``): geometry measured on the mesh
(:func:`deckbridge.importers.geometry.measured_geometry`), import keys, checked by meshing it."""

from __future__ import annotations

import os
from pathlib import Path

from .importers.geometry import measured_geometry


# the keys ``--like`` carries over from another model: everything but the mesh and the geometry
LIKE_KEYS = ("material", "contact", "load_introduction", "loads", "steps", "analysis", "units", "outputs")


def model_for_mesh(mesh_path: str | Path, model_path: str | Path, base: str, top: str, stop: str | None = None,
                   units: str = "m", axis=None, name: str | None = None, overrides: list[str] | None = None,
                   like=None):
    """(model, YAML text) for ``mesh_path``; the YAML names the mesh relative to ``model_path``'s folder.

    ``like``: a Model whose keys :data:`LIKE_KEYS` (material, contact, loads, steps, analysis, ...: all but
    ``mesh`` and ``geometry``) the imported model takes instead of the default JAR's; ``overrides`` apply
    after. The mesh is read and checked (every import check) before anything is returned.
    """
    from .mesh import build_mesh
    from .model import Model, apply_overrides
    mesh_path, model_path = Path(mesh_path).resolve(), Path(model_path).resolve()
    sets = {"base": base, "top": top, **({"stop": stop} if stop else {})}
    data = Model().to_dict()
    if like is not None:
        data.update({k: v for k, v in like.to_dict().items() if k in LIKE_KEYS})
    data["name"] = name or _name(mesh_path.stem)
    data["title"] = f"imported mesh {mesh_path.name}"
    data["mesh"].update({"file": str(mesh_path), "sets": sets, "units": units, "axis": axis})
    data["contact"]["stop"]["side"] = "inner" if stop is None else data["contact"]["stop"]["side"]
    model = Model.from_dict(apply_overrides(data, overrides or []))
    mesh = build_mesh(model)          # every import check; geometry below from the checked mesh
    data = model.to_dict()
    data["geometry"] = measured_geometry(mesh)
    data["mesh"]["file"] = os.path.relpath(mesh_path, model_path.parent)
    data["mesh"].update(n_theta=mesh.n_theta, n_z=mesh.n_z, n_r=mesh.n_r)   # measured; informative only
    model = Model.from_dict({**data, "mesh": {**data["mesh"], "file": str(mesh_path)}})
    return model, _yaml(data, None if like is None else like.name)


def _name(stem: str) -> str:
    import re
    s = re.sub(r"[^A-Za-z0-9_.-]", "_", stem)[:40]
    return s if s and s[0].isalnum() else f"M{s}"[:40]


def _yaml(data: dict, like: str | None = None) -> str:
    import yaml
    head = ("# deckbridge model of an imported mesh (deckbridge import). mesh.file is relative to this file;\n"
            "# geometry was measured on the mesh (base radii, top plane). "
            + ("Every other key is the default JAR's:\n# check material, loads and contact before use.\n"
               if like is None else
               f"{', '.join(LIKE_KEYS)}\n# are those of model {like!r} (--like).\n"))
    return head + yaml.safe_dump(data, sort_keys=False)
