"""Where the time of one ``deckbridge solve`` goes, per stage (issue 22): wall and process CPU seconds.

Runs the command in this process (the default JAR model meshed n_theta x n_z x n_r, default outputs), with
timers around the functions that make its stages (the condensation's own stage marks,
:mod:`reference_solver.stages`; the load path, the contact table, the summary; the output stage's
displacement recovery, stresses, result.vtu mesh and VTU writing, looked up at call time in their modules)
and prints each stage's wall and CPU seconds (process CPU: the VTU writer threads' CPU is charged to the
VTU stage) and its share of the command's CPU. What is not in a stage (imports, model, mesh, guard,
contact.csv, summary.json, interpreter exit not included) is printed as the rest.

    python bench/solve_stages.py 320 140 2 --method penalty
"""

from __future__ import annotations

import argparse
import functools
import os
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mesh", nargs=3, type=int, metavar=("NT", "NZ", "NR"))
    ap.add_argument("--method", default="penalty")
    ap.add_argument("--set", action="append", default=[], help="extra model key=value")
    a = ap.parse_args(argv)
    os.environ.setdefault("DECKBRIDGE_ALLOW_LARGE", "1")
    w0, c0 = time.perf_counter(), time.process_time()
    from deckbridge import paraview as pv
    from deckbridge import solve as sv
    from deckbridge.cli import main as cli
    from reference_solver import recover, stages
    rows: list[tuple[str, float, float]] = [("imports", time.perf_counter() - w0, time.process_time() - c0)]

    def timed(label, fn):
        @functools.wraps(fn)
        def wrapper(*args, **kw):
            w, c = time.perf_counter(), time.process_time()
            try:
                return fn(*args, **kw)
            finally:
                rows.append((label, time.perf_counter() - w, time.process_time() - c))
        return wrapper

    clock = [time.perf_counter(), time.process_time()]

    def hook(name):
        w, c = time.perf_counter(), time.process_time()
        rows.append((f"condensation: {name}", w - clock[0], c - clock[1]))
        clock[:] = [time.perf_counter(), time.process_time()]

    def condense_model(*args, **kw):
        clock[:] = [time.perf_counter(), time.process_time()]
        return original(*args, **kw)

    original = sv.condense_model
    sv.condense_model = condense_model
    for mod, name, label in [(sv, "_path", "load path"), (sv, "contact_table", "contact table"),
                             (sv, "make_summary", "summary"), (pv, "path_fields", "outputs: displacements"),
                             (recover, "path_fields", "displacements of every state (api.solve)"),
                             (pv, "states_stress", "outputs: stresses"), (pv, "result_mesh", "outputs: result.vtu mesh"),
                             (pv, "write_vtus", "outputs: VTU writing")]:
        setattr(mod, name, timed(label, getattr(mod, name)))
    stages.set_hook(hook)
    nt, nz, nr = a.mesh
    out = Path(tempfile.mkdtemp(prefix="bench-stages-")) / "o"
    args = ["solve", "--method", a.method, "--set", f"mesh.n_theta={nt}", "--set", f"mesh.n_z={nz}",
            "--set", f"mesh.n_r={nr}", "-o", str(out)] + [x for kv in a.set for x in ("--set", kv)]
    cli.main(args, standalone_mode=False)
    wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    print(f"mesh {nt}x{nz}x{nr} {a.method}: command in-process {wall:.2f} s wall, {cpu:.2f} s CPU; "
          f"load {os.getloadavg()[0]:.1f}")
    print(f"  {'stage':<36} {'wall s':>8} {'CPU s':>8} {'CPU %':>6}")
    for label, w, c in rows:
        print(f"  {label:<36} {w:8.2f} {c:8.2f} {100 * c / cpu:6.1f}")
    rest_w, rest_c = wall - sum(r[1] for r in rows), cpu - sum(r[2] for r in rows)
    print(f"  {'rest (model, mesh, guard, csv, json)':<36} {rest_w:8.2f} {rest_c:8.2f} {100 * rest_c / cpu:6.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
