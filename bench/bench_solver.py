"""Benchmark of the reference solver: wall time and peak memory at about 20k, 100k and 400k dofs.

Each measurement runs in its own process so that peak memory (max RSS) belongs to it alone:
- the reference solver's full load path, penalty and Lagrange on one condensed system
  (condensation once, then both methods), with the time of each stage;
- one sparse factorisation of K (CHOLMOD, contact and spring dofs held), the yardstick;
- optionally (``--with-ccx``) CalculiX 2.20 on the deckbridge ccx penalty deck of the same mesh.
Ratios are printed against the factorisation (and against ccx when run).

    python bench/bench_solver.py                     # 20k and 100k
    python bench/bench_solver.py --sizes 20k,100k,400k --schur both --with-ccx
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

MESHES = {"20k": (72, 30, 2), "100k": (160, 70, 2), "400k": (320, 140, 2), "1m": (500, 220, 2)}


def _peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _model(nt: int, nz: int, nr: int, increments: int):
    from deckbridge.model import load
    return load(None, [f"mesh.n_theta={nt}", f"mesh.n_z={nz}", f"mesh.n_r={nr}",
                       f"steps.increments={increments}"])


def case_solver(nt, nz, nr, increments, schur) -> dict:
    import reference_solver as rs
    from deckbridge.mesh import build_mesh
    from deckbridge.solve import build_problem
    model = _model(nt, nz, nr, increments)
    t0 = time.perf_counter()
    problem = build_problem(model, build_mesh(model))
    t1 = time.perf_counter()
    kw = {"schur": "trailing"} if schur == "trailing" else {"schur": "rhs", "factorize": rs.default_factorize()}
    system = rs.condense(problem, **kw)
    t2 = time.perf_counter()
    out = {"dofs": 3 * problem.n_nodes, "contact_rows": problem.n_contacts, "retained": system.info["retained"],
           "schur": system.info["schur"], "mesh_s": t1 - t0, "condense_total_s": t2 - t1,
           **{k: v for k, v in system.info.items() if k.endswith("_s")}}
    for method in ("penalty", "lagrange"):
        t = time.perf_counter()
        sol = rs.solve_path(system, method, lambda_max=model.steps.lambda_max, increments=increments, recover=True)
        out[f"{method}_s"] = time.perf_counter() - t
        out[f"{method}_liftoff"] = sol.liftoff_load_factor
        out[f"{method}_iterations"] = int(sol.iterations.sum())
    out["total_s"] = time.perf_counter() - t0
    out["peak_mb"] = _peak_mb()
    return out


def case_factor(nt, nz, nr) -> dict:
    """One CHOLMOD factorisation of the reduced K with the contact and spring dofs held."""
    import numpy as np
    import reference_solver as rs
    from deckbridge.mesh import build_mesh
    from deckbridge.solve import build_problem
    from reference_solver.frames import build_dofmap
    model = _model(nt, nz, nr, 1)
    p = build_problem(model, build_mesh(model))
    K = rs.assemble_stiffness(p.nodes, p.hexes, p.E, p.nu)
    dm = build_dofmap(p)
    Kq = (dm.T.T @ K @ dm.T).tocsr()
    keep = np.ones(Kq.shape[0], bool)
    keep[np.concatenate([dm.contact_dofs, dm.spring_dofs])] = False
    Kii = Kq[keep][:, keep].tocsc()
    base = _peak_mb()
    t = time.perf_counter()
    solve = rs.default_factorize()(Kii)
    tf = time.perf_counter() - t
    b = np.ones(Kii.shape[0])
    t = time.perf_counter()
    solve(b)
    ts = time.perf_counter() - t
    return {"factor_s": tf, "solve_s": ts, "factor_nnz_k": int(Kii.nnz), "peak_mb": _peak_mb(),
            "peak_before_factor_mb": base, "sparse": "cholmod" if rs.HAVE_CHOLMOD else "superlu"}


def case_ccx(nt, nz, nr, increments) -> dict:
    """CalculiX on the deckbridge ccx penalty deck (renderer 'calculix'), if both are available."""
    from deckbridge.dialects import DIALECTS
    from deckbridge.render import render_all
    ccx = shutil.which("ccx")
    if "calculix" not in DIALECTS or ccx is None:
        return {"skipped": "no 'calculix' renderer or no ccx binary"}
    model = _model(nt, nz, nr, increments)
    with tempfile.TemporaryDirectory(prefix="bench-ccx-") as d:
        paths = render_all(model, d, ["calculix"])
        deck = next((p for p in paths if "penalty" in p.name and p.suffix == ".inp"), None)
        if deck is None:
            return {"skipped": "no penalty deck among " + ", ".join(p.name for p in paths)}
        t = time.perf_counter()
        res = subprocess.run([ccx, "-i", deck.stem], cwd=d, capture_output=True, text=True)
        wall = time.perf_counter() - t
        peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0
    return {"ccx_s": wall, "peak_mb": peak, "returncode": res.returncode}


def _sub(args: list[str], repeat: int = 1, key: str | None = None) -> dict:
    """Run one measurement in a fresh process (``repeat`` times, keep the smallest ``key``)."""
    best = None
    for _ in range(max(1, repeat)):
        cmd = [sys.executable, os.path.abspath(__file__), *args]
        res = subprocess.run(cmd, capture_output=True, text=True)
        if res.returncode != 0:
            return {"error": (res.stderr.strip().splitlines() or ["?"])[-1]}
        out = json.loads(res.stdout.strip().splitlines()[-1])
        if best is None or (key in out and out[key] < best.get(key, float("inf"))):
            best = out
    return best


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="20k,100k", help=f"comma list of {', '.join(MESHES)}")
    ap.add_argument("--increments", type=int, default=10)
    ap.add_argument("--schur", choices=["trailing", "rhs", "both"], default="trailing")
    ap.add_argument("--with-ccx", action="store_true", help="also run ccx on the ccx penalty deck")
    ap.add_argument("--repeat", type=int, default=1, help="runs per measurement; the fastest is kept")
    ap.add_argument("--json", help="write all measurements to this file")
    ap.add_argument("--case", nargs=4, metavar=("KIND", "NT", "NZ", "NR"), help=argparse.SUPPRESS)
    ap.add_argument("--case-schur", default="trailing", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.case:
        kind, nt, nz, nr = a.case[0], *map(int, a.case[1:])
        if kind == "solver":
            out = case_solver(nt, nz, nr, a.increments, a.case_schur)
        elif kind == "factor":
            out = case_factor(nt, nz, nr)
        else:
            out = case_ccx(nt, nz, nr, a.increments)
        print(json.dumps(out))
        return 0

    sizes = [s.strip().lower() for s in a.sizes.split(",") if s.strip()]
    schurs = ["trailing", "rhs"] if a.schur == "both" else [a.schur]
    results = {}
    print(f"{'size':>6} {'dofs':>8} {'schur':>18} {'cond s':>8} {'pen s':>7} {'lag s':>7} {'total s':>8}"
          f" {'peak MB':>8} {'factor s':>9} {'fac MB':>7} {'tot/fac':>8} {'ccx s':>8} {'ccx/tot':>8}")
    for size in sizes:
        nt, nz, nr = MESHES[size]
        fac = _sub(["--case", "factor", str(nt), str(nz), str(nr)], a.repeat, "factor_s")
        ccx = (_sub(["--case", "ccx", str(nt), str(nz), str(nr), "--increments", str(a.increments)])
               if a.with_ccx else {})
        for schur in schurs:
            sol = _sub(["--case", "solver", str(nt), str(nz), str(nr), "--increments", str(a.increments),
                        "--case-schur", schur], a.repeat, "total_s")
            results[f"{size}-{schur}"] = {"solver": sol, "factor": fac, "ccx": ccx}
            if "error" in sol:
                print(f"{size:>6} error: {sol['error']}")
                continue
            ratio = sol["total_s"] / fac["factor_s"] if "factor_s" in fac else float("nan")
            cx = ccx.get("ccx_s")
            print(f"{size:>6} {sol['dofs']:>8} {sol['schur']:>18} {sol['condense_total_s']:>8.2f}"
                  f" {sol['penalty_s']:>7.2f}"
                  f" {sol['lagrange_s']:>7.2f} {sol['total_s']:>8.2f} {sol['peak_mb']:>8.0f}"
                  f" {fac.get('factor_s', float('nan')):>9.2f} {fac.get('peak_mb', float('nan')):>7.0f} {ratio:>8.2f}"
                  + (f" {cx:>8.1f} {cx / sol['total_s']:>8.1f}" if cx else f" {'-':>8} {'-':>8}"))
            print(f"{'':>6} stages: " + ", ".join(f"{k}={v:.2f}" for k, v in sol.items()
                                                    if k.endswith("_s") and k not in ("total_s",)))
        if ccx and "skipped" in ccx:
            print(f"{'':>6} ccx skipped: {ccx['skipped']}")
        elif ccx and ccx.get("returncode", 0) != 0:
            print(f"{'':>6} ccx exit code {ccx['returncode']}: its time is not a valid comparison")
    print("tot/fac: reference full load path, both methods (mesh, condensation, penalty, Lagrange, field recovery)"
          " over one CHOLMOD factorisation of K; peak MB: max RSS of each process")
    if a.json:
        Path(a.json).write_text(json.dumps(results, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
