"""`deckbridge solve` timed from outside (whole command, default outputs) against ONE CHOLMOD
factorisation of the same system, both in fresh processes of the same bench run (issue 22).

Per size and repeat: the command ``deckbridge solve --method M -o DIR`` of the default JAR model meshed
n_theta x n_z x n_r (wall time, CPU time = user + sys, peak RSS of the child), then the yardstick
``bench/scale.py --case factor`` (K with the contact and spring dofs held, CHOLMOD's own ordering,
its analyse included). Printed per row: both times, the ratio command / factorisation (wall and
CPU), the size written, and the load average before the row (the box is shared: compare ratios).
``--before DIR`` runs an older checkout's command (PYTHONPATH=DIR in front) alternately with this
tree's, so both sides see the same neighbours.

    python bench/solve_command.py --sizes 100k,200k,400k --repeat 2
    git archive main | tar -x -C /tmp/base && python bench/solve_command.py --sizes 200k --before /tmp/base
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from scale import MESHES  # noqa: E402


def _child(cmd: list[str], env: dict) -> dict:
    """Run ``cmd``; wall, CPU (user + sys) and peak RSS [MB] of that child alone (os.wait4's rusage)."""
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        t = time.perf_counter()
        proc = subprocess.Popen(cmd, env=env, stdout=out, stderr=err, text=True, cwd=tempfile.gettempdir())
        _, status, ru = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t
        proc.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        stdout, stderr = out.read(), err.read()
    res = {"wall_s": wall, "cpu_s": ru.ru_utime + ru.ru_stime, "peak_mb": ru.ru_maxrss / 1024.0,
           "rc": proc.returncode, "stdout": stdout}
    if proc.returncode:
        res["error"] = (stderr.strip().splitlines() or ["?"])[-1]
    return res


def solve_command(mesh: tuple[int, int, int], method: str, code: Path | None) -> dict:
    env = {**os.environ, "OMP_NUM_THREADS": "1", "DECKBRIDGE_ALLOW_LARGE": "1"}
    env["PYTHONPATH"] = f"{code or HERE.parent}{os.pathsep}{env.get('PYTHONPATH', '')}"   # cwd is elsewhere
    out = Path(tempfile.mkdtemp(prefix="bench-solve-"))
    nt, nz, nr = mesh
    cmd = [sys.executable, "-c", "import sys; from deckbridge.cli import main; sys.exit(main())", "solve",
           "--method", method, "--set", f"mesh.n_theta={nt}", "--set", f"mesh.n_z={nz}", "--set", f"mesh.n_r={nr}",
           "-o", str(out / "o")]
    res = _child(cmd, env)
    res["written_mb"] = sum(f.stat().st_size for f in (out / "o").glob("*")) / 1e6 if (out / "o").is_dir() else 0.0
    summary = out / "o" / "summary.json"
    if summary.is_file():
        res["dofs"] = json.loads(summary.read_text())["dofs"]
    shutil.rmtree(out, ignore_errors=True)
    res.pop("stdout")
    return res


def factorisation(mesh: tuple[int, int, int]) -> dict:
    env = {**os.environ, "OMP_NUM_THREADS": "1", "PYTHONPATH": f"{HERE.parent}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
    res = _child([sys.executable, str(HERE / "scale.py"), "--case", "factor", *map(str, mesh)], env)
    if res["rc"] == 0:
        res.update(json.loads(res.pop("stdout").strip().splitlines()[-1]))
    return res


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="100k", help=f"comma list of {', '.join(MESHES)}")
    ap.add_argument("--mesh", action="append", default=[], metavar="NTxNZxNR", help="an explicit mesh, e.g. 226x100x2")
    ap.add_argument("--method", default="penalty", choices=["penalty", "lagrange"])
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--before", type=Path, help="an older checkout run alternately (PYTHONPATH in front)")
    a = ap.parse_args(argv)
    meshes = [(s, MESHES[s]) for s in a.sizes.split(",") if s.strip()] if not a.mesh else []
    meshes += [(m, tuple(int(x) for x in m.split("x"))) for m in a.mesh]
    sides = [("before", a.before), ("this", None)] if a.before else [("this", None)]
    print(f"{'mesh':>12} {'code':>6} {'dofs':>9} {'command s':>10} {'CPU s':>7} {'factor s':>9} {'CPU s':>7}"
          f" {'ratio':>6} {'CPU':>6} {'peak MB':>8} {'out MB':>7} {'load':>5}")
    for label, mesh in meshes:
        for _ in range(a.repeat):
            for side, code in sides:
                load = os.getloadavg()[0]
                cmd = solve_command(mesh, a.method, code)
                fac = factorisation(mesh)
                if "error" in cmd or "error" in fac:
                    print(f"{label:>12} {side:>6} failed: {cmd.get('error') or fac.get('error')}")
                    continue
                print(f"{label:>12} {side:>6} {cmd.get('dofs', 0):>9} {cmd['wall_s']:>10.2f} {cmd['cpu_s']:>7.2f}"
                      f" {fac['factor_s']:>9.2f} {fac['factor_cpu_s']:>7.2f} {cmd['wall_s'] / fac['factor_s']:>6.2f}"
                      f" {cmd['cpu_s'] / fac['factor_cpu_s']:>6.2f} {cmd['peak_mb']:>8.0f} {cmd['written_mb']:>7.1f}"
                      f" {load:>5.1f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
