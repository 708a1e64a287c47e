"""Regression: a CHOLMOD factor caught in a reference cycle crashed the interpreter at exit.

scikit-sparse 0.4's ``Factor.__dealloc__`` frees the factor through ``self._common``; when the garbage
collector broke a cycle holding a Factor it could clear ``_common`` (set it to None) first, and CHOLMOD
then wrote its error status into libpython's static data next to ``Py_None`` (a segmentation fault at
exit: the single-hexahedron friction case with schur='trailing'). reference_solver.linalg keeps its
factors out of the cyclic collector. Each case runs in a child interpreter, which must exit cleanly,
and the trailing-factor condensation must give the results of the right-hand-side one.
"""

import json
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from reference_solver.linalg import HAVE_CHOLMOD

pytestmark = pytest.mark.skipif(not HAVE_CHOLMOD, reason="schur='trailing' needs CHOLMOD")

CHILD = textwrap.dedent("""
    import gc, json, sys
    import numpy as np
    import reference_solver as rs
    from reference_solver.friction import condense_friction

    schur = sys.argv[1]
    nodes = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
    p = rs.Problem(
        nodes=nodes, hexes=np.arange(8)[None, :], E=1.0e14, nu=0.3, element="c3d8",
        contact_nodes=np.arange(4), contact_normals=np.tile([0.0, 0.0, 1.0], (4, 1)),
        contact_area=np.full(4, 0.25), contact_k=np.full(4, 1.0e6), contact_clearance=np.zeros(4),
        contact_surface=["table"] * 4, spring_nodes=np.zeros(0, int), spring_dirs=np.zeros((0, 3)),
        spring_k=np.zeros(0), ref_point=[0.5, 0.5, 1.0], coupling="kinematic", coupling_nodes=np.arange(4, 8),
        coupling_weights=np.ones(4), loads={"N": (0, 0, -1.0e3, 0, 0, 0), "T": (1.0e3, 0, 0, 0, 0, 0)},
        k_open_ratio=1e-12, tangential="friction", friction=0.3, contact_kt=np.full(4, 1.0e6))
    gc.disable()                     # no collection reorders the factor behind its holders (see below)
    system = condense_friction(p, schur=schur)
    out = {"schur": system.info["schur"]}
    for method in ("penalty", "lagrange"):
        sol = rs.solve_path(system, method, base={"N": 1.0}, ramp={"T": 1.0}, targets=[0.25, 0.0],
                            increments=10, recover=True)
        out[method] = {"force": sol.force.tolist(), "ft": sol.tangential_force.tolist(),
                       "u": sol.retained_u.tolist(), "status": sol.stick_status.tolist()}
    system.cache["cycle"] = system           # the dead system (and its factor) left to the cyclic collector
    del system, sol
    gc.collect()
    print(json.dumps(out))
""")


DEAD_CYCLE = textwrap.dedent("""
    import gc, sys
    import numpy as np
    import scipy.sparse as sp
    from reference_solver.linalg import cholmod_factorize, schur_trailing

    n = 60
    K = sp.diags([-np.ones(n - 1), 2.05 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1], format="csc")
    gc.disable()                     # no collection in between: the factor stays ahead of its holders
    held = (cholmod_factorize(K) if sys.argv[1] == "factorize"
            else schur_trailing(K, np.array([0, n - 1]), np.ones((n, 1))))
    box = [held]
    box.append(box)                  # a dead reference cycle that holds the factor
    del held, box
    print(gc.collect())
""")


def _child(code: str, arg: str) -> str:
    run = subprocess.run([sys.executable, "-c", code, arg], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, f"{arg}: exit code {run.returncode}\n{run.stderr[-2000:]}"
    return run.stdout.strip().splitlines()[-1]


@pytest.mark.parametrize("which", ["factorize", "trailing"])
def test_a_factor_in_a_dead_reference_cycle_is_freed_without_corrupting_the_interpreter(which):
    """Deterministic form of the crash: the factor older than the cycle that holds it is the first
    object the collector clears (before the fix: exit code -11 on CPython 3.12, both factor kinds)."""
    assert int(_child(DEAD_CYCLE, which)) > 0


def test_single_hexahedron_friction_with_the_trailing_factor_exits_cleanly_and_matches_rhs():
    rhs, trailing = (json.loads(_child(CHILD, schur)) for schur in ("rhs", "trailing"))
    assert rhs["schur"].startswith("rhs") and trailing["schur"].startswith("cholmod-trailing")
    N = 1.0e3
    for method in ("penalty", "lagrange"):
        a, b = rhs[method], trailing[method]
        assert a["status"] == b["status"]
        assert np.allclose(a["force"], b["force"], rtol=0, atol=1e-6 * N)     # the hand test's tolerance
        assert np.allclose(a["ft"], b["ft"], rtol=0, atol=1e-6 * N)
        u = np.array(a["u"])
        assert np.allclose(u, b["u"], rtol=0, atol=1e-6 * np.abs(u).max())
