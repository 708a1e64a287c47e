"""Ids of the CalculiX decks beyond the inp family's (:mod:`deckbridge.numbering.inp`): which master rings each
deck has, the node-to-surface slave groups and the areas ccx gives slave nodes, the GAPUNI gaps and their
grounded nodes. Pure functions of mesh and model, used by the renderer (:mod:`.render`) and the reader
(:mod:`.reader`) alike, so that the reader maps ids without rendering a deck.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...mesh import SkirtMesh
from ...methods import PENALTY
from ...model import Model
from ...numbering.inp import Layout, layout
from ...numbering.skirt import mesh_node_ids

CCX_MASTERS = {PENALTY: (), "mortar": ("table",), "f2f": (), "penalty_n2f": ("table", "stop")}   # master rings


def ccx_penalty_is_n2f(model: Model) -> bool:
    """The CalculiX penalty deck is node-to-surface LINEAR contact (geometrically linear) unless NLGEOM is
    asked for; with NLGEOM it is GAPUNI gaps (which give wrong reactions without NLGEOM in ccx 2.20)."""
    return not model.analysis.nlgeom


def ccx_layout(model: Model, mesh: SkirtMesh, method: str) -> Layout:
    """Numbering of the CalculiX ``method`` deck ('penalty': GAPUNI gaps only, or table and stop rings for
    node-to-surface contact; 'mortar': table ring)."""
    key = "penalty_n2f" if method == PENALTY and ccx_penalty_is_n2f(model) else method
    return layout(model, mesh, masters=CCX_MASTERS[key])


def ccx_node_slave_areas(mesh: SkirtMesh) -> np.ndarray:
    """Area [m^2] that ccx 2.20 gives each skirt node of a node-based slave surface (``*SURFACE, TYPE=NODE``)
    in node-to-surface contact: a quarter of every free (exterior) face of the skirt at the node, base and
    wall faces alike (measured: the spring force is slope x this area x penetration). Indexed by mesh node.
    """
    faces = mesh.hexes[:, [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]]
    faces = faces.reshape(-1, 4)
    key = np.sort(faces, axis=1)
    _, inv, count = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    free = faces[count[inv.ravel()] == 1]
    x = mesh.nodes[free]                                       # (f, 4, 3)
    area = 0.5 * np.linalg.norm(np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 1]), axis=1)
    out = np.zeros(mesh.n_nodes)
    np.add.at(out, free.ravel(), np.repeat(area / 4.0, 4))
    return out


@dataclass(frozen=True)
class N2fGroup:
    """Slave nodes of one surface whose k_c / A_ccx is equal: one node-based surface, one interaction."""
    name: str                # e.g. TABLE1
    surface: str             # 'table' | 'stop'
    nodes: np.ndarray        # skirt node ids
    slope: float             # K = k_c / A_ccx [Pa/m]
    rows: np.ndarray         # rows of the slave set


def ccx_n2f_groups(mesh: SkirtMesh, rel: float = 1e-9) -> list[N2fGroup]:
    """Node-to-surface penalty groups of the CalculiX penalty deck: table groups first, then stop groups,
    each sorted by slope; within a group the nodes by ascending deck id (ccx prints a node surface's contact
    rows in that order; the structured mesh's slave-set order is the same, an imported mesh's need not be)."""
    a_ccx = ccx_node_slave_areas(mesh)
    out = []
    for ss in (mesh.table, mesh.stop):
        if ss is None:
            continue
        slope = np.asarray(ss.k, float) / a_ccx[ss.nodes]
        order = np.argsort(slope, kind="stable")
        groups: list[list[int]] = []
        for i in order:
            if groups and abs(slope[i] - slope[groups[-1][0]]) <= rel * abs(slope[groups[-1][0]]):
                groups[-1].append(int(i))
            else:
                groups.append([int(i)])
        ids = mesh_node_ids(mesh, ss.nodes)
        for n, g in enumerate(groups, start=1):
            rows = np.array(sorted(g, key=lambda r: ids[r]))   # ascending node id: ccx's order of a node set
            out.append(N2fGroup(name=f"{ss.surface.upper()}{n}", surface=ss.surface, nodes=ids[rows],
                                slope=float(np.mean(slope[rows])), rows=rows))
    return out


@dataclass(frozen=True)
class GapIds:
    """GAPUNI gaps of a CalculiX deck, one per slave node, in deck order. Arrays of equal length.

    ``set_index`` / ``row``: which slave set (of ``sets``) and which node of it each gap is on.
    """
    sets: tuple
    set_index: np.ndarray
    row: np.ndarray
    slave: np.ndarray        # skirt node id
    surface: np.ndarray      # 'table' or 'stop'
    ground: np.ndarray       # grounded node id (placed at the slave node)
    elem: np.ndarray         # GAPUNI element id


def ccx_gaps(model: Model, mesh: SkirtMesh, method: str, lay: Layout | None = None) -> GapIds:
    """Gaps of the CalculiX ``method`` deck: every slave (table, stop) for 'penalty', the stop for 'mortar'
    and 'f2f'.

    Grounded nodes follow the master rings; gap elements follow the SPRING1 restraints.
    """
    lay = lay or ccx_layout(model, mesh, method)
    if method == PENALTY and ccx_penalty_is_n2f(model):
        chosen = ()
    else:
        chosen = (mesh.table, mesh.stop) if method == PENALTY else (mesh.stop,)
    sets = tuple(ss for ss in chosen if ss is not None)
    set_index = np.concatenate([np.full(ss.nodes.size, k) for k, ss in enumerate(sets)] or [np.zeros(0, int)])
    row = np.concatenate([np.arange(ss.nodes.size) for ss in sets] or [np.zeros(0, int)])
    n = row.size
    return GapIds(sets=sets, set_index=set_index.astype(int), row=row.astype(int),
                  slave=np.concatenate([mesh_node_ids(mesh, ss.nodes) for ss in sets] or [np.zeros(0, np.int64)]),
                  surface=np.array([sets[k].surface for k in set_index.astype(int)], dtype=object),
                  ground=lay.next_node + np.arange(n), elem=lay.first_gap_elem + np.arange(n))


def ccx_ground_node_ids(model: Model, mesh: SkirtMesh, method: str) -> dict[tuple[int, str], int]:
    """(slave node id, surface) -> grounded GAPUNI node id, as numbered in the ``method`` deck."""
    gaps = ccx_gaps(model, mesh, method)
    return {(int(s), str(f)): int(g) for s, f, g in zip(gaps.slave, gaps.surface, gaps.ground)}
