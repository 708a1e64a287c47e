"""Coulomb friction on 8-/6-node contact faces: the face-weighted friction law (reference_solver/friction_face.py,
issue 23). No deckbridge import.

A block (1 x 0.8 x 1.2 m, graded, sheared in plan; nu = 0) of 20-node hexahedra or 10-node tetrahedra on a rigid
table with friction (mu = 0.3) under a rigid top (kinematic coupling above the base centroid): N down, then a
shear T along x at the top with the moment T H about the base removed. Independent truths:
- full stick (T = 0.05 N, every row closed and sticking): the base does not move, so the nodal forces (normal and
  tangential) are the clamped base's reactions -f of the condensed load to 1e-10 of N, in either basis;
- force balance at every state: the table's tangential forces sum to -T (1e-9 of T), normal ones to N;
- Coulomb on the multipliers (lambda_t = D^-T r_t, lambda_n = -sigma_N): |lambda_t| <= mu lambda_n;
- gross slip where the closed form says, T = mu N (lambda = 3), reported as the nodal law reports it.
"""

import numpy as np
import pytest

import reference_solver as rs
from element_meshes import block_mesh
from reference_solver.face_law import weighting_matrix

E, L, MU, N, T = 70e9, (1.0, 0.8, 1.2), 0.3, 1.0e6, 1.0e5


def _system(name, weighting):
    nodes, cells = block_mesh(name, nx=2, ny=2, nz=1, L=L, shear=0.3, grade=True)
    base = np.flatnonzero(nodes[:, 2] < 1e-12)
    top = np.flatnonzero(nodes[:, 2] > L[2] - 1e-12)
    nb = base.size
    kw = dict(nodes=nodes, hexes=cells, element=name, E=E, nu=0.0, contact_nodes=base,
              contact_normals=np.tile([0, 0, 1.0], (nb, 1)), contact_area=np.ones(nb), contact_k=np.ones(nb),
              contact_clearance=np.zeros(nb), contact_surface=["table"] * nb, spring_nodes=np.zeros(0, int),
              spring_dirs=np.zeros((0, 3)), spring_k=np.zeros(0), coupling_nodes=top,
              coupling_weights=np.ones(top.size), coupling="kinematic", tangential="friction", friction=MU,
              contact_weighting=weighting, ref_point=[L[0] / 2 + 0.15 * L[1], L[1] / 2, L[2]],   # above the centroid
              loads={"N": [0, 0, -N, 0, 0, 0], "T": [T, 0, 0, 0, -T * L[2], 0]})
    area = np.asarray(weighting_matrix(rs.Problem(**kw)) @ np.ones(nb)).ravel()   # int Phi_a dA
    kw.update(contact_area=area, contact_k=1e12 * area, contact_kt=1e12 * area)   # slope 1e12 Pa/m
    return rs.condense(rs.Problem(**kw))


@pytest.mark.parametrize("weighting", ["face", "face-dual"])
@pytest.mark.parametrize("name", ["c3d20", "c3d10"])
def test_full_stick_is_the_clamped_base(name, weighting):
    s = _system(name, weighting)
    sol = rs.solve_path(s, "lagrange", base={"N": 1.0}, ramp={"T": 1.0}, lambda_max=0.5, increments=1, recover=False)
    assert set(sol.stick_status[-1]) == {"stick"} and sol.closed[-1].all()
    f = -(s.fhat @ sol.coeffs[-1])                           # reactions of the clamped base: x = 0
    np.testing.assert_allclose(sol.force[-1], f[:s.n_contacts], rtol=0, atol=1e-10 * N)
    ft = np.zeros((s.n_contacts, 3))
    ft[s.rows] = np.einsum("fa,fak->fk", f[s.tdofs], s.tdir)
    np.testing.assert_allclose(sol.tangential_force[-1], ft, rtol=0, atol=1e-10 * N)
    assert np.abs(sol.u[-1]).max() <= 1e-12 * L[2]           # the base did not move
    corners = np.abs(ft[:, 0]).min()                         # (the consistent shares differ node by node)
    assert corners < np.abs(ft[:, 0]).max()


@pytest.mark.parametrize("method", ["lagrange", "penalty"])
@pytest.mark.parametrize("weighting", ["face", "face-dual"])
def test_balance_cone_and_gross_slip_at_mu_n(weighting, method):
    s = _system("c3d20", weighting)
    sol = rs.solve_path(s, method, base={"N": 1.0}, ramp={"T": 1.0}, lambda_max=4.0, increments=4,
                        on_gross_slip="stop")
    p = s.problem                                            # the recovered field is the reported one: normal
    u = sol.fields[2][p.contact_nodes]                       # displacement and slip at the end of step 2
    np.testing.assert_allclose(np.einsum("ik,ik->i", u, p.contact_normals), sol.u[-1], rtol=0, atol=1e-12 * L[2])
    step2 = sol.step == 2
    slip = sol.slip_increment[step2].sum(axis=0)[:, 0]      # Lagrange: a closed row's tangential motion is slip
    moved = u[:, 0] - sol.fields[1][p.contact_nodes][:, 0]
    closed = sol.closed[step2].all(axis=0)
    assert closed.sum() >= closed.size // 2 and np.abs(moved).max() > 1e-8       # rows slipped
    if method == "lagrange":
        np.testing.assert_allclose(slip[closed], moved[closed], rtol=0, atol=1e-9 * np.abs(moved).max())
    assert sol.gross_slip_load_factor == pytest.approx(MU * N / T, rel=1e-3)          # T = mu N
    Tl = T * sol.load_factor * (sol.step == 2)
    ft = sol.tangential_force.sum(axis=1)
    assert np.abs(ft[:, 0] + Tl).max() <= 1e-9 * T and np.abs(ft[:, 1:]).max() <= 1e-9 * T
    assert np.abs(sol.force.sum(axis=1) - N).max() <= 1e-9 * N
    D = weighting_matrix(s.problem).T.tocsc()
    import scipy.sparse.linalg as spla
    lam_t = np.stack([spla.spsolve(D, sol.tangential_force[i]) for i in range(len(sol.load_factor))])
    lam_n = -sol.sigma_n
    assert np.all(np.linalg.norm(lam_t, axis=2) <= MU * np.maximum(lam_n, 0) * (1 + 1e-8) + 1e-9 * N)
    assert method == "penalty" or "slip" in sol.stick_status[-1]      # rows slip before the body slides
    assert np.all(sol.dissipation >= -1e-9 * N * np.abs(sol.u).max())

