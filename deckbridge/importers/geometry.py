"""The geometry of a model with an imported mesh: measured on the mesh (the imported mesh is the geometry).

``geometry`` keys written into the model (used by beam theory, the master rings of the inp decks and the
report): mid-wall radius = (r_inner + r_outer) / 2 and thickness = r_outer - r_inner of the base faces'
inner and outer rings (each the mean radius of the ring's nodes, :func:`.measure.rings`: a file's limited
precision averages out), height = top plane - base plane, ``top_radius`` when the top's mid-wall radius
differs (a cone) [m]. Called by :func:`deckbridge.model.load` (this module imports no model module) and by
``deckbridge import`` (:mod:`deckbridge.imported_model`).
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError
from .general import imported_mesh
from .measure import rings


def measured_geometry(mesh) -> dict:
    """The ``geometry`` keys of an imported ``mesh`` measured on it [m] (module docstring)."""
    zt = float(np.mean(mesh.nodes[mesh.top_nodes, 2]))
    rnd = lambda x: float(f"{x:.12g}")  # noqa: E731
    if mesh.table_faces is not None:    # 10-, 15-, 20-node cells (issue 23): the extreme circles of the faces
        (r_in, r_out), (t_in, t_out) = (_extreme_radii(mesh.nodes, s) for s in (mesh.table.nodes, mesh.top_nodes))
        geo = {"radius": rnd((r_in + r_out) / 2), "thickness": rnd(r_out - r_in), "height": rnd(zt),
               "top_radius": None}
        r_top = rnd((t_in + t_out) / 2)
    else:
        rb = rings(mesh.nodes, mesh.hexes[mesh.base_elems, :4])
        rt = rings(mesh.nodes, mesh.hexes[mesh.top_elems, 4:])
        geo = {"radius": rnd(rb.mid_radius), "thickness": rnd(rb.thickness), "height": rnd(zt), "top_radius": None}
        r_top = rnd(rt.mid_radius)
    if abs(r_top - geo["radius"]) > 1e-6 * geo["radius"]:
        geo["top_radius"] = r_top
    return geo


def _extreme_radii(nodes, surf) -> tuple[float, float]:
    """(inner, outer) radius [m] of a face set: the mean radius of its nodes within 1e-3 of the wall of the
    smallest (largest) one (a file's limited precision averages out)."""
    r = np.hypot(nodes[surf, 0], nodes[surf, 1])
    tol = 1e-3 * float(np.ptp(r))
    return float(r[r <= r.min() + tol].mean()), float(r[r >= r.max() - tol].mean())


GEOMETRY_REL_TOL = 1e-3   # a geometry key within this fraction of the mesh's value agrees with it


def geometry_keys_given(text: str | None, overrides) -> set:
    """The ``geometry`` keys the user gave: in the model file's ``text`` (None for the embedded default,
    whose keys describe the default JAR, not a mesh) and in ``overrides`` (``--set`` strings or a mapping)."""
    from .. import safe_yaml
    given = set()
    data = safe_yaml.load(text) if text is not None else None
    if isinstance(data, dict) and isinstance(data.get("geometry"), dict):
        given |= set(data["geometry"])
    items = (overrides.items() if isinstance(overrides, dict)          # --set strings: checked by the loader
             else [(o.split("=", 1)[0].strip(), None) for o in overrides or []])
    for key, value in items:
        if key == "geometry" and isinstance(value, dict):
            given |= set(value)
        elif key.startswith("geometry."):
            given.add(key.split(".", 1)[1])
    return given


def mesh_geometry(model, text: str | None, overrides):
    """:func:`with_mesh_geometry` of a loaded ``model`` (its file's ``text``, None for the embedded default,
    and the ``overrides``); ``model`` itself when it has no ``mesh.file``."""
    if model.mesh.file is None:
        return model
    return with_mesh_geometry(model, geometry_keys_given(text, overrides))


def with_mesh_geometry(model, given: set):
    """``model`` with ``geometry`` measured on its imported mesh (the imported mesh is the geometry: beam
    theory, the decks' master rings and the report use it). A key in ``given`` (set by the user) that
    differs from the mesh's value by more than :data:`GEOMETRY_REL_TOL` is a ModelError naming both. A
    mesh that fails its import checks leaves ``model`` as it is: building its mesh reports the failure."""
    if model.mesh.file is None:
        return model
    try:
        mesh = imported_mesh(model)
    except ModelError:        # a broken mesh is reported where the mesh is built (every command builds it)
        return model
    geo = measured_geometry(mesh)
    for key in sorted(given):
        mine, theirs = getattr(model.geometry, key, None), geo.get(key)
        if key == "top_radius":
            mine = model.geometry.r_top
            theirs = geo["radius"] if theirs is None else theirs
        if mine is None or theirs is None:
            continue
        if abs(float(mine) - float(theirs)) > GEOMETRY_REL_TOL * abs(float(theirs)):
            raise ModelError(f"geometry.{key}", mine, f"contradicts the imported mesh {model.mesh.file}, which "
                             f"measures {key} = {theirs:.6g} m: the imported mesh is the geometry (drop the key "
                             "or give the mesh's value)")
    return model.with_overrides({f"geometry.{k}": v for k, v in geo.items()})
