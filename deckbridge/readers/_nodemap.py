"""Deck node ids -> azimuth, radius, height and contact surface, through the neutral model.

Shared by readers whose files name nodes but carry no coordinates (Abaqus .dat, plain CSV).
Deck node ids are the skirt ids of :mod:`deckbridge.numbering.skirt` (the mesh's user ids; index + 1
for the structured mesh).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import pandas as pd

from ..errors import DeckbridgeError
from ..azimuth import azimuth_deg
from ..mesh import build_mesh
from ..model import Model
from ..numbering.skirt import mesh_node_ids, mesh_node_index


@lru_cache(maxsize=8)
def slave_nodes(model: Model) -> pd.DataFrame:
    """Slave nodes of ``model``: index = deck node id; columns theta_deg, r, z, table, stop (bool)."""
    return slave_nodes_of(build_mesh(model))


def slave_nodes_of(mesh) -> pd.DataFrame:
    """:func:`slave_nodes` of a mesh already built."""
    ids = mesh_node_ids(mesh, mesh.table.nodes)
    in_stop = np.zeros(mesh.n_nodes, bool)
    if mesh.stop is not None:
        in_stop[mesh.stop.nodes] = True
        ids = np.union1d(ids, mesh_node_ids(mesh, mesh.stop.nodes))
    in_table = np.zeros(mesh.n_nodes, bool)
    in_table[mesh.table.nodes] = True
    idx = mesh_node_index(mesh, ids)
    xyz = mesh.nodes[idx]
    theta = azimuth_deg(mesh.nodes[:, 0], mesh.nodes[:, 1])
    for s in mesh.slave_sets:       # the slave sets' azimuths (an imported mesh's: one per through-wall row)
        theta[s.nodes] = s.theta_deg
    return pd.DataFrame({
        "theta_deg": theta[idx],
        "r": np.hypot(xyz[:, 0], xyz[:, 1]),
        "z": xyz[:, 2],
        "table": in_table[idx],
        "stop": in_stop[idx],
    }, index=pd.Index(ids, name="node"))


def locate(nodes: np.ndarray, model: Model, path, surface: str | None = None, mesh=None) -> pd.DataFrame:
    """Rows of :func:`slave_nodes` for ``nodes``; raise naming ``path`` if one is not a slave node.

    With ``surface`` ('table' or 'stop') the nodes must belong to that slave set. ``mesh``: ``model``'s
    mesh when already built.
    """
    table = slave_nodes(model) if mesh is None else slave_nodes_of(mesh)
    nodes = np.asarray(nodes, dtype=np.int64)
    known = np.isin(nodes, table.index.to_numpy())
    if not known.all():
        bad = int(nodes[~known][0])
        raise DeckbridgeError(
            f"{str(path)!r}: node {bad} is not a contact slave node of model {model.name!r} "
            f"(n_theta={model.mesh.n_theta}, n_r={model.mesh.n_r}, n_z={model.mesh.n_z}): results of another model?")
    out = table.loc[nodes]
    if surface is not None and not out[surface].all():
        bad = int(out.index[~out[surface].to_numpy()][0])
        raise DeckbridgeError(f"{str(path)!r}: node {bad} is not on the {surface} slave surface of model {model.name!r}")
    return out


def surface_of(rows: pd.DataFrame) -> np.ndarray:
    """Default surface of located nodes: 'table' where the node is a table slave, else 'stop'."""
    return np.where(rows["table"].to_numpy(), "table", "stop")


def slave_areas(model: Model, nodes, surfaces, mesh=None) -> np.ndarray:
    """Tributary contact area [m^2] of each (deck node id, surface) of ``model``'s mesh (``mesh`` when already
    built); NaN where the node is not a slave of that surface."""
    mesh = mesh if mesh is not None else build_mesh(model)
    out = np.full(len(nodes), np.nan)
    nodes, surfaces = np.asarray(nodes, np.int64), np.asarray(surfaces).astype(str)
    for s in mesh.slave_sets:
        amap = pd.Series(s.area, index=mesh_node_ids(mesh, s.nodes))
        rows = surfaces == s.surface
        out[rows] = amap.reindex(nodes[rows]).to_numpy(float)
    return out
