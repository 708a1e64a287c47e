"""Time the reference's whole-section onset on a friction path (deckbridge.wall_stress.reference_section_onset).

Usage: OMP_NUM_THREADS=1 .venv/bin/python bench/section_onset_friction.py [n_theta n_z n_r | default]
Prints, per method, the path's solve time, the onset's time, its answer and the number of one-increment
restarts (law increments called by the search). The scenario matrix's TestCase06 levels: t/R 0.005, n_r 3,
mu 0.3, kinematic top (parametric mesh here, not the Gmsh .bdf)."""

import sys
import time

from deckbridge.model import load
from deckbridge.solve import condense_model, solve_system
from deckbridge.wall_stress import reference_section_onset
import reference_solver.path as rp

FRICTION = ["contact.tangential=friction", "contact.friction=0.3"]
if sys.argv[1:2] == ["default"]:    # the default model with mu = 0.3 (tests/test_friction_section_onset.py)
    model = load(None, FRICTION)
    nt, nz, nr = model.mesh.n_theta, model.mesh.n_z, model.mesh.n_r
else:
    nt, nz, nr = (int(v) for v in sys.argv[1:4]) if len(sys.argv) > 3 else (48, 6, 3)
    R, H = 1.5, 2.0
    model = load(None, [f"geometry.radius={R}", f"geometry.height={H}", f"geometry.thickness={0.005 * R!r}",
                        f"mesh.n_theta={nt}", f"mesh.n_z={nz}", f"mesh.n_r={nr}", "load_introduction=kinematic",
                        *FRICTION])
mesh, system = condense_model(model)
calls = [0]
real = rp._advance


def counted(*a, **kw):
    calls[0] += 1
    return real(*a, **kw)


rp._advance = counted
trace: list[float] = []
real_onset = rp._section_onset


def traced(system, sol, groups, state_at, tol, **kw):
    def at(lam):
        n = calls[0]
        out = state_at(lam)
        trace.append((lam, calls[0] - n))
        return out
    return real_onset(system, sol, groups, at, tol, **kw)


rp._section_onset = traced
for method in ("penalty", "lagrange"):
    t0 = time.perf_counter()
    _, _, sol = solve_system(model, mesh, system, method, recover=False)
    t1 = time.perf_counter()
    calls[0] = 0
    trace.clear()
    lam, theta = reference_section_onset(system, mesh, sol)
    t2 = time.perf_counter()
    print(f"{nt}x{nz}x{nr} {method}: path {t1 - t0:.2f} s, section onset {t2 - t1:.2f} s "
          f"({calls[0]} increments), lambda {lam!r} theta {theta}", flush=True)
    print("  search points:", " ".join(f"{v:.9f}({n})" for v, n in trace), flush=True)
