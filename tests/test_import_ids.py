"""Node and element ids against each dialect's fields (issue 26): a Nastran small field holds 8
characters (ids up to 99,999,999), CalculiX reads ids as 10-character 32-bit integers (2,147,483,647).
Main imported ids near 1e12 and then failed in `decks` with pyNastran's "field='1000000000001' is not
8 characters long". Reference: the field widths and pyNastran / the project's inp reader reading the
decks back."""

import numpy as np
import pytest
from click.testing import CliRunner

from deckbridge.cli import main
from deckbridge.mesh import build_mesh
from deckbridge.model import ModelError, load
from deckbridge.importers.inp_mesh import read_inp_mesh
from gmsh_skirt import write_inp
from test_import_checks import N, _ring

SETS = "mesh.sets={base: BASE, top: TOP}"


def _mesh(tmp_path, first_node, first_elem):
    ids, xyz, eids, conn = _ring()
    nid = ids - 1 + first_node
    return write_inp(tmp_path / "ids.inp", nid, xyz, eids - 1 + first_elem, nid[conn - 1],
                     {"BASE": nid[: 2 * N], "TOP": nid[2 * N:]})


@pytest.mark.parametrize("first", [10 ** 12, 2 ** 31, 0])
def test_ids_no_dialect_carries_are_refused_at_import(tmp_path, first):
    f = _mesh(tmp_path, first, 1)
    with pytest.raises(ModelError, match=rf"node id {first}: ids must lie in 1..2147483647 .*nastran 99999999"):
        build_mesh(load(None, [f"mesh.file={f}", SETS]))


def test_ids_beyond_nastran_fields_leave_the_nastran_decks_out_with_a_reason(tmp_path):
    """Ids from 500,000,001: `import` notes that nastran and mystran cannot carry them; `decks` refuses
    those dialects in one line before writing when named (`--dialect`), leaves them out with a note
    otherwise (as `run` does); the CalculiX deck carries them (read back: the same ids)."""
    f = _mesh(tmp_path, 500_000_001, 700_000_001)
    out = tmp_path / "m.yaml"
    r = CliRunner().invoke(main, ["import", str(f), "-o", str(out), "--base", "BASE", "--top", "TOP"])
    assert r.exit_code == 0, r.output
    assert "note: nastran decks cannot carry this mesh's ids" in r.output and "note: mystran" in r.output
    assert "note: calculix" not in r.output and "note: abaqus" not in r.output
    r = CliRunner().invoke(main, ["decks", str(out), "-o", str(tmp_path / "all")])     # as run: the others, a note
    assert r.exit_code == 0, r.output
    assert "mystran deck: its decks would use ids up to" in r.output and "nastran" in r.output
    names = [p.name for p in (tmp_path / "all").iterdir()]
    assert any(n.endswith("_ccx_penalty.inp") for n in names) and not any(n.endswith(".bdf") for n in names)
    r = CliRunner().invoke(main, ["decks", str(out), "-o", str(tmp_path / "my"), "--dialect", "mystran"])
    assert r.exit_code == 2 and not (tmp_path / "my").exists()
    assert "mystran deck: its decks would use ids up to" in r.output.strip().splitlines()[-1]
    r = CliRunner().invoke(main, ["decks", str(out), "-o", str(tmp_path / "ccx"), "--dialect", "calculix"])
    assert r.exit_code == 0, r.output
    deck = read_inp_mesh(next((tmp_path / "ccx").glob("*_ccx_penalty.inp")))
    assert set(range(500_000_001, 500_000_001 + 4 * N)) <= set(deck.node_ids.tolist())
    np.testing.assert_array_equal(np.sort(deck.elements["C3D8I"][0]) if "C3D8I" in deck.elements
                                  else np.sort(deck.elements["C3D8"][0]), 700_000_001 + np.arange(N))


def test_ids_that_fit_8_characters_write_a_nastran_deck_pynastran_reads(tmp_path):
    from pyNastran.bdf.bdf import BDF
    f = _mesh(tmp_path, 1_000_001, 2_000_001)
    m = load(None, [f"mesh.file={f}", SETS, "name=ids"])
    r = CliRunner().invoke(main, ["decks", "--set", f"mesh.file={f}", "--set", "mesh.sets={base: BASE, top: TOP}",
                                  "--set", "name=ids", "-o", str(tmp_path / "d"), "--dialect", "nastran"])
    assert r.exit_code == 0, r.output
    bdf = BDF(debug=None)
    bdf.read_bdf(str(tmp_path / "d" / "ids_penalty.bdf"), xref=False)
    assert set(range(1_000_001, 1_000_001 + 4 * N)) <= set(bdf.nodes) and max(bdf.nodes) <= 99_999_999
    assert m.mesh.file == str(f)
