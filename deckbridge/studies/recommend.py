"""What "the penalty reproduces Lagrange" means, and the penalty to write in a deck, in the deck's terms.

One definition serves the sweep's recommendation (:mod:`.sweep`) and the report's verdict
(:mod:`deckbridge.studies.verdict`), so that the two cannot disagree. A penalty case *reproduces
Lagrange* within ``tol`` when

- the contact stress: max over theta of |sigma_N(penalty) - sigma_N(Lagrange)| <= tol x |Lagrange peak
  compression| at every compared load factor (the sweep's ``within_tol``), and
- the onset: |lambda_onset(penalty) - lambda_onset(Lagrange)| <= onset_tol x lambda_onset(Lagrange), the
  bisected liftoff of the first table node (both lifting off or neither; one alone fails).

A k-factor f multiplies every node's normal stiffness k_c = alpha A^2 K / V (or ``k_normal``): it is
alpha' = f alpha, and the Nastran PGAP KA / Abaqus or CalculiX penalty slope of node i is f k_c,i. With
``contact.penalty.k_tangent`` following (null) the tangential stiffness is the same f k_c,i per table
node; a fixed k_t is not scaled. Deck values are in the deck's units (``units``: SI N/m, mm N/mm).
"""

from __future__ import annotations

import numpy as np

from .. import summary_keys as K
from ..units import scale


def onset_gap(pen_lambda: float | None, lag_lambda: float | None) -> float | None:
    """|lambda_pen - lambda_lag| / lambda_lag [-]; 0 when neither lifts off, inf when only one does."""
    if pen_lambda is None and lag_lambda is None:
        return 0.0
    if pen_lambda is None or lag_lambda is None or lag_lambda <= 0:
        return float("inf")
    return abs(pen_lambda - lag_lambda) / lag_lambda


def reproduces(per_k: dict, lagrange: dict, tol: float, onset_tol: float | None = None) -> bool:
    """True when one sweep row ``per_k`` (:func:`.metrics.variant_metrics`) reproduces ``lagrange``:
    stress within ``tol`` at every compared load factor and onset within ``onset_tol`` (default tol)."""
    if per_k.get("error") or not per_k.get("within_tol"):
        return False
    gap = onset_gap(per_k.get("liftoff_load_factor"), lagrange.get("liftoff_load_factor"))
    return gap <= (tol if onset_tol is None else onset_tol)


def node_stiffness(mesh) -> np.ndarray:
    """k_c of every table slave node at k-factor 1 [N/m] (the model's alpha rule or k_normal)."""
    return np.asarray(mesh.table.k, float)


def deck_terms(model, k_c: np.ndarray, k_factor: float) -> dict:
    """The penalty of k-factor ``k_factor`` in a deck's terms: alpha, KA per node (min, max, in the deck's
    units), k_t, and their unit label."""
    pen = model.contact.penalty
    f = scale(model.units).stiffness
    unit = "N/m" if model.units == "SI" else "N/mm"
    ka = k_factor * k_c * f
    if pen.k_tangent is None:
        kt = {"k_t_min": float(ka.min()), "k_t_max": float(ka.max()), "k_t_rule": "follows KA (k_t = KA per node)"}
    else:
        kt = {"k_t_min": pen.k_tangent * f, "k_t_max": pen.k_tangent * f, "k_t_rule": "fixed (contact.penalty.k_tangent)"}
    return {"k_factor": k_factor, "alpha": None if pen.k_normal is not None else pen.alpha * k_factor,
            "ka_min": float(ka.min()), "ka_max": float(ka.max()), "unit": unit, "units": model.units, **kt}


def terms_text(t: dict) -> str:
    """'k-factor 100 (alpha = 10): KA 1.2e+09 ... 2.4e+09 N/m per node, k_t = KA' — one line."""
    alpha = "" if t["alpha"] is None else f" (alpha = {t['alpha']:.4g})"
    ka = _range(t["ka_min"], t["ka_max"])
    kt = "k_t = KA per node" if t["k_t_rule"].startswith("follows") else f"k_t = {_range(t['k_t_min'], t['k_t_max'])} {t['unit']}"
    return f"k-factor {t['k_factor']:g}{alpha}: KA = {ka} {t['unit']} per node, {kt}"


def _range(lo: float, hi: float) -> str:
    return f"{lo:.4g}" if np.isclose(lo, hi, rtol=1e-9) else f"{lo:.4g} … {hi:.4g}"


def variant_name(variant) -> str:
    """A grid point named by its keys and values: 'mesh 24x6x1, contact.penalty.open_ratio=0.001'."""
    parts = [f"mesh {variant.mesh_label}"]
    parts += [f"{k}={'follow' if v is None else v}" for k, v in variant.grid]
    return ", ".join(parts)


def variant_recommendation(variant, k_c: np.ndarray, per_k: list[dict], lagrange: dict, tol: float,
                           onset_tol: float | None = None) -> dict:
    """Mark every row of ``per_k`` with 'onset_rel_diff' and 'reproduces' (in place) and return the grid
    point's recommendation: its name, the smallest k-factor that reproduces Lagrange (None when none
    does) in deck terms (:func:`deck_terms`; ``k_c`` the variant's node stiffness at k-factor 1 [N/m]), and
    one line saying so (or what the stiffest k-factor still misses)."""
    for d in per_k:
        d[K.ONSET_REL_DIFF] = (None if d.get("error") else
                               onset_gap(d.get("liftoff_load_factor"), lagrange.get("liftoff_load_factor")))
        d[K.REPRODUCES] = bool(not lagrange.get("error") and reproduces(d, lagrange, tol, onset_tol))
    name = variant_name(variant)
    ok = [d["k_factor"] for d in per_k if d[K.REPRODUCES]]
    if ok:
        terms = deck_terms(variant.model, k_c, min(ok))
        return {"name": name, **terms, "text": f"{name}: {terms_text(terms)}"}
    rows = [d for d in per_k if not d.get("error")]
    if lagrange.get("error") or not rows:
        why = "no Lagrange reference" if lagrange.get("error") else "every penalty case failed"
        return {"name": name, "k_factor": None, "text": f"{name}: none ({why})"}
    top = max(rows, key=lambda d: d["k_factor"])
    og = top[K.ONSET_REL_DIFF]
    return {"name": name, "k_factor": None,
            "text": (f"{name}: none up to k-factor {top['k_factor']:g} (there worst |dsigma_N| = "
                     f"{100 * top['max_rel_diff']:.3g} % of the Lagrange peak, onset "
                     + ("only one method lifts off" if og == float("inf") else f"{100 * og:.3g} % off") + ")")}


def overall_recommendation(k_factors, variants, k_cs: list[np.ndarray], recs: list[dict],
                           per_ks: list[list[dict]], tol: float) -> dict:
    """The smallest k-factor that reproduces Lagrange at every grid point (None when none does), its
    alpha(s) and the KA range over the grid points in the deck's units, and a note naming each grid
    point's own answer."""
    every = [k for k in k_factors if all(any(d["k_factor"] == k and d.get(K.REPRODUCES) for d in pk) for pk in per_ks)]
    k = min(every) if every else None
    many = len(recs) > 1
    head = (f"reproduces Lagrange (max |dsigma_N| <= {tol:g} x |Lagrange peak compression| at every compared load "
            f"factor and the first-node onset within {tol:g} x the Lagrange onset)")
    where = (" at every grid point" if many else "") + "; per grid point: " + "; ".join(r["text"] for r in recs)
    if k is None:
        return {"k_factor": None, "note": f"no k-factor of the sweep {head}{where}"}
    terms = [deck_terms(v.model, kc, k) for v, kc in zip(variants, k_cs)]
    alphas = sorted({t["alpha"] for t in terms if t["alpha"] is not None})
    units = sorted({t["unit"] for t in terms})
    return {"k_factor": k, "alpha": alphas, "ka_min": min(t["ka_min"] for t in terms),
            "ka_max": max(t["ka_max"] for t in terms), "unit": ", ".join(units),
            "note": f"smallest k-factor that {head}{where}"}
