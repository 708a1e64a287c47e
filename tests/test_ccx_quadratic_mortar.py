"""CalculiX mortar deck on quadratic skirts (issue 23, deckbridge/deck_elements.py): ccx 2.20 runs the C3D20R /
C3D10 / C3D15 deck and its face-weighted (mortar) contact carries uniform compression without opening a
corner node. The truths here are the closed form sigma_N = -N / (2 pi R t) (a thin ring in uniform
compression) and the force balance (the reference solver's face-weighted Lagrange on these faces is checked
against the same closed form in tests/test_face_weighted_skirt.py).

Only step 1 (N alone): with a moment in step 2, ccx 2.20's mortar stalls on these quadratic faces (largest
residual stuck at ~0.06 N on mid-side table nodes near the neutral axis, then too many cutbacks), measured
on 24 x 3 x 1 skirts of every quadratic type, with distributing and kinematic load introduction alike."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ccx_job import ccx_job
from deckbridge.model import load
from deckbridge.dialects.calculix.result_files import _dat_blocks, _frd_blocks


@pytest.mark.parametrize("element", ["hex20r", "tet10", "wedge15"])
def test_mortar_deck_uniform_compression(tmp_path, element):
    m = load(None, [f"mesh.element={element}", "mesh.n_theta=24", "mesh.n_z=3", "mesh.n_r=1",
                    "contact.stop.side=none", "loads.M=0", "loads.T=0", "steps.increments=1"])
    inp = ccx_job(m, tmp_path, "lagrange")
    assert f"TYPE={element.upper().replace('HEX', 'C3D').replace('TET', 'C3D').replace('WEDGE', 'C3D')}" \
        in inp.read_text()
    _, blocks = _frd_blocks(inp.with_suffix(".frd"))
    contact = next(b for b in blocks if b["name"] == "CONTACT" and b["step"] == 1)
    cpress = np.array([v[3] for v in contact["values"].values()])
    exact = m.loads.N / (2 * math.pi * m.geometry.radius * m.geometry.thickness)
    assert cpress.size == build_table_size(m)                   # every table node, corners included, pressed
    assert np.abs(cpress / exact - 1).max() < 5e-3
    forces = next(b for b in _dat_blocks(inp.with_suffix(".dat")) if b["kind"] == "forces" and b["time"] == 1.0)
    rz = sum(v[2] for v in forces["values"].values())
    assert rz == pytest.approx(m.loads.N, rel=1e-6)


def build_table_size(model) -> int:
    from deckbridge.mesh import build_mesh
    return int(build_mesh(model).table.nodes.size)
