"""The memory guard's estimate (deckbridge.limits) against the measured peak of `deckbridge solve`, per
mesh proportion (issue 22: long-thin, short-wide, n_r 1-3).

Per mesh: the command ``deckbridge solve --method M`` with the model's default outputs (VTUs incl.) in a
fresh process, its peak resident memory from ``os.wait4`` (ru_maxrss, the same figure as
``/usr/bin/time -v``), then in this process the guard's estimate from the mesh's own symbolic
factorisation (:func:`deckbridge.limits.symbolic_estimate`) and the quick arithmetic bound
(:func:`deckbridge.limits.quick_estimate`). Printed: both, estimate / peak (goal: 1.0-1.2), and the
load average (memory does not depend on it, time does).

    python bench/memory_guard.py --mesh 160x70x2 --mesh 320x35x2 --mesh 60x180x2 --mesh 160x100x1 --mesh 160x50x3
    python bench/memory_guard.py --mesh 160x70x2 --set outputs.vtu=false      # the solve without VTUs
    python bench/memory_guard.py --mesh 800x16x2                               # dense-dominated (nr 5,600)
    python bench/memory_guard.py --estimate-only --mesh 1292x257x2              # the estimate alone (3M: minutes)
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from solve_command import _child  # noqa: E402


def measure(mesh: tuple[int, int, int], method: str, extra: list[str]) -> dict:
    nt, nz, nr = mesh
    out = Path(tempfile.mkdtemp(prefix="bench-mem-"))
    env = {**os.environ, "OMP_NUM_THREADS": "1", "DECKBRIDGE_ALLOW_LARGE": "1",
           "PYTHONPATH": f"{HERE.parent}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
    sets = [f"mesh.n_theta={nt}", f"mesh.n_z={nz}", f"mesh.n_r={nr}", *extra]
    cmd = [sys.executable, "-c", "import sys; from deckbridge.cli import main; sys.exit(main())", "solve",
           "--method", method, *[a for s in sets for a in ("--set", s)], "-o", str(out / "o")]
    res = _child(cmd, env)
    shutil.rmtree(out, ignore_errors=True)
    res.pop("stdout", None)
    return res


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mesh", action="append", default=[], metavar="NTxNZxNR", help="mesh, e.g. 160x70x2 (repeatable)")
    ap.add_argument("--method", default="penalty", choices=["penalty", "lagrange"])
    ap.add_argument("--set", dest="extra", action="append", default=[], help="more model overrides")
    ap.add_argument("--json", help="append the rows to this JSON-lines file")
    ap.add_argument("--estimate-only", action="store_true", help="print the guard's estimate and its parts, solve nothing")
    a = ap.parse_args(argv)
    from deckbridge import limits
    from deckbridge.model import load
    print(f"{'mesh':>12} {'dofs':>9} {'retained':>8} {'peak MB':>8} {'estimate MB':>11} {'est/peak':>8}"
          f" {'quick MB':>9} {'wall s':>7} {'load':>5}")
    for spec in a.mesh:
        mesh = tuple(int(x) for x in spec.split("x"))
        load_avg = os.getloadavg()[0]
        if a.estimate_only:
            model = load(None, [f"mesh.n_theta={mesh[0]}", f"mesh.n_z={mesh[1]}", f"mesh.n_r={mesh[2]}", *a.extra])
            est = limits.symbolic_estimate(model)
            print(f"{spec:>12} {est.dofs:>9} {est.retained:>8} {'-':>8} {est.bytes / 2**20:>11.0f} {'-':>8}"
                  f" {limits.quick_estimate(model) / 2**20:>9.0f}  factor entries {est.factor_entries:.3g}, parts GiB "
                  + ", ".join(f"{k} {v / 2**30:.2f}" for k, v in est.parts.items()), flush=True)
            continue
        res = measure(mesh, a.method, a.extra)
        model = load(None, [f"mesh.n_theta={mesh[0]}", f"mesh.n_z={mesh[1]}", f"mesh.n_r={mesh[2]}", *a.extra])
        est = limits.symbolic_estimate(model)
        quick = limits.quick_estimate(model)
        if "error" in res:
            print(f"{spec:>12} failed: {res['error']}")
            continue
        row = {"mesh": spec, "dofs": est.dofs, "retained": est.retained, "peak_mb": res["peak_mb"],
               "estimate_mb": est.bytes / 2**20, "quick_mb": quick / 2**20, "wall_s": res["wall_s"],
               "load": load_avg, "method": a.method, "extra": a.extra, "parts_mb": {k: v / 2**20 for k, v in est.parts.items()}}
        print(f"{spec:>12} {est.dofs:>9} {est.retained:>8} {res['peak_mb']:>8.0f} {row['estimate_mb']:>11.0f}"
              f" {row['estimate_mb'] / res['peak_mb']:>8.2f} {row['quick_mb']:>9.0f} {res['wall_s']:>7.1f} {load_avg:>5.1f}",
              flush=True)
        if a.json:
            with open(a.json, "a") as fh:
                fh.write(json.dumps(row) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
