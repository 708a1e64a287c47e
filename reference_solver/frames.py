"""Local nodal frames and the map u_global = T q from the reduced unknowns q.

Nodes that carry contact or springs get a local orthonormal frame whose axes include every contact
normal and spring direction of that node, so that each contact gap and each spring elongation is one
reduced dof. Kinematic coupling removes the coupled nodes and adds the reference point's six dofs
(translation, rotation) at the end of q: u_i = u_ref + omega x (x_i - ref).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .errors import ReferenceSolverError
from .problem import Problem


@dataclass(frozen=True)
class DofMap:
    """Reduced dof numbering: ``T`` (3n x nq) maps q to global displacements."""
    T: sp.csr_matrix
    contact_dofs: np.ndarray      # (nc,) index in q of each contact row's normal dof
    spring_dofs: np.ndarray       # (ns,) index in q of each spring's dof
    ref_dofs: np.ndarray | None   # (6,) for kinematic coupling, else None

    @property
    def n_reduced(self) -> int:
        return self.T.shape[1]


def _complete_frame(dirs: list[np.ndarray], node: int) -> np.ndarray:
    """Rows: the given mutually orthogonal unit directions, completed to an orthonormal basis."""
    for a in range(len(dirs)):
        for b in range(a):
            if abs(dirs[a] @ dirs[b]) > 1e-9:
                raise ReferenceSolverError(
                    f"node {node}: its contact normals and spring directions must be mutually orthogonal")
    if len(dirs) > 3:
        raise ReferenceSolverError(f"node {node}: more than three contact/spring directions")
    return np.array(complete_basis(dirs))


def complete_basis(dirs: list[np.ndarray]) -> list[np.ndarray]:
    """The given (1 to 3) orthonormal directions followed by the axes completing a right-handed basis."""
    axes = list(dirs)
    if len(axes) == 1:
        helper = np.eye(3)[int(np.argmin(np.abs(axes[0])))]
        v = helper - (helper @ axes[0]) * axes[0]
        axes.append(v / np.linalg.norm(v))
    if len(axes) == 2:
        axes.append(np.cross(axes[0], axes[1]))
    return axes


def build_dofmap(p: Problem) -> DofMap:
    n = p.n_nodes
    dirs: dict[int, list[np.ndarray]] = {}
    slot_c = np.empty(p.n_contacts, np.int64)
    slot_s = np.empty(p.n_springs, np.int64)
    for rows, nodes, vecs, slot in ((range(p.n_contacts), p.contact_nodes, p.contact_normals, slot_c),
                                    (range(p.n_springs), p.spring_nodes, p.spring_dirs, slot_s)):
        for j in rows:
            lst = dirs.setdefault(int(nodes[j]), [])
            v = vecs[j]
            if any(abs(v @ d) > 1 - 1e-9 for d in lst):
                raise ReferenceSolverError(f"node {int(nodes[j])}: two contacts or springs along the same direction")
            slot[j] = len(lst)
            lst.append(v)

    kin = p.coupling == "kinematic"
    keep = np.ones(n, bool)
    if kin:
        keep[p.coupling_nodes] = False
    rank = np.cumsum(keep) - 1                       # reduced node number of kept nodes
    nq = 3 * int(keep.sum()) + (6 if kin else 0)

    # rotation blocks: u_global(node) = R^T u_local
    blocks = np.tile(np.eye(3), (n, 1, 1))
    for node, lst in dirs.items():
        blocks[node] = _complete_frame(lst, node).T
    kept = np.flatnonzero(keep)
    rows = (3 * kept[:, None, None] + np.arange(3)[None, :, None]).repeat(3, axis=2)
    cols = (3 * rank[kept][:, None, None] + np.arange(3)[None, None, :]).repeat(3, axis=1)
    vals = blocks[kept]
    r_list, c_list, v_list = [rows.ravel()], [cols.ravel()], [vals.ravel()]
    ref_dofs = None
    if kin:
        ref_dofs = np.arange(nq - 6, nq)
        cn = p.coupling_nodes
        d = p.nodes[cn] - p.ref_point
        m = np.zeros((cn.size, 3, 6))
        m[:, :, :3] = np.eye(3)
        skew = np.zeros((cn.size, 3, 3))             # -[d]x : omega -> omega x d
        skew[:, 0, 1], skew[:, 0, 2] = d[:, 2], -d[:, 1]
        skew[:, 1, 0], skew[:, 1, 2] = -d[:, 2], d[:, 0]
        skew[:, 2, 0], skew[:, 2, 1] = d[:, 1], -d[:, 0]
        m[:, :, 3:] = skew
        r_list.append((3 * cn[:, None, None] + np.arange(3)[None, :, None]).repeat(6, axis=2).ravel())
        c_list.append(np.broadcast_to(ref_dofs[None, None, :], (cn.size, 3, 6)).ravel())
        v_list.append(m.ravel())
    T = sp.csr_matrix((np.concatenate(v_list), (np.concatenate(r_list), np.concatenate(c_list))),
                      shape=(3 * n, nq))
    T.eliminate_zeros()
    contact_dofs = 3 * rank[p.contact_nodes] + slot_c
    spring_dofs = 3 * rank[p.spring_nodes] + slot_s
    return DofMap(T=T, contact_dofs=contact_dofs, spring_dofs=spring_dofs, ref_dofs=ref_dofs)
