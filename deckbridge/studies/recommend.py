"""What "the penalty reproduces Lagrange" means, and the penalty to write in a deck, in the deck's terms.

One definition serves the sweep's recommendation (:mod:`.sweep`) and the report's verdict
(:mod:`deckbridge.report.verdict`), so that the two cannot disagree. A penalty case *reproduces
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
