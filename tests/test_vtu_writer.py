"""The VTU writer of deckbridge.paraview: zlib-compressed binary XML at ZLIB_LEVEL, several files at once,
read back by meshio bit for bit; meshio's own zlib is restored afterwards."""

import zlib

import meshio
import meshio.vtu._vtu as meshio_vtu
import numpy as np

from deckbridge.paraview import ZLIB_LEVEL, state_mesh, write_vtus, zlib_level


def _states(n_states, rng):
    nodes = rng.random((27, 3))
    hexes = np.array([[0, 1, 4, 3, 9, 10, 13, 12], [1, 2, 5, 4, 10, 11, 14, 13]], np.int64)
    states = [{"point": {"displacement_m": rng.random((27, 3)) * 1e-4, "node_id": np.arange(1, 28),
                         "table_status": rng.integers(-1, 2, 27).astype(np.int8)},
               "cell": {"stress_pa": rng.normal(size=(2, 6)) * 1e6, "bottom_row": np.array([1, 0], np.uint8)}}
              for _ in range(n_states)]
    return nodes, hexes, states


def test_vtus_round_trip_bit_for_bit_and_are_zlib_binary(tmp_path):
    nodes, hexes, states = _states(3, np.random.default_rng(22))
    paths = [tmp_path / f"s{k}.vtu" for k in range(3)]
    write_vtus([(p, state_mesh(nodes, hexes, st)) for p, st in zip(paths, states)])
    for p, st in zip(paths, states):
        head = p.read_bytes()[:400].decode()
        assert 'compressor="vtkZLibDataCompressor"' in head and 'format="binary"' in p.read_text()
        v = meshio.read(p)
        np.testing.assert_array_equal(v.points, nodes)
        np.testing.assert_array_equal(v.cells[0].data, hexes)
        for k, a in st["point"].items():
            np.testing.assert_array_equal(v.point_data[k], a)
            assert v.point_data[k].dtype == a.dtype
        for k, a in st["cell"].items():
            np.testing.assert_array_equal(v.cell_data[k][0], a)
    assert meshio_vtu.zlib is zlib                       # the level is set only while writing


def test_zlib_level_is_the_one_compressing():
    block = np.random.default_rng(1).random(4096).tobytes()
    with zlib_level(ZLIB_LEVEL):
        assert meshio_vtu.zlib.compress(block) == zlib.compress(block, ZLIB_LEVEL)
        assert meshio_vtu.zlib.decompress(zlib.compress(block)) == block
    assert ZLIB_LEVEL != 6 and zlib.compress(block, 6) != zlib.compress(block, ZLIB_LEVEL)
