"""Reference solver against independent anchors: patch test, beam theory, statics, closed forms of
REFERENCE.md section 3, complementarity, and penalty -> Lagrange as k grows."""

from functools import lru_cache

import numpy as np
import pytest
import scipy.sparse.linalg as spla

import reference_solver as rs
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.solve import build_problem
from reference_solver.elements import centroid_strain


# ----------------------------------------------------------------------------- helpers
def _box(nx, ny, nz, lx, ly, lz):
    """Structured box of hexahedra in C3D8 order."""
    x, y, z = (np.linspace(0, lx, nx + 1), np.linspace(0, ly, ny + 1), np.linspace(0, lz, nz + 1))
    X, Y, Z = np.meshgrid(x, y, z, indexing="ij")
    nodes = np.stack([X.ravel(), Y.ravel(), Z.ravel()], 1)
    idx = lambda i, j, k: (i * (ny + 1) + j) * (nz + 1) + k  # noqa: E731
    I, J, K = (a.ravel() for a in np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij"))
    hexes = np.stack([idx(I, J, K), idx(I + 1, J, K), idx(I + 1, J + 1, K), idx(I, J + 1, K),
                      idx(I, J, K + 1), idx(I + 1, J, K + 1), idx(I + 1, J + 1, K + 1), idx(I, J + 1, K + 1)], 1)
    return nodes, hexes


def _dirichlet(K, fixed, ufix, f=None):
    n = K.shape[0]
    free = np.setdiff1d(np.arange(n), fixed)
    u = np.zeros(n)
    u[fixed] = ufix
    rhs = -K[free][:, fixed] @ ufix + (0.0 if f is None else f[free])
    u[free] = spla.spsolve(K[free][:, free].tocsc(), rhs)
    return u


@lru_cache(maxsize=None)
def _system(*overrides):
    model = load(None, list(overrides))
    return model, rs.condense(build_problem(model, build_mesh(model)))


def _applied(system, coeffs):
    """Applied force and moment about the reference point for load-case coefficients."""
    loads = np.array([system.problem.loads[n] for n in system.case_names])   # (ncase, 6)
    v = coeffs @ loads
    return v[:3], v[3:]


def _reactions(p, sol, i):
    f = sol.force[i][:, None] * p.contact_normals
    fs = sol.spring_force[i][:, None] * p.spring_dirs
    F = f.sum(0) + fs.sum(0)
    M = (np.cross(p.nodes[p.contact_nodes] - p.ref_point, f).sum(0)
         + np.cross(p.nodes[p.spring_nodes] - p.ref_point, fs).sum(0))
    return F, M


def _beam_sigma(model, lam, theta_deg):
    """sigma_N = -N/(2 pi R t) + M_b cos(theta - azimuth)/(pi R^2 t), M_b = lam (M + T H)."""
    g = model.geometry
    th = np.radians(theta_deg - model.loads.azimuth)
    return (-model.loads.N / (2 * np.pi * g.radius * g.thickness)
            + lam * model.base_moment * np.cos(th) / (np.pi * g.radius ** 2 * g.thickness))


def _e_over_r(a):
    """REFERENCE.md section 3: e/R against the contact half-angle a of a rigid ring."""
    return (a - np.sin(a) * np.cos(a)) / (2 * (np.sin(a) - a * np.cos(a)))


SMALL = ("mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1")


# ----------------------------------------------------------------------------- elements
@pytest.mark.parametrize("element", ["c3d8", "c3d8i"])
def test_patch_test_reproduces_a_linear_field_on_distorted_hexahedra(element):
    nodes, hexes = _box(2, 2, 2, 1.0, 1.0, 1.0)
    nodes = nodes + 0.08 * np.random.default_rng(1).uniform(-1, 1, nodes.shape)
    A = np.array([[1e-3, 2e-3, -1e-3], [0.5e-3, -2e-3, 1e-3], [3e-3, 1e-3, 1.5e-3]])
    exact = nodes @ A.T + np.array([1e-3, -2e-3, 0.5e-3])
    K = rs.assemble_stiffness(nodes, hexes, 1.0, 0.3, element).tocsr()
    inner = np.flatnonzero(np.all(np.abs(nodes - 0.5) < 0.3, axis=1))
    assert inner.size == 1
    fixed = (3 * np.setdiff1d(np.arange(len(nodes)), inner)[:, None] + np.arange(3)).ravel()
    u = _dirichlet(K, fixed, exact.ravel()[fixed]).reshape(-1, 3)
    np.testing.assert_allclose(u, exact, atol=1e-14)
    eps = centroid_strain(nodes[hexes], u[hexes].reshape(-1, 24))
    E = 0.5 * (A + A.T)
    np.testing.assert_allclose(eps, np.tile([E[0, 0], E[1, 1], E[2, 2], 2 * E[0, 1], 2 * E[1, 2], 2 * E[2, 0]],
                                            (len(hexes), 1)), atol=1e-14)


def test_incompatible_modes_bend_like_a_beam_where_full_integration_locks():
    """Cantilever L/h = 20, one element through the thickness, tip load: Timoshenko beam deflection."""
    L, h, b, E, P = 2.0, 0.1, 0.1, 210e9, 1000.0
    nodes, hexes = _box(10, 1, 1, L, b, h)
    exact = P * L ** 3 / (3 * E * b * h ** 3 / 12) + P * L / (5 / 6 * E / 2 * b * h)
    clamp, tip = np.flatnonzero(nodes[:, 0] < 1e-9), np.flatnonzero(nodes[:, 0] > L - 1e-9)
    fixed = (3 * clamp[:, None] + np.arange(3)).ravel()
    ratio = {}
    for element in ("c3d8i", "c3d8"):
        K = rs.assemble_stiffness(nodes, hexes, E, 0.0, element).tocsr()
        f = np.zeros(K.shape[0])
        f[3 * tip + 2] = -P / tip.size
        u = _dirichlet(K, fixed, np.zeros(fixed.size), f).reshape(-1, 3)
        ratio[element] = -u[tip, 2].mean() / exact
    assert ratio["c3d8i"] == pytest.approx(1.0, abs=0.015)
    assert ratio["c3d8"] < 0.4          # shear locking: a third of the deflection


def test_element_stiffness_has_exactly_six_rigid_modes():
    nodes, hexes = _box(1, 1, 1, 2.0, 1.0, 0.5)
    xyz = nodes[hexes] + 0.05 * np.random.default_rng(3).standard_normal((1, 8, 3))
    w = np.linalg.eigvalsh(rs.hex8_stiffness(xyz, 1.0, 0.3)[0])
    assert np.sum(np.abs(w) < 1e-10 * w.max()) == 6 and w.min() > -1e-10 * w.max()


# ----------------------------------------------------------------------------- load introduction
def test_distributing_forces_are_statically_equivalent():
    rng = np.random.default_rng(7)
    xyz = rng.uniform(-1, 1, (30, 3)) + [0, 0, 2]
    w = rng.uniform(0.1, 2.0, 30)
    ref = np.array([0.1, -0.2, 2.5])
    F, M = np.array([1e5, -2e5, -3e6]), np.array([4e6, -1e6, 2e5])
    f = rs.distributing_forces(xyz, w, ref, F, M)
    np.testing.assert_allclose(f.sum(0), F, rtol=0, atol=1e-9 * np.abs(F).max())
    np.testing.assert_allclose(np.cross(xyz - ref, f).sum(0), M, rtol=0, atol=1e-9 * np.abs(M).max())


def test_kinematic_coupling_keeps_the_top_ring_rigid():
    model, system = _system(*SMALL, "load_introduction=kinematic")
    sol = rs.solve_path(system, "penalty", increments=2)
    p = system.problem
    u = sol.fields[2]
    top = p.nodes[p.coupling_nodes] - p.ref_point
    # fit u = a + w x d on the top nodes by least squares; the residual must vanish
    A = np.zeros((3 * top.shape[0], 6))
    for k, d in enumerate(top):
        A[3 * k:3 * k + 3, :3] = np.eye(3)
        A[3 * k:3 * k + 3, 3:] = [[0, d[2], -d[1]], [-d[2], 0, d[0]], [d[1], -d[0], 0]]
    b = u[p.coupling_nodes].ravel()
    res = b - A @ np.linalg.lstsq(A, b, rcond=None)[0]
    assert np.abs(res).max() < 1e-12 * np.abs(b).max()


# ----------------------------------------------------------------------------- equilibrium
@pytest.mark.parametrize("intro", ["distributing", "kinematic"])
@pytest.mark.parametrize("method", ["penalty", "lagrange"])
def test_reactions_balance_the_applied_loads_at_every_increment(method, intro):
    model, system = _system(*SMALL, f"load_introduction={intro}")
    sol = rs.solve_path(system, method, lambda_max=1.0, increments=5, recover=False)
    assert sol.liftoff_load_factor is not None          # the path crosses liftoff: contact states change
    scale = model.loads.N
    for i in range(sol.step.size):
        F, M = _applied(system, sol.coeffs[i])
        RF, RM = _reactions(system.problem, sol, i)
        np.testing.assert_allclose(RF + F, 0.0, atol=1e-8 * scale)
        np.testing.assert_allclose(RM + M, 0.0, atol=1e-8 * scale * model.geometry.radius)


# ----------------------------------------------------------------------------- beam theory
@pytest.mark.parametrize("method", ["penalty", "lagrange"])
def test_full_contact_matches_beam_theory_on_the_default_mesh(method):
    """Default 72x30x2 mesh, lambda up to 0.5 (liftoff is near 0.57): within 2 % of the peak."""
    model, system = _system("steps.lambda_max=0.5", "steps.increments=2")
    sol = rs.solve_path(system, method, lambda_max=0.5, increments=2, recover=False)
    p = system.problem
    table = p.contact_surface == "table"
    theta = np.degrees(np.arctan2(p.nodes[p.contact_nodes, 1], p.nodes[p.contact_nodes, 0]))[table]
    for i in range(sol.step.size):
        beam = _beam_sigma(model, sol.load_factor[i], theta)
        err = np.abs(sol.sigma_n[i, table] - beam).max()
        assert err < 0.02 * np.abs(beam).max(), (i, err / np.abs(beam).max())
        assert sol.closed[i, table].all()


# ----------------------------------------------------------------------------- rigid top on springs
KIN = ("mesh.n_theta=48", "mesh.n_z=12", "mesh.n_r=1", "load_introduction=kinematic", "loads.T=0")


def test_kinematic_penalty_liftoff_at_the_kern_for_any_k():
    """Liftoff at M_b = N R / 2 (REFERENCE.md section 3), whatever the penalty stiffness."""
    model, system = _system(*KIN, "loads.M=3.4e6")
    expected = model.loads.N * model.geometry.radius / 2 / model.base_moment
    found = [rs.solve_path(system, "penalty", kf, increments=10, recover=False, liftoff_surface="table").liftoff_load_factor
             for kf in (0.1, 1.0, 10.0)]
    for lf in found:
        assert lf == pytest.approx(expected, rel=0.02)
    assert max(found) - min(found) < 0.005 * expected


def test_kinematic_penalty_bisected_liftoff_matches_the_linear_onset():
    """Before liftoff the response is linear in lambda: the exact onset is min(-g0/g1) over the nodes."""
    model, system = _system(*KIN, "loads.M=3.4e6", "contact.stop.side=none")
    p = system.problem
    kf = 1.0
    sol = rs.solve_path(system, "penalty", kf, increments=10, recover=False)
    k = kf * p.contact_k
    g0, _ = rs.penalty_solve(system.Sc, system.fc @ system.coeffs({"N": 1}), k, 1e-6 * k, p.contact_clearance)
    g1, _ = rs.penalty_solve(system.Sc, system.fc @ system.coeffs({"M": 1}), k, k, p.contact_clearance)
    onset = np.min(-g0[g1 > 0] / g1[g1 > 0])
    assert sol.liftoff_load_factor == pytest.approx(onset, abs=2e-6)


@pytest.mark.parametrize("method", ["penalty", "lagrange"])
def test_path_following_onset_agrees_with_bisection(method):
    model, system = _system(*SMALL)
    exact = rs.solve_path(system, method, increments=4, recover=False, liftoff_surface="table")
    bis = rs.solve_path(system, method, increments=4, recover=False, onset="bisection", liftoff_tol=1e-7,
                        liftoff_surface="table")
    assert exact.liftoff_method == "path-following" and bis.liftoff_method == "bisection"
    assert bis.liftoff_load_factor - 1e-7 <= exact.liftoff_load_factor <= bis.liftoff_load_factor
    assert exact.liftoff_row == bis.liftoff_row


def test_kinematic_penalty_past_liftoff_follows_the_rigid_ring_closed_form():
    """e/R against the contact half-angle a within 2 %, and sigma_N(theta) independent of k."""
    model, system = _system(*KIN, "loads.M=1.0e7")
    p = system.problem
    R, t = model.geometry.radius, model.geometry.thickness
    table = np.flatnonzero(p.contact_surface == "table")
    xy = p.nodes[p.contact_nodes[table], :2]
    theta = np.mod(np.arctan2(xy[:, 1], xy[:, 0]), 2 * np.pi)
    r = np.hypot(xy[:, 0], xy[:, 1])
    sols = {kf: rs.solve_path(system, "penalty", kf, lambda_max=0.38, increments=19, recover=False)
            for kf in (0.01, 0.1)}
    checked = 0
    for i in np.flatnonzero(sols[0.1].load_factor > 0.21):
        lam = sols[0.1].load_factor[i]
        e = lam * model.base_moment / (model.loads.N * R)
        for kf, sol in sols.items():
            angles = []
            for rv in np.unique(np.round(r, 9)):      # compressed side is theta = 180 deg
                sel = np.isclose(r, rv) & (theta <= np.pi)
                phi = np.pi - theta[sel]
                gap = sol.gap[i, table][sel]
                o = np.argsort(phi)
                phi, gap = phi[o], gap[o]
                j = np.flatnonzero(gap > 0)[0]
                angles.append(phi[j - 1] + (phi[j] - phi[j - 1]) * (-gap[j - 1]) / (gap[j] - gap[j - 1]))
            a = np.mean(angles)
            assert _e_over_r(a) == pytest.approx(e, rel=0.02), (kf, lam)
            # closed-form pressure of the rigid ring: -N (cos phi - cos a) / (2 R t (sin a - a cos a))
            phi_all = np.abs(np.pi - theta)
            cf = -model.loads.N * np.clip(np.cos(phi_all) - np.cos(a), 0, None) / (
                2 * R * t * (np.sin(a) - a * np.cos(a)))
            assert np.abs(sol.sigma_n[i, table] - cf).max() < 0.03 * np.abs(cf).max(), (kf, lam)
            checked += 1
        d = np.abs(sols[0.01].sigma_n[i, table] - sols[0.1].sigma_n[i, table]).max()
        assert d < 0.02 * np.abs(sols[0.1].sigma_n[i, table]).max()
    assert checked >= 16


# ----------------------------------------------------------------------------- Lagrange
def test_lagrange_no_penetration_no_tension_complementarity():
    model, system = _system(*SMALL)
    sol = rs.solve_path(system, "lagrange", increments=5, recover=False)
    assert sol.liftoff_load_factor is not None and (~sol.closed[-1]).sum() > 5
    scale = np.abs(sol.force).max()
    assert sol.gap.min() >= -1e-10
    assert sol.force.min() >= -1e-10 * scale
    assert sol.sigma_n.max() <= 0.0
    assert np.abs(sol.force * sol.gap).max() <= 1e-12 * scale * np.abs(sol.gap).max()
    # open rows carry nothing, closed rows have zero gap
    assert np.all(sol.force[~sol.closed] == 0) and np.all(sol.gap[sol.closed] == 0)


def test_gauss_seidel_and_active_set_agree():
    model, system = _system(*SMALL)
    kw = dict(lambda_max=0.6, increments=3, recover=False)     # liftoff near 0.54: past it at 0.6
    exact = rs.solve_path(system, "lagrange", algorithm="active-set", **kw)
    gs = rs.solve_path(system, "lagrange", algorithm="gauss-seidel", **kw)
    assert (~exact.closed[-1]).any()
    peak = np.abs(exact.sigma_n).max()
    assert np.abs(gs.sigma_n - exact.sigma_n).max() <= 1e-8 * peak
    assert np.abs(gs.gap - exact.gap).max() <= 1e-8 * np.abs(exact.gap).max()
    assert np.array_equal(gs.closed, exact.closed)
    assert gs.liftoff_load_factor == pytest.approx(exact.liftoff_load_factor, abs=1e-6)


def test_primal_and_primal_dual_active_sets_agree_on_random_lcps():
    rng = np.random.default_rng(11)
    for _ in range(20):
        A = rng.standard_normal((30, 30))
        S = A @ A.T + 0.1 * np.eye(30)
        q = rng.standard_normal(30)
        g1, _ = rs.lcp_active_set(S, q)
        g2, _ = rs.contact.lcp_primal_active_set(S, q)
        w = S @ g1 + q
        assert g1.min() >= 0 and w.min() >= -1e-10 and np.abs(g1 * w).max() < 1e-10
        np.testing.assert_allclose(g1, g2, atol=1e-10)


def test_penalty_tends_to_lagrange_as_k_grows():
    model, system = _system(*SMALL, "contact.penalty.open_ratio=1e-12")
    kw = dict(increments=5, recover=False)
    lag = rs.solve_path(system, "lagrange", **kw)
    peak = np.abs(lag.sigma_n).max()
    diffs = [np.abs(rs.solve_path(system, "penalty", kf, **kw).sigma_n - lag.sigma_n).max()
             for kf in (1, 10, 100, 1000, 10000)]
    assert all(b < a for a, b in zip(diffs, diffs[1:])), diffs
    assert diffs[-1] < 0.01 * peak


# ----------------------------------------------------------------------------- solvers and reuse
def test_trailing_schur_and_rhs_schur_with_superlu_agree():
    model = load(None, list(SMALL))
    p = build_problem(model, build_mesh(model))
    a = rs.condense(p, schur="trailing")
    b = rs.condense(p, factorize=rs.splu_factorize, schur="rhs")
    np.testing.assert_allclose(a.Sc, b.Sc, atol=1e-9 * np.abs(a.Sc).max())
    np.testing.assert_allclose(a.fc, b.fc, atol=1e-9 * np.abs(a.fc).max())
    sa = rs.solve_path(a, "penalty", increments=2)
    sb = rs.solve_path(b, "penalty", increments=2)
    np.testing.assert_allclose(sa.fields[2], sb.fields[2], atol=1e-9 * np.abs(sa.fields[2]).max())


def test_recovered_field_reproduces_the_contact_displacements():
    model, system = _system(*SMALL)
    sol = rs.solve_path(system, "lagrange", increments=3)
    p = system.problem
    for s, u in sol.fields.items():
        last = np.flatnonzero(sol.step == s)[-1]
        un = np.einsum("ij,ij->i", u[p.contact_nodes], p.contact_normals)
        np.testing.assert_allclose(un, sol.u[last], atol=1e-12 * np.abs(u).max())
    vm = rs.element_von_mises(p, sol.fields[1])
    # step 1 is nearly uniform compression: von Mises about N / (2 pi R t) away from the ends
    g = model.geometry
    mid = (p.nodes[p.hexes].mean(1)[:, 2] > 0.3 * g.height) & (p.nodes[p.hexes].mean(1)[:, 2] < 0.7 * g.height)
    assert np.median(vm[mid]) == pytest.approx(model.loads.N / (2 * np.pi * g.radius * g.thickness), rel=0.02)


def test_friction_check_counts_tangential_forces_beyond_mu_times_normal():
    model, system = _system(*SMALL)
    sol = rs.solve_path(system, "lagrange", increments=2, recover=False)
    p = system.problem
    fn = np.zeros(p.n_nodes)                    # normal force of every contact row at the spring's node
    np.add.at(fn, p.contact_nodes, sol.force[-1])
    fn, ft = fn[p.spring_nodes], np.abs(sol.spring_force[-1])
    lifted = (fn <= 0) & (ft > 1e-9 * ft.max())  # a lifted node cannot carry a tangential force
    assert lifted.any() and (~lifted).any()
    ratio = ft[fn > 0] / fn[fn > 0]
    mu = float(np.median(ratio))
    report = sol.friction_check(p, mu)
    assert report["violations_last_increment"] == int(np.sum(ratio > mu * (1 + 1e-9)) + lifted.sum())
    assert sol.friction_check(p, 10 * ratio.max())["violations_last_increment"] == lifted.sum()


# ----------------------------------------------------------------------------- bad problems
def _problem(**changes):
    model = load(None, list(SMALL))
    p = build_problem(model, build_mesh(model))
    fields = {f: getattr(p, f) for f in p.__dataclass_fields__ if f != "extra"}
    fields.update(changes)
    return rs.Problem(**fields)


def test_mechanism_without_tangential_restraint_is_reported():
    model = load(None, list(SMALL) + ["contact.stop.side=none"])
    p = build_problem(model, build_mesh(model))
    p = rs.Problem(**{**{f: getattr(p, f) for f in p.__dataclass_fields__ if f != "extra"},
                      "spring_k": np.zeros(p.n_springs)})
    with pytest.raises(rs.ReferenceSolverError, match=r"^mechanism: .*rotation z"):
        rs.condense(p)


def test_load_lifting_the_body_means_no_contact_possible():
    p = _problem(loads={"N": (0, 0, 1e6, 0, 0, 0), "T": (0,) * 6, "M": (0,) * 6})
    system = rs.condense(p)
    with pytest.raises(rs.ReferenceSolverError, match=r"^no contact possible"):
        rs.solve_path(system, "lagrange")
    with pytest.raises(rs.ReferenceSolverError, match=r"^no contact possible"):
        rs.solve_path(system, "penalty")


@pytest.mark.parametrize("method", ["penalty", "lagrange"])
def test_moment_beyond_the_base_tips_the_body_over(method):
    model, system = _system(*SMALL, "loads.M=2.0e7")       # e/R = 4.9 at lambda = 1
    with pytest.raises(rs.ReferenceSolverError, match=r"^step 2, load factor [0-9.]+: the load tips"):
        rs.solve_path(system, method, increments=10)


def test_non_finite_input_is_refused():
    with pytest.raises(rs.ReferenceSolverError, match="E = nan"):
        _problem(E=float("nan"))
    with pytest.raises(rs.ReferenceSolverError, match="contact_area"):
        _problem(contact_area=np.full(_problem().n_contacts, np.nan))
