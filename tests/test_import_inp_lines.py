"""Element data lines of an .inp as CalculiX reads them (issue 21.14, issue 26): an element of a type
with n nodes takes its id and n node ids, continuing on the next lines until it has them (ccx's
elements.f: C3D10 written 8 + 3, C3D20 16 + 5); a ',' ending a complete line and ids past the n-th are
ignored. Reference: the same ring written one element per plain line (what every reader agrees on)."""

import numpy as np
import pytest

from deckbridge.errors import DeckbridgeError
from deckbridge.mesh import build_mesh
from deckbridge.model import ModelError, load
from deckbridge.importers.inp_mesh import read_inp_mesh
from gmsh_skirt import write_inp
from test_import_checks import N, _ring

SETS = "mesh.sets={base: BASE, top: TOP}"


def _deck(path, element_lines, etype="C3D8"):
    """The ring of test_import_checks with its element block replaced by ``element_lines``."""
    ids, xyz, eids, conn = _ring()
    plain = write_inp(path, ids, xyz, eids, conn, {"BASE": ids[: 2 * N], "TOP": ids[2 * N:]}).read_text()
    head, rest = plain.split("*ELEMENT", 1)
    sets = rest[rest.index("*NSET"):]
    path.write_text(head + f"*ELEMENT, TYPE={etype}, ELSET=SKIRT\n" + "\n".join(element_lines) + "\n" + sets)
    return path


def _lines(style):
    _, _, eids, conn = _ring()
    out = []
    for e, c in zip(eids, conn):
        c = [str(v) for v in c]
        if style == "trailing_comma":          # a complete C3D8 line ending with ','
            out.append(", ".join([str(e), *c]) + ",")
        elif style == "split":                 # 1 + 4 ids, then 4 (no ',' at the end of the first line)
            out += [", ".join([str(e), *c[:4]]), ", ".join(c[4:])]
        elif style == "split_comma":           # continuation announced by ','
            out += [", ".join([str(e), *c[:5]]) + ",", ", ".join(c[5:])]
        elif style == "extra_ids":             # more than 8 ids: ccx takes the first 8
            out.append(", ".join([str(e), *c, c[0], c[1]]))
    return out


@pytest.mark.parametrize("style", ["trailing_comma", "split", "split_comma", "extra_ids"])
def test_c3d8_lines_read_as_calculix_reads_them(tmp_path, style):
    """Main: 'no 8-node hexahedra in the file' (trailing ',' swallowed the next line or card; > 8 ids) or
    a ragged-array ValueError. Now the same 8 hexahedra, node for node, as the plain deck."""
    plain = build_mesh(load(None, [f"mesh.file={_deck(tmp_path / 'plain.inp', _plain())}", SETS]))
    got = build_mesh(load(None, [f"mesh.file={_deck(tmp_path / f'{style}.inp', _lines(style))}", SETS]))
    np.testing.assert_array_equal(got.hexes, plain.hexes)
    np.testing.assert_array_equal(got.elem_ids, np.arange(1, N + 1))
    np.testing.assert_array_equal(got.table.nodes, plain.table.nodes)


def _plain():
    _, _, eids, conn = _ring()
    return [", ".join(map(str, [e, *c])) for e, c in zip(eids, conn)]


def test_c3d10_written_8_plus_3_is_refused_naming_the_type(tmp_path):
    """C3D10 as in CalculiX's test decks (id and 7 node ids, then 3 more): main ended in 'ValueError:
    setting an array element with a sequence'; read whole (10 nodes each), these four tetrahedra on the hexahedral
    ring's nodes are then refused in one line (since issue 23 C3D10 is taken: here nodes are left unused)."""
    lines = []
    for e in range(1, 5):
        lines += [", ".join(map(str, [e, 1, 2, 3, 4, 17, 18, 19])) + ",", "20, 5, 6"]
    m = load(None, [f"mesh.file={_deck(tmp_path / 'tet.inp', lines, 'C3D10')}", SETS])
    with pytest.raises(ModelError, match=r"tet.inp': node 7 is used by no element") as err:
        build_mesh(m)
    assert "\n" not in str(err.value)
    assert read_inp_mesh(tmp_path / "tet.inp").elements["C3D10"][1].shape == (4, 10)


def test_incomplete_element_before_the_next_card_is_named(tmp_path):
    lines = _plain()[:-1] + [", ".join(_plain()[-1].split(", ")[:6])]     # the last element lacks 3 ids
    with pytest.raises(DeckbridgeError, match=r"element 8 of type C3D8 is incomplete \(5 of 8 node ids"):
        read_inp_mesh(_deck(tmp_path / "cut.inp", lines))
