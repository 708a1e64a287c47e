"""Benchmark: ``deckbridge sweep`` (six k-factors + Lagrange, one condensation, Dask) against the same
seven solves run as separate ``deckbridge solve`` commands (penalty --k-factor F each, one Lagrange).

Both sides are timed as whole commands in subprocesses (interpreter start, imports, cluster start,
writing outputs included), alternately, ``--repeat`` times; the ratio of the medians is printed with
the sweep's own breakdown (run.json). Target (issue 16): the sweep at least 5x faster. Both sides run
with the model's defaults (the separate solves write their usual outputs, ParaView series included;
nothing is switched off on either side). CPU seconds (user + sys of the command and the processes it
waited for, Dask workers included) are printed beside the wall times: on a shared machine the sweep's
two workers compete with the neighbours' load more than one serial solve does.

BLAS threads: the separate solves run with OPENBLAS_NUM_THREADS=OMP_NUM_THREADS=1 by default, the
faster setting for them (the sweep's workers use one thread each anyway). With ``--blas-default``
they run in the caller's environment: on a busy 2-core machine their many small dense Cholesky
factorisations then spin in OpenBLAS threads and one solve took 36-68 s instead of about 5 s, which
would flatter the sweep.

    python bench/bench_sweep.py                       # default JAR model, 0.01 ... 1000
    python bench/bench_sweep.py --repeat 3 --set mesh.n_theta=120 --workers 2
    python bench/bench_sweep.py --repeat 5 --before /tmp/old   # also an older checkout, alternated

``--before DIR``: a checkout of another commit (e.g. ``git archive BASE | tar -x -C DIR``) measured in
the same bench run, alternately with this one (PYTHONPATH=DIR in front of this tree for both of its
sides; its ``deckbridge`` and ``reference_solver`` packages are then DIR's), so that before and after
see the same load of a shared machine.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

K_FACTORS = "0.01,0.1,1,10,100,1000"


def _cli() -> list[str]:
    exe = Path(sys.executable).with_name("deckbridge")
    return [str(exe)] if exe.exists() else [sys.executable, "-m", "deckbridge.cli"]


CPU = [0.0]        # CPU seconds of the commands timed so far (user + sys of the reaped children)


def _child_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _timed(cmd: list[str], env: dict | None = None) -> float:
    c, t = _child_cpu(), time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True, env=env)
    dt = time.perf_counter() - t
    CPU[0] += _child_cpu() - c
    if res.returncode != 0:
        raise SystemExit(f"failed ({res.returncode}): {' '.join(cmd)}\n{res.stderr[-2000:]}")
    return dt


def _with_path(env: dict | None, before: str | None) -> dict | None:
    if before is None:
        return env
    env = dict(os.environ if env is None else env)
    env["PYTHONPATH"] = before + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    return env


def separate_solves(work: Path, k_factors: list[str], sets: list[str], env: dict | None) -> float:
    t = 0.0
    for k in k_factors:
        t += _timed(_cli() + ["solve", "--method", "penalty", "--k-factor", k, *sets, "-o", str(work / f"k{k}")], env)
    t += _timed(_cli() + ["solve", "--method", "lagrange", *sets, "-o", str(work / "lagrange")], env)
    return t


def sweep(work: Path, k_factors: list[str], sets: list[str], extra: list[str], env: dict | None = None
          ) -> tuple[float, dict]:
    out = work / "sweep"
    t = _timed(_cli() + ["sweep", "--k-factors", ",".join(k_factors), *sets, *extra, "-o", str(out)], env)
    return t, json.loads((out / "run.json").read_text())


def measure(label: str, ks, sets, extra, env, env_sweep, repeat_i: int, rec: dict) -> None:
    """One repeat of both sides for one code tree; appends to ``rec`` (lists of times, CPU, runs)."""
    with tempfile.TemporaryDirectory(prefix="bench_sweep_") as tmp:
        work = Path(tmp)
        c0 = CPU[0]
        rec["sep"].append(separate_solves(work, ks, sets, env))
        c1 = CPU[0]
        shutil.rmtree(work, ignore_errors=True)
        work.mkdir(exist_ok=True)
        t, run = sweep(work, ks, sets, extra, env_sweep)
        rec["sw"].append(t)
        rec["runs"].append(run)
        rec["cpu"].append((c1 - c0, CPU[0] - c1))
    a, b = rec["sep"][-1], rec["sw"][-1]
    ca, cb = rec["cpu"][-1]
    print(f"{label}run {repeat_i + 1}: {len(ks) + 1} separate solves {a:.2f} s (CPU {ca:.2f} s), sweep {b:.2f} s "
          f"(CPU {cb:.2f} s), ratio {a / b:.2f}x (CPU {ca / cb:.2f}x); load average {os.getloadavg()[0]:.2f}",
          flush=True)


def report(label: str, rec: dict, repeat: int) -> None:
    a, b = statistics.median(rec["sep"]), statistics.median(rec["sw"])
    run = rec["runs"][-1]
    cond = {v["condensed_on"]: v["condense_s"] for v in run["case_timings_s"].values()}
    solves = [v["wall_time_s"] for v in run["case_timings_s"].values()]
    print(f"{label}sweep ({run['executor']}): phases {', '.join(f'{k} {v:.2f} s' for k, v in run['timings_s'].items())}; "
          f"condensation {sum(cond.values()):.2f} s ({len(cond)}x), case solves {sum(solves):.2f} s in all")
    ca, cb = statistics.median(c[0] for c in rec["cpu"]), statistics.median(c[1] for c in rec["cpu"])
    ratios = sorted(x / y for x, y in zip(rec["sep"], rec["sw"]))
    print(f"{label}median of {repeat}: separate solves {a:.2f} s, sweep {b:.2f} s -> sweep is {a / b:.2f}x faster "
          f"(target >= 5x; per-run ratios {ratios[0]:.2f}-{ratios[-1]:.2f}x); CPU {ca:.2f} s against {cb:.2f} s "
          f"({ca / cb:.2f}x)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k-factors", default=K_FACTORS)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--workers", type=int, default=None)
    ap.add_argument("--strategy", choices=["split", "mesh"], default=None)
    ap.add_argument("--executor", choices=["auto", "local", "dask"], default=None,
                    help="the sweep's --executor (this tree only; not passed to --before)")
    ap.add_argument("--before", default=None, metavar="DIR",
                    help="also measure the checkout in DIR (another commit), alternated with this tree")
    ap.add_argument("--blas-default", action="store_true",
                    help="run the separate solves with the caller's BLAS threads (default: one thread)")
    args = ap.parse_args()
    env = None if args.blas_default else {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1",
                                          "MKL_NUM_THREADS": "1"}
    ks = [k.strip() for k in args.k_factors.split(",")]
    sets = [x for s in args.sets for x in ("--set", s)]
    extra = (["--workers", str(args.workers)] if args.workers else []) + (
        ["--strategy", args.strategy] if args.strategy else [])
    print(f"cores: {os.cpu_count()}; k-factors {','.join(ks)} + lagrange; model overrides {args.sets or 'none'}; "
          f"separate solves with {'the default BLAS threads' if env is None else 'one BLAS thread'}"
          + (f"; before = {args.before}, alternated" if args.before else ""))
    now = {"sep": [], "sw": [], "runs": [], "cpu": []}
    old = {"sep": [], "sw": [], "runs": [], "cpu": []}
    mine = extra + (["--executor", args.executor] if args.executor else [])
    for i in range(args.repeat):
        if args.before:
            measure("before: ", ks, sets, extra, _with_path(env, args.before), _with_path(None, args.before), i, old)
        measure("after:  " if args.before else "", ks, sets, mine, env, None, i, now)
    if args.before:
        report("before: ", old, args.repeat)
    report("after:  " if args.before else "", now, args.repeat)


if __name__ == "__main__":
    main()
