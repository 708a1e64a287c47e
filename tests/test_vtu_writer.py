"""The VTU writer of deckbridge.paraview: zlib-compressed binary XML at ZLIB_LEVEL (blocks that hardly deflate
stored, zlib level 0), several files at once, read back by meshio bit for bit; meshio's own zlib is restored
afterwards."""

import zlib

import meshio
import meshio.vtu._vtu as meshio_vtu
import numpy as np

from deckbridge.paraview import STORE_SAMPLE, ZLIB_LEVEL, state_mesh, write_vtus, zlib_level


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


def test_zlib_level_is_the_one_compressing_and_random_floats_are_stored():
    rng = np.random.default_rng(1)
    smooth = np.repeat(np.arange(1024), 4).astype(np.int64).tobytes()         # deflates to a fraction
    noise = rng.random(4096).tobytes()                                        # float64 mantissas: ~0.9 at level 1
    with zlib_level(ZLIB_LEVEL):
        assert meshio_vtu.zlib.compress(smooth) == zlib.compress(smooth, ZLIB_LEVEL)
        assert meshio_vtu.zlib.compress(noise) == zlib.compress(noise, 0)     # stored
        assert meshio_vtu.zlib.decompress(meshio_vtu.zlib.compress(noise)) == noise
    assert len(zlib.compress(smooth, ZLIB_LEVEL)) < 0.2 * len(smooth) and len(noise) > 2 * STORE_SAMPLE
    assert ZLIB_LEVEL != 6 and zlib.compress(smooth, 6) != zlib.compress(smooth, ZLIB_LEVEL)


def test_stored_blocks_round_trip(tmp_path):
    """Results that hardly deflate (random stresses, 3 blocks of 32 KiB and a partial one) go stored and are
    read back bit for bit beside a compressed all-zero array; the file holds them at about their raw size."""
    rng = np.random.default_rng(5)
    nodes, hexes, _ = _states(1, rng)
    stress = rng.normal(size=(2200, 6)) * 1e8
    mesh = meshio.Mesh(np.vstack([nodes, rng.random((2200 - 27, 3))]), [("hexahedron", hexes)],
                       point_data={"stress_nodal_pa": stress, "zeros": np.zeros((2200, 6))})
    write_vtus([(tmp_path / "s.vtu", mesh)])
    v = meshio.read(tmp_path / "s.vtu")
    np.testing.assert_array_equal(v.point_data["stress_nodal_pa"], stress)
    np.testing.assert_array_equal(v.point_data["zeros"], 0.0)
    size = (tmp_path / "s.vtu").stat().st_size
    assert 4 / 3 * (stress.nbytes + v.points.nbytes * 0.8) < size < 4 / 3 * 1.1 * (stress.nbytes + v.points.nbytes)
