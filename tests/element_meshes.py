"""Small block meshes of every element type for the element tests (imports nothing from deckbridge).

A box [0, Lx] x [0, Ly] x [0, H] of nx x ny x nz cells; ``shear`` slants it in plan (x += shear y),
``grade`` makes the spacings unequal, both keeping every cell affine (a parallelepiped); ``jiggle``
moves the inner nodes at random (cells no longer affine, faces no longer planar; base and top stay flat).
Cells split into 2 wedges (plan diagonal 0-2) or 6 tetrahedra (Kuhn: conforming on the grid); quadratic
types get their mid-side nodes at the edge midpoints (straight edges), shared between cells.
"""

from __future__ import annotations

import itertools

import numpy as np

from reference_solver.elements import element_type

# the corners (i, j, k) of a cell in C3D8 order
_HEX = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]


def grid(nx=2, ny=2, nz=2, L=(1.0, 0.8, 1.2), shear=0.0, grade=False, jiggle=0.0, seed=0):
    """Node coordinates (n, 3) and hexahedra (m, 8) of the box."""
    def axis(n, length):
        t = np.linspace(0.0, 1.0, n + 1)
        return length * (t ** 1.3 if grade else t)
    x, y, z = axis(nx, L[0]), axis(ny, L[1]), axis(nz, L[2])
    X, Y, Z = np.meshgrid(x, y, z, indexing="ij")
    nodes = np.stack([X + shear * Y, Y, Z], -1).reshape(-1, 3)
    idx = np.arange(nodes.shape[0]).reshape(nx + 1, ny + 1, nz + 1)
    if jiggle:
        rng = np.random.default_rng(seed)
        inner = np.zeros(idx.shape, bool)
        inner[1:-1, 1:-1, 1:-1] = True
        h = min(L[0] / nx, L[1] / ny, L[2] / nz)
        nodes[idx[inner]] += jiggle * h * rng.uniform(-1, 1, (inner.sum(), 3))
    hexes = np.array([[idx[i + a, j + b, k + c] for a, b, c in _HEX]
                      for i in range(nx) for j in range(ny) for k in range(nz)])
    return nodes, hexes


def _orient(nodes, cells, corner_count, sign_nodes):
    """Swap two corners where the element is inside out (negative triple product)."""
    c = cells.copy()
    a, b, d, e = (nodes[c[:, i]] for i in sign_nodes)
    neg = np.einsum("ij,ij->i", np.cross(b - a, d - a), e - a) < 0
    c[neg, 1], c[neg, 2] = cells[neg, 2], cells[neg, 1]
    if corner_count == 6:
        c[neg, 4], c[neg, 5] = cells[neg, 5], cells[neg, 4]
    return c


def split(nodes, hexes, kind):
    """Corner connectivity of 'hex' (unchanged), 'wedge' (2 per cell) or 'tet' (6 per cell)."""
    if kind == "hex":
        return hexes
    if kind == "wedge":
        w = np.concatenate([hexes[:, [0, 1, 2, 4, 5, 6]], hexes[:, [0, 2, 3, 4, 6, 7]]])
        return _orient(nodes, w, 6, (0, 1, 2, 3))
    tets = []
    for perm in itertools.permutations(range(3)):
        path = [np.zeros(3, int)]
        for p in perm:
            path.append(path[-1] + np.eye(3, dtype=int)[p])
        tets.append([_HEX.index(tuple(v)) for v in path])
    t = np.concatenate([hexes[:, q] for q in tets])
    return _orient(nodes, t, 4, (0, 1, 2, 3))


def _midside_pairs(el, nc):
    """For each mid-side node of ``el``: the two corners whose midpoint it is (natural coordinates)."""
    return [next((a, b) for a in range(nc) for b in range(a + 1, nc)
                 if np.allclose((el.nodes[a] + el.nodes[b]) / 2, m)) for m in el.nodes[nc:]]


def quadratic_blocks(nodes, groups):
    """Nodes and [(element, cells)] of quadratic ``groups`` [(element, corner cells)], one mid-side node per
    edge (at its midpoint) shared by every cell and block that has that edge."""
    edges, sizes = [], []
    for element, corners in groups:
        pairs = _midside_pairs(element_type(element), corners.shape[1])
        e = np.sort(np.stack([corners[:, [a for a, _ in pairs]], corners[:, [b for _, b in pairs]]], -1), -1)
        edges.append(e.reshape(-1, 2))
        sizes.append(e.shape[:2])
    uniq, inv = np.unique(np.concatenate(edges), axis=0, return_inverse=True)
    out, start = [], 0
    for (element, corners), (m, k) in zip(groups, sizes):
        new = nodes.shape[0] + inv.ravel()[start:start + m * k].reshape(m, k)
        out.append((element, np.hstack([corners, new])))
        start += m * k
    return np.vstack([nodes, nodes[uniq].mean(axis=1)]), out


def with_midsides(nodes, corners, element):
    """Nodes and cells of ``element`` (quadratic) built on corner cells: one node per edge, at its midpoint."""
    nodes, [(_, cells)] = quadratic_blocks(nodes, [(element, corners)])
    return nodes, cells


def block_mesh(element, **grid_kw):
    """(nodes, cells) of one element type on the box (see :func:`grid`)."""
    el = element_type(element)
    nodes, hexes = grid(**grid_kw)
    kind = {8: "hex", 20: "hex", 6: "wedge", 15: "wedge", 4: "tet", 10: "tet"}[el.n_nodes]
    corners = split(nodes, hexes, kind)
    if el.n_nodes in (20, 15, 10):
        return with_midsides(nodes, corners, el)
    return nodes, corners


def mixed_mesh(**grid_kw):
    """Hex20 cells where the cell centre has x below the middle, pairs of Wedge15 elsewhere: (nodes, blocks)."""
    nodes, hexes = grid(**grid_kw)
    cx = nodes[hexes].mean(axis=1)[:, 0]
    left = cx < np.median(cx)
    return quadratic_blocks(nodes, [("c3d20", hexes[left]), ("c3d15", split(nodes, hexes[~left], "wedge"))])
