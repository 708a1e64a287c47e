"""The contact law every read contact table must obey: a sign that contradicts it is a read error.

Per state (source, method, step, increment), with peak = max |sigma_n| and g = max |gap| of that state,
``LAW_REL`` = 1e-3 and a gap floor ``GAP_FLOOR`` = 1e-8 x the largest radius of the table (1.5e-8 m on
the JAR; a Lagrange state whose gaps are all round-off, ~1e-32 m, has no open node by its
gaps), a row is refused when

- it is in tension (sigma_n > LAW_REL * peak) while closed: penetrating (gap < -max(LAW_REL * p, floor),
  p = the state's largest penetration: a stiff penalty's penetrations are small beside the lift of the
  open nodes),
  or, in a Lagrange-type result (method ``lagrange`` or ``mortar``), not open (gap <= max(LAW_REL * g,
  floor): a Lagrange contact is closed at gap 0);
- it is in compression (sigma_n < -LAW_REL * peak) while open (gap > max(LAW_REL * g, floor)); for a
  Lagrange-type (mortar) row or a ccx face-to-face penalty row (method ``f2f``), while its whole
  neighbourhood is open (its own azimuth and the two beside it: these laws act on face-weighted gaps, a
  half-closed face hands force to its open node, :func:`_neighbourhood_gap`).

The gap judged is the solver's own where the reader has it (column ``law_gap_m``: ccx's ``*CONTACT PRINT``
CDIS normal of a node-to-surface penalty row, printed from the same contact element and solution as its
CSTR pressure), else ``gap_m``. The table's gap_m is the model's clearance + n . u; the solver measures
against its own master (ccx: faceted stop faces) from the deck's node coordinates, and the two differ by
the mesh file's rounding: on an imported Gmsh .bdf skirt (8-character fields, 24 x 6 x 1) stop node 119
sits 3.25e-6 m inside the stop master, so ccx closes it at n . u = 3.2e-6 m (its gap -4.1e-8 m, pressure
K x 4.1e-8 = 4.6e4 Pa, K = 1.12e12 Pa/m) while gap_m reads +3.2e-6 m. ccx's LINEAR law (slope K, tension
sigma_inf at wide clearances; ccx 2.20 springforc_n2f: p = -K c (1/2 + atan(-c/eps)/pi), eps = pi
sigma_inf / K, c its clearance; no c0 there) never compresses at c > 0, and no gap scale of the law (p / K = 4.1e-8 m,
eps ~ 5e-14 m) covers 3.2e-6 m: the law is judged on ccx's gap, not on a widened tolerance.

Face-weighted rows (issue 23, ``deckbridge/dialects/calculix/face_rows.py``) are judged by the pressure, never by
the sign of a nodal force: on 8-node faces a uniform pressure gives the corners -1/12 of p A. Their sigma_n_pa is
a pressure (the L2-projected -M^-1 r of a quadratic mortar job, -CPRESS of a face-to-face one); where the solver's
own pressure differs from the reported one the reader gives it in column ``law_sigma_pa`` and the sign is judged
on it (ccx mortar: -CPRESS, its nodal multiplier, >= 0 by its law, where the L2 projection of the nodal forces
overshoots to tension next to the contact edge: +4 % / +8 % of the peak on hex20r / tet10 24 x 3 x 1 at lambda
0.6), and the gap of a pressed row is the smallest of its faces' nodes (``law_gap_m``).

A tension at an open node is left alone: penalty contacts carry a small one there (GAPUNI f_inf / A,
~1e-2 Pa on the mortar deck's stop), and tables written by hand (tests, other tools) hold beam-theory
tension at lifted nodes.

Measured on real CalculiX 2.20 penalty (node-to-surface and GAPUNI), mortar, friction, mm/outer-stop
runs and the reference solver (16 x 4 x 1/2 meshes): the worst row scored min(|sigma_n| / peak,
|gap| / g) = 1.6e-5 on the wrong side (a mortar node next to a lifted one, compressed with a gap of
4e-7 m); a flipped sign of a step-1 table node scores ~4e-2. The imported .bdf skirt's node-to-surface
penalty job (issue 26): judged on gap_m its worst row scored 1.15e-3 (node 119 above, refused), on ccx's
own CDIS gap no row is on the wrong side (score 0); its sigma_n equals the reference penalty to 3.0e-4 of
the peak, table and stop, at the 9 increments with lift / R <= 0.01. Exempt: method ``linear`` (MYSTRAN's
closed springs carry tension by design and its gap is derived from the force), and a preload
``preload_pa`` column (Nastran PGAP F0 / area, compression < 0) is subtracted before the check.

Where: the reader's optional ``origin`` column (file and line, or record) names the row; the table is
returned without the :data:`EXTRA` columns (``origin``, ``preload_pa``, ``law_gap_m``, ``law_sigma_pa``).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..errors import InputError
from ..methods import LAGRANGE

LAW_REL = 1e-3
GAP_FLOOR = 1e-8          # times the largest |r| of the table (1 m without radii) [m]
LAGRANGE_METHODS = (LAGRANGE, "mortar")
WEIGHTED_METHODS = ("mortar", "f2f")      # laws on face-weighted gaps (ccx mortar, ccx face-to-face penalty)
_STATE = ["source", "method", "step", "increment"]
EXTRA = ("origin", "preload_pa", "law_gap_m", "law_sigma_pa", "law_weighted")   # reader columns only this check uses
# The reference's face-integrated penalty on 8-/6-node faces reports sigma_N as the projection -D^-T r of its
# consistent nodal forces on the hat basis (reference_solver/face_penalty.py): not its law's pointwise pressure
# K max(-g, 0), which it does not write. Near the contact edge the projection of that kinked pressure rings to
# either sign (measured on the quadratic scenario-matrix cases, 16 x 4 x n_r, lambda <= 1: compression at open
# rows up to 4.5 % of the state's peak, tension at penetrating rows 0.19 %): such rows (reader column
# ``law_weighted``) are judged on their neighbourhood, as mortar, at this fraction of the peak; a flipped sign
# scores ~1.
PROJECTED_REL = 0.1


def _neighbourhood_gap(df: pd.DataFrame, gap: np.ndarray, group: np.ndarray) -> np.ndarray:
    """Per row, the smallest gap [m] of its state and surface at its own azimuth and the two azimuths beside it
    (every through-wall node). A mortar (weak) contact constrains the gap weighted over a node's faces, so a node
    at the edge of the contact patch may press with a small positive gap of its own while a neighbour is closed
    (measured: 1.2e-7 and 8.9e-7 m at -11.4 and -4.6 MPa on 16 x 4 x n_r ccx mortar runs): it is open by its law
    only where its whole neighbourhood is."""
    surf = df["surface"].astype(str).to_numpy() if "surface" in df.columns else np.full(len(df), "")
    key = pd.Series(group).astype(str).to_numpy() + "|" + surf
    theta = np.round(pd.to_numeric(df["theta_deg"], errors="coerce").to_numpy(float), 6)
    out = np.full(len(df), np.inf)
    for k in np.unique(key):
        rows = np.flatnonzero(key == k)
        cols, idx = np.unique(theta[rows], return_inverse=True)
        g = np.full(cols.size, np.inf)
        np.minimum.at(g, idx, np.nan_to_num(gap[rows], nan=np.inf))
        around = np.minimum(g, np.minimum(np.roll(g, 1), np.roll(g, -1))) if cols.size > 2 else np.full_like(g, g.min())
        out[rows] = around[idx]
    return out


def check_contact_law(df: pd.DataFrame, path) -> pd.DataFrame:
    """Raise :class:`InputError` on the first row whose sign contradicts the contact law; return
    ``df`` without the :data:`EXTRA` columns. sigma_n_pa [Pa] < 0 compression, gap_m [m] > 0 open."""
    if not {"sigma_n_pa", "gap_m"} <= set(df.columns) or len(df) == 0:
        return df.drop(columns=[c for c in EXTRA if c in df.columns])
    raw = pd.to_numeric(df["sigma_n_pa"], errors="coerce").to_numpy(float)
    s = raw - np.nan_to_num(df["preload_pa"].to_numpy(float)) if "preload_pa" in df.columns else raw
    if "law_sigma_pa" in df.columns:        # the solver's own pressure beside a projected one (face-weighted rows)
        own_s = pd.to_numeric(df["law_sigma_pa"], errors="coerce").to_numpy(float)
        s = np.where(np.isfinite(own_s), own_s, s)
    gap = pd.to_numeric(df["gap_m"], errors="coerce").to_numpy(float)
    if "law_gap_m" in df.columns:           # the solver's own gap beside its pressure, where it printed one
        own = pd.to_numeric(df["law_gap_m"], errors="coerce").to_numpy(float)
        gap = np.where(np.isfinite(own), own, gap)
    method = df["method"].astype(str).to_numpy() if "method" in df.columns else np.full(len(df), "")
    keys = [c for c in _STATE if c in df.columns]
    group = df.groupby(keys, sort=False).ngroup().to_numpy() if keys else np.zeros(len(df), int)
    peak = pd.Series(np.abs(s)).groupby(group).transform("max").to_numpy()
    gmax = pd.Series(np.abs(gap)).groupby(group).transform("max").fillna(0.0).to_numpy()
    pmax = pd.Series(np.clip(-gap, 0.0, None)).groupby(group).transform("max").fillna(0.0).to_numpy()
    r = pd.to_numeric(df["r"], errors="coerce").abs().max() if "r" in df.columns else np.nan
    floor = GAP_FLOOR * (float(r) if np.isfinite(r) and r > 0 else 1.0)
    tol_s, tol_g, tol_p = LAW_REL * peak, np.maximum(LAW_REL * gmax, floor), np.maximum(LAW_REL * pmax, floor)
    lagrange = np.isin(method, LAGRANGE_METHODS)
    face = df["law_weighted"].fillna(False).to_numpy(bool) if "law_weighted" in df.columns else np.zeros(len(df), bool)
    tol_s = np.where(face, PROJECTED_REL * peak, tol_s)
    with np.errstate(invalid="ignore"):
        closed = (gap < -tol_p) | (lagrange & (gap <= tol_g))
        opened = gap > tol_g
        weighted = lagrange | np.isin(method, WEIGHTED_METHODS) | face
        if weighted.any() and "theta_deg" in df.columns:   # mortar, face-to-face: laws on weighted gaps
            opened &= ~weighted | (_neighbourhood_gap(df, gap, group) > tol_g)
            if face.any():      # a projected pressure: closed where every node around penetrates
                closed &= ~face | (-_neighbourhood_gap(df, -gap, group) < -tol_p)
        tension, compression = s > tol_s, s < -tol_s
    live = method != "linear"
    rules = [
        (live & tension & closed, "tension in a closed contact"),
        (live & compression & opened, "compression in an open contact"),
    ]
    for bad, what in rules:
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            row = df.iloc[i]
            where = row["origin"] if "origin" in df.columns and isinstance(row["origin"], str) else repr(str(path))
            state = ", ".join(f"{k} {row[k]}" for k in keys + [c for c in ("node", "surface") if c in df.columns])
            n = int(bad.sum())
            raise InputError(f"{where}: sigma_n = {raw[i]:.6g} Pa with gap {gap[i]:.6g} m at {state}: {what} "
                             f"contradicts the contact law ({n} row{'s' if n > 1 else ''} so: a flipped sign, or "
                             "results of another sign convention)")
    return df.drop(columns=[c for c in EXTRA if c in df.columns])
