"""The paper's two claims (FIG. 4), measured per study variant, and the tidy table of the compared quantities.

Claim 1: at one load factor lambda, the penalty model shows sigma > 0 in its lifted zones (azimuths
whose every table node is open) while the Lagrange model shows sigma <= 0 at every azimuth.
Claim 2: the peak |sigma| over the azimuth, against the penalty factor k, is monotone; the paper
says it *falls* as k grows, and that some k reproduces Lagrange (within ``tol`` x the Lagrange peak).

Both are judged per quantity of :mod:`deckbridge.quantities`: contact sigma_N through the wall
(``sigma_n_wall_pa``) and the base-wall sigma_zz on the inner face, the outer face and through-wall
mean (``szz_inner_pa``, ``szz_outer_pa``, ``szz_mean_pa``; present when the case was solved with field
recovery). "> 0" means above ``ZERO`` x the Lagrange peak |sigma| of that quantity (numerical zero).
Every number is of a solved state (the state of step 2 nearest to lambda; its own load factor is
reported), never interpolated. Onsets per method: first table node open (bisected by the solver)
and whole section (every node of one azimuth open, :func:`deckbridge.wall_stress.reference_section_onset`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import summary_keys as K
from ..azimuth import snap_deg
from ..methods import LAGRANGE, PENALTY
from ..quantities import CLAIM_QUANTITIES, DEFINITIONS, sigma_n_wall, table_rows

QUANTITIES = CLAIM_QUANTITIES
ZERO = 1e-6
TIDY_COLUMNS = ["case_id", "mesh", "grid", "method", "k_factor", "load_factor", "quantity", "theta_deg",
                "value", "unit"]


def _state(lfs: np.ndarray, lam: float) -> float:
    return float(lfs[np.argmin(np.abs(lfs - lam))])


def profiles(table: pd.DataFrame, wall: pd.DataFrame | None, lam: float) -> tuple[float, dict, pd.Series]:
    """(load factor of the state used, {quantity: Series over theta}, lifted Series[bool] over theta)."""
    s2 = table[table["step"] == 2]
    lf = _state(s2["load_factor"].to_numpy(float), lam)
    rows = s2[s2["load_factor"] == lf]
    out = {"sigma_n_wall_pa": sigma_n_wall(rows)}
    t = table_rows(rows)
    lifted = (pd.Series((t["status"] == "open").to_numpy(), index=snap_deg(t["theta_deg"].to_numpy(float)))
              .groupby(level=0).all().sort_index())
    if wall is not None:
        w2 = wall[wall["step"] == 2]
        w = w2[w2["load_factor"] == _state(w2["load_factor"].to_numpy(float), lf)]
        for q in QUANTITIES[1:]:
            out[q] = pd.Series(w[q].to_numpy(float), index=snap_deg(w["theta_deg"].to_numpy(float))).sort_index()
    return lf, out, lifted


def _direction(v: list[float]) -> str:
    d = np.diff(v)
    if len(v) < 2:
        return "one k only"
    if np.all(d < 0):
        return "falls"
    if np.all(d > 0):
        return "rises"
    return "non-monotone"


def variant_claims(variant, cases, tables: dict, walls: dict, records: dict, lam: float, tol: float) -> tuple[dict, list]:
    """(verdict dict, tidy rows) of one variant at load factor ``lam``."""
    grid = variant.grid_label
    lag = next(c for c in cases if c.method == LAGRANGE)
    pens = sorted((c for c in cases if c.method == PENALTY and not records[c.case_id].get("error")),
                  key=lambda c: c.k_factor)
    follows = bool((records[lag.case_id].get("summary") or {}).get(K.K_TANGENT_FOLLOWS_K,
                                                                  variant.model.contact.penalty.k_tangent_follows))
    springs = variant.model.contact.tangential == "springs"
    out = {"variant": variant.label, "mesh": variant.mesh_label, "grid": dict(variant.grid), "grid_label": grid,
           "load_factor_requested": lam, K.K_TANGENT_FOLLOWS_K: follows,
           "lagrange_depends_on_alpha": False,
           "lagrange_depends_on_alpha_note": (
               ("k_tangent follows alpha: the penalty cases scale the circumferential springs with k "
                "(k_t = k-factor x k_c); the Lagrange reference is their limit k -> infinity, rigid springs "
                "(no circumferential motion of the table nodes), so it does not move with alpha")
               if follows and springs else
               ("k_tangent follows alpha: the penalty stick slope scales with k; the Lagrange reference "
                "sticks exactly, their limit k -> infinity" if follows else
                "k_tangent is a fixed N/m: penalty and Lagrange carry the same springs; the Lagrange result "
                "does not depend on alpha"))}
    if records[lag.case_id].get("error"):
        out["error"] = records[lag.case_id]["error"]
        return out, []
    rows = []
    prof = {}
    for c in [lag] + pens:
        lf, p, lifted = profiles(tables[c.case_id], walls.get(c.case_id), lam)
        prof[c.case_id] = (lf, p, lifted)
        for q, ser in p.items():
            unit = DEFINITIONS[q].unit
            base = {"case_id": c.case_id, "mesh": variant.mesh_label, "grid": grid, "method": c.method,
                    "k_factor": c.k_factor, "load_factor": lf, "quantity": q, "unit": unit}
            rows += [{**base, "theta_deg": float(t), "value": float(v)} for t, v in ser.items()]
            rows.append({**base, "theta_deg": "peak", "value": float(np.max(np.abs(ser.to_numpy())))})
    lf0, lp, _ = prof[lag.case_id]
    out["load_factor"] = lf0
    rec = lambda c: records[c.case_id]["summary"]  # noqa: E731
    out["onsets"] = {LAGRANGE: {"first_node": rec(lag)["liftoff_load_factor"],
                                  "whole_section": rec(lag).get(K.SECTION_LIFTOFF_LOAD_FACTOR)},
                     PENALTY: [{"k_factor": c.k_factor, "first_node": rec(c)["liftoff_load_factor"],
                                  "whole_section": rec(c).get(K.SECTION_LIFTOFF_LOAD_FACTOR)} for c in pens]}
    c1, c2 = {}, {}
    for q in QUANTITIES:
        if q not in lp or any(q not in prof[c.case_id][1] for c in pens):
            continue
        lag_peak = float(np.max(np.abs(lp[q].to_numpy())))
        zero = ZERO * lag_peak
        lag_max = float(lp[q].max())
        per_k, peaks = [], []
        for c in pens:
            _, p, lifted = prof[c.case_id]
            ser = p[q]
            zone = ser[lifted.reindex(ser.index, fill_value=False).to_numpy()]
            mx = float(zone.max()) if zone.size else None
            per_k.append({"k_factor": c.k_factor, "max_in_lifted_pa": mx, "lifted_azimuths": int(zone.size),
                          "holds": bool(mx is not None and mx > zero and lag_max <= zero)})
            peaks.append(float(np.max(np.abs(ser.to_numpy()))))
        ks = [c.k_factor for c in pens]
        c1[q] = {"holds": any(d["holds"] for d in per_k), "holds_for_k": [d["k_factor"] for d in per_k if d["holds"]],
                 "lagrange_max_pa": lag_max, "lagrange_le_zero_everywhere": bool(lag_max <= zero), PENALTY: per_k}
        within = [k for k, pk in zip(ks, peaks) if abs(pk - lag_peak) <= tol * lag_peak]
        direction = _direction(peaks)
        c2[q] = {"holds": direction == "falls", "direction": direction, "k_factors": ks, "peak_abs_pa": peaks,
                 "lagrange_peak_abs_pa": lag_peak, "reproduces_lagrange_at_k": within, "tol": tol}
    out["claim1"], out["claim2"] = c1, c2
    return out, rows


def tidy_frame(rows: list[dict], variants) -> pd.DataFrame:
    """The tidy table; one extra column per grid key (its value in the case's variant)."""
    df = pd.DataFrame(rows, columns=TIDY_COLUMNS)
    keys = []
    for v in variants:
        keys += [k for k, _ in v.grid if k not in keys]
    by_label = {v.grid_label: dict(v.grid) for v in variants}
    for k in keys:
        df.insert(3, k, [("follow" if by_label.get(g, {}).get(k, "") is None else by_label.get(g, {}).get(k, ""))
                         for g in df["grid"]])
    return df
