"""The layout of the report's verdict section (plain-text lines and rows; the template only places them).
The verdict itself is computed by :mod:`deckbridge.studies.verdict` and handed to the report."""

from __future__ import annotations

import math

from .. import summary_keys as K
from ..model import Model
from ..methods import LAGRANGE


def _pct(v) -> str:
    return "–" if v is None else ("∞" if math.isinf(v) else f"{100 * v:.3g} %")


def _lam(v) -> str:
    return "no liftoff" if v is None else f"{v:.4g}"


def verdict_view(verdict: dict, measured: list[dict], model: Model) -> dict:
    """Plain-text lines and rows of the report's verdict section (the template only lays them out)."""
    if verdict.get("error"):
        return {"head": f"No verdict on the penalty: {verdict['error']}", "advice": "", "command": "", "definition": "",
                "head_row": [], "rows": [], "measured": [], "measured_head": []}
    mp, rec, lag = verdict["model_penalty"], verdict["recommended"], verdict[LAGRANGE]
    what = ("the model's penalty (" + ("α = " + format(mp["alpha"], "g") if mp["alpha"] is not None
                                       else "k_normal") + ", k-factor 1: the k_c per node of the reference penalty, "
            "the Nastran PGAP KA and the Abaqus / CalculiX penalty decks)")
    head = (f"{'CONVERGED' if mp['converged'] else 'NOT CONVERGED'}: {what}: worst |ΔσN| = {_pct(mp['max_rel_diff'])} "
            f"of the Lagrange peak (at λ = {mp['worst_load_factor']:.4g}), onset λ = {_lam(mp['liftoff_load_factor'])} "
            f"against Lagrange {_lam(lag['liftoff_load_factor'])} ({_pct(mp['onset_rel_diff'])}), largest penetration "
            f"{mp['penetration_m'] * 1e3:.3g} mm = {_pct(mp['penetration_over_t'])} of t "
            f"(tolerance: {_pct(verdict['tol'])} of the peak, onset {_pct(verdict['onset_tol'])}).")
    if rec is None:
        advice = ("No k-factor up to the penalty range's limit (k_c ≤ 1e4 E A / h) reproduces Lagrange within the "
                  "tolerance: use the Lagrange deck, or a looser tolerance.")
    else:
        advice = (f"Write in the deck (units {model.units}): {verdict['recommended_text']}; it reproduces Lagrange "
                  f"here with worst |ΔσN| = {_pct(rec['max_rel_diff'])}, onset {_pct(rec['onset_rel_diff'])}, "
                  f"penetration {_pct(rec['penetration_over_t'])} of t.")
        if rec["k_factor"] == 1.0:
            advice = f"Keep the deck's penalty (units {model.units}): {verdict['recommended_text']}."
    rows = [[f"{r['k_factor']:g}", "–" if r.get("alpha") is None else f"{r['alpha']:.4g}",
             "–" if "ka_min" not in r else f"{r['ka_min']:.4g} … {r['ka_max']:.4g}",
             _pct(r.get("max_rel_diff")), _pct(r.get(K.ONSET_REL_DIFF)), _pct(r.get("penetration_over_t")),
             "yes" if r[K.REPRODUCES] else ("error: " + r["error"] if r.get("error") else "no")]
            for r in verdict["evaluated"]]
    unit = mp["unit"]
    meas = [[m["source"], m["against"], _pct(m["max_rel_diff"]), f"{_lam(m['liftoff_load_factor'])} / "
             f"{_lam(m['lagrange_liftoff_load_factor'])}", _pct(m[K.ONSET_REL_DIFF]), _pct(m["penetration_over_t"])]
            for m in measured]
    return {"head": head, "advice": advice, "command": verdict["command"], "definition": verdict["definition"],
            "head_row": ["k-factor", "α", f"KA per node [{unit}]", "worst |ΔσN| / peak", "onset difference",
                         "penetration / t", "reproduces Lagrange"],
            "rows": rows, "measured": meas,
            "measured_head": ["penalty source", "against", "worst |ΔσN| / peak", "onset λ (this / Lagrange)",
                              "onset difference", "penetration / t"]}
