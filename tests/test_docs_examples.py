"""Every code example of the documentation site (docs/examples/*.py, included into its pages) runs and
asserts its numbers: an example that breaks fails here."""

from __future__ import annotations

import runpy
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "docs" / "examples").glob("*.py"))


def test_the_examples_folder_is_not_empty():
    assert len(EXAMPLES) >= 5, EXAMPLES


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_example_runs_and_its_assertions_hold(path, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)                 # an example writes only into temporary folders
    runpy.run_path(str(path), run_name="__main__")
    assert capsys.readouterr().out.strip()      # it prints what it shows on the site
    assert not any(tmp_path.iterdir())


def test_every_example_is_shown_on_a_page_and_every_included_file_exists():
    docs = Path(__file__).resolve().parents[1] / "docs"
    pages = "\n".join(p.read_text(encoding="utf-8") for p in docs.rglob("*.md"))
    for ex in EXAMPLES:
        assert f'--8<-- "docs/examples/{ex.name}"' in pages, f"{ex.name} is on no page"
    for inc in __import__("re").findall(r'--8<-- "([^"]+)"', pages):
        assert (docs.parent / inc).is_file(), inc
