"""Coulomb friction in the reference solver (issue 14) against independent truths: the gross-slip load
mu N of a rigid-topped skirt, the balance of forces, the Coulomb cone, non-negative dissipation, and a
single hexahedron on a table whose stick/slip history is solved by hand."""

from functools import lru_cache

import numpy as np
import pytest

import reference_solver as rs
from deckbridge.mesh import build_mesh
from deckbridge.model import ModelError, load
from deckbridge.solve import build_problem

MU = 0.3
SKIRT = ("mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1", "load_introduction=kinematic", "contact.stop.side=none",
         "loads.M=0", "contact.tangential=friction", f"contact.friction={MU}")


@lru_cache(maxsize=None)
def _skirt():
    model = load(None, list(SKIRT))
    return model, rs.condense(build_problem(model, build_mesh(model)))


@lru_cache(maxsize=None)
def _skirt_path(method):
    """Shear T alone (with N): lambda up to 5, beyond the closed-form gross slip at mu N / T = 4.05."""
    model, system = _skirt()
    return rs.solve_path(system, method, base={"N": 1.0}, ramp={"T": 1.0}, lambda_max=5.0, increments=10,
                         on_gross_slip="stop", recover=False)


# ----------------------------------------------------------------------------- (a) gross slip at mu N
@pytest.mark.parametrize("method", ["penalty", "lagrange"])
def test_rigid_topped_skirt_slides_at_mu_times_n(method):
    """Closed form: with N and a growing shear T (M = 0, no stop) the base slides when T = mu N."""
    model, _ = _skirt()
    sol = _skirt_path(method)
    expected = MU * model.loads.N / model.loads.T
    assert sol.gross_slip_load_factor is not None
    assert abs(sol.gross_slip_load_factor - expected) <= 0.01 * expected
    assert sol.load_factor[-1] < expected <= sol.load_factor[-1] + 0.5 + 1e-12
    assert np.all(np.isfinite(sol.tangential_force)) and np.all(np.isfinite(sol.force))


@pytest.mark.parametrize("method", ["penalty", "lagrange"])
def test_beyond_gross_slip_the_solver_says_the_load_slides_the_body(method):
    _, system = _skirt()
    with pytest.raises(rs.GrossSlip, match="the load slides the body") as err:
        rs.solve_path(system, method, base={"N": 1.0}, ramp={"T": 1.0}, lambda_max=5.0, increments=10,
                      recover=False)
    assert "\n" not in str(err.value)
    assert isinstance(err.value, rs.ReferenceSolverError)


# ----------------------------------------------------------------------------- (b) balance, cone, dissipation
@pytest.mark.parametrize("method", ["penalty", "lagrange"])
def test_tangential_forces_balance_the_shear_and_stay_in_the_cone(method):
    model, _ = _skirt()
    sol = _skirt_path(method)
    T = sol.load_factor * model.loads.T                       # applied shear along -x (azimuth 0)
    ft = sol.tangential_force.sum(axis=1)                     # force of the table on the body [N]
    step2 = sol.step == 2
    assert np.all(np.abs(ft[step2, 0] - T[step2]) <= 1e-9 * np.maximum(T[step2], model.loads.T))
    assert np.all(np.abs(ft[:, 1:]) <= 1e-9 * model.loads.T)
    stick = np.array([not np.any(s == "slip") for s in sol.stick_status])
    assert not stick[-1]                                      # rows slip before the body slides
    fn = np.maximum(sol.force, 0.0)
    tn = np.linalg.norm(sol.tangential_force, axis=2)
    assert np.all(tn <= MU * fn * (1 + 1e-9) + 1e-8 * fn.max())
    assert np.all(sol.dissipation >= -1e-12 * model.loads.N * np.abs(sol.u).max())
    assert sol.dissipation[-1] > 0


# ----------------------------------------------------------------------------- (c) one hexahedron by hand
def _hexahedron(E=1.0e14, k=1.0e6, N=1.0e3, nu=0.3):
    """Unit cube on a table: 4 slave nodes at z = 0, rigid top (kinematic) loaded at its centre (h = 1)."""
    nodes = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
    p = rs.Problem(
        nodes=nodes, hexes=np.arange(8)[None, :], E=E, nu=nu, element="c3d8",
        contact_nodes=np.arange(4), contact_normals=np.tile([0.0, 0.0, 1.0], (4, 1)), contact_area=np.full(4, 0.25),
        contact_k=np.full(4, k), contact_clearance=np.zeros(4), contact_surface=["table"] * 4,
        spring_nodes=np.zeros(0, int), spring_dirs=np.zeros((0, 3)), spring_k=np.zeros(0),
        ref_point=[0.5, 0.5, 1.0], coupling="kinematic", coupling_nodes=np.arange(4, 8), coupling_weights=np.ones(4),
        loads={"N": (0, 0, -N, 0, 0, 0), "T": (N, 0, 0, 0, 0, 0)}, k_open_ratio=1e-12,
        tangential="friction", friction=MU, contact_kt=np.full(4, k))
    return rs.condense(p)


def test_single_hexahedron_stick_slip_history_matches_the_hand_solution():
    """Hand solution (penalty, a block much stiffer than its springs: a rigid body on 4 springs).

    Cube of side 1 (half-width a = 0.5) on 4 normal springs k and 4 tangential springs k_t = k at its
    base corners, loaded at the top centre (height h = 1) by N down and T = lambda N along +x.
    Moments about the base centre: the normal forces are linear in x, p = N/4 -+ h T / (4 a) = N/4 -+ T/2
    at x = 0 ('low' nodes) and x = 1 ('high' nodes); the tangential forces act in the base plane and
    carry no moment about y. A rigid body moves all base nodes alike along x by u, so in stick each
    node carries t = k_t u = T/4 (the table pushes along -x).
    - The low nodes slip when T/4 = mu (N/4 - T/2): T_s = mu N / (1 + 2 mu) = 0.1875 N (mu = 0.3).
    - Then t_low = mu p_low(T), t_high = T/2 - t_low (stick while <= mu p_high); the body slides when
      T = mu (p_low + p_high) * 2 = mu N = 0.3 N.
    - Load to T1 = 0.25 N: p_low = 0.125 N, t_low = 0.0375 N (slip), t_high = 0.0875 N (stick,
      below mu p_high = 0.1125 N), u = t_high / k_t.
    - Unload to 0: every node sticks again (elastic), each t falls by T1/4 = 0.0625 N: residual
      t_low = -0.025 N, t_high = +0.025 N (inside the cone mu N/4 = 0.075 N), residual displacement
      u = 0.025 N / k_t and accumulated slip of the low nodes 0.05 N / k_t.
    Loading only to T = 0.15 N < T_s and back leaves no tangential force at all.
    """
    N, k = 1.0e3, 1.0e6
    system = _hexahedron(N=N, k=k)
    low = system.problem.nodes[system.problem.contact_nodes, 0] < 0.5
    sol = rs.solve_path(system, "penalty", base={"N": 1.0}, ramp={"T": 1.0}, targets=[0.25, 0.0],
                        increments=10, recover=False)
    top = int(np.flatnonzero(np.isclose(sol.load_factor, 0.25))[0])
    fx = sol.tangential_force[:, :, 0]                        # table on node, along x [N]
    tol = 1e-6 * N
    assert np.allclose(sol.force[top], np.where(low, 0.125 * N, 0.375 * N), atol=tol)
    assert np.allclose(fx[top], np.where(low, -0.0375 * N, -0.0875 * N), atol=tol)
    assert list(sol.stick_status[top]) == ["slip" if lo else "stick" for lo in low]
    assert np.allclose(fx[-1], np.where(low, 0.025 * N, -0.025 * N), atol=tol)      # the residual state
    assert np.allclose(sol.force[-1], 0.25 * N, atol=tol)
    assert set(sol.stick_status[-1]) == {"stick"}
    x_ref = system.problem.contact_nodes
    u_res = sol.retained_u[-1][system.tdofs[:, 0]] * system.tdir[:, 0, 0] + \
        sol.retained_u[-1][system.tdofs[:, 1]] * system.tdir[:, 1, 0]             # x displacement of the base
    assert np.allclose(u_res, 0.025 * N / k, rtol=1e-5) and x_ref.size == 4
    slip_x = sol.slip_increment[:, :, 0].sum(axis=0)
    assert np.allclose(slip_x, np.where(low, 0.05 * N / k, 0.0), atol=1e-6 * N / k)
    first = sol.load_factor[np.array([np.any(s == "slip") for s in sol.stick_status])].min()
    assert 0.1875 <= first <= 0.1875 + 0.025 + 1e-12                               # first slip within the bracket
    assert np.all(sol.dissipation >= -1e-15) and sol.dissipation.sum() > 0
    below = rs.solve_path(system, "penalty", ramp={"T": 1.0}, targets=[0.15, 0.0], increments=6, recover=False)
    assert np.abs(below.tangential_force[-1] - below.tangential_force[0]).max() <= 1e-9 * N   # back to step 1
    assert np.abs(below.tangential_force[0]).max() <= 1e-5 * N                             # (Poisson, E/k = 1e8)
    assert not np.any(below.stick_status == "slip")


def test_lagrange_loading_and_unloading_leaves_a_residual_tangential_state_after_slip():
    """Elastic block (Lagrange, exact stick, nu = 0: no Poisson forces under N): after slip, unloading
    to T = 0 leaves self-balanced tangential forces inside the cone; without slip, nothing is left."""
    N = 1.0e3
    system = _hexahedron(E=2.0e8, N=N, nu=0.0)
    sol = rs.solve_path(system, "lagrange", ramp={"T": 1.0}, targets=[0.28, 0.0], increments=7, recover=False)
    assert np.any(sol.stick_status == "slip")
    res = sol.tangential_force[-1]
    assert np.abs(res).max() > 1e-3 * N                       # a residual state ...
    assert np.abs(res.sum(axis=0)).max() <= 1e-9 * N          # ... that balances itself
    assert np.all(np.linalg.norm(res, axis=1) <= MU * sol.force[-1] * (1 + 1e-9) + 1e-9 * N)
    assert np.all(sol.dissipation >= -1e-12 * N)
    small = rs.solve_path(system, "lagrange", ramp={"T": 1.0}, targets=[0.02, 0.0], increments=2, recover=False)
    assert not np.any(small.stick_status == "slip")
    assert np.abs(small.tangential_force[-1]).max() <= 1e-9 * N


def test_penalty_friction_tends_to_the_lagrange_answer_as_k_grows():
    """Same increments (path), k_n and k_t times 1e3 and 1e5: the error falls like 1/k."""
    model, system = _skirt()
    kw = dict(base={"N": 1.0}, ramp={"T": 1.0}, lambda_max=2.0, increments=4, recover=False)
    lag = rs.solve_path(system, "lagrange", **kw)
    err = []
    for kf in (1.0e3, 1.0e5):
        pen = rs.solve_path(system, "penalty", kf, **kw)
        err.append([np.abs(pen.tangential_force[i] - lag.tangential_force[i]).max()
                    / np.abs(lag.tangential_force[i]).max() for i in (0, -1)])
    err = np.array(err)
    assert err[1, 0] <= 1e-4 and err[1, 1] <= 0.02
    assert np.all(err[1] < 0.1 * err[0])


# ----------------------------------------------------------------------------- model
def test_model_tangential_friction_needs_mu_and_default_is_springs():
    assert load(None).contact.tangential == "springs"
    with pytest.raises(ModelError, match="contact.friction"):
        load(None, ["contact.tangential=friction"])
    with pytest.raises(ModelError, match="contact.tangential"):
        load(None, ["contact.tangential=glue"])
    m = load(None, ["contact.penalty.k_tangent=follow"])
    assert m.contact.penalty.k_tangent is None and m.contact.penalty.k_tangent_follows
    fixed = load(None, ["contact.penalty.k_tangent=2.5e8"]).contact.penalty
    assert fixed.k_tangent == 2.5e8 and not fixed.k_tangent_follows
    p = build_problem(load(None, list(SKIRT)))
    assert p.n_springs == 0 and p.tangential == "friction" and p.friction == MU


@pytest.mark.parametrize("method,surfaces", [("penalty", ("table", "stop")), ("lagrange", ("table",))])
def test_reactions_balance_the_loads_with_friction_at_table_and_stop(method, surfaces):
    """Distributing top, radial stop (frictionless, or with friction too): the inner base nodes sit on
    both masters, their radial axis is the stop's normal and carries no table friction."""
    import dataclasses
    model = load(None, ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1", "contact.tangential=friction",
                        f"contact.friction={MU}"])
    p = build_problem(model)
    p = rs.Problem(**{**{f.name: getattr(p, f.name) for f in dataclasses.fields(p)},
                      "friction_surfaces": surfaces})
    system = rs.condense(p)
    sol = rs.solve_path(system, method, lambda_max=1.0, increments=10, recover=False)
    loads = np.array([p.loads[n] for n in system.case_names])
    arm = p.nodes[p.contact_nodes] - p.ref_point
    for i in range(sol.step.size):
        applied = sol.coeffs[i] @ loads
        f = sol.force[i][:, None] * p.contact_normals + sol.tangential_force[i]
        assert np.allclose(f.sum(0), -applied[:3], atol=1e-9 * model.loads.N)
        assert np.allclose(np.cross(arm, f).sum(0), -applied[3:], atol=1e-9 * model.loads.N * model.geometry.height)
    assert sol.friction_check(p, MU)["violations"] == 0
    assert np.all(sol.dissipation >= -1e-12 * model.loads.N * np.abs(sol.u).max())
    assert sol.liftoff_load_factor is not None
