"""Low-rank penalty solves (reference_solver.shifted) against a direct dense solve."""

import numpy as np
import pytest

from reference_solver.shifted import ShiftedSolver


def _spd(n, seed=0):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    return A @ A.T / n + np.eye(n), rng


def test_states_near_the_reference_are_solved_without_a_new_factorisation():
    S, rng = _spd(60)
    k, k_open = 5.0, 5e-12
    closed = np.ones(60, bool)
    solver = ShiftedSolver(S, max_rank=10)
    for step in range(8):                        # open one more row each time, then close two
        closed[rng.integers(60)] = False
        if step == 5:
            closed[:] = True
            closed[[3, 7]] = False
        D = np.where(closed, k, k_open)
        b = rng.standard_normal(60)
        x = solver.solve(D, b)
        np.testing.assert_allclose(x, np.linalg.solve(S + np.diag(D), b), rtol=1e-10, atol=1e-12)
    assert solver.factorisations == 1 and solver.solves == 8


def test_a_state_far_from_the_reference_refactors_and_not_positive_definite_is_none():
    S, rng = _spd(40, 1)
    solver = ShiftedSolver(S, max_rank=4)
    solver.solve(np.full(40, 2.0), np.ones(40))
    D = np.full(40, 2.0)
    D[:6] = 1e-9                                   # 6 rows changed > max_rank
    np.testing.assert_allclose(solver.solve(D, np.ones(40)), np.linalg.solve(S + np.diag(D), np.ones(40)),
                               rtol=1e-10)
    assert solver.factorisations == 2
    bad = -np.diag(S) - 1.0                        # S + D indefinite
    assert ShiftedSolver(S).solve(bad, np.ones(40)) is None


@pytest.mark.parametrize("flip", [1, 3])
def test_an_indefinite_update_is_caught_by_the_residual_check(flip):
    S, rng = _spd(30, 2)
    solver = ShiftedSolver(S)
    D = np.full(30, 1.0)
    solver.solve(D, np.ones(30))
    D[:flip] = -np.diag(S)[:flip] - 10.0           # the updated matrix is not positive definite
    assert solver.solve(D, np.ones(30)) is None


def test_subsets_near_the_reference_match_direct_solves_of_the_principal_submatrix():
    from reference_solver.shifted import SubsetSolver
    S, rng = _spd(50, 3)
    solver = SubsetSolver(S, max_rank=8)
    open_ = np.zeros(50, bool)
    open_[10:30] = True
    for step in range(10):                         # one row opens or closes per event
        open_[rng.integers(50)] ^= True
        I = np.flatnonzero(open_)
        b = rng.standard_normal(I.size)
        np.testing.assert_allclose(solver.solve(I, b), np.linalg.solve(S[np.ix_(I, I)], b), rtol=1e-10, atol=1e-12)
    assert solver.factorisations <= 2 and solver.solves == 10
    assert solver.solve(np.zeros(0, int), np.zeros(0)).size == 0
