"""Dense blocks of the condensed contact problem (issue 22, memory on any proportions): one nr x nr S, the
contact operator built with one nc x nc array and the same numbers, the recovery unchanged by the springs
added in place, `deckbridge solve` releasing the factor and the dense blocks, and the memory guard counting
at least the dense arrays a solve really holds."""

import numpy as np
import pytest

from deckbridge import limits
from deckbridge.model import load
from reference_solver.condense import condense, contact_operator
from reference_solver.shifted import ShiftedSolver

SMALL = ["mesh.n_theta=24", "mesh.n_z=4", "mesh.n_r=1"]


def _problem(extra=()):
    from deckbridge.mesh import build_mesh
    from deckbridge.solve import build_problem
    m = load(None, SMALL + list(extra))
    return build_problem(m, build_mesh(m))


@pytest.mark.parametrize("nc, ns, block", [(7, 3, 512), (130, 40, 32), (64, 0, 16), (97, 31, 97)])
def test_contact_operator_is_the_symmetrised_difference_bit_for_bit(nc, ns, block):
    rng = np.random.default_rng(nc + ns)
    A = rng.normal(size=(nc + ns, nc + ns))
    S = A @ A.T + (nc + ns) * np.eye(nc + ns)
    Gs = rng.normal(size=(ns, nc))
    ref = S[:nc, :nc] - S[:nc, nc:] @ Gs           # what condense computed before: three temporaries
    ref = 0.5 * (ref + ref.T)
    got = contact_operator(S, nc, Gs, block=block)
    assert np.array_equal(got, ref)
    assert np.array_equal(got, got.T)


def test_one_condensed_stiffness_and_the_recovery_matches_the_other_schur_method():
    """S with the springs is the Schur's own array (no copy); the trailing recovery (S + D0 less the springs
    added in place) gives the displacements of the independent 'rhs' condensation (K_ii factored, K_ir solved)."""
    p = _problem()
    assert p.n_springs > 0
    trailing, rhs = condense(p, schur="trailing"), condense(p, schur="rhs")
    assert trailing.S is trailing.schur.S
    idx = np.arange(p.n_contacts, p.n_contacts + p.n_springs)
    assert np.allclose(trailing.S[idx, idx] - rhs.S[idx, idx], 0.0, atol=1e-9 * np.abs(rhs.S).max())
    rng = np.random.default_rng(3)
    uc = 1e-4 * rng.normal(size=(2, p.n_contacts))
    co = np.array([[1.0, 0.5, 0.2], [1.0, 1.0, 1.0]])[:, :len(trailing.case_names)]
    a, b = trailing.recover(uc, co), rhs.recover(uc, co)
    assert np.abs(a - b).max() <= 1e-8 * np.abs(b).max()


def test_released_system_holds_no_factor_and_no_dense_block():
    from deckbridge.studies.tasks import has_factor
    p = _problem()
    system = condense(p)
    light = system.released()
    assert not has_factor(light) and has_factor(system)
    assert light.S.size == light.Sc.size == light.Gs.size == 0
    assert light.n_contacts == system.n_contacts == p.n_contacts
    with pytest.raises(Exception):
        light.recover(np.zeros(p.n_contacts), np.ones(len(system.case_names)))


@pytest.mark.parametrize("method", ["penalty", "lagrange"])
def test_solve_released_writes_the_same_files(tmp_path, method):
    """`deckbridge solve` releases the factor before writing (api.solve(release=True)): the same contact table
    and VTU data as the solution that keeps it."""
    import meshio

    from deckbridge.api import solve
    from deckbridge.studies.tasks import has_factor
    m = load(None, SMALL)
    kept, light = solve(m, method), solve(m, method, release=True)
    assert has_factor(kept._solved[1]) and not has_factor(light._solved[1])
    assert light.wall_stress() is None
    kept.write(tmp_path / "kept")
    light.write(tmp_path / "light")
    assert (tmp_path / "kept" / "contact.csv").read_text() == (tmp_path / "light" / "contact.csv").read_text()
    for name in ("result.vtu", "result_005.vtu"):
        a, b = meshio.read(tmp_path / "kept" / name), meshio.read(tmp_path / "light" / name)
        for key in a.point_data:
            assert np.array_equal(a.point_data[key], b.point_data[key]), key


def test_the_guard_counts_the_dense_arrays_a_solve_holds():
    """PATH_DENSE_ARRAYS x nr^2 x 8 bytes covers the dense arrays alive beside the factor in `deckbridge solve`
    (S dropped after binding, api.solve(release=True)), counted from the arrays themselves: the Schur step
    (the trailing block L_rr and L_rr L_rr^T), the load path (S_c, G_s, the path's dense factor of S_c + D),
    the recovery (S_c, G_s, L_rr re-read); and it is not far above the largest of them."""
    from reference_solver.linalg import trailing_block
    for extra in ([], ["mesh.n_r=2"], ["mesh.n_r=3"]):
        p = _problem(extra)
        system = condense(p)
        nr = p.n_contacts + p.n_springs
        light = system.without_S()
        assert light.S.size == 0 and light.schur.S.size == 0 and not light.schur.recover_uses_S
        solver = ShiftedSolver(light.Sc)
        assert solver.solve(np.full(p.n_contacts, 1e12), np.ones(p.n_contacts)) is not None
        held = light.Sc.nbytes + light.Gs.nbytes
        f = light.schur.recover.__closure__          # the factor, read as the recovery reads it
        factor = next(c.cell_contents for c in f if type(c.cell_contents).__name__ == "Factor")
        Lrr = trailing_block(factor, 3 * p.n_nodes, nr)
        stages = {"schur": 2 * Lrr.nbytes, "path": held + solver.cf[0].nbytes, "recovery": held + Lrr.nbytes}
        assert max(stages.values()) <= limits.PATH_DENSE_ARRAYS * 8 * nr * nr, stages
        assert limits.PATH_DENSE_ARRAYS * 8 * nr * nr <= 1.25 * max(stages.values()), stages
        uc = np.zeros(p.n_contacts)
        co = np.ones(len(system.case_names))
        assert np.array_equal(light.recover(uc, co), system.recover(uc, co))    # the same recovery without S


def test_a_command_that_keeps_the_system_is_estimated_with_its_factor_and_blocks(tmp_path):
    """`deckbridge run` keeps the condensed system (both methods, the report's verdict): its estimate counts S,
    S_c, G_s beside the factor in the VTU stage (checked against those arrays), and the run command is refused
    where `deckbridge solve`, which frees them, is not."""
    from click.testing import CliRunner

    from deckbridge.cli import main
    p = _problem(["mesh.n_r=2"])
    system = condense(p)
    nr = p.n_contacts + p.n_springs
    held = system.S.nbytes + system.Sc.nbytes + system.Gs.nbytes
    assert held <= limits.KEPT_VTU_DENSE_ARRAYS * 8 * nr * nr <= 1.25 * held
    assert held + 8 * nr * nr <= limits.KEPT_PATH_DENSE_ARRAYS * 8 * nr * nr <= 1.25 * (held + 8 * nr * nr)
    m = load(None, SMALL + ["mesh.n_r=2"])
    solve_est, run_est = limits.symbolic_estimate(m), limits.symbolic_estimate(m, released=False)
    assert run_est.parts["vtu"] - solve_est.parts["vtu"] >= limits.FACTOR_BYTES_PER_ENTRY * run_est.factor_entries
    assert run_est.bytes > solve_est.bytes
    mid = 0.5 * (solve_est.bytes + run_est.bytes)
    with pytest.MonkeyPatch.context() as mp:
        mp.delenv(limits.ALLOW_ENV, raising=False)
        mp.setattr(limits, "available_bytes", lambda: mid)
        assert limits.check_memory(m) == pytest.approx(solve_est.bytes)
        with pytest.raises(Exception, match="from its symbolic factorisation"):
            limits.check_memory(m, released=False)
        sets = [a for s in SMALL + ["mesh.n_r=2"] for a in ("--set", s)]
        res = CliRunner().invoke(main, ["run", *sets, "-o", str(tmp_path / "o")])
        assert res.exit_code != 0 and "from its symbolic factorisation" in res.output
