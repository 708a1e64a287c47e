"""CalculiX 2.20 mortar against the reference face-weighted Lagrange on quadratic skirts, coarse to fine (issue 23).

For each case ``element:n_theta x n_z x n_r`` the parametric skirt (no stop, default loads N then T and M to
lambda 1, or ``--top kinematic``) is solved by the reference (``solve --method lagrange``) and by ccx's mortar deck
as rendered (``OMP_NUM_THREADS=1``); per state inside the small-strain range (lift / (R + t/2) <= 0.01) it prints
max |d sigma_N| through the wall (tests/mortar_columns.py) / the reference's peak |sigma_N|, over the columns
within one cell of the reference's contact edge, elsewhere, and the force of the columns within one cell / 15 deg of
each edge (mortar_columns.edge_windows); with ccx's wall and CPU times.

    OMP_NUM_THREADS=1 .venv/bin/python bench/mortar_convergence.py --cases hex20r:24x3x1,hex20r:48x6x1
    ... --json out.json   (every column of every state, to post-process without rerunning ccx)
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from mortar_columns import edge_columns, edge_windows, mortar_states, reference_lagrange  # noqa: E402

SMALL_STRAIN = 0.01
WINDOW_DEG = 15.0       # the tests' edge window: one cell of the 24-cell meshes


def run_case(element: str, shape: str, top: str, increments: int, folder: Path, timeout_s: float) -> dict:
    from deckbridge.dialects.calculix.runner import run as ccx_run
    from deckbridge.model import load
    from deckbridge.render import render_all
    nt, nz, nr = (int(v) for v in shape.split("x"))
    keys = [f"mesh.element={element}", f"mesh.n_theta={nt}", f"mesh.n_z={nz}", f"mesh.n_r={nr}",
            "contact.stop.side=none", f"steps.increments={increments}"]
    if top == "kinematic":
        keys += ["load_introduction=kinematic"]
    model = load(None, keys)
    t0 = time.perf_counter()
    mesh, system, sol = reference_lagrange(model)
    t_ref = time.perf_counter() - t0
    render_all(model, folder / "decks", names=["calculix"])
    inp = folder / "ccx" / f"{model.name}_ccx_lagrange.inp"
    inp.parent.mkdir(parents=True)
    shutil.copyfile(folder / "decks" / inp.name, inp)
    t0, c0 = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
    ccx_run(inp, timeout_s=timeout_s, threads=1)
    c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t_ccx, cpu_ccx = time.perf_counter() - t0, c1.ru_utime + c1.ru_stime - c0.ru_utime - c0.ru_stime
    states = mortar_states(model, mesh, system, sol, inp)
    cell = 360.0 / nt
    rows = []
    for s in states:
        d = np.abs(s["ref"] - s["ccx"]) / s["peak"]
        edge = edge_columns(s["theta"], s["pressed"], cell)
        rows.append({"lam": s["lam"], "lift": s["lift"], "closed": s["closed"], "peak": s["peak"],
                     "all": float(d.max()), "edge": float(d[edge].max()) if edge.any() else 0.0,
                     "rest": float(d[~edge].max()), "worst_theta": float(s["theta"][np.argmax(d)]),
                     "theta": s["theta"].tolist(), "area": s["area"].tolist(), "pressed": s["pressed"].tolist(), "ref": s["ref"].tolist(), "ccx": s["ccx"].tolist()})
    return {"element": element, "mesh": shape, "top": top, "dof": int(3 * mesh.n_nodes), "t_ref": t_ref,
            "t_ccx": t_ccx, "cpu_ccx": cpu_ccx, "states": rows}


def table(results: list[dict]) -> None:
    """Print the markdown table of :func:`run_case` results: errors as % of the reference's nodal peak |sigma_N|
    (the test's yardstick) and, in brackets, of its through-wall peak; edge cells (column by column within one
    cell of a contact edge), elsewhere, the edge windows' force (mortar_columns.edge_windows); the largest
    column difference [MPa] and its azimuth."""
    print("| element | mesh | dof | ccx wall / CPU s | lambda | lift/R | peak node / wall MPa | edge cells "
          "| elsewhere | edge windows ±1 cell | ±15° | max diff MPa at deg |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in results:
        cell = 360.0 / int(r["mesh"].split("x")[0])
        for s in r["states"]:
            if s["lift"] > SMALL_STRAIN:
                continue
            d = np.abs(np.array(s["ref"]) - np.array(s["ccx"]))
            edge = edge_columns(np.array(s["theta"]), np.array(s["pressed"]), cell)
            wall = float(np.abs(s["ref"]).max())
            cells = [d[edge].max(initial=0.0), d[~edge].max(), edge_windows(s, cell), edge_windows(s, WINDOW_DEG)]
            print(f"| {r['element']} | {r['mesh']} | {r['dof']} | {r['t_ccx']:.0f} / {r.get('cpu_ccx', float('nan')):.0f} "
                  f"| {s['lam']:.1f} | {s['lift']:.4f} | {s['peak'] / 1e6:.0f} / {wall / 1e6:.0f} | "
                  + " | ".join(f"{100 * v / s['peak']:.2f} ({100 * v / wall:.2f})" for v in cells)
                  + f" | {d.max() / 1e6:.1f} at {s['worst_theta']:g} |", flush=True)


def summary(results: list[dict]) -> None:
    """One row per case: the largest column error over the full-contact states, then at the last small-strain
    state past liftoff the edge cells, elsewhere and the edge windows (% of the nodal peak, in brackets of the
    through-wall peak, as :func:`table`)."""
    print("| element | mesh | dof | ccx wall / CPU s | full contact | lambda | lift/R | peak node / wall MPa "
          "| edge cells | elsewhere | edge windows ±1 cell | ±15° |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in results:
        cell = 360.0 / int(r["mesh"].split("x")[0])
        full = max(s["all"] for s in r["states"] if s["closed"])
        past = [s for s in r["states"] if not s["closed"] and s["lift"] <= SMALL_STRAIN]
        row = f"| {r['element']} | {r['mesh']} | {r['dof']} | {r['t_ccx']:.0f} / {r.get('cpu_ccx', float('nan')):.0f} " \
              f"| {100 * full:.2f} % | "
        if past:
            s = past[-1]
            d = np.abs(np.array(s["ref"]) - np.array(s["ccx"]))
            edge = edge_columns(np.array(s["theta"]), np.array(s["pressed"]), cell)
            wall = float(np.abs(s["ref"]).max())
            cells = [d[edge].max(initial=0.0), d[~edge].max(), edge_windows(s, cell), edge_windows(s, WINDOW_DEG)]
            row += f"{s['lam']:.2f} | {s['lift']:.4f} | {s['peak'] / 1e6:.0f} / {wall / 1e6:.0f} | " + " | ".join(
                f"{100 * v / s['peak']:.2f} ({100 * v / wall:.2f})" for v in cells) + " |"
        else:
            row += "– | – | – | – | – | – | – |"
        print(row)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", default="hex20r:24x3x1,hex20r:48x6x1,hex20r:48x6x2")
    ap.add_argument("--top", choices=["distributing", "kinematic"], default="distributing")
    ap.add_argument("--increments", type=int, default=5)
    ap.add_argument("--timeout", type=float, default=900.0)
    ap.add_argument("--json", type=Path)
    ap.add_argument("--from-json", type=Path, help="print the table of an earlier --json, run nothing")
    args = ap.parse_args(argv)
    if args.from_json:
        results = json.loads(args.from_json.read_text())
        table(results)
        summary(results)
        return 0
    print(f"load average {os.getloadavg()[0]:.1f}, top {args.top}, {args.increments} increments")
    out = []
    for case in args.cases.split(","):
        element, shape = case.split(":")
        with tempfile.TemporaryDirectory(prefix="mortar_conv_") as tmp:
            r = run_case(element, shape, args.top, args.increments, Path(tmp), args.timeout)
        out.append(r)
        table([r])
        if args.json:
            args.json.write_text(json.dumps(out))
    summary(out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
