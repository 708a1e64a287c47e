"""The dialect table: each record's renderer, templates, reader, runner and deck names agree with each other."""

import importlib
from importlib.resources import files

import pytest
from click.testing import CliRunner

from deckbridge.cli import main
from deckbridge.dialects import DIALECTS, dialect
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.readers import _load_all, formats
from deckbridge.readers._registry import READERS

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
def test_record_reader_is_a_registered_format_and_runner_has_run(name):
    _load_all()
    d = dialect(name)
    assert d.reader in READERS and d.reader in formats()
    assert READERS[d.reader].read.__module__ == f"deckbridge.readers.{d.reader}"
    if d.runner is not None:
        assert callable(importlib.import_module(d.runner).run)


def test_every_registered_reader_is_listed_and_unknown_dialect_is_refused(tmp_path):
    _load_all()
    assert sorted(READERS) == formats()
    res = CliRunner().invoke(main, ["decks", "-o", str(tmp_path / "d"), "--dialect", "ccx"])
    assert res.exit_code != 0 and "deck dialect 'ccx': unknown (known: abaqus, calculix, mystran, nastran, nastran_surface)" in res.output
    assert not (tmp_path / "d").exists() or not any((tmp_path / "d").iterdir())
