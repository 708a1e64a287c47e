"""Memory and time per dof of ``deckbridge solve`` for each element of the parametric skirt (issue 23), beside
ONE CHOLMOD factorisation of the same system, in fresh processes of the same bench run.

Per element (``mesh.element``: hex8i, hex20r, tet10) and size, a mesh n_theta x n_z x n_r chosen so that the
element gives about that many dofs (:data:`MESHES`); then, in this order, fresh processes:
  1. the command ``deckbridge solve --method M`` with its default outputs (contact.csv, summary.json,
     result.vtu, the ParaView series): wall, CPU (user + sys) and peak RSS of that child (os.wait4), and the
     solver's own time for mesh + condensation + load path (summary.json ``wall_time_s``, the "path");
  2. the yardstick: K of the same problem assembled, the contact and spring dofs held, ``cholmod.analyze``
     (CHOLMOD's own ordering) + ``cholesky_inplace`` of K_ii: its wall and CPU.
Printed per row: dofs, command wall / CPU, path wall, factorisation wall / CPU, command / factorisation
(wall, CPU), path / factorisation (wall), microseconds of command CPU per dof, peak kB per dof, and the load
average before the row (the box is shared: compare the ratios of one row, not rows of different runs).

The quadratic elements run the frictionless Lagrange method (the face-weighted law; penalty is refused on
quadratic faces), so the default ``--method`` is lagrange for every row.

    python bench/elements_scale.py --sizes 20k,100k
    python bench/elements_scale.py --sizes 20k --elements hex20r,tet10 --method lagrange
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from solve_command import _child  # noqa: E402

# (element, size) -> mesh n_theta x n_z x n_r, about the size's dofs for that element (n_theta / n_z near
# the default JAR meshes' 2.3; hex20r has about 3.6x and tet10 6.4x the dofs of hex8i on the same grid)
MESHES = {
    ("hex8i", "20k"): (72, 30, 2), ("hex8i", "100k"): (160, 70, 2), ("hex8i", "400k"): (320, 140, 2),
    ("hex20r", "20k"): (40, 14, 2), ("hex20r", "100k"): (90, 34, 2), ("hex20r", "400k"): (170, 72, 2),
    ("tet10", "20k"): (32, 10, 2), ("tet10", "100k"): (64, 26, 2), ("tet10", "400k"): (128, 54, 2),
}


def _sets(element: str, mesh: tuple[int, int, int]) -> list[str]:
    nt, nz, nr = mesh
    return [f"mesh.element={element}", f"mesh.n_theta={nt}", f"mesh.n_z={nz}", f"mesh.n_r={nr}"]


def _env() -> dict:
    env = {**os.environ, "OMP_NUM_THREADS": "1", "DECKBRIDGE_ALLOW_LARGE": "1"}
    env["PYTHONPATH"] = f"{HERE.parent}{os.pathsep}{env.get('PYTHONPATH', '')}"     # cwd is elsewhere
    return env


def run_command(element: str, mesh, method: str) -> dict:
    out = Path(tempfile.mkdtemp(prefix="bench-elements-"))
    cmd = [sys.executable, "-c", "import sys; from deckbridge.cli import main; sys.exit(main())", "solve",
           "--method", method, *[x for kv in _sets(element, mesh) for x in ("--set", kv)], "-o", str(out / "o")]
    res = _child(cmd, _env())
    summary = out / "o" / "summary.json"
    if summary.is_file():
        s = json.loads(summary.read_text())
        res["dofs"], res["path_s"] = s["dofs"], s["wall_time_s"]
    shutil.rmtree(out, ignore_errors=True)
    res.pop("stdout", None)
    return res


def run_factor(element: str, mesh) -> dict:
    res = _child([sys.executable, str(Path(__file__).resolve()), "--factor", element, *map(str, mesh)], _env())
    if res["rc"] == 0:
        res.update(json.loads(res.pop("stdout").strip().splitlines()[-1]))
    return res


def case_factor(element: str, mesh) -> dict:
    """K of the model's problem with the contact and spring dofs held; CHOLMOD analyse + factorise."""
    import warnings

    import numpy as np
    from sksparse import cholmod

    import reference_solver as rs
    from deckbridge.mesh import build_mesh
    from deckbridge.model import load
    from deckbridge.solve import build_problem
    from reference_solver.condense import _reduced_stiffness
    from reference_solver.frames import build_dofmap
    model = load(None, _sets(element, mesh))
    p = build_problem(model, build_mesh(model))
    dm = build_dofmap(p)
    Kq = _reduced_stiffness(p, dm, {}).pop()
    keep = np.ones(Kq.shape[0], bool)
    keep[np.concatenate([dm.contact_dofs, dm.spring_dofs])] = False
    Kii = Kq[keep][:, keep].tocsc()
    del Kq
    with rs.blas_threads(1), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t, c = time.perf_counter(), time.process_time()
        f = cholmod.analyze(Kii)
        f.cholesky_inplace(Kii)
        tf, cf = time.perf_counter() - t, time.process_time() - c
    return {"factor_s": tf, "factor_cpu_s": cf, "dofs_k": 3 * p.n_nodes}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="20k,100k", help="comma list of 20k, 100k, 400k")
    ap.add_argument("--elements", default="hex8i,hex20r,tet10")
    ap.add_argument("--method", default="lagrange", choices=["penalty", "lagrange"])
    ap.add_argument("--factor", nargs=4, metavar=("ELEMENT", "NT", "NZ", "NR"), help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.factor:
        print(json.dumps(case_factor(a.factor[0], tuple(int(x) for x in a.factor[1:]))))
        return 0
    print(f"elements_scale: method {a.method}; {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")
    print(f"{'element':>7} {'size':>5} {'mesh':>10} {'dofs':>8} {'cmd s':>7} {'CPU s':>7} {'path s':>7}"
          f" {'fac s':>6} {'CPU s':>6} {'cmd/fac':>7} {'CPU':>5} {'path/fac':>8} {'us/dof':>6} {'kB/dof':>6}"
          f" {'peak MB':>7} {'load':>5}")
    for size in [s.strip().lower() for s in a.sizes.split(",") if s.strip()]:
        for element in [e.strip() for e in a.elements.split(",") if e.strip()]:
            mesh = MESHES[(element, size)]
            load = os.getloadavg()[0]
            cmd = run_command(element, mesh, a.method)
            fac = run_factor(element, mesh)
            label = "x".join(map(str, mesh))
            if "error" in cmd or "error" in fac:
                print(f"{element:>7} {size:>5} {label:>10} failed: {cmd.get('error') or fac.get('error')}", flush=True)
                continue
            n = cmd["dofs"]
            print(f"{element:>7} {size:>5} {label:>10} {n:>8} {cmd['wall_s']:>7.2f} {cmd['cpu_s']:>7.2f}"
                  f" {cmd['path_s']:>7.2f} {fac['factor_s']:>6.2f} {fac['factor_cpu_s']:>6.2f}"
                  f" {cmd['wall_s'] / fac['factor_s']:>7.2f} {cmd['cpu_s'] / fac['factor_cpu_s']:>5.2f}"
                  f" {cmd['path_s'] / fac['factor_s']:>8.2f} {1e6 * cmd['cpu_s'] / n:>6.1f}"
                  f" {1024 * cmd['peak_mb'] / n:>6.2f} {cmd['peak_mb']:>7.0f} {load:>5.1f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
