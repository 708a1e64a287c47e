"""``deckbridge import MESH -o model.yaml`` and the commands on the model it writes (issue 15)."""

import json

import numpy as np
import pytest
from click.testing import CliRunner

from deckbridge.cli import main
from gmsh_skirt import write_inp


def _tube(tmp_path, n=16, mm=False):
    """A tube R = 1 +- 0.05 m, H = 0.5 m, 16 x 2 x 1 hexahedra (numpy, ids from 11, elements from 501)."""
    th = 2 * np.pi * np.arange(n) / n
    xyz = np.array([(r * np.cos(t), r * np.sin(t), z) for z in (0, 0.25, 0.5) for r in (0.95, 1.05) for t in th])
    idx = lambda k, i, j: (k * 2 + i) * n + j % n  # noqa: E731
    conn = np.array([[idx(k, 0, j), idx(k, 1, j), idx(k, 1, j + 1), idx(k, 0, j + 1), idx(k + 1, 0, j),
                      idx(k + 1, 1, j), idx(k + 1, 1, j + 1), idx(k + 1, 0, j + 1)] for k in range(2) for j in range(n)])
    ids = np.arange(11, 11 + len(xyz))
    scale = 1000.0 if mm else 1.0
    return write_inp(tmp_path / "tube.inp", ids, xyz * scale, np.arange(501, 501 + len(conn)), ids[conn],
                     {"FLOOR": ids[: 2 * n], "LID": ids[4 * n:]})


def test_import_writes_a_checked_model_that_every_command_takes(tmp_path):
    mesh = _tube(tmp_path, mm=True)
    out = tmp_path / "models" / "tube.yaml"
    r = CliRunner().invoke(main, ["import", str(mesh), "-o", str(out), "--base", "FLOOR", "--top", "LID",
                                  "--units", "mm", "--set", "loads.T=0", "--set", "loads.M=2.0e6", "--set", "load_introduction=kinematic"])
    assert r.exit_code == 0, r.output
    text = out.read_text()
    assert "file: ../tube.inp" in text and "units: mm" in text
    r = CliRunner().invoke(main, ["solve", str(out), "--method", "penalty", "-o", str(tmp_path / "sol")])
    assert r.exit_code == 0, r.output
    s = json.loads((tmp_path / "sol" / "summary.json").read_text())
    # measured geometry (mm -> m): beam theory N R / (2 M) with R = 1 m
    assert s["beam_theory_liftoff_load_factor"] == pytest.approx(2.7e6 * 1.0 / (2 * 2.0e6), rel=1e-9)
    assert s["liftoff_load_factor"] == pytest.approx(0.675, rel=0.05)   # coarse 16 x 2 x 1 ring
    r = CliRunner().invoke(main, ["decks", str(out), "-o", str(tmp_path / "decks")])
    assert r.exit_code == 0, r.output
    bdf = (tmp_path / "decks" / "tube_penalty.bdf").read_text()
    assert "CHEXA        501" in bdf and "GRID*                 11" in bdf


def test_import_refuses_unknown_set_in_one_line_and_writes_nothing(tmp_path):
    mesh = _tube(tmp_path)
    out = tmp_path / "m.yaml"
    r = CliRunner().invoke(main, ["import", str(mesh), "-o", str(out), "--base", "BASE", "--top", "LID"])
    assert r.exit_code == 2
    assert r.output.strip().splitlines()[-1].startswith("deckbridge: error: mesh.sets.base = 'BASE': no such node set")
    assert "found: FLOOR, LID" in r.output and not out.exists()
