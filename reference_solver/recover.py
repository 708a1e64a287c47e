"""Whole-model fields of every state of a load path: displacements in one solve, stresses per state.

Units: displacements [m], stresses [Pa], tension > 0. Voigt order of every stress array here:
(xx, yy, zz, xy, yz, zx) (:mod:`reference_solver.stress`).
"""

from __future__ import annotations

import os
from collections import deque
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from scipy import sparse

from .condense import CondensedSystem
from .kinematics import elasticity_matrix, gradient_to_strain, von_mises
from .path import Solution

# elements per chunk of the stress recovery: its displacement gradients, stresses and nodal values about
# 1.6-1.9 kB per state and 8-node hexahedron (about 50 MB at 13 states); under glibc's 32 MB mmap threshold
# for most of its arrays, so freed arrays are reused, not page-faulted afresh (8192: 1.6x the CPU, bench/README.md)
STRESS_CHUNK = 2048
# threads recovering chunks at once (at most the cores this process may use); each holds one chunk's arrays,
# and at most two chunks wait to be summed
STRESS_THREADS = 2


def _stress_threads() -> int:
    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cores = os.cpu_count() or 1
    return max(1, min(STRESS_THREADS, cores))


def _ordered_map(fn, items):
    """``map(fn, items)`` in order, computed on :func:`_stress_threads` threads with at most threads + 1 results
    ahead of the consumer (memory bounded by a few chunks)."""
    n = _stress_threads()
    if n == 1 or len(items) < 2:
        yield from map(fn, items)
        return
    with ThreadPoolExecutor(n) as pool:
        pending = deque()
        for item in items:
            pending.append(pool.submit(fn, item))
            if len(pending) > n:
                yield pending.popleft().result()
        while pending:
            yield pending.popleft().result()


def path_fields(system: CondensedSystem, sol: Solution, rows=None) -> np.ndarray:
    """Global displacements (m, n, 3) [m] of the Solution's rows ``rows`` (default every row, i.e.
    the end of step 1 and every increment of step 2), recovered with ONE call of
    :meth:`CondensedSystem.recover` (one multi-right-hand-side back substitution)."""
    idx = np.arange(sol.step.size) if rows is None else np.asarray(rows, np.int64)
    x = sol.u if sol.retained_u is None else sol.retained_u     # friction: normal + tangential dofs
    return system.recover(x[idx], sol.coeffs[idx]).reshape(idx.size, -1, 3)


def states_stress(p, U: np.ndarray, chunk: int = STRESS_CHUNK) -> list[dict]:
    """Stresses of m states with nodal displacements ``U`` (m, n, 3) [m] of problem ``p``. The elements
    are taken ``chunk`` at a time, every state at once (``Element.displacement_gradients`` at the Gauss points,
    the states as the last axis; stress = D T du/dx): memory bounded by the chunk.

    Per state a dict: ``cell`` (ne, 6) volume average of the element's stress by its own quadrature,
    sum_g sigma_g w_g det J_g / sum_g w_g det J_g [Pa] (so that sum over a layer of elements of cell
    sigma_zz x volume is the layer's integral of sigma_zz, as in the stiffness); ``cell_von_mises``
    (ne,) von Mises of that average [Pa]; ``nodal`` (n, 6): Gauss values extrapolated to the element
    nodes (``Element.extrapolation``, an estimate) and averaged, unweighted, over the elements sharing
    the node [Pa]; ``nodal_von_mises`` (n,) von Mises of the nodal average [Pa]. Nodes no element
    touches get 0. Elements are numbered block by block (``p.blocks``).
    """
    C = elasticity_matrix(p.E, p.nu) @ gradient_to_strain()      # (6, 9): stress of du/dx [Pa]
    n = p.nodes.shape[0]
    U = np.asarray(U, float).reshape(-1, n, 3)
    m = U.shape[0]
    Ut = np.ascontiguousarray(U.transpose(1, 2, 0))                 # (n, 3, m): the states last
    ne = sum(len(b.cells) for b in p.blocks)
    cell, total, count = np.empty((m, ne, 6)), np.zeros((m, n, 6)), np.zeros(n)
    step = max(int(chunk), 1)
    jobs, start = [], 0
    for b in p.blocks:
        jobs += [(b.element, b.element.extrapolation(), b.cells[lo:lo + step], start + lo)
                 for lo in range(0, len(b.cells), step)]
        start += len(b.cells)

    def chunk_stress(job):
        element, ext, cells, _ = job
        k, nn = cells.shape
        H, w = element.displacement_gradients(p.nodes[cells], Ut[cells], p.E, p.nu)   # (k, ng, 3, 3, m)
        w /= w.sum(axis=1, keepdims=True)
        g = (C @ H.reshape(k, -1, 9, m)).reshape(k, -1, 6 * m)              # (k, ng, 6m) [Pa]
        return (w[:, None, :] @ g)[:, 0], (ext @ g).reshape(k * nn, 6 * m)

    # the chunks' element work on up to STRESS_THREADS threads (NumPy releases the GIL in it); the cell
    # values and the nodal sums taken in chunk order on this thread, so the sums are the same bits
    for (_, _, cells, at), (cell_k, at_nodes) in zip(jobs, _ordered_map(chunk_stress, jobs)):
        k, nn = cells.shape
        cell[:, at:at + k] = cell_k.reshape(k, 6, m).transpose(2, 0, 1)
        lo, hi = int(cells.min()), int(cells.max()) + 1      # the nodes this chunk touches lie in [lo, hi)
        scatter = sparse.csr_matrix((np.ones(k * nn), (cells.ravel() - lo, np.arange(k * nn))), shape=(hi - lo, k * nn))
        total[:, lo:hi] += (scatter @ at_nodes).reshape(hi - lo, 6, m).transpose(2, 0, 1)
        count += np.bincount(cells.ravel(), minlength=n)
    nodal = total                                   # in place; nodes no element touches keep 0
    nodal /= np.maximum(count, 1)[:, None]
    return [{"cell": cell[s], "cell_von_mises": von_mises(cell[s]),
             "nodal": nodal[s], "nodal_von_mises": von_mises(nodal[s])} for s in range(m)]


def centre_stress(p, U: np.ndarray) -> np.ndarray:
    """Stresses (m, ne, 6) [Pa] at the element centres of m states ``U`` (m, n, 3) [m] (what
    :func:`fields.element_stress` gives state by state: the compatible gradients at the centre, where the
    c3d8i modes' gradient is zero), every state by one product per block."""
    C = elasticity_matrix(p.E, p.nu) @ gradient_to_strain()
    U = np.asarray(U, float).reshape(-1, p.nodes.shape[0], 3)
    m = U.shape[0]
    Ut = np.ascontiguousarray(U.transpose(1, 2, 0))                 # (n, 3, m)
    out = []
    for b in p.blocks:
        k, nn = b.cells.shape
        _, grad = b.element.point_gradients(p.nodes[b.cells], b.element.centre)     # (k, 3, nn)
        H = grad @ Ut[b.cells].reshape(k, nn, 3 * m)                                   # (k, 3, 3m)
        out.append((C @ H.reshape(k, 9, m)).transpose(2, 0, 1))
    return np.concatenate(out, axis=1)
