"""Where the CPU time of one ``deckbridge solve`` goes, per stage (issue 22).

Runs the command in this process (the default JAR model meshed n_theta x n_z x n_r, default outputs)
under cProfile with the process CPU clock as its timer (threads' CPU included: a stage that waits on its
writer threads is charged their CPU), then prints the cumulative CPU seconds of the functions that make
the stages, and the whole command's CPU. Profiling overhead is small here (the work is in compiled code)
but not nil: take the shares, and the ratios of bench/solve_command.py for the totals.

    python bench/solve_stages.py 320 140 2 --method penalty
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

# (label, file suffix, function name): cumulative CPU of the function named so, in the file named so
STAGES = [
    ("memory guard (mesh + estimate)", "deckbridge/cli/_common.py", "guarded"),
    ("mesh", "deckbridge/mesh.py", "build_mesh"),
    ("problem", "deckbridge/solve.py", "build_problem"),
    ("condensation (all)", "reference_solver/condense.py", "_condense"),
    ("  assembly", "reference_solver/assembly.py", "assemble_problem_blocks"),
    ("  split + factor + Schur", "reference_solver/trailing.py", "schur_blocks"),
    ("load path", "reference_solver/path.py", "solve_path"),
    ("contact table", "deckbridge/solve.py", "contact_table"),
    ("summary", "deckbridge/solve.py", "make_summary"),
    ("write outputs (all)", "deckbridge/solve.py", "write_outputs"),
    ("  contact.csv", "pandas/core/generic.py", "to_csv"),
    ("  displacements (path_fields)", "reference_solver/recover.py", "path_fields"),
    ("  stresses (states_stress)", "reference_solver/recover.py", "states_stress"),
    ("  result.vtu mesh", "deckbridge/paraview.py", "result_mesh"),
    ("  VTU writing", "deckbridge/paraview.py", "write_vtus"),
]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mesh", nargs=3, type=int, metavar=("NT", "NZ", "NR"))
    ap.add_argument("--method", default="penalty")
    ap.add_argument("--set", action="append", default=[], help="extra model key=value")
    ap.add_argument("--top", type=int, default=0, help="also print the N functions of largest own CPU")
    a = ap.parse_args(argv)
    os.environ.setdefault("DECKBRIDGE_ALLOW_LARGE", "1")
    from deckbridge.cli import main as cli
    nt, nz, nr = a.mesh
    out = Path(tempfile.mkdtemp(prefix="bench-stages-")) / "o"
    args = ["solve", "--method", a.method, "--set", f"mesh.n_theta={nt}", "--set", f"mesh.n_z={nz}",
            "--set", f"mesh.n_r={nr}", "-o", str(out)] + [x for kv in a.set for x in ("--set", kv)]
    prof = cProfile.Profile(timer=time.process_time)
    w, c = time.perf_counter(), time.process_time()
    prof.enable()
    try:
        cli.main(args, standalone_mode=False)
    finally:
        prof.disable()
    wall, cpu = time.perf_counter() - w, time.process_time() - c
    st = pstats.Stats(prof)
    cum: dict[str, float] = {}
    for (fname, _line, func), (_cc, _nc, _tt, ct, _callers) in st.stats.items():
        for label, suffix, name in STAGES:
            if func == name and fname.endswith(suffix):
                cum[label] = cum.get(label, 0.0) + ct
    print(f"mesh {nt}x{nz}x{nr} {a.method}: command in-process {wall:.2f} s wall, {cpu:.2f} s CPU; "
          f"load {os.getloadavg()[0]:.1f}")
    for label, _s, _n in STAGES:
        if label in cum:
            print(f"  {label:<34} {cum[label]:8.2f} s CPU  {100 * cum[label] / cpu:5.1f} %")
    if a.top:
        st.sort_stats("tottime").print_stats(a.top)
    return 0


if __name__ == "__main__":
    sys.exit(main())
