"""Render the decks of a small model and read the Nastran deck back with pyNastran.

One CGAP per table slave node (n_theta x (n_r + 1) base-ring nodes) plus one per stop node (n_theta);
each gap's PGAP KA is that node's k_c = alpha A^2 K / V [N/m].
"""

import tempfile
from pathlib import Path

from pyNastran.bdf.bdf import read_bdf

from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.render import render_all

model = load(None, ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1"])
with tempfile.TemporaryDirectory() as out:
    files = render_all(model, Path(out))
    print(f"{len(files)} files:", ", ".join(sorted(p.name for p in Path(out).iterdir())))
    bdf = read_bdf(Path(out) / f"{model.name}_penalty.bdf", xref=False, debug=None)
    gaps = [e for e in bdf.elements.values() if e.type == "CGAP"]
    n_table, n_stop = 16 * 2, 16
    print(f"{len(gaps)} CGAP elements (table {n_table} + stop {n_stop})")
    assert len(gaps) == n_table + n_stop
    ka = sorted(bdf.properties[e.pid].ka for e in gaps[:n_table])
    k_c = sorted(build_mesh(model).table.k)
    print(f"PGAP KA {ka[0]:.4g} ... {ka[-1]:.4g} N/m; mesh k_c {k_c[0]:.4g} ... {k_c[-1]:.4g} N/m")
    assert abs(ka[0] / k_c[0] - 1) < 1e-6 and abs(ka[-1] / k_c[-1] - 1) < 1e-6
