"""Metrics of a penalty sweep against the Lagrange reference, per mesh variant and k-factor.

The comparison is the comparator's (:mod:`deckbridge.compare`): sigma_N(theta) profiles (through-
wall mean per azimuth), aligned on azimuth, compared at the same load factors for every k — by
default the comparator's: end of step 1, first liftoff of any source, end of step 2. Per k and
compared load factor lambda:

- ``max_abs_diff_pa``: max over theta of |sigma_N(penalty) - sigma_N(Lagrange)| [Pa];
- ``rel_diff``: that over |peak compression of Lagrange at lambda| [-];
- ``liftoff_zone_iou``: intersection over union of the liftoff zones (1 when neither lifts off);
- ``peak_compression_pa``: the most compressive sigma_N of the profile (< 0) and its azimuth.

Per k also: the liftoff load factor (bisected onset of the first table node, from the solver),
the most compressive node value over the load path and the largest tension (open gaps of penalty
carry k_open * gap). A k-factor is *within tol* when rel_diff <= tol at every compared lambda; the
recommended k-factor is the smallest such k (None when none is).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..compare import ComparisonResult, compare_series
from ..jsonable import json_clean
from ..compare.series import series_of
from ..results import SourceResult
from .cases import Case, MeshVariant
from ..methods import AUGMENTED, LAGRANGE, PENALTY

SIG_DIGITS = 10        # floats in summary.json: stable across re-runs, far below any physical meaning


def rnd(x):
    """Round floats to SIG_DIGITS significant digits (recursively); non-finite -> None."""
    return json_clean(x, SIG_DIGITS)


@dataclass
class VariantResult:
    """Everything measured on one mesh variant."""
    variant: MeshVariant
    comparison: ComparisonResult | None
    lagrange: dict
    per_k: list[dict]
    rows: list[dict]
    recommended_k_factor: float | None
    errors: dict = field(default_factory=dict)
    augmented: list[dict] = field(default_factory=list)   # per k-factor, as per_k (flat: it is exact at any k)


def _table_stats(df: pd.DataFrame) -> dict:
    t = df[df["surface"] == "table"]["sigma_n_pa"].to_numpy(float)
    return {"node_peak_compression_pa": float(t.min()) if t.size else None,
            "max_tension_pa": float(max(t.max(), 0.0)) if t.size else None}


def variant_metrics(variant: MeshVariant, cases: list[Case], tables: dict[str, pd.DataFrame],
                    records: dict[str, dict], tol: float, load_factors: list[float] | None = None,
                    series: dict | None = None) -> VariantResult:
    """Compare every penalty case of ``variant`` with its Lagrange case.

    ``tables`` / ``records``: by case id, the stored table and record (a record with 'error' is a
    case that failed; it is listed, not compared). ``series``: by case id, ``series_of(table, label)``
    already built from the same stored table (the sweep builds them while the workers still run);
    the others are built here.
    """
    series = series or {}
    of = lambda c: series[c.case_id] if c.case_id in series else series_of(tables[c.case_id], c.label)  # noqa: E731
    lag = next(c for c in cases if c.method == LAGRANGE)
    pens = sorted((c for c in cases if c.method == PENALTY), key=lambda c: c.k_factor)
    augs = sorted((c for c in cases if c.method == AUGMENTED), key=lambda c: c.k_factor)
    errors = {c.label: records[c.case_id]["error"] for c in cases if records[c.case_id].get("error")}
    lrec = records[lag.case_id]
    lagrange = {"case_id": lag.case_id, "error": lrec.get("error")}
    if lrec.get("error"):
        per_k = [{"k_factor": c.k_factor, "case_id": c.case_id, "error": records[c.case_id].get("error")
                  or "no Lagrange reference on this mesh", "within_tol": False} for c in pens]
        return VariantResult(variant, None, lagrange, per_k, [], None, errors)

    ok = [c for c in pens + augs if not records[c.case_id].get("error")]
    # with each case's solver summary the onsets are the solver's exact ones, the numbers summary.json gives
    comp = compare_series([of(lag)] + [of(c) for c in ok], load_factors,
                          {c.label: SourceResult(tables[c.case_id], summary=records[c.case_id].get("summary"))
                           for c in [lag] + ok})
    ls = lrec["summary"]
    lagrange.update({
        "liftoff_load_factor": ls["liftoff_load_factor"], "liftoff_theta_deg": ls["liftoff_theta_deg"],
        **_table_stats(tables[lag.case_id]),
        "peak_compression_pa": {f"{p.load_factor:g}": p.peaks[lag.label][0] for p in comp.points},
        "peak_compression_theta_deg": {f"{p.load_factor:g}": p.peaks[lag.label][1] for p in comp.points},
        "liftoff_zones": {f"{p.load_factor:g}": p.zones[lag.label] for p in comp.points},
        "dofs": ls["dofs"], "contact_rows": ls["contact_rows"],
        "k_tangent_rigid": bool(ls.get("k_tangent_rigid", False)),     # the limit of following springs
    })
    rows, per_k = [], []
    for pt in comp.points:
        lp = pt.peaks[lag.label]
        rows.append({"mesh": variant.label, "method": LAGRANGE, "k_factor": None, "case_id": lag.case_id,
                     "load_factor": pt.load_factor, "what": pt.what, "max_abs_diff_pa": None, "rel_diff": None,
                     "theta_of_max_diff_deg": None, "rms_diff_pa": None, "liftoff_zone_iou": None,
                     "peak_compression_pa": lp[0], "peak_compression_theta_deg": lp[1],
                     "lagrange_peak_compression_pa": lp[0], "within_tol": None,
                     "liftoff_load_factor": ls["liftoff_load_factor"], "liftoff_theta_deg": ls["liftoff_theta_deg"]})
    def versus(c: Case, per_k: list) -> None:
        rec = records[c.case_id]
        if rec.get("error"):
            per_k.append({"k_factor": c.k_factor, "case_id": c.case_id, "error": rec["error"], "within_tol": False})
            return
        s = rec["summary"]
        kstat = (s.get("penalty_k") or {}).get("table") or {}
        by_lf = []
        for pt in comp.points:
            if c.label not in pt.labels:
                continue
            pair = next(p for p in pt.pairs if p["a"] == lag.label and p["b"] == c.label)
            lpeak = abs(pt.peaks[lag.label][0])
            rel = pair["max_abs_diff_pa"] / lpeak if lpeak > 0 else math.inf
            item = {"load_factor": pt.load_factor, "what": pt.what, "max_abs_diff_pa": pair["max_abs_diff_pa"],
                    "rel_diff": rel, "theta_of_max_diff_deg": pair["theta_of_max_diff_deg"],
                    "rms_diff_pa": pair["rms_diff_pa"], "liftoff_zone_iou": pair["liftoff_zone_overlap"],
                    "peak_compression_pa": pt.peaks[c.label][0],
                    "peak_compression_theta_deg": pt.peaks[c.label][1],
                    "lagrange_peak_compression_pa": pt.peaks[lag.label][0], "within_tol": bool(rel <= tol)}
            by_lf.append(item)
            rows.append({"mesh": variant.label, "method": c.method, "k_factor": c.k_factor, "case_id": c.case_id,
                         **item, "liftoff_load_factor": s["liftoff_load_factor"],
                         "liftoff_theta_deg": s["liftoff_theta_deg"]})
        worst = max(by_lf, key=lambda d: d["rel_diff"])
        prim = by_lf[-1]
        per_k.append({
            "k_factor": c.k_factor, "case_id": c.case_id, "penalty_k_mean_n_per_m": kstat.get("mean"),
            "max_abs_diff_pa": max(d["max_abs_diff_pa"] for d in by_lf), "max_rel_diff": worst["rel_diff"],
            "worst_load_factor": worst["load_factor"],
            "liftoff_zone_iou": prim["liftoff_zone_iou"], "min_liftoff_zone_iou": min(d["liftoff_zone_iou"] for d in by_lf),
            "peak_compression_pa": prim["peak_compression_pa"],
            "peak_compression_theta_deg": prim["peak_compression_theta_deg"],
            **_table_stats(tables[c.case_id]),
            "liftoff_load_factor": s["liftoff_load_factor"], "liftoff_theta_deg": s["liftoff_theta_deg"],
            "within_tol": all(d["within_tol"] for d in by_lf), "by_load_factor": by_lf,
        })
    for c in pens:
        versus(c, per_k)
    augmented: list[dict] = []
    for c in augs:
        versus(c, augmented)
    passing = [d["k_factor"] for d in per_k if d["within_tol"]]
    return VariantResult(variant, comp, lagrange, per_k, rows, min(passing) if passing else None, errors, augmented)


def monotone(values: list[float]) -> bool:
    """True when the values never increase."""
    return all(b <= a for a, b in zip(values, values[1:]))
