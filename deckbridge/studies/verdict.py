"""The verdict on each penalty source (computed here, laid out by :mod:`deckbridge.report.verdict`): is the penalty converged against Lagrange on this
model, how deep do the nodes penetrate, and what KA (and k_t) to write in the deck for a stated tolerance.

:func:`penalty_verdict` answers for the model's own penalty (k-factor 1, the k_c = alpha A^2 K / V of
every slave node, which the Nastran PGAP KA, the Abaqus / CalculiX penalty slopes and the reference
penalty all carry) with the sweep's own machinery (:mod:`deckbridge.studies.tasks`,
:mod:`deckbridge.studies.metrics`) and the sweep's definition of "reproduces Lagrange"
(:func:`deckbridge.studies.recommend.reproduces`: stress within tol x peak at every compared load factor
and the first-node onset within onset_tol x lambda_onset), so that ``deckbridge sweep`` with the
k-factors it names gives the same call. The Lagrange reference is the sweep's: the limit k -> infinity
of the penalty (tangential springs rigid when k_t follows k_n).

The KA is found by solving, not extrapolated: one condensation (the sparse factor of the model, done once),
then the load path at k-factors 1, 10, 100, ... (while the penalty stays within
:data:`deckbridge.solve.PENALTY_RATIO`) until one reproduces Lagrange, then 1/5 and 1/2 of that decade;
the recommendation is the smallest k-factor solved that reproduces. Cost: a few load paths on the
condensed system (about 1 s each on the default 72 x 30 x 2 mesh).

:func:`measured_rows` adds, per penalty source of a comparison (reference, CalculiX, ...), what the run
itself measured against its Lagrange source: worst |Delta sigma_N| / peak, onset difference, penetration / t.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from .. import summary_keys as K
from ..compare.series import series_of
from ..errors import DeckbridgeError
from ..methods import LAGRANGE, PENALTY
from ..model import Model
from ..solve import PENALTY_RATIO, penalty_ratio
from .cases import Case, mesh_variants
from .metrics import variant_metrics
from .recommend import deck_terms, node_stiffness, onset_gap, reproduces, terms_text
from .tasks import Condensed, condense_variant, solve_case

DEFAULT_TOL = 0.02


def penetration(table: pd.DataFrame) -> float:
    """Largest penetration of a closed table node into the table over the load path [m] (>= 0; gap < 0)."""
    t = table[(table["surface"] == "table") & (table["status"] == "closed")]["gap_m"].to_numpy(float)
    t = t[np.isfinite(t)]
    return float(max(0.0, -t.min())) if t.size else 0.0


def _ladder(model: Model) -> list[float]:
    top = PENALTY_RATIO[1] / penalty_ratio(model, 1.0)
    out, k = [], 1.0
    while k <= top * (1 + 1e-12):
        out.append(k)
        k *= 10.0
    return out


def penalty_verdict(model: Model, tol: float = DEFAULT_TOL, onset_tol: float | None = None,
                    model_path: str = "MODEL", condensed: tuple | None = None) -> dict:
    """The verdict on the model's penalty and the recommended deck penalty (see the module doc).

    Returns a JSON-able dict: 'tol', 'onset_tol', 'lagrange' (onset, peak), 'model_penalty' (the
    penalty as written: worst |Delta sigma_N| / peak, onset difference, penetration [m] and / t,
    'converged'), 'evaluated' (every k-factor solved, ascending), 'recommended' (deck terms of the
    smallest k-factor solved that reproduces Lagrange, or None), 'command' (the sweep that checks it).
    ``condensed``: (mesh, condensed system) of ``model`` already built (``run`` passes its own), else built here."""
    onset_tol = tol if onset_tol is None else onset_tol
    variant = mesh_variants(model)[0]
    md = model.to_dict()
    if condensed is None:
        cond = condense_variant(md, light=False)  # in process: the factor stays (friction systems need it)
    else:
        cond = Condensed(condensed[0], condensed[1], 0.0, "this process", md)
    k_c = node_stiffness(cond.mesh)
    lag = Case(variant, LAGRANGE)
    tables, records, series = {}, {}, {}

    def solve(case: Case):
        df, summary, _ = solve_case(cond, md, case.method, case.k_factor, wall=False)   # no field recovery
        tables[case.case_id], records[case.case_id] = df, {"summary": summary}
        series[case.case_id] = series_of(df, case.label)

    solve(lag)
    lag_summary = records[lag.case_id]["summary"]
    rows: dict[float, dict] = {}

    def judge(kf: float) -> bool:
        case = Case(variant, PENALTY, float(kf))
        try:
            solve(case)
        except DeckbridgeError as exc:
            rows[kf] = {"k_factor": kf, "error": str(exc), K.REPRODUCES: False}
            return False
        vr = variant_metrics(variant, [lag, case], tables, records, tol, series=series)
        pk = vr.per_k[0]
        pen = penetration(tables[case.case_id])
        rows[kf] = {"k_factor": kf, "max_rel_diff": pk["max_rel_diff"], "worst_load_factor": pk["worst_load_factor"],
                    "stress_within_tol": pk["within_tol"], "liftoff_load_factor": pk["liftoff_load_factor"],
                    K.ONSET_REL_DIFF: onset_gap(pk["liftoff_load_factor"], vr.lagrange["liftoff_load_factor"]),
                    "penetration_m": pen, "penetration_over_t": pen / model.geometry.thickness,
                    K.REPRODUCES: reproduces(pk, vr.lagrange, tol, onset_tol),
                    **deck_terms(model, k_c, kf)}
        return rows[kf][K.REPRODUCES]

    found = None
    for kf in _ladder(model):
        if judge(kf):
            found = kf
            break
    if found is not None and found > 1.0:
        for kf in (found / 5.0, found / 2.0):
            if kf >= 1.0 and kf not in rows:
                judge(kf)
    passing = sorted(k for k, r in rows.items() if r[K.REPRODUCES])
    best = passing[0] if passing else None
    ks = sorted(rows)
    return {
        "tol": tol, "onset_tol": onset_tol,
        "definition": (f"reproduces Lagrange: max over theta |sigma_N(penalty) - sigma_N(Lagrange)| <= {tol:g} x "
                       f"|Lagrange peak compression| at every compared load factor, and the first-node liftoff "
                       f"onset within {onset_tol:g} x the Lagrange onset; Lagrange = the limit k -> infinity "
                       "(tangential springs rigid when k_t follows k_n), as in deckbridge sweep"),
        LAGRANGE: {"liftoff_load_factor": lag_summary["liftoff_load_factor"],
                     "liftoff_theta_deg": lag_summary["liftoff_theta_deg"]},
        "model_penalty": rows[1.0] | {"converged": rows[1.0][K.REPRODUCES]},
        "evaluated": [rows[k] for k in ks],
        "recommended": None if best is None else rows[best],
        "recommended_text": None if best is None else terms_text(rows[best]),
        "command": (f"deckbridge sweep {model_path} --k-factors {','.join(f'{k:g}' for k in ks)} "
                    f"--tol {tol:g} -o sweep-check"),
    }


def measured_rows(result, model: Model) -> list[dict]:
    """Per penalty source of ``result`` (a ComparisonResult) against its first Lagrange source: worst
    |Delta sigma_N| / |Lagrange peak| over the compared load factors, onset difference (first node) and the
    largest penetration / t (None where the source's table has no gap)."""
    labels = [s.label for s in result.series]
    methods = {s.label: s.method for s in result.series}
    lag = next((lab for lab in labels if methods[lab] == LAGRANGE), None)
    out = []
    if lag is None:
        return out
    for lab in labels:
        if methods[lab] != PENALTY:
            continue
        worst = None
        for pt in result.points:
            pair = next((p for p in pt.pairs if {p["a"], p["b"]} == {lab, lag}), None)
            peak = abs(pt.peaks.get(lag, (0.0,))[0] or 0.0)
            if pair is not None and peak > 0:
                rel = pair["max_abs_diff_pa"] / peak
                if worst is None or rel > worst[0]:
                    worst = (rel, pt.load_factor)
        rec = result.source(lab)
        pen = penetration(rec.table) if rec is not None and "gap_m" in rec.table else None
        lo = result.liftoff
        gap = onset_gap(lo.get(lab), lo.get(lag))
        out.append({"source": lab, "against": lag, "max_rel_diff": None if worst is None else worst[0],
                    "worst_load_factor": None if worst is None else worst[1],
                    "liftoff_load_factor": lo.get(lab), "lagrange_liftoff_load_factor": lo.get(lag),
                    K.ONSET_REL_DIFF: None if gap is None or math.isinf(gap) else gap,
                    "penetration_over_t": None if pen is None else pen / model.geometry.thickness})
    return out


def report_verdict(result, model: Model | None, extra: dict | None = None) -> tuple[dict, list[dict]] | None:
    """(penalty_verdict, measured_rows) of a comparison ``result`` for the report's verdict section, when a
    model is given and a penalty source is compared (``extra['verdict'] = False`` leaves it out;
    ``extra['tol']`` its tolerance, ``extra['model_path']`` the model named in the command it prints,
    ``extra['condensed']`` (mesh, condensed system) of ``model``, reused). A verdict that cannot be made is
    ``{"error": why}``: the report still stands and says why."""
    extra = extra or {}
    if model is None or not extra.get("verdict", True) or not any(s.method == PENALTY for s in result.series):
        return None
    try:
        verdict = penalty_verdict(model, extra.get("tol", DEFAULT_TOL), model_path=extra.get("model_path", "MODEL"),
                                  condensed=extra.get("condensed"))
    except DeckbridgeError as exc:
        verdict = {"error": str(exc)}
    return verdict, measured_rows(result, model)


def write_report_with_verdict(result, outdir, model: Model | None = None, extra: dict | None = None):
    """:func:`deckbridge.report.write_report` with the verdict of :func:`report_verdict` (``extra['verdict']``)."""
    from ..report import write_report
    extra = dict(extra or {})
    extra["verdict"] = report_verdict(result, model, extra)
    extra.pop("condensed", None)
    return write_report(result, outdir, model=model, extra=extra)
