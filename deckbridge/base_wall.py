"""The skirt's wall at its base: axial stress across the wall per azimuth (inner, outer, membrane, bending).

Moved here from ``reference_solver.stress`` (issue 22: the solver stays generic; these are the skirt's
quantities). A leaf of deckbridge: imports the solver's generic stress recovery only, so that both
:mod:`deckbridge.wall_stress` (reference) and :mod:`deckbridge.dialects.calculix.el_stress` (CalculiX) use it.
Units [m], [Pa]; tension > 0, compression < 0 (as sigma_N). Voigt order (xx, yy, zz, xy, yz, zx).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference_solver.azimuths import azimuth_clusters, element_span_deg
from reference_solver.stress import corner_stress, nodal_average

from .errors import DeckbridgeError

CCX_TO_VOIGT = np.array([0, 1, 2, 3, 5, 4])   # ccx (xx, yy, zz, xy, xz, yz)[CCX_TO_VOIGT] -> (.., yz, zx)
AXES = {"x": 0, "y": 1, "z": 2}
# corners of a 10-, 15-, 20-node cell (CalculiX order: corners first); the wall is reduced at the corner nodes,
# whose through-wall rows are alike at every corner azimuth (a mid-side azimuth has other counts)
CORNERS = {10: 4, 15: 6, 20: 8}


@dataclass(frozen=True)
class BaseWall:
    """Axial stress across the wall at the base, one entry per azimuth (sorted by ``theta_deg``).

    ``nodes`` (na, nw): base nodes at each azimuth, inner face first (sorted by radius); ``radius``
    (na, nw) [m]; ``s_axial`` (na, nw) [Pa] their axial stress. ``inner``, ``outer`` [Pa]: the faces;
    ``mean`` [Pa]: membrane, the trapezoid rule over the node radii divided by the wall thickness,
    (1 / (r_out - r_in)) int s dr with s linear between nodes; ``bending`` [Pa]: (outer - inner) / 2
    (> 0 when the outer face is more tensile). Tension > 0, compression < 0 (as sigma_N).

    ``force`` (na,) [N] or None: on cells with mid-side nodes (10-, 15-, 20-node), whose rows hold the corner
    nodes only, the axial force of the base section per row, :func:`section_forces` (the sigma_zz resultant
    of the equilibrium check, ``deckbridge/quantities.py``); None where every base node is in a row.
    """
    theta_deg: np.ndarray
    nodes: np.ndarray
    radius: np.ndarray
    s_axial: np.ndarray
    inner: np.ndarray
    outer: np.ndarray
    mean: np.ndarray
    bending: np.ndarray
    force: np.ndarray | None = None


def through_wall_weights(radius: np.ndarray) -> np.ndarray:
    """Trapezoid weights (na, nw) over the node radii, summing to 1 per azimuth."""
    dr = np.diff(radius, axis=1)
    w = np.zeros_like(radius)
    w[:, :-1] += 0.5 * dr
    w[:, 1:] += 0.5 * dr
    return w / w.sum(axis=1, keepdims=True)


def base_wall(nodes: np.ndarray, bottom_hexes: np.ndarray, s_axial_nodal: np.ndarray, axis: str = "z",
              rel_tol: float = 1e-3) -> BaseWall:
    """Group the base nodes of the bottom element row by azimuth and reduce across the wall.

    ``nodes`` (n, 3) [m], ``bottom_hexes`` (ne, 8) node indices of the bottom element row, the wall's axis
    through the origin along ``axis`` ('x', 'y' or 'z'); base nodes are the row's nodes at the lowest
    axial coordinate. ``s_axial_nodal`` (n,) [Pa]: the axial normal stress per node (e.g. column zz of
    :func:`reference_solver.stress.nodal_average` over the bottom row). Azimuth [deg, 0..360) counter-clockwise
    about ``axis`` (from +x towards +y for 'z'); nodes whose azimuths agree to ``rel_tol`` of the smallest
    element's angular span share an azimuth (:func:`reference_solver.azimuths.azimuth_clusters`: an imported
    mesh's nodes sit off their nominal azimuth by round-off, 1e-7 deg in Gmsh's files, 1e-5 deg in
    8-character Nastran fields), ``theta_deg`` is each group's mean.
    """
    if axis not in AXES:
        raise DeckbridgeError(f"axis = {axis!r}: must be one of x, y, z")
    a = AXES[axis]
    b, c = (a + 1) % 3, (a + 2) % 3
    nodes = np.asarray(nodes, float)
    cells = np.asarray(bottom_hexes, np.int64)
    bottom_hexes = cells[:, :CORNERS.get(cells.shape[1], cells.shape[1])]   # corners only
    row = np.unique(bottom_hexes)
    h = nodes[row, a]
    tol = 1e-9 * max(float(np.ptp(nodes, axis=0).max()), 1.0)
    base = row[h <= h.min() + tol]
    az = lambda i: np.mod(np.degrees(np.arctan2(nodes[i, c], nodes[i, b])), 360.0)  # noqa: E731
    span = element_span_deg(az(np.asarray(bottom_hexes, np.int64)))
    th, centres = azimuth_clusters(az(base), rel_tol * float(span[span > 0].min() if (span > 0).any() else 360.0))
    rad = np.hypot(nodes[base, b], nodes[base, c])
    order = np.lexsort((rad, th))
    base, th, rad = base[order], th[order], rad[order]
    uth, counts = np.unique(th, return_counts=True)
    uth = centres[uth]
    if np.any(counts != counts[0]) or counts[0] < 2:
        raise DeckbridgeError("bottom_hexes: base nodes do not form the same through-wall row at every azimuth "
                              "(an unstructured base such as Gmsh's plain tetrahedra has no rows: the wall table "
                              "needs them; solve and liftoff do not)")
    shape = (uth.size, int(counts[0]))
    nd, rr = base.reshape(shape), rad.reshape(shape)
    s = np.asarray(s_axial_nodal, float)[nd]
    if not np.all(np.isfinite(s)):
        raise DeckbridgeError("s_axial_nodal: NaN or infinite at a base node")
    inner, outer = s[:, 0], s[:, -1]
    mean = np.sum(through_wall_weights(rr) * s, axis=1)
    force = (section_forces(nodes, cells, s_axial_nodal, nd)
             if cells.shape[1] in CORNERS and axis == "z" else None)
    return BaseWall(theta_deg=uth, nodes=nd, radius=rr, s_axial=s, inner=inner, outer=outer,
                    mean=mean, bending=0.5 * (outer - inner), force=force)


def section_forces(nodes: np.ndarray, cells: np.ndarray, s_axial_nodal: np.ndarray, wall_nodes: np.ndarray
                   ) -> np.ndarray | None:
    """Axial force [N] (tension > 0) of the base section per wall row ``wall_nodes`` (na, nw; rows sorted by
    azimuth about z): int s dA over the base faces (lowest z) of the bottom row's ``cells`` (m, 10 | 15 | 20,
    CalculiX order), s interpolated on each face by its own shape functions from the nodal values
    ``s_axial_nodal`` (n,) [Pa] at EVERY face node, mid-side nodes included: Sum_a s_a int N_a dA
    (:func:`reference_solver.face_weights.face_shares`, the consistent shares: -1/12 of a flat 8-node face at
    its corners), each node's term to the row of nearest azimuth (:func:`deckbridge.mesh_data.nearest_row_sums`).
    The rows' trapezoid mean x area (corners only) is not that integral on these cells: on the Gmsh C3D20
    skirt of the quadratic scenario matrix (16 x 4 x 1) past liftoff it missed the contact resultant by
    2.72 % at lambda 0.8 and 18.8 % at 1 where this integral misses it by 1.09 % and 3.46 %; the FE stress D B u
    itself, integrated at the base faces' 3 x 3 points, misses it by the same 1.08 % on hex20 24 x 3 x 1 at 0.8
    (a residual of the 27-point element's stress there, not of the recovery; C3D20R balances to 1e-9). None where
    a base-face node's value is not finite (a source that gives the corners only)."""
    from reference_solver.elements import element_type
    from reference_solver.face_weights import face_shares, surface_faces
    from reference_solver.problem import ElementBlock

    from .mesh_data import nearest_row_sums
    names = {10: "c3d10", 15: "c3d15", 20: "c3d20"}
    z = nodes[:, 2]
    used = np.unique(cells)
    on = np.zeros(nodes.shape[0], bool)
    on[used[z[used] <= z[used].min() + 1e-9 * max(float(np.ptp(nodes, axis=0).max()), 1.0)]] = True
    s = np.asarray(s_axial_nodal, float)
    f = np.zeros(nodes.shape[0])
    for ftype, conn in surface_faces((ElementBlock(element_type(names[cells.shape[1]]), cells),), on):
        if not np.isfinite(s[conn]).all():
            return None
        np.add.at(f, conn.ravel(), (s[conn] * face_shares(ftype, nodes[conn])).ravel())
    return nearest_row_sums(nodes, f, wall_nodes)


def reference_base_wall(p, u: np.ndarray, bottom_elems: np.ndarray, axis: str = "z") -> BaseWall:
    """:func:`base_wall` of the reference solution: element-node stresses of the bottom row ``bottom_elems``
    (element indices of the solver problem ``p``) averaged over the row's elements sharing a node; axial
    component."""
    if len(p.blocks) > 1:                    # a mixed mesh (issue 23): each block's own element nodes
        return _mixed_base_wall(p, u, np.asarray(bottom_elems, np.int64), axis)
    bottom = p.hexes[np.asarray(bottom_elems, np.int64)]
    avg, _ = nodal_average(corner_stress(p, u, bottom_elems), bottom, p.nodes.shape[0])
    return base_wall(p.nodes, bottom, avg[:, AXES[axis]], axis)


def _mixed_base_wall(p, u: np.ndarray, bottom_elems: np.ndarray, axis: str) -> BaseWall:
    """:func:`reference_base_wall` on several element blocks: element-node stresses summed block by block
    (:func:`reference_solver.stress.nodal_sums`), the row reduced on each block's corners (a shorter cell's row
    filled with its first corner, which changes neither the row's nodes nor its angular span)."""
    from reference_solver.stress import nodal_sums
    n = p.nodes.shape[0]
    total, count, corners, start = np.zeros((n, 6)), np.zeros(n), [], 0
    for b in p.blocks:
        m = b.cells.shape[0]
        mine = bottom_elems[(bottom_elems >= start) & (bottom_elems < start + m)]
        start += m
        if mine.size == 0:
            continue
        cells = b.cells[mine - (start - m)]
        t, c = nodal_sums(corner_stress(p, u, mine), cells, n)
        total, count = total + t, count + c
        corners.append(cells[:, :CORNERS.get(cells.shape[1], cells.shape[1])])
    width = max(c.shape[1] for c in corners)
    bottom = np.vstack([np.hstack([c, np.repeat(c[:, :1], width - c.shape[1], axis=1)]) for c in corners])
    with np.errstate(invalid="ignore", divide="ignore"):
        avg = np.where(count[:, None] > 0, total / count[:, None], np.nan)
    return base_wall(p.nodes, bottom, avg[:, AXES[axis]], axis)
