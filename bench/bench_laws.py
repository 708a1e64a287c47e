"""Cost of each contact law's load path beside one sparse factorisation, in the same run (issue 22, 24).

One process, one mesh: the condensation (its CHOLMOD factorisation time ``schur_factor_s`` is the
yardstick, and one plain CHOLMOD factorisation of K with the retained dofs held, as bench_solver.py), then
the load path of every law on the same condensed system: penalty, Lagrange and the augmented Lagrangian at
k x 1 and x 10, with the dense factorisations of the contact operator each needed
(``reference_solver.shifted.COUNTS``) and the augmentations. Ratios: each path / one factorisation.

    python bench/bench_laws.py                          # 72 x 30 x 2 (the default JAR, ~26k dofs)
    python bench/bench_laws.py --mesh 160,70,2          # ~115k dofs
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time


def run(nt: int, nz: int, nr: int) -> dict:
    import reference_solver as rs
    from bench_solver import case_factor                      # bench/ is on sys.path when run as a script
    from reference_solver import shifted
    from deckbridge.mesh import build_mesh
    from deckbridge.model import load
    from deckbridge.solve import build_problem

    model = load(None, [f"mesh.n_theta={nt}", f"mesh.n_z={nz}", f"mesh.n_r={nr}"])
    p = build_problem(model, build_mesh(model))
    t = time.perf_counter()
    system = rs.condense(p)
    out = {"mesh": f"{nt}x{nz}x{nr}", "dofs": 3 * p.n_nodes, "contact_rows": p.n_contacts,
           "condense_s": time.perf_counter() - t, "schur_factor_s": system.info.get("schur_factor_s")}
    out["factor_s"] = case_factor(nt, nz, nr)["factor_s"]     # bench_solver.py's yardstick, this process
    for name, method, kf in [("penalty", "penalty", 1.0), ("lagrange", "lagrange", 1.0),
                             ("augmented_k1", "augmented", 1.0), ("augmented_k10", "augmented", 10.0)]:
        before = dict(shifted.COUNTS)
        t = time.perf_counter()
        sol = rs.solve_path(system, method, kf, lambda_max=model.steps.lambda_max,
                            increments=model.steps.increments, recover=False, liftoff_surface="table")
        wall = time.perf_counter() - t
        out[name] = {"path_s": wall, "path_over_factor": wall / out["factor_s"],
                     "dense_factorisations": shifted.COUNTS["factorisations"] - before["factorisations"],
                     "dense_solves": shifted.COUNTS["solves"] - before["solves"],
                     "liftoff": sol.liftoff_load_factor,
                     "augmentations": None if sol.augmentations is None else int(sol.augmentations.sum())}
    out["augmented_k1_over_penalty"] = out["augmented_k1"]["path_s"] / out["penalty"]["path_s"]
    out["augmented_k10_over_penalty"] = out["augmented_k10"]["path_s"] / out["penalty"]["path_s"]
    out["machine"] = f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}"
    return out


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", default="72,30,2", help="n_theta,n_z,n_r")
    args = ap.parse_args()
    print(json.dumps(run(*(int(v) for v in args.mesh.split(","))), indent=1))
