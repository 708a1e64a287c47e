"""Cost of the ParaView series (result.pvd + one VTU per increment) against the solve it belongs to.

On one condensed system of the model, per method and repeat, side by side in one process: the solve
(solve_system, load path with contact.csv's table) and the series (one recover call for every increment,
stresses, meshio writes). Prints seconds, the ratio series / solve, the size written [MB] and the
process's peak RSS [MB].

    python bench/bench_paraview.py                       # default model (72 x 30 x 2, ~20k dofs)
    python bench/bench_paraview.py --set mesh.n_theta=160 --set mesh.n_z=70 --repeat 1
"""

from __future__ import annotations

import argparse
import resource
import shutil
import statistics
import tempfile
import time
from pathlib import Path

from deckbridge.model import load
from deckbridge.paraview import write_reference_series
from deckbridge.solve import condense_model, solve_system


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--set", dest="overrides", action="append", default=[], help="model override key=value")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    model = load(None, args.overrides)
    t = time.perf_counter()
    mesh, system = condense_model(model)
    print(f"model {model.name}: {system.dofs} dofs, {mesh.hexes.shape[0]} hexahedra, "
          f"condensed in {time.perf_counter() - t:.2f} s")
    for method in ("penalty", "lagrange"):
        solve_s, series_s, mb = [], [], 0.0
        for _ in range(args.repeat):
            t = time.perf_counter()
            _, _, sol = solve_system(model, mesh, system, method, recover=False)
            solve_s.append(time.perf_counter() - t)
            out = Path(tempfile.mkdtemp(prefix="bench-pv-"))
            t = time.perf_counter()
            paths = write_reference_series(out, model, mesh, system, sol)
            series_s.append(time.perf_counter() - t)
            mb = sum(p.stat().st_size for p in paths) / 1e6
            shutil.rmtree(out)
        a, b = statistics.median(solve_s), statistics.median(series_s)
        print(f"{method:8s} solve {a:6.2f} s   series {b:6.2f} s   series/solve {b / a:5.2f}   "
              f"{len(paths) - 1} VTUs {mb:.1f} MB   (median of {args.repeat})")
    print(f"peak RSS {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB")


if __name__ == "__main__":
    main()
