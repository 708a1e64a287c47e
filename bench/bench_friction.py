"""Cost of Coulomb friction against the frictionless reference path, side by side on the same model.

For each method (penalty, Lagrange) the default JAR model (or ``--set`` overrides) is condensed and
solved twice: ``contact.tangential=springs`` (today's path, circumferential springs) and
``contact.tangential=friction`` with ``contact.friction=MU``. Printed: condensation and load-path
wall times [s] (the best of ``--repeat`` runs, alternated: a shared box's neighbours add to single
runs), retained dofs, and the ratio friction / frictionless of the load path and of the total.
The header gives the load average (1 min) before and after.

    python bench/bench_friction.py                       # default model, mu = 0.3
    python bench/bench_friction.py --mu 0.2 --set mesh.n_theta=36 --set mesh.n_z=10
"""

from __future__ import annotations

import argparse
import os
import time


def _run(overrides: list[str], method: str) -> dict:
    import reference_solver as rs
    from deckbridge.mesh import build_mesh
    from deckbridge.model import load
    from deckbridge.solve import build_problem
    model = load(None, overrides)
    t0 = time.perf_counter()
    system = rs.condense(build_problem(model, build_mesh(model)))
    t1 = time.perf_counter()
    sol = rs.solve_path(system, method, lambda_max=model.steps.lambda_max, increments=model.steps.increments,
                        recover=False)
    t2 = time.perf_counter()
    return {"condense_s": t1 - t0, "path_s": t2 - t1, "total_s": t2 - t0, "retained": system.info["retained"],
            "liftoff": sol.liftoff_load_factor, "iterations": int(sol.iterations.sum())}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mu", type=float, default=0.3)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--methods", default="penalty,lagrange")
    ap.add_argument("--repeat", type=int, default=3, help="runs per case, the best kept (default 3)")
    a = ap.parse_args()
    load0 = os.getloadavg()[0]
    rows = []
    for method in a.methods.split(","):
        runs = {"springs": [], "friction": []}
        for _ in range(max(a.repeat, 1)):
            runs["springs"].append(_run(a.set + ["contact.tangential=springs"], method))
            runs["friction"].append(_run(a.set + ["contact.tangential=friction", f"contact.friction={a.mu}"], method))
        best = {name: {**r[0], **{key: min(x[key] for x in r) for key in ("condense_s", "path_s", "total_s")}}
                for name, r in runs.items()}
        rows.append((method, best["springs"], best["friction"]))
    import reference_solver
    print(f"# reference_solver: {os.path.dirname(reference_solver.__file__)}")
    print(f"# load average (1 min) {load0:.2f} before, {os.getloadavg()[0]:.2f} after; best of {max(a.repeat, 1)}")
    print(f"{'method':9} {'tangential':10} {'retained':>8} {'condense_s':>10} {'path_s':>8} {'total_s':>8} "
          f"{'iters':>6} {'liftoff':>8}  path_ratio total_ratio")
    for method, ref, fr in rows:
        for name, r in (("springs", ref), ("friction", fr)):
            lift = "-" if r["liftoff"] is None else f"{r['liftoff']:.4f}"
            ratio = (f"  {r['path_s'] / ref['path_s']:10.1f} {r['total_s'] / ref['total_s']:11.2f}"
                     if name == "friction" else "")
            print(f"{method:9} {name:10} {r['retained']:8d} {r['condense_s']:10.3f} {r['path_s']:8.3f} "
                  f"{r['total_s']:8.3f} {r['iterations']:6d} {lift:>8}{ratio}")


if __name__ == "__main__":
    main()
