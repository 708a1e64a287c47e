"""Stress recovery of many states taken a chunk of elements at a time (reference_solver.recover.states_stress)
against the closed form of a homogeneous strain field (imports nothing from deckbridge).

u = eps . x is reproduced exactly by every element type (incompatible modes of c3d8i stay at zero), so every
Gauss point, every cell average and every nodal average carries sigma = D eps; chunks of 3 elements split the
blocks unevenly (a partial last chunk), and three states (u, 2u, -u) go through one product.
"""

import numpy as np
import pytest

from element_meshes import block_mesh, mixed_mesh
from reference_solver import recover
from reference_solver.kinematics import elasticity_matrix, von_mises
from reference_solver.problem import ElementBlock, Problem

E, NU = 70e9, 0.3
EPS = np.array([[-1e-3, 2e-4, 3e-4], [2e-4, 5e-4, -1e-4], [3e-4, -1e-4, 2e-4]])   # symmetric strain tensor


def _problem(nodes, blocks):
    return Problem(nodes=nodes, hexes=None, blocks=tuple(ElementBlock(*b) for b in blocks), E=E, nu=NU,
                   contact_nodes=[0], contact_normals=[[0, 0, 1]], contact_area=[1.0], contact_k=[1.0],
                   contact_clearance=[0.0], contact_surface=["table"], spring_nodes=[],
                   spring_dirs=np.zeros((0, 3)), spring_k=[], ref_point=[0, 0, 1.2], coupling_nodes=[1],
                   coupling_weights=[1.0], loads={})


def _meshes():
    yield "c3d8i", [("c3d8i", block_mesh("c3d8i", nx=3, ny=2, nz=2, shear=0.3, grade=True)[1])], \
        block_mesh("c3d8i", nx=3, ny=2, nz=2, shear=0.3, grade=True)[0]
    nodes, blocks = mixed_mesh(nx=4, ny=2, nz=2, shear=0.2)
    yield "c3d20+c3d15", blocks, nodes
    yield "c3d10", [("c3d10", block_mesh("c3d10", nx=2, ny=2, nz=2, jiggle=0.2)[1])], \
        block_mesh("c3d10", nx=2, ny=2, nz=2, jiggle=0.2)[0]


@pytest.mark.parametrize("chunk", [3, 10_000])
@pytest.mark.parametrize("name, blocks, nodes", list(_meshes()), ids=lambda v: v if isinstance(v, str) else "")
def test_states_stress_by_chunks_is_the_homogeneous_stress(name, blocks, nodes, chunk):
    p = _problem(nodes, blocks)
    u = nodes @ EPS.T
    states = recover.states_stress(p, np.stack([u, 2 * u, -u]), chunk=chunk)
    voigt = np.array([EPS[0, 0], EPS[1, 1], EPS[2, 2], 2 * EPS[0, 1], 2 * EPS[1, 2], 2 * EPS[0, 2]])
    sigma = elasticity_matrix(E, NU) @ voigt                       # [Pa]
    tol = 1e-9 * np.abs(sigma).max()
    assert len(states) == 3
    for f, st in zip((1.0, 2.0, -1.0), states):
        assert st["cell"].shape == (p.n_elements, 6)
        assert np.abs(st["cell"] - f * sigma).max() <= tol
        assert np.abs(st["nodal"] - f * sigma).max() <= tol
        assert np.abs(st["cell_von_mises"] - von_mises(f * sigma)).max() <= tol
        assert np.abs(st["nodal_von_mises"] - von_mises(f * sigma)).max() <= tol


@pytest.mark.parametrize("name", ["c3d8i", "c3d8", "c3d20", "c3d20r", "c3d10", "c3d15", "c3d4"])
def test_states_stress_of_a_random_field_is_the_strain_operators(name):
    """A random displacement field (the incompatible modes of c3d8i active, distorted elements): the stresses of
    ``states_stress`` (displacement gradients, the modes condensed from K_au u_e) are those of the element's
    (ng, 6, 3n) strain operator (``stress.gauss_stress``: the modes folded in by B-matrix condensation),
    Gauss values averaged with w det J and extrapolated to the nodes, to 1e-12 of the largest stress."""
    from reference_solver.stress import extrapolate_to_nodes, gauss_stress, nodal_average
    nodes, cells = block_mesh(name, nx=3, ny=2, nz=2, jiggle=0.2)
    p = _problem(nodes, [(name, cells)])
    U = np.random.default_rng(7).standard_normal((2, len(nodes), 3)) * 1e-3
    states = recover.states_stress(p, U, chunk=5)
    w = p.blocks[0].element.volume_weights(nodes[cells])
    for u, st in zip(U, states):
        g = gauss_stress(p, u)
        want_nodal, _ = nodal_average(extrapolate_to_nodes(g, name), cells, len(nodes))
        tol = 1e-12 * np.abs(g).max()
        assert np.abs(st["cell"] - np.einsum("eg,egk->ek", w, g) / w.sum(1)[:, None]).max() <= tol
        assert np.abs(st["nodal"] - want_nodal).max() <= tol
