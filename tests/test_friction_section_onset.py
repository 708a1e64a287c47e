"""The whole-section onset on a friction path (path-dependent) restarts from the path's own converged state.

Independent truth: :func:`reference_solver.solve_path` itself, run along the same increments as the solved
path up to lambda -/+ delta (delta = 1e-4, the friction law's onset resolution SLIDE_TOL): no azimuth is
wholly open just below the onset, one is just above. On the default model with mu = 0.3 (Lagrange) the
former search (each state one increment from lambda = 0) answered 0.602219, which lies 1.7e-4 past the
path's opening (an azimuth is already open at 0.602119 along the path); the restarted search answers
0.602046 and is bracketed. With mu -> 0 friction is path-independent and both agree to 1e-12 (the
24 x 6 x 1 mesh, mu = 1e-12: 0.5852620593209583 before, 0.5852620593202347 after).

The search on a friction path bisects to the first-node onset's resolution (law.onset_floor = SLIDE_TOL x the
largest load factor) instead of regula falsi to 1e-9: 10 friction increments instead of 28 on this model
(bench/section_onset_friction.py default: 0.38 s instead of 1.08 s; the 48 x 6 x 3 TestCase06 levels 14 instead
of 56, 4.8 s instead of 13.7 s). Its answer 0.6020508 equals the former one, 0.6020462, to SLIDE_TOL.
"""

import numpy as np
import pytest

import reference_solver as rs
import reference_solver.path as rp
from deckbridge.model import load
from deckbridge.solve import condense_model, solve_system
from deckbridge.wall_stress import azimuth_groups, reference_section_onset
from reference_solver.onset import SLIDE_TOL, group_open


def _open_along_path(system, sol, groups, lam: float) -> bool:
    """Whether a whole group is open at ``lam`` reached along ``sol``'s increments (then one more)."""
    lfs = [float(v) for v in sol.load_factor[sol.step == 2][1:] if v < lam] + [lam]
    s = rs.solve_path(system, sol.method, sol.k_factor or 1.0, targets=lfs, lambda_max=max(lfs), increments=1,
                      algorithm=sol.algorithm, onset="off", recover=False)
    return bool(group_open(s.gap[-1], s.closed[-1], groups).any())


def test_friction_section_onset_is_bracketed_by_the_path_itself(monkeypatch):
    model = load(None, ["contact.tangential=friction", "contact.friction=0.3"])
    mesh, system = condense_model(model)
    _, _, sol = solve_system(model, mesh, system, "lagrange", recover=False)
    assert sol.path_states is not None and len(sol.path_states) == int((sol.step == 2).sum())
    increments, advance = [], rp._advance
    monkeypatch.setattr(rp, "_advance", lambda *a, **kw: increments.append(a[3]) or advance(*a, **kw))
    lam, theta = reference_section_onset(system, mesh, sol)
    monkeypatch.undo()
    # the bracket [0.6, 0.7] of the path's increments bisected to SLIDE_TOL: ceil(log2(0.1 / 1e-4)) = 10 states
    assert len(increments) == 10
    groups, _ = azimuth_groups(system, mesh)
    lo = max(v for v in sol.load_factor[sol.step == 2] if v < lam)
    assert lo < lam - SLIDE_TOL                      # the check below restarts from the same stored state
    assert not _open_along_path(system, sol, groups, lam - SLIDE_TOL)
    assert _open_along_path(system, sol, groups, lam + SLIDE_TOL)
    assert lam == pytest.approx(0.602046, abs=SLIDE_TOL) and theta == 0.0    # the former search's 1e-9 answer


def test_a_path_independent_law_keeps_no_states():
    model = load(None, ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1"])
    mesh, system = condense_model(model)
    _, _, sol = solve_system(model, mesh, system, "lagrange", recover=False)
    assert sol.path_states is None
    lam, _ = reference_section_onset(system, mesh, sol)
    groups, _ = azimuth_groups(system, mesh)
    assert not _open_along_path(system, sol, groups, lam - 1e-6) and _open_along_path(system, sol, groups, lam + 1e-6)
