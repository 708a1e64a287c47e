"""The condensation's large-mesh ordering (trailing.LARGE_ORDERING from METIS_MIN_NODES nodes on) gives the
Schur complement of a dense reference, and the memory estimate analyses with that same ordering.

A small default-model mesh is forced through the large-mesh branch (METIS_MIN_NODES = 0). Reference: the
reduced stiffness T^T K T (the sparse path of the condensation, not the node blocks) made dense,
S = K_rr - K_ri K_ii^-1 K_ir and fhat = F_r - K_ri K_ii^-1 F_i by LAPACK (numpy.linalg.solve).
"""

import importlib

import numpy as np
import pytest

import reference_solver as rs
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.solve import build_problem
from reference_solver import estimate, linalg, trailing
from reference_solver.frames import build_dofmap

pytestmark = pytest.mark.skipif(not rs.HAVE_CHOLMOD, reason="needs CHOLMOD")
cond = importlib.import_module("reference_solver.condense")


@pytest.fixture
def forced_large(monkeypatch):
    """The large-mesh branch on any mesh; records each node-graph analysis (n, ordering_method)."""
    calls = []
    analyze = linalg._cholmod.analyze

    def spy(A, **kw):
        calls.append((A.shape[0], kw.get("ordering_method")))
        return analyze(A, **kw)

    monkeypatch.setattr(trailing, "METIS_MIN_NODES", 0)
    monkeypatch.setattr(linalg._cholmod, "analyze", spy)
    return calls


def test_large_mesh_ordering_gives_the_dense_schur_complement(forced_large):
    model = load(None, ["mesh.n_theta=24", "mesh.n_z=12", "mesh.n_r=1"])
    p = build_problem(model, build_mesh(model))
    system = rs.condense(p)
    assert system.info["schur"] == "cholmod-trailing-blocks"
    assert forced_large == [(p.n_nodes, trailing.LARGE_ORDERING)]        # the node graph, large-mesh ordering
    dm = build_dofmap(p)
    K = cond._reduced_stiffness(p, dm, {}).pop().toarray()
    F = cond.load_vectors(p, dm, system.case_names)
    r = np.concatenate([dm.contact_dofs, dm.spring_dofs])
    i = np.setdiff1d(np.arange(K.shape[0]), r)
    X = np.linalg.solve(K[np.ix_(i, i)], np.hstack([K[np.ix_(i, r)], F[i]]))
    S = K[np.ix_(r, r)] - K[np.ix_(r, i)] @ X[:, :r.size]
    fhat = F[r] - K[np.ix_(r, i)] @ X[:, r.size:]
    assert r.size > 50 and 3 * p.n_nodes > 10 * r.size
    # the Schur's own array carries the springs on its spring diagonal (condense: added in place, no copy of S)
    D = system.schur.S - S
    tol = 1e-10 * np.abs(S).max()
    np.testing.assert_allclose(D - np.diag(np.diag(D)), 0.0, rtol=0, atol=tol)
    nc = dm.contact_dofs.size
    np.testing.assert_allclose(np.diag(D)[:nc], 0.0, rtol=0, atol=tol)
    np.testing.assert_allclose(np.sort(np.diag(D)[nc:]), np.sort(p.spring_k), rtol=1e-9, atol=tol)
    np.testing.assert_allclose(system.schur.fhat, fhat, rtol=0, atol=1e-10 * np.abs(fhat).max())


def test_memory_estimate_analyses_with_the_condensation_ordering(forced_large):
    model = load(None, ["mesh.n_theta=24", "mesh.n_z=12", "mesh.n_r=1"])
    p = build_problem(model, build_mesh(model))
    nL = estimate.factor_entries(p.hexes, p.n_nodes)
    assert forced_large == [(p.n_nodes, trailing.LARGE_ORDERING)]
    # an upper bound of the dof factor's entries: at least the lower triangle of K, at most dense
    assert 0.5 * 27 * 3 * p.n_nodes <= nL <= 3 * p.n_nodes * (3 * p.n_nodes + 1) / 2


def test_long_indices_give_the_same_condensation(monkeypatch):
    """Past LONG_INDEX_ENTRIES estimated factor entries the factorisation runs on CHOLMOD's 64-bit version (its
    32-bit one stops with 'problem too large' past 2^31 entries: 1292 x 193 x 3, 3.0M dof): forced on a small
    mesh, the same Schur complement and loads bit for bit, and a factor with 64-bit indices."""
    model = load(None, ["mesh.n_theta=24", "mesh.n_z=12", "mesh.n_r=1"])
    p = build_problem(model, build_mesh(model))
    base = rs.condense(p)
    seen = []
    cholesky = linalg._cholmod.cholesky

    def spy(A, **kw):
        seen.append(kw.get("use_long"))
        return cholesky(A, **kw)

    monkeypatch.setattr(trailing, "LONG_INDEX_ENTRIES", 0)
    monkeypatch.setattr(trailing._cholmod, "cholesky", spy)
    forced = rs.condense(p)
    assert seen == [True] and forced.info["schur"] == "cholmod-trailing-blocks"
    assert np.array_equal(forced.schur.S, base.schur.S) and np.array_equal(forced.schur.fhat, base.schur.fhat)
    assert np.array_equal(forced.Sc, base.Sc)
