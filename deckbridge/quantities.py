"""Every compared quantity, defined once: one function each, its unit, its weighting, its definition.

The report prints :data:`DEFINITIONS`; the comparator, the console and summary.json call these
functions and nothing else. Conventions: sigma_N < 0 compression, > 0 tension (open-gap tension of
a penalty model is kept as sigma_N > 0, never clipped); force_n > 0 compressive; theta [deg] in
[0, 360); wall ring 0 = inner face.

A table row's area ``area_m2`` [m^2] and sigma_N per face type (issue 23; the area's one definition is
:func:`deckbridge.face_areas.contact_areas`): 4-node faces (8-node solids) the tributary area, sigma_N =
-force / area; 3-node faces the HRZ (= tributary) area, the same; 8- and 6-node faces (hex20, hex20r, tet10,
wedge15: reference face-weighted Lagrange and face penalty; ccx mortar and reference/mortar in ccx's dual basis,
its shares d instead) A_a = int Phi_a dA of the
non-negative hat multiplier basis Phi (``reference_solver.face_weights.hat_mortar``) and sigma_N = -lambda_a,
the nodal value of the pressure field sum lambda_a Phi_a with lambda = D^-T r (D_ab = int Phi_a N_b dA, r the
nodal contact forces [N]). A row's ``force_n`` [N] (> 0 compressive) is the normal force the solver applies to
its node (:func:`nodal_force`): -sigma_N x area on 4-/3-node faces, the consistent r = D^T lambda on 8-/6-node
faces (the reference's face laws, ccx mortar's RF . n; a pressed 8-node face's corners pull), so both its sum
(= N under N) and its first moment are the contact resultant's; NaN where the source prints no nodal force (ccx
face-to-face on quadratic faces, whose sigma_N = -CPRESS is ccx's nodal pressure). The pressure's share
-sigma_N x area (:func:`pressure_force`) sums to Sum r exactly where sigma_N is the projection, but its moment
about the nodes is not the resultant's (1.1-1.6e-3 of N R on the hex20r cone). Node values are the nodal
values sigma_N; through-wall values Sum sigma_N x area / Sum area of the azimuth's rows.

Equilibrium check (what it compares): the corner-extrapolated base-wall sigma_zz (Gauss points of
the bottom element row extrapolated to the base corners, averaged over the elements sharing a node,
trapezoid mean through the wall) against the through-wall contact sigma_N = Sum sigma_N x area / Sum area.
Two numbers: ``szz_resultant_residual`` (Sum over every azimuth of the wall of mean sigma_zz x the
base area the azimuth stands on, against the contact resultant Sum sigma_N x area, relative) is the
equilibrium check and is warned above 1 %; on cells with mid-side nodes (10-, 15-, 20-node), whose wall rows
hold the corners only, the axial resultant is the wall table's ``axial_force_n`` summed (int sigma_zz dA with
every base-face node, deckbridge.base_wall.section_forces). The base area is the whole wall's (wall table column
``area_m2``), not the contact area: on pads a pad-edge node's sigma_zz is the average of a loaded and
an unloaded element, which the full area weights as the two half faces it stands for (weighted by
the half contact area the check read 28-45 % off on 4 pads; tables without ``area_m2`` fall back to
the contact areas of the contact azimuths, equal without pads). On a cone the check is the same force
balance (sigma_zz is the vertical traction on the horizontal base section, whatever the wall's slope)
and its warning is true: the reference's C3D8I (Taylor's det J0 / det J modes, patch test passed)
flattens sigma_zz's axial gradient in an inclined bottom element, an O(element height) recovery error
(top_radius 1.6, 24 x n_z x 1: 1.64 % at n_z 2, 0.54 % at 6, 0.10 % on the default mesh; the
solver's reactions balance to 1e-10), where ccx's own C3D8I balances to 0.01-0.02 % on 24 x 6 x 1
(its Gauss stresses are those of J0 modes without the det ratio, to 1e-4: a form that fails the
reference's distorted patch test). ``szz_local_residual`` (max over theta of
|mean sigma_zz - sigma_N| / max |sigma_N|) also carries the extrapolation error (5-8 % past liftoff on the default mesh, the lower
Gauss layer alone ~1.3 %) and is reported, not warned.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from .azimuth import arc_weights, periodic_interp, snap_deg
from .methods import LAGRANGE
from .summary_keys import RING_LINE_FORCE_MAX_DIFF

CLAIM_QUANTITIES = ("sigma_n_wall_pa", "szz_inner_pa", "szz_outer_pa", "szz_mean_pa")   # judged by the paper's claims (studies/claims.py)

RESIDUAL_WARN = 0.01          # equilibrium residual warned above this (relative)
TENSION_WARN = 0.01           # open-gap tension warned above this fraction of the peak compression
PENETRATION_WARN = 0.1        # force-free penetration warned above this fraction of a loaded node's largest
PENETRATION_FLOOR = 1e-6      # ... and above this fraction of the largest node radius (round-off, mortar edges)
SMALL_STRAIN_LIFT = 0.01      # lift / R above which a small-strain answer is past its range (REFERENCE.md §8)
RING_LINE_WHY = ("on 8-/6-node faces the two nodal sigma_N are two readings of one pressure field that part at the "
                 "contact edge: ccx's is CPRESS, the integration-point pressure extrapolated to the nodes, the "
                 "reference's the hat-basis projection -D^-T r; the ring's line forces are exact on both sides")


@dataclass(frozen=True)
class Quantity:
    key: str
    unit: str
    weighting: str
    definition: str


DEFINITIONS = {q.key: q for q in [
    Quantity("sigma_n_wall_pa", "Pa", "area (row areas of the through-wall nodes: tributary; hat int Phi dA on 8-/6-node faces)",
             "contact sigma_N through the wall at one azimuth = Sum sigma_N x area / Sum area of its table nodes"),
    Quantity("force_n", "N", "none (one node)",
             "normal contact force the solver applies to one slave node, > 0 compressive: -sigma_N x area on "
             "4-/3-node faces, the consistent nodal force r = D^T lambda on 8-/6-node faces (corners of a pressed "
             "8-node face < 0); its sum and first moment are the contact resultant's; NaN where not printed (ccx "
             "face-to-face on 8-/6-node faces)"),
    Quantity("pressure_force_n", "N", "area (the row's area)",
             "the pressure's share of one row = -sigma_N x area (> 0 compressive): force_n on 4-/3-node faces; on "
             "8-/6-node faces its sum is the resultant where sigma_N is the projected pressure, its moment is not"),
    Quantity("sigma_n_node_pa", "Pa", "none (one node)",
             "contact sigma_N of one slave node = -force_n / its area on 4-/3-node faces (inner, mid, outer); on 8-/6-node faces the "
             "pressure field's nodal value -lambda (hat basis)"),
    Quantity("peak_sigma_n_wall_pa", "Pa", "area", "most compressive through-wall sigma_N along the azimuth"),
    Quantity("peak_sigma_n_node_pa", "Pa", "none", "most compressive sigma_N of any single table node"),
    Quantity("line_load_n_per_m", "N/m", "arc length at the mid-wall radius",
             "line load q(theta) = Sum sigma_N x area at the azimuth / its tributary arc length at the mid-wall radius"),
    Quantity("szz_inner_pa", "Pa", "none", "wall sigma_zz at the base, inner face (Gauss -> corner, node average)"),
    Quantity("szz_outer_pa", "Pa", "none", "wall sigma_zz at the base, outer face (Gauss -> corner, node average)"),
    Quantity("szz_mean_pa", "Pa", "trapezoid over the node radii / thickness", "membrane: through-wall mean sigma_zz at the base"),
    Quantity("szz_bending_pa", "Pa", "none", "bending: (outer - inner) / 2 of sigma_zz at the base"),
    Quantity("szz_resultant_residual", "1", "base area per azimuth (the whole wall, pads or not)",
             "|Sum mean sigma_zz x area - Sum sigma_N x area| / |Sum sigma_N x area| over the base (equilibrium check); "
             "on 10-/15-/20-node cells Sum mean sigma_zz x area is int sigma_zz dA over every base-face node "
             "(wall column axial_force_n)"),
    Quantity("szz_local_residual", "1", "none", "max over theta |mean sigma_zz - sigma_N wall| / max |sigma_N wall|"),
    Quantity("open_tension_ratio", "1", "none",
             "largest sigma_N > 0 of an open node / |peak compression| (penalty open-gap stiffness)"),
    Quantity("lifted_arc_deg", "deg", "arc weights", "arc of azimuths whose every table node is open"),
    Quantity("lift_over_radius", "1", "none (one node)",
             "largest table-node opening / largest table-node radius; above 0.01 the answer is past the "
             "small-strain range (the headline comparison stays at or below it)"),
    Quantity("gap_m", "m", "none (one row); on 8-/6-node faces of a Lagrange-type law the row's multiplier function",
             "a table row's gap (> 0 open) as its contact law constrains it: nodal laws and penalty laws (node or "
             "face-integrated) the node's clearance + n . u; the face-weighted Lagrange law (reference "
             "lagrange and mortar on 8-/6-node faces, ccx mortar) the projected gap g~_a / int Phi_a dA = "
             "(D g)_a / Sum_b D_ab (projected_gap), >= 0 where the law holds and 0 at a pressed row; its "
             "nodal gap D^-1 g~ is not written (past liftoff it is < 0 at force-free rows beside the "
             "contact edge: -1.7 um hex20r, -6.7 um tet10 at lambda 1 of the quadratic scenario matrix)"),
    Quantity("free_penetration_m", "m", "none (one node)",
             "largest penetration -gap_m (the law's gap) of a table node that carries no contact pressure "
             "(pressure_force_n <= 0): a penalty node carries k x penetration and a Lagrange node has none, so a "
             "value here is an output that "
             "contradicts its own contact law (e.g. a node the solver's contact search missed); warned above "
             "10 % of the largest penetration of a loaded node and above 1e-6 of the largest node radius"),
    Quantity("tau_wall_pa", "Pa", "area (tributary areas of the through-wall nodes)",
             "tangential (friction) traction through the wall at one azimuth = Sum |F_t| / Sum area of its "
             "table nodes, F_t the table's tangential force on the node (friction.csv)"),
    Quantity("tangential_resultant_n", "N", "none (vector sum)",
             "resultant of the tangential forces of the contact rows (table on body, global x, y, z); "
             "with no stop in contact it balances the applied shear: Sum F_t = -T lambda"),
    Quantity("ring_line_force_n", "N", "the ring's C3D8 shape functions (a contact force at azimuth s of a face goes "
             "1 - s / s to its two lines)",
             "ccx face-to-face on 8-/6-node faces and its partner reference/f2f: the contact force on one azimuth line "
             "j (360 j / n_theta deg) of the deck's clamped C3D8 master ring, > 0 pressing the skirt up: ccx's RF of "
             "the ring's top nodes summed per line, the reference's integration-point forces K w (-g) spread with the "
             "ring's shape functions; exact on both sides (no nodal extrapolation), unlike their nodal sigma_N"),
    Quantity(RING_LINE_FORCE_MAX_DIFF, "1", "none (largest over the lines, then over the states)",
             "ccx/f2f vs reference/f2f on 8-/6-node faces: max_j |F_j(b) - F_j(a)| / max_j |F_j(a)| of "
             "ring_line_force_n (ring_line_rel_diff), largest over their common states with lift/R <= 0.01"),
    Quantity("contact_resultant_n", "N", "none (vector sum)",
             "resultant of the whole contact forces F_n n + F_t of every row (table and stop, on the body); "
             "balances the applied loads: its horizontal part = -T lambda"),
]}


def table_rows(rows: pd.DataFrame) -> pd.DataFrame:
    """The table-surface rows of one state."""
    return rows[rows["surface"] == "table"] if "surface" in rows else rows


def nodal_force(rows: pd.DataFrame) -> np.ndarray:
    """``force_n`` [N] of the rows (> 0 compressive; :data:`DEFINITIONS`): the force the solver applies to the
    node, exact in sum and first moment; NaN where the source does not print it."""
    return rows["force_n"].to_numpy(float) if "force_n" in rows else np.full(len(rows), np.nan)


def pressure_force(rows: pd.DataFrame) -> np.ndarray:
    """-sigma_N x area [N] of the rows (> 0 compressive; ``pressure_force_n`` of :data:`DEFINITIONS`): the
    weight of through-wall and line-load sums; NaN where the area is unknown."""
    a = rows["area_m2"].to_numpy(float) if "area_m2" in rows else np.full(len(rows), np.nan)
    return -rows["sigma_n_pa"].to_numpy(float) * a


def sigma_n_wall(rows: pd.DataFrame) -> pd.Series:
    """Through-wall contact sigma_N [Pa] per azimuth (index theta_deg, sorted) of one state:
    Sum sigma_N x area / Sum area; the unweighted node mean only where a source has no areas (NaN)."""
    r = table_rows(rows)
    th = snap_deg(r["theta_deg"].to_numpy(float))
    a = r["area_m2"].to_numpy(float) if "area_m2" in r else np.full(len(r), np.nan)
    f = pressure_force(r)
    g = pd.DataFrame({"t": th, "a": a, "f": f, "s": r["sigma_n_pa"].to_numpy(float),
                      "known": np.isfinite(a)}).groupby("t", sort=True)
    weighted = -g["f"].sum(min_count=1) / g["a"].sum(min_count=1)
    known = g["known"].all()              # every area of the azimuth finite (one vectorised pass)
    out = weighted.where(known, g["s"].mean()) + 0.0          # + 0.0: an open azimuth's -0 / A is 0.0
    out.index.name = "theta_deg"
    return out.astype(float)


def sigma_n_nodes(rows: pd.DataFrame) -> pd.DataFrame:
    """Node sigma_N [Pa] per azimuth: columns inner (ring 0), mid (middle ring when the count is odd,
    else NaN), outer (last ring); index theta_deg."""
    r = table_rows(rows)
    df = pd.DataFrame({"t": snap_deg(r["theta_deg"].to_numpy(float)), "w": r["wall"].to_numpy(np.int64),
                       "s": r["sigma_n_pa"].to_numpy(float)})
    piv = df.pivot_table(index="t", columns="w", values="s", aggfunc="mean").sort_index()
    rings = list(piv.columns)
    mid = rings[len(rings) // 2] if len(rings) % 2 == 1 and len(rings) > 1 else None
    out = pd.DataFrame({"inner": piv[rings[0]], "mid": piv[mid] if mid is not None else np.nan,
                        "outer": piv[rings[-1]]})
    out.index.name = "theta_deg"
    return out


def peak_node(rows: pd.DataFrame) -> tuple[float, float]:
    """Most compressive single table node: (sigma_N [Pa], theta [deg])."""
    r = table_rows(rows)
    i = int(np.argmin(r["sigma_n_pa"].to_numpy(float)))
    return float(r["sigma_n_pa"].iloc[i]), float(snap_deg(r["theta_deg"].iloc[i]))


def line_load(rows: pd.DataFrame, r_mid: float) -> pd.Series:
    """q(theta) [N/m] (< 0 compression) = Sum sigma_N x area at the azimuth / (r_mid x its arc [rad])."""
    r = table_rows(rows)
    th = snap_deg(r["theta_deg"].to_numpy(float))
    f = pd.Series(pressure_force(r), index=th).groupby(level=0).sum(min_count=1).sort_index()
    arc = np.radians(arc_weights(f.index.to_numpy(float))) * float(r_mid)
    out = -f / arc
    out.index.name = "theta_deg"
    return out


def contact_resultant(rows: pd.DataFrame) -> float:
    """Sum of the table nodes' sigma_N x area [N] (= -vertical contact resultant on the skirt; < 0
    when the table pushes up)."""
    r = table_rows(rows)
    return float(np.sum(r["sigma_n_pa"].to_numpy(float) * r["area_m2"].to_numpy(float)))


def equilibrium(wall_szz: pd.DataFrame, rows: pd.DataFrame) -> dict:
    """The equilibrium check of one state (see the module doc): {'szz_resultant_residual',
    'szz_local_residual', 'warn'}. ``wall_szz``: columns theta_deg, szz_mean_pa of that state."""
    sw = sigma_n_wall(rows)
    szz = pd.Series(wall_szz["szz_mean_pa"].to_numpy(float), index=snap_deg(wall_szz["theta_deg"].to_numpy(float)))
    szz = szz.groupby(level=0).mean().reindex(sw.index)
    r = table_rows(rows)
    w = pd.Series(r["area_m2"].to_numpy(float), index=snap_deg(r["theta_deg"].to_numpy(float))).groupby(level=0).sum()
    w = w.reindex(sw.index).to_numpy(float)
    resultant = contact_resultant(rows)
    wall_area = wall_szz["area_m2"].to_numpy(float) if "area_m2" in wall_szz else None
    force = wall_szz["axial_force_n"].to_numpy(float) if "axial_force_n" in wall_szz else None
    if force is not None and np.isfinite(force).all():               # cells with mid-side nodes: every base node
        axial = float(np.sum(force))
    elif wall_area is not None and np.isfinite(wall_area).all():    # the whole base section
        axial = float(np.sum(wall_szz["szz_mean_pa"].to_numpy(float) * wall_area))
    else:                                                            # older tables: contact areas
        axial = float(np.sum(szz.to_numpy() * w))
    res_glob = abs(axial - resultant) / max(abs(resultant), 1e-300)
    scale = float(np.max(np.abs(sw.to_numpy()))) or 1.0
    res_loc = float(np.nanmax(np.abs(szz.to_numpy() - sw.to_numpy()))) / scale
    return {"szz_resultant_residual": res_glob, "szz_local_residual": res_loc, "warn": res_glob > RESIDUAL_WARN}


def open_tension(rows: pd.DataFrame) -> dict:
    """Open-gap tension of one state: {'max_open_sigma_n_pa', 'open_tension_ratio', 'warn'} (kept, never clipped)."""
    r = table_rows(rows)
    s = r["sigma_n_pa"].to_numpy(float)
    is_open = r["status"].to_numpy() == "open"
    top = float(s[is_open].max()) if is_open.any() else 0.0
    top = max(top, 0.0)
    peak = abs(float(min(s.min(), 0.0))) or 1.0
    return {"max_open_sigma_n_pa": top, "open_tension_ratio": top / peak, "warn": top / peak > TENSION_WARN}


def projected_gap(D, gap: np.ndarray) -> np.ndarray:
    """The gap [m] a face-weighted Lagrange law constrains, per contact row (> 0 open; ``gap_m`` in
    :data:`DEFINITIONS`): g~_a / int Phi_a dA = (D g)_a / Sum_b D_ab, with D_ab = int Phi_a N_b dA [m^2] the
    rows' mortar matrix (``reference_solver.face_law.weighting_matrix``, the ccx mortar reader's
    ``TableProjection.D``: hat or ccx's dual multiplier basis Phi) and ``gap`` the nodal gaps g [m]
    (clearance + n . u), one row per contact row or (states, rows). The law keeps g~ = D g >= 0 and
    lambda . g~ = 0 (reference_solver/face_law.py), so this is >= 0 at every row where it holds and 0 at a
    pressed one; with the hat basis (Phi >= 0) a weighted mean of the gap field over the row's multiplier
    function. A row of D with one entry (a row on no face: D = its area; 4-/3-node faces lumped) keeps its own
    nodal gap exactly. Measured on the quadratic scenario matrix (tests/test_quadratic_offpath_matrix.py): closed
    rows 0 to 5e-21 m (reference lagrange, mortar) and 1.7e-15 - 3.3e-8 m (ccx mortar in its dual basis, the
    largest in mm), every open row > 0 (>= 1e-10 m)."""
    import scipy.sparse as sp
    D = sp.csr_matrix(D)
    g = np.asarray(gap, float)
    share = np.asarray(D.sum(axis=1)).ravel()
    weighted = (D @ g.T).T / share
    return np.where(np.diff(D.indptr) > 1, weighted, g)


def law_gaps(problem, sol) -> np.ndarray:
    """``gap_m`` (states, rows) [m] of a reference solution ``sol`` on ``problem`` (reference_solver): the
    face-weighted Lagrange's :func:`projected_gap` on 8-/6-node faces (``contact_weighting`` 'face' or
    'face-dual'), the solver's nodal gaps elsewhere (nodal laws, penalty laws: they act on the nodal gap field)."""
    if problem.contact_weighting == "nodal" or sol.method != LAGRANGE:
        return sol.gap
    from reference_solver.face_law import weighting_matrix
    return projected_gap(weighting_matrix(problem), sol.gap)


def free_penetration(rows: pd.DataFrame) -> dict:
    """Force-free penetration of one state: {'free_penetration_m', 'free_penetration_nodes' (table node ids,
    sorted), 'free_penetration_warn'} (definition: ``free_penetration_m`` in :data:`DEFINITIONS`)."""
    r = table_rows(rows)
    gap, force = r["gap_m"].to_numpy(float), pressure_force(r)     # the pressure: an 8-node face's corners pull
    ok = np.isfinite(gap) & np.isfinite(force)
    pen = np.where(ok, -gap, 0.0)
    free = ok & (force <= 0.0) & (pen > 0.0)
    loaded = ok & (force > 0.0)
    worst = float(pen[free].max()) if free.any() else 0.0
    floor = PENETRATION_FLOOR * float(np.nanmax(np.abs(r["r"].to_numpy(float)), initial=0.0))
    limit = max(PENETRATION_WARN * (float(pen[loaded].max()) if loaded.any() else 0.0), floor)
    over = free & (pen > limit)
    return {"free_penetration_m": worst, "free_penetration_nodes": sorted(int(n) for n in r["node"].to_numpy()[over]),
            "free_penetration_warn": bool(over.any())}


def lift_over_radius(rows: pd.DataFrame) -> float:
    """Largest table-node opening of one state over the largest table-node radius [-] (0 when nothing is
    open or the source gives no gaps): above :data:`SMALL_STRAIN_LIFT` the lifted side has turned as a
    rigid body far enough that a small-strain analysis and a large-displacement one part ways."""
    r = table_rows(rows)
    gap, rad = r["gap_m"].to_numpy(float), np.abs(r["r"].to_numpy(float))
    ok = np.isfinite(gap) & np.isfinite(rad)
    if not ok.any() or rad[ok].max() <= 0.0:
        return 0.0
    return float(max(gap[ok].max(), 0.0) / rad[ok].max())


def lifted_arc_deg(rows: pd.DataFrame) -> float:
    """Arc [deg] of the azimuths whose every table node is open."""
    r = table_rows(rows)
    g = pd.Series(r["status"].to_numpy() == "open", index=snap_deg(r["theta_deg"].to_numpy(float)))
    up = g.groupby(level=0).all().sort_index()
    return float(np.sum(arc_weights(up.index.to_numpy(float))[up.to_numpy()]))


def tangential_traction(rows: pd.DataFrame) -> pd.Series:
    """tau [Pa] through the wall per azimuth (index theta_deg, sorted) of one state of friction.csv:
    Sum |F_t| / Sum area of the table nodes at the azimuth (>= 0; the magnitude, not a component)."""
    r = table_rows(rows)
    g = pd.DataFrame({"t": snap_deg(r["theta_deg"].to_numpy(float)), "f": r["ft_n"].to_numpy(float),
                      "a": r["area_m2"].to_numpy(float)}).groupby("t", sort=True)
    out = g["f"].sum() / g["a"].sum()
    out.index.name = "theta_deg"
    return out.astype(float)


def tangential_resultant(rows: pd.DataFrame) -> np.ndarray:
    """Vector sum (3,) [N] of the tangential forces F_t (table on body, global xyz) of the given rows."""
    return rows[["ft_x_n", "ft_y_n", "ft_z_n"]].to_numpy(float).sum(axis=0)


def contact_resultant_vector(rows: pd.DataFrame) -> np.ndarray:
    """Vector sum (3,) [N] of the whole contact forces F_n n + F_t (masters on body, global xyz) of the
    given rows of friction.csv; over every row it balances the applied loads: = -(N + T lambda)."""
    return rows[["fn_x_n", "fn_y_n", "fn_z_n"]].to_numpy(float).sum(axis=0) + tangential_resultant(rows)


def section_sides(rows: pd.DataFrame, azimuth_deg: float) -> dict:
    """Through-wall sigma_N [Pa] at the tension side (the load azimuth) and the compression side (+180)."""
    sw = sigma_n_wall(rows)
    th = sw.index.to_numpy(float)
    t, c = periodic_interp(th, sw.to_numpy(), np.array([azimuth_deg % 360.0, (azimuth_deg + 180.0) % 360.0]))
    return {"tension_side_pa": float(t), "compression_side_pa": float(c)}


def beam_theory_sigma(N: float, M_b: float, R: float, t: float, theta_rel_deg) -> np.ndarray:
    """Closed form sigma [Pa] = -N / (2 pi R t) + M_b cos(theta_rel) / (pi R^2 t), theta_rel from the
    tension side (full contact, beam theory)."""
    c = np.cos(np.radians(np.asarray(theta_rel_deg, float)))
    return -N / (2 * np.pi * R * t) + M_b * c / (np.pi * R * R * t)


def ring_line_rel_diff(a: np.ndarray, b: np.ndarray) -> float:
    """max_j |b_j - a_j| / max_j |a_j| of two ring_line_force_n arrays [N] of one state (0 where a is all 0)."""
    scale = float(np.abs(a).max()) if np.size(a) else 0.0
    return 0.0 if scale == 0.0 else float(np.abs(np.asarray(b) - np.asarray(a)).max() / scale)

