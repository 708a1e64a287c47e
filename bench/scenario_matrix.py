"""The larger scenario matrix (issue 21): the CI matrix's generator and invariants (tests/scenarios.py,
tests/scenario_checks.py) on larger meshes and finer load paths, every case with every invariant; prints one
row per case (levels, seconds, each invariant ok / FAIL / skip) and the failures' messages, then the size and
the wall time. Not a test: it reports, it does not stop at the first failure.

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 .venv/bin/python bench/scenario_matrix.py
    .venv/bin/python bench/scenario_matrix.py --n-theta 24 --n-z 6 --increments 10 --seed 7 --only 0,3
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from scenario_checks import CHECKS  # noqa: E402
from scenarios import Case, covering_array, run_case  # noqa: E402

SHORT = {"ran": "ran", "decks_command": "decks", "decks_read_back": "read", "ccx_finished": "ccx", "analysis_as_asked": "anal",
         "equilibrium": "equil", "no_free_penetration": "penet", "stop_frictionless": "stopmu", "ccx_vs_reference": "vsref",
         "si_equals_mm": "SI=mm", "paraview_si_equals_mm": "pv", "warnings_true": "warn"}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n-theta", type=int, default=32, help="elements around (a multiple of 8; pads need 16k)")
    ap.add_argument("--n-z", type=int, default=8)
    ap.add_argument("--increments", type=int, default=10)
    ap.add_argument("--seed", type=int, default=2026, help="seed of the covering array (CI uses 21)")
    ap.add_argument("--only", default="", help="comma-separated case numbers")
    ap.add_argument("--keep", default=None, help="folder for the runs (default: a temporary one, removed)")
    args = ap.parse_args()
    cases = [Case(v, n_theta=args.n_theta, n_z=args.n_z, increments=args.increments)
             for v in covering_array(seed=args.seed)]
    only = {int(i) for i in args.only.split(",") if i}
    t0 = time.perf_counter()
    failures = []
    print(f"{len(cases)} cases (pairwise, seed {args.seed}), mesh {args.n_theta} x {args.n_z} x n_r, "
          f"{args.increments} increments")
    heads = [SHORT.get(name, name) for name in CHECKS]
    print(" # | " + " | ".join(heads) + " |     s | case")
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(args.keep or tmp)
        for i, case in enumerate(cases):
            if only and i not in only:
                continue
            t = time.perf_counter()
            run = run_case(case, root / f"case{i:02d}")
            cells = []
            for name, check in CHECKS.items():
                try:
                    note = check(run)
                    cells.append("skip" if str(note).startswith("skipped") else "ok")
                except Exception as exc:          # noqa: BLE001 - a table of results, not a test
                    cells.append("FAIL")
                    failures.append((i, name, f"{type(exc).__name__}: {exc}".splitlines()[0][:300]))
            print(f"{i:2d} | " + " | ".join(c.ljust(len(h)) for c, h in zip(cells, heads))
                  + f" | {time.perf_counter() - t:5.1f} | {case.name}", flush=True)
    for i, name, msg in failures:
        print(f"case {i} {name}: {msg}")
    print(f"{len(cases) if not only else len(only)} cases x {len(CHECKS)} invariants, "
          f"{len(failures)} failures, {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
