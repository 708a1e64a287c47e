"""Import checks (issue 15): each refused with one line naming the set/file and the node/element,
on a minimal broken mesh (a ring of 8 hexahedra, 1 element high, through the wall)."""

import numpy as np
import pytest

from deckbridge.mesh import build_mesh
from deckbridge.model import ModelError, load
from gmsh_skirt import write_inp

N = 8


def _ring(z_levels=(0.0, 1.0)):
    """Nodes (ids 1..) and C3D8 hexes (ids 1..) of a ring of N elements, R = 1 +- 0.05."""
    th = 2 * np.pi * np.arange(N) / N
    xyz = [(r * np.cos(t), r * np.sin(t), z) for z in z_levels for r in (0.95, 1.05) for t in th]
    idx = lambda k, i, j: (k * 2 + i) * N + j % N  # noqa: E731
    conn = [[idx(0, 0, j), idx(0, 1, j), idx(0, 1, j + 1), idx(0, 0, j + 1),
             idx(1, 0, j), idx(1, 1, j), idx(1, 1, j + 1), idx(1, 0, j + 1)] for j in range(N)]
    ids = np.arange(1, len(xyz) + 1)
    return ids, np.array(xyz), np.arange(1, N + 1), np.array(conn) + 1


def _model(tmp_path, ids, xyz, eids, conn, sets=None, etype="C3D8", extra=()):
    sets = sets or {"BASE": ids[: 2 * N], "TOP": ids[2 * N: 4 * N]}
    f = write_inp(tmp_path / "m.inp", ids, xyz, eids, conn, sets, etype=etype)
    return load(None, [f"mesh.file={f}", "mesh.sets={base: BASE, top: TOP}", *extra])


def _fails(model, pattern):
    with pytest.raises(ModelError, match=pattern) as err:
        build_mesh(model)
    assert "\n" not in str(err.value)


def test_minimal_ring_imports(tmp_path):
    me = build_mesh(_model(tmp_path, *_ring()))
    assert me.table.nodes.size == 2 * N and me.base_elems.size == N


def test_unknown_set_name_lists_the_sets_found(tmp_path):
    m = _model(tmp_path, *_ring(), extra=["mesh.sets={base: FLOOR, top: TOP}"])
    _fails(m, r"mesh.sets.base = 'FLOOR': no such node set .*found: BASE, TOP")


def test_base_node_off_the_plane(tmp_path):
    ids, xyz, eids, conn = _ring()
    xyz[3, 2] = 0.01
    _fails(_model(tmp_path, ids, xyz, eids, conn), r"mesh.sets.base = 'BASE': node 4 .*off the base plane")


def test_top_set_empty_or_not_above_base(tmp_path):
    ids, xyz, eids, conn = _ring()
    _fails(_model(tmp_path, ids, xyz, eids, conn, sets={"BASE": ids[:16], "TOP": ids[:0]}), r"mesh.sets.top.*is empty")
    _fails(_model(tmp_path, ids, xyz, eids, conn, sets={"BASE": ids[:16], "TOP": ids[:16]}),
           r"mesh.sets.top = 'TOP': node 1 .*not above the base")


def test_duplicate_and_unreferenced_nodes(tmp_path):
    ids, xyz, eids, conn = _ring()
    ids2, xyz2 = np.append(ids, 99), np.vstack([xyz, [5.0, 5.0, 5.0]])
    _fails(_model(tmp_path, ids2, xyz2, eids, conn), r"node 99 is used by no element")
    ids3, xyz3 = np.append(ids, 5), np.vstack([xyz, [5.0, 5.0, 5.0]])
    _fails(_model(tmp_path, ids3, xyz3, eids, conn), r"node 5 is defined twice")
    ids4, xyz4 = np.append(ids, 99), np.vstack([xyz, xyz[0]])   # an unmerged copy of node 1, used by element 1
    conn4 = conn.copy()
    conn4[0, 0] = 99
    _fails(_model(tmp_path, ids4, xyz4, eids, conn4), r"nodes 1 and 99 coincide")


def test_inverted_element(tmp_path):
    ids, xyz, eids, conn = _ring()
    conn = conn.copy()
    conn[2] = conn[2][[4, 5, 6, 7, 0, 1, 2, 3]]   # element 3 upside down: negative Jacobian
    _fails(_model(tmp_path, ids, xyz, eids, conn), r"element 3 is inverted")


def test_mesh_not_connected(tmp_path):
    ids, xyz, eids, conn = _ring()
    keep = [0, 1, 2, 4, 5, 6]                       # two arcs of 3 elements each
    conn = conn[keep]
    used = np.unique(conn)
    _fails(_model(tmp_path, ids[used - 1], xyz[used - 1], eids[keep], conn,
                  sets={"BASE": used[used <= 16], "TOP": used[used > 16]}), r"not connected: 2 parts")


def test_other_element_type_names_type_and_count(tmp_path):
    ids, xyz, eids, conn = _ring()
    conn20 = np.hstack([conn, conn[:, :8], conn[:, :4]])     # 20 node ids per element, as a C3D20 has
    _fails(_model(tmp_path, ids, xyz, eids, conn20, etype="C3D20"),     # taken since issue 23: its order is checked
           r"element 1 \(C3D20\): node 9 is not near the mid-point of nodes 1 and 2 \(not CalculiX's node order\)")
    _fails(_model(tmp_path, ids, xyz, eids, conn[:, :4], etype="C3D4"),
           r"8 elements of type C3D4: 4-node tetrahedra; deckbridge takes 8-node hexahedra .* 10-node tetrahedra")
