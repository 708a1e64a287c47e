"""Where `deckbridge solve`'s output time goes: CPU seconds of each stage in one process (issue 22).

Condensation, load path (no recovery), the recovery of every state's displacements, the stresses of
every state (reference_solver.recover.states_stress), result.vtu's mesh, and the VTUs written
(deckbridge.paraview.write_vtus: zlib level ZLIB_LEVEL on writer threads, blocks that hardly deflate stored),
alternated with the same without the repeated-block memo and with every block deflated (no stored blocks,
its MB printed), then 4 VTUs with meshio's defaults (zlib level 6, one thread) for comparison.

    python bench/solve_outputs.py --mesh 160x70x2
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
import time
from pathlib import Path


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mesh", default="160x70x2", metavar="NTxNZxNR")
    ap.add_argument("--method", default="penalty", choices=["penalty", "lagrange"])
    a = ap.parse_args(argv)
    import meshio
    from deckbridge import paraview as pv
    from deckbridge.model import load
    from deckbridge.solve import condense_model, solve_system
    from reference_solver.recover import path_fields
    nt, nz, nr = (int(x) for x in a.mesh.split("x"))
    model = load(None, [f"mesh.n_theta={nt}", f"mesh.n_z={nz}", f"mesh.n_r={nr}"])
    rows = []

    def timed(name, fn):
        c = time.process_time()
        out = fn()
        rows.append((name, time.process_time() - c))
        return out

    mesh, system = timed("condensation", lambda: condense_model(model))
    _, _, sol = timed("load path", lambda: solve_system(model, mesh, system, a.method, recover=False))
    U = timed("recovery (every state)", lambda: path_fields(system, sol))
    states, _ = timed("stresses (every state)", lambda: pv.reference_states(model, mesh, system, sol, U))
    timed("result.vtu mesh", lambda: pv.result_mesh(system.problem, sol, U))
    out = Path(tempfile.mkdtemp(prefix="bench-out-"))
    jobs = [(out / f"s{k}.vtu", pv.state_mesh(mesh.nodes, mesh.hexes, s)) for k, s in enumerate(states)]
    name = f"{len(jobs)} VTUs, zlib level {pv.ZLIB_LEVEL}, {pv.writer_threads(len(jobs))} threads"
    memo = pv._LeveledZlib.compress
    for _ in range(2):             # alternated: with the repeated-block memo, without (every block compressed)
        timed(name, lambda: pv.write_vtus(jobs))
        first = [p.read_bytes() for p, _ in jobs]
        pv._LeveledZlib.compress = lambda self, block: self._compress(block)
        try:
            timed(name + ", no memo", lambda: pv.write_vtus(jobs))
        finally:
            pv._LeveledZlib.compress = memo
        assert first == [p.read_bytes() for p, _ in jobs], "the memo changed the bytes written"
    mb = sum(p.stat().st_size for p, _ in jobs) / 1e6
    ratio, pv.STORE_RATIO = pv.STORE_RATIO, float("inf")
    try:
        timed(name + ", every block deflated", lambda: pv.write_vtus(jobs))
        rows[-1] = (rows[-1][0] + f" ({sum(p.stat().st_size for p, _ in jobs) / 1e6:.1f} MB)", rows[-1][1])
    finally:
        pv.STORE_RATIO = ratio
    timed("4 VTUs, meshio defaults (level 6, one thread)", lambda: [meshio.write(p, m) for p, m in jobs[:4]])
    shutil.rmtree(out, ignore_errors=True)
    print(f"{a.mesh}: {3 * mesh.n_nodes} dofs, {len(states)} states, {mb:.1f} MB of VTUs (level {pv.ZLIB_LEVEL})")
    for name, cpu in rows:
        print(f"  {name:<48} {cpu:7.2f} s CPU")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
