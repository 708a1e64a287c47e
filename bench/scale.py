"""Scale benchmark of the reference solver: whole load path against ONE CHOLMOD factorisation of K.

For each size, two fresh processes run side by side in one bench run:
- ``path``: the default JAR model meshed to about that many dofs, condensed once (assembly, split
  and ordering, factorisation, Schur complement, dense condensation), then the penalty and the
  Lagrange load paths with field recovery. Per stage: wall time and peak RSS (VmHWM, reset between
  stages through /proc/self/clear_refs, so each figure is the peak inside that stage);
- ``factor``: the same K with the contact and spring dofs held, assembled and split as before the
  issue, then one ``cholmod.cholesky`` (CHOLMOD's own ordering) timed alone: the yardstick.
Printed: stage table, whole path / one factorisation, the peak RSS, the peak estimated from the mesh
before starting (reference_solver.estimate), the BLAS library, kernel and threads (threadpoolctl).

    python bench/scale.py --sizes 20k,100k,400k
    python bench/scale.py --sizes 100k --with-ccx        # ccx on the same mesh (minutes)
    python bench/scale.py --sizes 3m --only path --limit-rss 20G   # killed above 20 GiB resident
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time

# (n_theta, n_z, n_r): about 3 * n_theta * (n_z + 1) * (n_r + 1) dofs; elements stay near square
MESHES = {"20k": (72, 30, 2), "100k": (160, 70, 2), "200k": (226, 100, 2), "400k": (320, 140, 2),
          "1m": (500, 220, 2), "2m": (700, 316, 2), "3m": (860, 388, 2)}


def _hwm_mb() -> float:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def _reset_hwm() -> bool:
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")
        return True
    except OSError:
        return False


class Stages:
    """Stage clock: time and peak RSS since the previous mark."""

    def __init__(self):
        self.rows, self.t, self.c = [], time.perf_counter(), time.process_time()
        self.resettable = _reset_hwm()

    def __call__(self, name: str) -> None:
        now, cpu = time.perf_counter(), time.process_time()
        self.rows.append((name, now - self.t, _hwm_mb(), cpu - self.c))
        _reset_hwm()
        self.t, self.c = time.perf_counter(), time.process_time()


def _model(nt: int, nz: int, nr: int, increments: int = 10):
    from deckbridge.model import load
    return load(None, [f"mesh.n_theta={nt}", f"mesh.n_z={nz}", f"mesh.n_r={nr}",
                       f"steps.increments={increments}"])


def case_path(nt, nz, nr, threads) -> dict:
    import reference_solver as rs
    from deckbridge.mesh import build_mesh
    from deckbridge.solve import build_problem
    from reference_solver import estimate, shifted, stages
    st = Stages()
    model = _model(nt, nz, nr)
    p = build_problem(model, build_mesh(model))
    est = estimate.estimate_peak_bytes(p.n_nodes, len(p.hexes), p.n_contacts, p.n_springs,
                                       factor_entries=estimate.factor_entries(p.hexes, p.n_nodes))
    st("mesh")
    stages.set_hook(st)
    t0, c0 = time.perf_counter(), time.process_time()
    system = rs.condense(p, threads=threads)
    stages.set_hook(None)
    out = {"dofs": 3 * p.n_nodes, "hexes": len(p.hexes), "contact_rows": p.n_contacts,
           "retained": system.info["retained"], "schur": system.info["schur"]}
    for method in ("penalty", "lagrange"):
        before = dict(shifted.COUNTS)
        sol = rs.solve_path(system, method, lambda_max=model.steps.lambda_max,
                            increments=model.steps.increments, recover=True, threads=threads)
        st(method)
        out[f"{method}_liftoff"] = sol.liftoff_load_factor
        out[f"{method}_dense"] = {k: shifted.COUNTS[k] - before[k] for k in before}
    out["path_s"] = time.perf_counter() - t0
    out["path_cpu_s"] = time.process_time() - c0
    out["stages"] = st.rows
    out["peak_mb"] = max(r[2] for r in st.rows) if st.resettable else _hwm_mb()
    out["estimate_mb"] = est / 2**20
    with rs.blas_threads(threads):
        out["blas"] = rs.blas_info()
    return out


def case_factor(nt, nz, nr, threads) -> dict:
    """One CHOLMOD factorisation (its own ordering) of K with the contact and spring dofs held."""
    import importlib
    import numpy as np
    import reference_solver as rs
    from deckbridge.mesh import build_mesh
    from deckbridge.solve import build_problem
    from reference_solver.frames import build_dofmap
    cond = importlib.import_module("reference_solver.condense")
    model = _model(nt, nz, nr, 1)
    p = build_problem(model, build_mesh(model))
    dm = build_dofmap(p)
    Kq = cond._reduced_stiffness(p, dm, {}).pop()
    keep = np.ones(Kq.shape[0], bool)
    keep[np.concatenate([dm.contact_dofs, dm.spring_dofs])] = False
    Kii = Kq[keep][:, keep].tocsc()
    del Kq
    _reset_hwm()
    base = _hwm_mb()
    import warnings
    from sksparse import cholmod
    with rs.blas_threads(threads), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t, c = time.perf_counter(), time.process_time()
        f = cholmod.analyze(Kii)                   # CHOLMOD's own fill-reducing ordering
        ta = time.perf_counter() - t
        f.cholesky_inplace(Kii)
        tf, cf = time.perf_counter() - t, time.process_time() - c
    return {"factor_s": tf, "factor_cpu_s": cf, "analyze_s": ta, "factor_peak_mb": _hwm_mb(), "before_mb": base, "nnz_k": int(Kii.nnz)}


def case_liftoff(nt, nz, nr, threads) -> dict:
    """``deckbridge liftoff`` (both methods, one condensation, onset search) on the same mesh."""
    from deckbridge.studies.liftoff import critical_load
    os.environ["REFERENCE_SOLVER_THREADS"] = str(threads)
    model = _model(nt, nz, nr)
    t = time.perf_counter()
    res = critical_load(model)
    return {"liftoff_s": time.perf_counter() - t, "lambda_c": {m: res[m]["lambda_c"] for m in res["methods"]}}


def case_ccx(nt, nz, nr) -> dict:
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from bench_solver import case_ccx as run
    return run(nt, nz, nr, 10)


def _bytes(text: str) -> int:
    units = {"k": 2**10, "m": 2**20, "g": 2**30}
    tail = text[-1].lower()
    return int(float(text[:-1]) * units[tail]) if tail in units else int(text)


def _rss_of(pid: int) -> int:
    try:
        with open(f"/proc/{pid}/status") as fh:
            for line in fh:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return 0


def _sub(args: list[str], limit_as: str | None = None, limit_rss: str | None = None) -> dict:
    """Run one case in a fresh process. ``limit_as``: prlimit --as (bytes; "21G" is not GiB to prlimit);
    ``limit_rss``: this process polls the child's resident memory and kills it above the limit
    (the address space of OpenBLAS/glibc reservations runs far ahead of the resident memory)."""
    cmd = [sys.executable, os.path.abspath(__file__), *args]
    if limit_as:
        cmd = ["prlimit", f"--as={_bytes(limit_as)}", *cmd]
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        proc = subprocess.Popen(cmd, stdout=out, stderr=err, text=True)
        cap, killed = (_bytes(limit_rss) if limit_rss else None), False
        while proc.poll() is None:
            if cap and _rss_of(proc.pid) > cap:
                proc.kill()
                killed = True
            time.sleep(0.05)
        out.seek(0)
        err.seek(0)
        stdout, stderr = out.read(), err.read()
    if killed:
        return {"error": f"killed: resident memory above {limit_rss}"}
    if proc.returncode != 0:
        return {"error": (stderr.strip().splitlines() or [f"exit {proc.returncode}"])[-1]}
    return json.loads(stdout.strip().splitlines()[-1])


def _cpu() -> str:
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
        name = next((ln.split(":", 1)[1].strip() for ln in out.splitlines() if ln.startswith("Model name")), "?")
    except OSError:
        name = platform.processor() or "?"
    mem = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30
    return f"{name}, {os.cpu_count()} cores, {mem:.0f} GiB"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="20k,100k", help=f"comma list of {', '.join(MESHES)}")
    ap.add_argument("--threads", type=int, default=1, help="BLAS threads in both processes (default 1)")
    ap.add_argument("--only", choices=["path", "factor"], help="run one side only")
    ap.add_argument("--with-ccx", action="store_true", help="also run CalculiX on the same mesh (penalty deck)")
    ap.add_argument("--with-liftoff", action="store_true", help="also time deckbridge's liftoff study on the same mesh")
    ap.add_argument("--limit-as", help="address-space limit of each process, e.g. 21G (GiB) or bytes (prlimit --as)")
    ap.add_argument("--limit-rss", help="kill a case whose resident memory exceeds this, e.g. 20G (polled)")
    ap.add_argument("--json", help="write all measurements to this file")
    ap.add_argument("--case", nargs=4, metavar=("KIND", "NT", "NZ", "NR"), help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.case:
        kind, nt, nz, nr = a.case[0], *map(int, a.case[1:])
        out = {"path": lambda: case_path(nt, nz, nr, a.threads), "factor": lambda: case_factor(nt, nz, nr, a.threads),
               "liftoff": lambda: case_liftoff(nt, nz, nr, a.threads), "ccx": lambda: case_ccx(nt, nz, nr)}[kind]()
        print(json.dumps(out))
        return 0

    print(f"machine: {_cpu()}; load average {os.getloadavg()[0]:.1f}; BLAS threads {a.threads}")
    results = {}
    for size in [s.strip().lower() for s in a.sizes.split(",") if s.strip()]:
        nt, nz, nr = MESHES[size]
        geo = [str(nt), str(nz), str(nr), "--threads", str(a.threads)]
        path = _sub(["--case", "path", *geo], a.limit_as, a.limit_rss) if a.only != "factor" else {}
        fac = _sub(["--case", "factor", *geo], a.limit_as, a.limit_rss) if a.only != "path" else {}
        ccx = _sub(["--case", "ccx", str(nt), str(nz), str(nr)]) if a.with_ccx else {}
        lift = _sub(["--case", "liftoff", *geo], a.limit_as, a.limit_rss) if a.with_liftoff else {}
        results[size] = {"path": path, "factor": fac, "ccx": ccx, "liftoff": lift, "mesh": (nt, nz, nr)}
        print(f"\n== {size}: mesh {nt}x{nz}x{nr}")
        if "error" in path:
            print(f"   path failed: {path['error']}")
        elif path:
            for b in path.get("blas", []):
                print(f"   BLAS: {b['internal_api']} {b['version']} kernel {b['architecture']}, "
                      f"{b['num_threads']} thread(s) while solving: {os.path.basename(b['filepath'] or '?')}")
            print(f"   {path['dofs']} dofs, {path['hexes']} hexes, {path['retained']} retained, {path['schur']}")
            print(f"   {'stage':<10} {'time s':>8} {'CPU s':>8} {'peak RSS MB':>12}")
            for name, dt, mb, cpu in path["stages"]:
                print(f"   {name:<10} {dt:>8.2f} {cpu:>8.2f} {mb:>12.0f}")
            print(f"   whole path (condensation + penalty + Lagrange, fields) {path['path_s']:.2f} s"
                  f" (CPU {path['path_cpu_s']:.2f} s);"
                  f" peak RSS {path['peak_mb']:.0f} MB (estimate from the mesh {path['estimate_mb']:.0f} MB)")
            print(f"   onsets: penalty {path['penalty_liftoff']:.4f}, Lagrange {path['lagrange_liftoff']:.4f}")
            for m in ("penalty", "lagrange"):
                if f"{m}_dense" in path:
                    what = "S_c + D" if m == "penalty" else "S_c's open block S_II"
                    print(f"   {m}: {path[f'{m}_dense']['factorisations']} dense factorisations ({what})"
                          f" for {path[f'{m}_dense']['solves']} solves")
        if "error" in fac:
            print(f"   factorisation failed: {fac['error']}")
        elif fac:
            print(f"   one CHOLMOD factorisation of K_ii: {fac['factor_s']:.2f} s (of which its ordering"
                  f" {fac['analyze_s']:.2f} s; CPU {fac['factor_cpu_s']:.2f} s), peak RSS {fac['factor_peak_mb']:.0f} MB")
        if path.get("path_s") and fac.get("factor_s"):
            print(f"   RATIO whole path / one factorisation = {path['path_s'] / fac['factor_s']:.2f}"
                  f" (against its numeric part alone {path['path_s'] / (fac['factor_s'] - fac['analyze_s']):.2f};"
                  f" CPU time ratio {path['path_cpu_s'] / fac['factor_cpu_s']:.2f})")
        if lift:
            if "liftoff_s" in lift:
                print(f"   liftoff study (both methods, no fields): {lift['liftoff_s']:.2f} s"
                      + (f", {lift['liftoff_s'] / path['path_s']:.2f}x the whole path" if path.get("path_s") else ""))
            else:
                print(f"   liftoff: {lift}")
        if ccx:
            if "ccx_s" in ccx and ccx.get("returncode") == 0:
                print(f"   ccx (penalty deck, same mesh): {ccx['ccx_s']:.1f} s"
                      + (f", {ccx['ccx_s'] / path['path_s']:.1f}x the reference path" if path.get("path_s") else ""))
            else:
                print(f"   ccx: {ccx}")
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(results, fh, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
