"""One name per fact (issue 22/25): every key of the reference summaries is defined once in
deckbridge/summary_keys.py with a unit and a meaning, and the retired duplicates are gone from the package,
the tests and the documentation."""

import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from deckbridge import summary_keys as K
from deckbridge.cli import main

ROOT = Path(__file__).resolve().parents[1]
TINY = ["--set", "mesh.n_theta=12", "--set", "mesh.n_z=3", "--set", "mesh.n_r=1", "--set", "steps.increments=2",
        "--set", "outputs.vtu=false"]


def test_every_key_has_a_unit_and_a_meaning_and_retired_names_are_not_keys():
    for name, key in K.KEYS.items():
        assert key == name and key.unit and len(key.meaning) > 10, name
    assert not set(K.RETIRED) & set(K.KEYS)
    assert K.describe("section_liftoff_load_factor").startswith("section_liftoff_load_factor [-]: ")


def test_retired_names_appear_nowhere():
    own = {ROOT / "deckbridge" / "summary_keys.py", Path(__file__).resolve()}
    files = [p for d in ("deckbridge", "tests", "docs", "bench", "examples", "templates") if (ROOT / d).is_dir()
             for p in (ROOT / d).rglob("*") if p.suffix in (".py", ".md", ".j2", ".ipynb", ".yaml", ".html")]
    files += [ROOT / "README.md", ROOT / "ARCHITECTURE.md"]
    pattern = re.compile(r"\b(" + "|".join(map(re.escape, K.RETIRED)) + r")\b")
    hits = [f"{p.relative_to(ROOT)}: {m.group(0)}" for p in files if p.is_file() and p.resolve() not in own
            for m in pattern.finditer(p.read_text(errors="replace"))]
    assert hits == []


@pytest.mark.parametrize("method", ["penalty", "lagrange"])
def test_solve_summary_keys_are_defined_and_plain(method, tmp_path):
    r = CliRunner().invoke(main, ["solve", *TINY, "--method", method, "-o", str(tmp_path)])
    assert r.exit_code == 0, r.output
    text = (tmp_path / "summary.json").read_text()
    assert set(json.loads(text)) <= set(K.KEYS)
    assert not re.search(r"-0(\.0+)?(?![0-9.eE])", text)                # no -0.0 written


def test_liftoff_summary_keys_are_defined(tmp_path):
    r = CliRunner().invoke(main, ["liftoff", *TINY, "--tol", "0.01", "-o", str(tmp_path)])
    assert r.exit_code == 0, r.output
    s = json.loads((tmp_path / "summary.json").read_text())
    assert set(s) - set(s["methods"]) <= set(K.KEYS)
    assert s["k_tangent_follows_k"] is True and s["beam_theory_liftoff_load_factor"] > 0
