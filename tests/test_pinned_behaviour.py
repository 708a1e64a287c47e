"""Behaviour pins for refactors (issue 9): rendered decks byte-identical, reference results identical.

The pins in ``tests/pinned/`` were written from the code *before* the refactor started
(``python tests/test_pinned_behaviour.py --write``). A change that is meant to alter a deck or a
result (a new deck semantics, a solver change) regenerates them in the same commit and says why.
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

import numpy as np
import pytest

from deckbridge.model import load
from deckbridge.render import render_all
from deckbridge.solve import solve_model

PINS = Path(__file__).resolve().parent / "pinned"

# The default model and two variants that exercise the other branches of every template.
VARIANTS = {
    "default": [],
    "kinematic_outer": ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1", "load_introduction=kinematic",
                        "contact.stop.side=outer", "contact.penalty.k_tangent=3.0e7",
                        "contact.penalty.open_ratio=1.0e-5", "loads.azimuth=30", "steps.increments=7"],
    "cone_nostop": ["name=CONE", "mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=3", "geometry.top_radius=1.2",
                    "contact.stop.side=none", "contact.penalty.k_normal=2.5e8", "steps.lambda_max=0.8"],
    # pinned before the round-3 redesign (issue 22): pads with the default stop, friction, an imported mesh
    "pads": ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1", "contact.pads={count: 4, width_deg: 30, first_deg: 45}"],
    "friction": ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=2", "contact.friction=0.2",
                 "contact.tangential=friction"],
    "imported_msh": "IMPORTED",
}
# Reference results: small meshes, both methods, both couplings.
SOLVES = {
    "distributing": ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1"],
    "kinematic": ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1", "load_introduction=kinematic"],
    "pads": VARIANTS["pads"],
    "friction": VARIANTS["friction"],
    "imported_msh": "IMPORTED",
}


def overrides_of(spec, folder: Path) -> list[str]:
    """The ``--set`` list of a pin; "IMPORTED" = a 16 x 4 x 1 skirt as Gmsh's own ``.msh`` writes it (gmsh
    pinned in the venv), imported with its physical groups BASE / TOP."""
    if spec != "IMPORTED":
        return list(spec)
    from gmsh_skirt import gmsh_files
    files = gmsh_files(folder / "gmsh")
    return [f"mesh.file={files['msh']}", f"mesh.sets={files['sets']['msh']}"]


def deck_hashes(spec, outdir: Path) -> dict[str, str]:
    """sha256 of every rendered deck file of the model, keyed by file name."""
    paths = render_all(load(None, overrides_of(spec, outdir.parent)), outdir, on_unsupported=lambda err: None)
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(paths)}


def reference_values(spec, folder: Path) -> dict:
    """Per method: sigma_n, gap of every row and the summary's liftoff load factor."""
    out = {}
    overrides = overrides_of(spec, folder)
    for method in ("penalty", "lagrange"):
        df, summary = solve_model(load(None, overrides), method, recover=False)
        out[method] = {"sigma_n_pa": df["sigma_n_pa"].tolist(), "gap_m": df["gap_m"].tolist(),
                       "status": df["status"].tolist(), "node": df["node"].tolist(),
                       "liftoff_load_factor": summary["liftoff_load_factor"]}
    return out


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_decks_byte_identical(variant, tmp_path):
    pinned = json.loads((PINS / f"decks_{variant}.json").read_text())
    assert deck_hashes(VARIANTS[variant], tmp_path) == pinned


@pytest.mark.parametrize("case", sorted(SOLVES))
def test_reference_results_identical(case, tmp_path):
    pinned = json.loads((PINS / f"reference_{case}.json").read_text())
    now = reference_values(SOLVES[case], tmp_path)
    for method in ("penalty", "lagrange"):
        a, b = now[method], pinned[method]
        assert a["node"] == b["node"] and a["status"] == b["status"]
        scale = max(abs(v) for v in b["sigma_n_pa"])
        np.testing.assert_allclose(a["sigma_n_pa"], b["sigma_n_pa"], rtol=0, atol=1e-9 * scale)
        np.testing.assert_allclose(a["gap_m"], b["gap_m"], rtol=0, atol=1e-9 * max(abs(v) for v in b["gap_m"]))
        assert a["liftoff_load_factor"] == pytest.approx(b["liftoff_load_factor"], rel=1e-9)


if __name__ == "__main__" and "--write" in sys.argv:
    import tempfile
    PINS.mkdir(exist_ok=True)
    for name, ov in VARIANTS.items():
        with tempfile.TemporaryDirectory() as d:
            (PINS / f"decks_{name}.json").write_text(json.dumps(deck_hashes(ov, Path(d) / "x"), indent=1) + "\n")
    for name, ov in SOLVES.items():
        with tempfile.TemporaryDirectory() as d:
            (PINS / f"reference_{name}.json").write_text(json.dumps(reference_values(ov, Path(d))) + "\n")
