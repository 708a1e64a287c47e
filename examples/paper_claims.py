"""Worked example: which modelling choices turn on the paper's two claims (FIG. 4). See docs/paper_claims.md.

Runs one study (deckbridge.studies.sweep.run_sweep, the machinery of ``deckbridge sweep``) on a small
mesh: Lagrange and penalty at k-factors 0.1 .. 100 (alpha = 0.01 .. 10), over the grid
open_ratio in {1e-12, 1e-3} x k_tangent in {follow, fixed 2e8 N/m, about 2 x the mean k_c of alpha 0.1 on this mesh (9.1e7 N/m)}.
Writes the study to OUT (default /tmp/deckbridge_paper_claims), one claims figure per grid point into
docs/figures/ (small PNGs), and prints the verdicts and the Lagrange / penalty liftoff against alpha.
About 15 s on a 2-core box.

    .venv/bin/python examples/paper_claims.py [OUT]
"""

from __future__ import annotations

import sys
from pathlib import Path

from deckbridge.cli.studies_cmd import claims_lines
from deckbridge.model import load
from deckbridge.report.claims_figures import claims_figure
from deckbridge.studies.cases import parse_grid_options
from deckbridge.studies.liftoff import critical_load
from deckbridge.studies.sweep import run_sweep

MESH = ["mesh.n_theta=36", "mesh.n_z=6", "mesh.n_r=2"]
KS = [0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0]
GRID = ["contact.penalty.open_ratio=1e-12,1e-3", "contact.penalty.k_tangent=follow,2e8"]
FIGURES = Path(__file__).resolve().parents[1] / "docs" / "figures"


def main(out: str) -> None:
    model = load(None, MESH)
    res = run_sweep(model, KS, out, grid=parse_grid_options(GRID), progress=False, report=True)
    FIGURES.mkdir(parents=True, exist_ok=True)
    q = res["quantities"]
    for c in res["summary"]["claims"]:
        g = c["grid"]
        kt = "follow" if g["contact.penalty.k_tangent"] is None else "fixed"
        name = f"claims_open{g['contact.penalty.open_ratio']:g}_kt-{kt}.png"
        fig = claims_figure(c, q[q["case_id"].str.startswith(c["variant"] + "_")], c["grid_label"])
        fig.savefig(FIGURES / name, dpi=60)
        print(f"wrote {FIGURES / name}")
    for line in claims_lines(res["summary"]["claims"]):
        print(line)
    print("liftoff lambda_c (first node) against alpha:")
    for kt in ("follow", "2e8"):
        for alpha in (0.01, 0.1, 1.0, 10.0):
            m = load(None, MESH + [f"contact.penalty.k_tangent={kt}", f"contact.penalty.alpha={alpha}"])
            r = critical_load(m, ("lagrange", "penalty"), tol=1e-4)
            print(f"  k_tangent {kt:>6}  alpha {alpha:>5g}: Lagrange {r['lagrange']['lambda_c']:.4f}  "
                  f"penalty {r['penalty']['lambda_c']:.4f}")
    print(f"study: {out}/report.html, {out}/quantities.csv, {out}/summary.json")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "/tmp/deckbridge_paper_claims")
