"""The documentation site: built offline by MkDocs (what ``bash scripts/docs.sh`` runs, --strict: a broken
link or a missing include fails), its generated parts checked against the code, and its main pages opened
in headless Chromium: the expected title in the DOM, a screenshot that is not blank and shows the theme's
header (its CSS loaded from the site itself, no network)."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from deckbridge.model import Model
from deckbridge.model_fields import NU_MAX
from deckbridge.model_reference import key_docs, rules_of

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run", "--window-size=1280,1000"]
PAGES = {"index.html": "deckbridge", "getting-started.html": "Getting started",
         "reference/model.html": "Model reference", "reference/api.html": "Python API",
         "guide/sweep.html": "deckbridge sweep", "verdict.html": "The penalty verdict"}


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    out = tmp_path_factory.mktemp("site")
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    r = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--quiet", "-f", str(ROOT / "mkdocs.yml"),
                        "-d", str(out)], capture_output=True, text=True, timeout=300, env=env, cwd=ROOT)
    assert r.returncode == 0, (r.stdout + r.stderr)[-3000:]
    return out


def test_the_model_rules_come_from_the_validators():
    nu = rules_of("material.nu")
    assert any(r.startswith(f"must be < {NU_MAX:g}") for r in nu), nu
    keys = [d.key for d in key_docs()]
    assert "contact.penalty.alpha" in keys and "steps.increments" in keys
    assert len(keys) == len(set(keys))


def test_site_pages_carry_the_generated_reference_help_and_api(site):
    for page in PAGES:
        assert (site / page).is_file(), page
    model_html = (site / "reference" / "model.html").read_text(encoding="utf-8")
    leaves = []

    def walk(d, prefix=""):
        for k, v in d.items():
            (walk(v, f"{prefix}{k}.") if isinstance(v, dict) else leaves.append(prefix + k))
    walk(Model().to_dict())
    for key in leaves:                          # every model key is in the reference
        assert f"<code>{key}</code>" in model_html, key
    assert f"must be &lt; {NU_MAX:g}" in model_html
    sweep = (site / "guide" / "sweep.html").read_text(encoding="utf-8")
    assert "Usage: deckbridge sweep" in sweep and "--k-factors" in sweep          # click's own help
    api = (site / "reference" / "api.html").read_text(encoding="utf-8")
    assert "penalty_verdict" in api and "solve_model" in api                     # from the docstrings
    assert "onset within" in (site / "reference" / "modules.html").read_text(encoding="utf-8")
    assert "google" not in (site / "index.html").read_text(encoding="utf-8").lower()   # no web fonts


def _chromium(*args, timeout=60):
    with tempfile.TemporaryDirectory() as profile:
        return subprocess.run([CHROMIUM, *FLAGS, f"--user-data-dir={profile}", *args],
                              capture_output=True, text=True, timeout=timeout)


@pytest.mark.skipif(CHROMIUM is None, reason="chromium not installed (scripts/bootstrap.sh installs it)")
@pytest.mark.parametrize("page", ["index.html", "reference/model.html", "reference/api.html"])
def test_main_pages_render_in_headless_chromium(site, page, tmp_path):
    url = (site / page).as_uri()
    dom = _chromium("--dump-dom", url)
    assert dom.returncode == 0, dom.stderr[-2000:]
    h1 = re.search(r"<h1[^>]*>(.*?)</h1>", dom.stdout, re.S)
    assert h1 is not None and PAGES[page] in re.sub(r"<[^>]+>", "", h1.group(1)), (h1 and h1.group(1))
    shot = tmp_path / "shot.png"
    r = _chromium(f"--screenshot={shot}", url)
    assert r.returncode == 0 and shot.is_file(), r.stderr[-2000:]
    img = np.asarray(Image.open(shot).convert("RGB"), dtype=int)
    assert img.shape[0] >= 900 and img.shape[1] >= 1200
    ink = (img.min(axis=2) < 200).mean()
    assert 0.01 < ink < 0.6, ink                                        # text drawn, not blank, not all dark
    header = img[5:40, :, :].reshape(-1, 3)                             # Material's indigo header bar
    indigo = (np.abs(header - np.array([0x40, 0x51, 0xb5])).max(axis=1) < 40).mean()
    assert indigo > 0.5, indigo


def test_the_notebook_slot_renders_cells_and_outputs(tmp_path):
    """docs/notebooks/quickstart.md shows the notebook through the hook: code cells, markdown, text outputs."""
    import json
    import runpy

    hook = runpy.run_path(str(ROOT / "docs" / "hooks" / "deckbridge_docs.py"))
    nb = {"metadata": {"kernelspec": {"language": "python"}}, "nbformat": 4, "nbformat_minor": 5, "cells": [
        {"cell_type": "markdown", "metadata": {}, "source": ["# Load the model"]},
        {"cell_type": "code", "metadata": {}, "execution_count": 1, "source": ["print(2 + 2)"],
         "outputs": [{"output_type": "stream", "name": "stdout", "text": ["4\n"]}]}]}
    (tmp_path / "notebooks").mkdir()
    (tmp_path / "notebooks" / "q.ipynb").write_text(json.dumps(nb))
    md = hook["on_page_markdown"]("x <!-- notebook: notebooks/q.ipynb --> y", None, {"docs_dir": str(tmp_path)}, None)
    assert "# Load the model" in md and "```python\nprint(2 + 2)\n```" in md and "```text\n4\n```" in md
    missing = hook["on_page_markdown"]("<!-- notebook: notebooks/none.ipynb -->", None, {"docs_dir": str(tmp_path)}, None)
    assert "not in this checkout yet" in missing


def test_every_markdown_page_of_docs_is_in_the_nav():
    """A page written under docs/ but left out of mkdocs.yml's nav would be built yet unreachable."""
    import yaml

    nav = yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))
    listed = set()

    def walk(items):
        for it in items:
            for v in it.values():
                walk(v) if isinstance(v, list) else listed.add(v)
    walk(nav["nav"])
    docs = ROOT / "docs"
    pages = {str(p.relative_to(docs)) for p in docs.rglob("*.md") if "hooks" not in p.parts}
    assert pages - listed == set(), pages - listed
