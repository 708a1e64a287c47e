"""The dialect records: each record's renderer, templates, reader, runner and deck names agree with each other,
and every result format (the dialects' readers and the others) is one :class:`~deckbridge.dialects.Format`."""

from importlib.resources import files

import pytest
from click.testing import CliRunner

from deckbridge.cli import main
from deckbridge.dialects import DIALECTS, NAMES, OTHER_FORMATS, dialect, formats
from deckbridge.mesh import build_mesh
from deckbridge.model import load

SMALL = ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1"]


@pytest.mark.parametrize("name", sorted(DIALECTS))
def test_record_renders_exactly_its_deck_names_from_its_template_folder(name, tmp_path):
    d = dialect(name)
    model = load(None, SMALL)
    written = d.write(model, build_mesh(model), tmp_path)
    assert [p.name for p in written] == d.deck_names("JAR")
    assert d.decks_in(tmp_path, "JAR") == sorted(written)
    assert (files("deckbridge.templates") / d.templates).is_dir()


@pytest.mark.parametrize("name", sorted(DIALECTS))
def test_record_lives_in_its_folder_and_its_parts_are_there(name):
    """One folder per dialect: the record is deckbridge.dialects.<name>.RECORD, its renderer, reader and
    runner (when it has one) are modules of that folder and hold the functions the record names."""
    d = dialect(name)
    assert d.name == name and d.package == f"deckbridge.dialects.{name}"
    assert d.part(d.renderer).__module__ == f"{d.package}.render"
    f = formats()[d.reader]
    for fn in ("read", "detect"):
        assert d.part(f"{f.module}:{fn}").__module__ == f"{d.package}.reader"
    for ref in (d.runner, d.run_check, d.wall_reader, d.series_writer):
        if ref is not None:
            assert callable(d.part(ref)) and d.part(ref).__module__.startswith(d.package + ".")


def test_formats_are_the_dialects_readers_and_the_others(tmp_path):
    assert set(NAMES) == set(DIALECTS)
    assert sorted(formats()) == sorted({d.reader for d in DIALECTS.values()} | set(OTHER_FORMATS))
    assert sorted(formats()) == ["abaqus_dat", "calculix", "mystran_f06", "nastran_contact", "nastran_op2", "plain_csv", "reference"]
    res = CliRunner().invoke(main, ["decks", "-o", str(tmp_path / "d"), "--dialect", "ccx"])
    assert res.exit_code != 0 and "deck dialect 'ccx': unknown (known: abaqus, calculix, mystran, nastran, nastran_surface)" in res.output
    assert not (tmp_path / "d").exists() or not any((tmp_path / "d").iterdir())
