"""report.html of a penalty sweep, in the style of the comparison report (same CSS, embedded PNGs).

Figures: per mesh and compared load factor, sigma_N(theta) of every k-factor against Lagrange (the
paper's FIG. 4 for all k, :func:`deckbridge.report.figures.sigma_n_figure`), except where every curve
lies on Lagrange's (within 10 % of the tolerance: typically the end of step 1, N only; a table says so); and the metrics against
k on log axes: max |delta sigma_N| relative to the Lagrange peak (with the tolerance), liftoff-zone
overlap, peak compression and liftoff load factor, Lagrange drawn as horizontal lines.
"""

from __future__ import annotations

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter

from .. import summary_keys as K
from .figures import plain_text, png_bytes, sigma_n_figure
from ..methods import AUGMENTED, LAGRANGE, PENALTY
from .html import SOURCE_HEAD, deckbridge_version, env, fmt, model_rows, mpa, source_rows

FIGURE_BELOW = 0.1       # no sigma_N figure where every k is within 10 % of the tolerance of Lagrange
_MESH_COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b"]


@plain_text
def metrics_figure(summary: dict) -> Figure:
    """2 x 2 panels of the sweep metrics against the k-factor (log axes), one line per mesh."""
    fig = Figure(figsize=(10.0, 7.4), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.subplots(2, 2)
    fig.subplots_adjust(left=0.085, right=0.985, bottom=0.07, top=0.96, wspace=0.22, hspace=0.3)  # no layout engine: 2x faster
    tol = summary["tol"]
    for i, m in enumerate(summary["meshes"]):
        col = _MESH_COLOURS[i % len(_MESH_COLOURS)]
        pk = [d for d in m[PENALTY] if not d.get("error")]
        if not pk:
            continue
        k = np.array([d["k_factor"] for d in pk])
        lab = m.get("name") or f"mesh {m['mesh']}"
        rel = np.array([max(d["max_rel_diff"], 1e-16) for d in pk]) * 100
        ax[0, 0].loglog(k, rel, "o-", color=col, label=lab)
        for j, lf in enumerate(m["compared_load_factors"]):
            r = [max(d["by_load_factor"][j]["rel_diff"], 1e-16) * 100 if j < len(d["by_load_factor"]) else np.nan
                 for d in pk]
            ax[0, 0].loglog(k, r, ":", color=col, lw=0.9, alpha=0.7)
        ax[0, 1].semilogx(k, [d["liftoff_zone_iou"] for d in pk], "o-", color=col, label=lab)
        ax[1, 0].semilogx(k, [d["peak_compression_pa"] / 1e6 for d in pk], "o-", color=col, label=f"{lab}: penalty")
        lag = m[LAGRANGE]
        if lag.get("peak_compression_pa"):
            last = list(lag["peak_compression_pa"].values())[-1]
            ax[1, 0].axhline(last / 1e6, color=col, ls="--", lw=1.0, label=f"{lab}: Lagrange")
        lf = [np.nan if d["liftoff_load_factor"] is None else d["liftoff_load_factor"] for d in pk]
        ax[1, 1].semilogx(k, lf, "o-", color=col, label=f"{lab}: penalty")
        au = [d for d in m.get(AUGMENTED, []) if not d.get("error")]      # sweep --augmented: flat in k
        if au:
            ka = np.array([d["k_factor"] for d in au])
            ax[0, 0].loglog(ka, [max(d["max_rel_diff"], 1e-16) * 100 for d in au], "s--", color=col,
                            label=f"{lab}: augmented")
            ax[1, 0].semilogx(ka, [d["peak_compression_pa"] / 1e6 for d in au], "s--", color=col, mfc="none",
                              label=f"{lab}: augmented")
        if lag.get("liftoff_load_factor") is not None:
            ax[1, 1].axhline(lag["liftoff_load_factor"], color=col, ls="--", lw=1.0, label=f"{lab}: Lagrange")
    ax[0, 0].axhline(tol * 100, color="black", ls="--", lw=1.0, label=f"tol {tol * 100:g} %")
    bt = summary.get("beam_theory_liftoff_load_factor")
    if bt is not None:
        ax[1, 1].axhline(bt, color="grey", ls="-.", lw=1.0, label="beam theory N R / (2 M_b)")
    titles = [("max |ΔσN| / |Lagrange peak| [%]  (solid: worst λ, dotted: each λ)", "[%]"),
              ("liftoff-zone overlap with Lagrange (IoU) at λ_max", "IoU [-]"),
              ("peak compression σN at λ_max [MPa]", "σN [MPa]"),
              ("liftoff load factor (onset)", "λ [-]")]
    plain = FuncFormatter(lambda v, _: f"{v:g}")      # no mathtext: 10x cheaper to draw
    for a, (t, y) in zip(ax.ravel(), titles):
        a.minorticks_off()
        a.xaxis.set_major_formatter(plain)
        if a.get_yscale() == "log":
            a.yaxis.set_major_formatter(plain)
        a.set_title(t, fontsize=9)
        a.set_xlabel("k-factor (× default k_c)")
        a.set_ylabel(y)
        a.grid(True, lw=0.4, alpha=0.6)
        a.legend(fontsize=7)
    return fig


def _mesh_rows(m: dict) -> list[list[str]]:
    """The per-case rows of one mesh's table (plain text)."""
    lag = m[LAGRANGE]
    rows = []
    if not lag.get("error"):
        peak = list(lag["peak_compression_pa"].values())[-1]
        rows.append(["Lagrange", "–", "–", "–", "–", mpa(peak), mpa(lag.get("node_peak_compression_pa")),
                     mpa(lag.get("max_tension_pa")), fmt(lag.get("liftoff_load_factor")), "–", "reference", "reference"])
    for d in m[PENALTY]:
        if d.get("error"):
            rows.append([f"penalty k = {d['k_factor']:g}"] + ["–"] * 10 + [d["error"]])
            continue
        rows.append([f"penalty k = {d['k_factor']:g}", mpa(d["max_abs_diff_pa"]), f"{d['max_rel_diff'] * 100:.2f}",
                     fmt(d["worst_load_factor"]), f"{d['liftoff_zone_iou']:.3f}", mpa(d["peak_compression_pa"]),
                     mpa(d["node_peak_compression_pa"]), mpa(d["max_tension_pa"]), fmt(d["liftoff_load_factor"]),
                     _pct(d.get(K.ONSET_REL_DIFF)), "yes" if d["within_tol"] else "no",
                     "yes" if d.get(K.REPRODUCES) else "no"])
    return rows


def _pct(v) -> str:
    return "–" if v is None else ("only one lifts off" if v == float("inf") else f"{v * 100:.2f}")


POINT_HEAD = ["case"] + SOURCE_HEAD[1:] + ["max |ΔσN| vs Lagrange [MPa]", "zone IoU"]    # the columns of _point_rows


def _point_rows(pt) -> list[list[str]]:
    """Per case at one load factor (columns :data:`POINT_HEAD`): the comparison report's source columns
    (:func:`~deckbridge.report.html.source_rows`), then the difference and zone IoU against Lagrange."""
    lab = pt.labels[0]
    rows = []
    for x, base in zip(pt.labels, source_rows(pt, pt.labels)):
        p = next((q for q in pt.pairs if q["a"] == lab and q["b"] == x), None)
        rows.append(base + (["–", "–"] if x == lab else [mpa(p["max_abs_diff_pa"]), f"{p['liftoff_zone_overlap']:.3f}"]))
    return rows


def metrics_png(summary: dict) -> bytes:
    return png_bytes(metrics_figure(summary))


def sigma_png(point, labels: list[str], title: str) -> bytes:
    return png_bytes(sigma_n_figure(point, labels, title=title))


def claims_png(verdict: dict, q, title: str) -> bytes:
    from .claims_figures import claims_figure
    return png_bytes(claims_figure(verdict, q, title))


def _claims_view(summary: dict, quantities, pngs) -> list[dict]:
    """Per variant: title, figure and one row per quantity (verdicts with their numbers)."""
    from .claims_figures import claims_quantity_names
    names = claims_quantity_names()
    out = []
    for c in summary.get("claims") or []:
        if c.get("error"):
            out.append({"title": c["variant"], "error": c["error"], "rows": [], "png": None, "note": None,
                        "onsets": []})
            continue
        rows = []
        for q, v1 in c["claim1"].items():
            v2 = c["claim2"][q]
            mx = max((d["max_in_lifted_pa"] for d in v1[PENALTY] if d["max_in_lifted_pa"] is not None), default=None)
            rows.append([names[q], "holds" if v1["holds"] else "no", mpa(mx), mpa(v1["lagrange_max_pa"]),
                         ", ".join(f"{k:g}" for k in v1["holds_for_k"]) or "–",
                         v2["direction"], ", ".join(mpa(x) for x in v2["peak_abs_pa"]), mpa(v2["lagrange_peak_abs_pa"]),
                         ", ".join(f"{k:g}" for k in v2["reproduces_lagrange_at_k"]) or "none"])
        on = c["onsets"]
        onsets = [["Lagrange", fmt(on[LAGRANGE]["first_node"]), fmt(on[LAGRANGE]["whole_section"])]] + [
            [f"penalty k = {p['k_factor']:g}", fmt(p["first_node"]), fmt(p["whole_section"])] for p in on[PENALTY]]
        out.append({"title": f"{c['grid_label'] or 'model as given'} (mesh {c['mesh']}), λ = {c['load_factor']:.4g}",
                    "rows": rows, "onsets": onsets, "png": next(pngs), "error": None,
                    "note": c["lagrange_depends_on_alpha_note"], "follows": c["k_tangent_follows_k"]})
    return out


def render_sweep(summary: dict, results: list, model=None, mapper=None, quantities=None) -> str:
    """The sweep report as one HTML string (``results``: :class:`~deckbridge.studies.metrics.VariantResult`).

    ``mapper(fn, jobs) -> list`` renders the figures (default: the builtin map, in process;
    the sweep passes one that renders them on its Dask workers in parallel).
    """
    jobs = [(metrics_png, (summary,))]
    for m, r in zip(summary["meshes"], results):
        for pt in ([] if r.comparison is None else r.comparison.points):
            if _drawn(pt, summary["tol"]):
                jobs.append((sigma_png, (pt, r.comparison.labels,
                                         f"{m.get('name') or 'mesh ' + m['mesh']}: σN vs azimuth, λ = {pt.load_factor:.4g} ({pt.what})")))
    for c in summary.get("claims") or []:
        if not c.get("error"):
            q = quantities[quantities["case_id"].str.startswith(c["variant"] + "_")] if quantities is not None else None
            jobs.append((claims_png, (c, q, c["grid_label"] or c["mesh"])))
    pngs = iter(list(mapper(_call, jobs)) if mapper is not None else [_call(j) for j in jobs])
    metrics = next(pngs)
    meshes = []
    for m, r in zip(summary["meshes"], results):
        points = None if r.comparison is None else [
            {"load_factor": pt.load_factor, "what": pt.what, "rows": _point_rows(pt),
             "png": next(pngs) if _drawn(pt, summary["tol"]) else None} for pt in r.comparison.points]
        rec = m.get("recommended") or {}
        meshes.append({"label": m.get("name", m["mesh"]), "recommended": rec.get("text", fmt(m["recommended_k_factor"], "g")),
                       "rows": _mesh_rows(m),
                       "monotone": m.get("max_rel_diff_never_grows_with_k"), "points": points})
    claims = _claims_view(summary, quantities, pngs)
    return env().get_template("sweep.html.j2").render(claims=claims, claims_definition=summary.get("claims_definition"),
        ver=deckbridge_version(), penalty_rule=summary["penalty_rule"], recommended=summary["recommended_k_factor"],
        rec_terms=summary.get("recommended") or {},
        lagrange_reference=summary.get("lagrange_reference"),
        recommended_note=summary["recommended_k_factor_note"], tol_pct=summary["tol"] * 100, metrics_png=metrics,
        meshes=meshes, figure_below_pct=FIGURE_BELOW * 100, point_head=POINT_HEAD,
        model_rows=None if model is None else model_rows(model))


def _drawn(pt, tol: float) -> bool:
    """A sigma_N figure is drawn unless every curve is within FIGURE_BELOW x tol of Lagrange's there."""
    lab = pt.labels[0]
    peak = abs(pt.peaks[lab][0])
    worst = max((p["max_abs_diff_pa"] for p in pt.pairs if p["a"] == lab), default=0.0)
    return peak == 0 or worst > FIGURE_BELOW * tol * peak


def _call(job):
    fn, args = job
    return fn(*args)
