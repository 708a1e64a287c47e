"""report.html of a penalty sweep, in the style of the comparison report (same CSS, embedded PNGs).

Figures: per mesh and compared load factor, sigma_N(theta) of every k-factor against Lagrange (the
paper's FIG. 4 for all k, :func:`deckbridge.report.figures.sigma_n_figure`), except where every curve
lies on Lagrange's (within 10 % of the tolerance: typically the end of step 1, N only; a table says so); and the metrics against
k on log axes: max |delta sigma_N| relative to the Lagrange peak (with the tolerance), liftoff-zone
overlap, peak compression and liftoff load factor, Lagrange drawn as horizontal lines.
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter

from .figures import png_bytes, sigma_n_figure
from .html import _CSS, _SCRIPT, esc, fmt, img, model_rows, mpa, table, zones_text

FIGURE_BELOW = 0.1       # no sigma_N figure where every k is within 10 % of the tolerance of Lagrange
_MESH_COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b"]


def metrics_figure(summary: dict) -> Figure:
    """2 x 2 panels of the sweep metrics against the k-factor (log axes), one line per mesh."""
    fig = Figure(figsize=(10.0, 7.4), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.subplots(2, 2)
    fig.subplots_adjust(left=0.085, right=0.985, bottom=0.07, top=0.96, wspace=0.22, hspace=0.3)  # no layout engine: 2x faster
    tol = summary["tol"]
    for i, m in enumerate(summary["meshes"]):
        col = _MESH_COLOURS[i % len(_MESH_COLOURS)]
        pk = [d for d in m["penalty"] if not d.get("error")]
        if not pk:
            continue
        k = np.array([d["k_factor"] for d in pk])
        lab = f"mesh {m['mesh']}"
        rel = np.array([max(d["max_rel_diff"], 1e-16) for d in pk]) * 100
        ax[0, 0].loglog(k, rel, "o-", color=col, label=lab)
        for j, lf in enumerate(m["compared_load_factors"]):
            r = [max(d["by_load_factor"][j]["rel_diff"], 1e-16) * 100 if j < len(d["by_load_factor"]) else np.nan
                 for d in pk]
            ax[0, 0].loglog(k, r, ":", color=col, lw=0.9, alpha=0.7)
        ax[0, 1].semilogx(k, [d["liftoff_zone_iou"] for d in pk], "o-", color=col, label=lab)
        ax[1, 0].semilogx(k, [d["peak_compression_pa"] / 1e6 for d in pk], "o-", color=col, label=f"{lab}: penalty")
        lag = m["lagrange"]
        if lag.get("peak_compression_pa"):
            last = list(lag["peak_compression_pa"].values())[-1]
            ax[1, 0].axhline(last / 1e6, color=col, ls="--", lw=1.0, label=f"{lab}: Lagrange")
        lf = [np.nan if d["liftoff_load_factor"] is None else d["liftoff_load_factor"] for d in pk]
        ax[1, 1].semilogx(k, lf, "o-", color=col, label=f"{lab}: penalty")
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


def _headline(summary: dict) -> str:
    rec = summary["recommended_k_factor"]
    if rec is not None:
        return (f"<p><b>Recommended penalty: k-factor {rec:g}</b> ({esc(summary['recommended_k_factor_note'])}; "
                f"tol = {summary['tol'] * 100:g} %).</p>")
    return (f"<p><b>No recommended penalty</b>: {esc(summary['recommended_k_factor_note'])} "
            f"(tol = {summary['tol'] * 100:g} %).</p>")


def _mesh_table(m: dict) -> str:
    lag = m["lagrange"]
    rows = []
    if not lag.get("error"):
        peak = list(lag["peak_compression_pa"].values())[-1]
        rows.append(["Lagrange", "–", "–", "–", "–", mpa(peak), mpa(lag.get("node_peak_compression_pa")),
                     mpa(lag.get("max_tension_pa")), fmt(lag.get("liftoff_load_factor")), "reference"])
    for d in m["penalty"]:
        if d.get("error"):
            rows.append([f"penalty k = {d['k_factor']:g}"] + ["–"] * 8 + [esc(d["error"])])
            continue
        rows.append([f"penalty k = {d['k_factor']:g}", mpa(d["max_abs_diff_pa"]), f"{d['max_rel_diff'] * 100:.2f}",
                     fmt(d["worst_load_factor"]), f"{d['liftoff_zone_iou']:.3f}", mpa(d["peak_compression_pa"]),
                     mpa(d["node_peak_compression_pa"]), mpa(d["max_tension_pa"]), fmt(d["liftoff_load_factor"]),
                     "yes" if d["within_tol"] else "no"])
    head = ["case", "max |ΔσN| [MPa]", "/ Lagrange peak [%]", "at λ", "zone IoU at λ_max",
            "peak σN at λ_max [MPa]", "node peak σN, path [MPa]", "max tension [MPa]", "liftoff λ", "within tol"]
    return table(head, rows)


def metrics_png(summary: dict) -> bytes:
    return png_bytes(metrics_figure(summary))


def sigma_png(point, labels: list[str], title: str) -> bytes:
    return png_bytes(sigma_n_figure(point, labels, title=title))


def render_sweep(summary: dict, results: list, model=None, mapper=None) -> str:
    """The sweep report as one HTML string (``results``: :class:`~deckbridge.studies.metrics.VariantResult`).

    ``mapper(fn, jobs) -> list`` renders the figures (default: the builtin map, in process;
    the sweep passes one that renders them on its Dask workers in parallel).
    """
    jobs = [(metrics_png, (summary,))]
    for m, r in zip(summary["meshes"], results):
        for pt in ([] if r.comparison is None else r.comparison.points):
            if _drawn(pt, summary["tol"]):
                jobs.append((sigma_png, (pt, r.comparison.labels,
                                         f"mesh {m['mesh']}: σN vs azimuth, λ = {pt.load_factor:.4g} ({pt.what})")))
    pngs = iter(list(mapper(_call, jobs)) if mapper is not None else [_call(j) for j in jobs])
    try:
        ver = version("deckbridge")
    except PackageNotFoundError:
        ver = "dev"
    out = ["<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
           "<title>deckbridge: penalty sensitivity sweep</title>", f"<style>{_CSS}</style>",
           f"<script>{_SCRIPT}</script></head><body>",
           "<h1>Penalty sensitivity: σN at the base for every k-factor against Lagrange</h1>",
           f"<p class='note'>deckbridge {esc(ver)}. σN &lt; 0 compression, &gt; 0 tension / liftoff; azimuth θ "
           "in degrees counter-clockwise from +x. Differences are σN(penalty) − σN(Lagrange). Penalty: "
           f"{esc(summary['penalty_rule'])}.</p>", _headline(summary)]
    out.append(img(next(pngs), "sweep metrics against the k-factor"))
    for m, r in zip(summary["meshes"], results):
        out.append(f"<h2>Mesh {esc(m['mesh'])} (θ × z × r): recommended k-factor "
                   f"{esc(fmt(m['recommended_k_factor'], 'g'))}</h2>")
        out.append(_mesh_table(m))
        mono = m.get("max_rel_diff_never_grows_with_k")
        out.append("<p>max |ΔσN| against Lagrange " + ("never grows as k grows." if mono else
                   "<b>grows again</b> past some k (see the max tension column: open penalty gaps carry "
                   "k_open × gap, a tension Lagrange never has).") + "</p>")
        if r.comparison is None:
            out.append("<p class='note'>No Lagrange reference on this mesh: nothing compared.</p>")
            continue
        for pt in r.comparison.points:
            out.append(f"<h3>λ = {pt.load_factor:.4g}: {esc(pt.what)}</h3>")
            if _drawn(pt, summary["tol"]):
                out.append(img(next(pngs), f"sigma_N vs azimuth, mesh {m['mesh']}, load factor {pt.load_factor:.4g}"))
            else:
                out.append(f"<p class='note'>Every k-factor gives the Lagrange curve here, within "
                           f"{FIGURE_BELOW * 100:g} % of the tolerance (table below): no figure.</p>")
            lab = r.comparison.labels[0]
            rows = [[esc(x), zones_text(pt.zones[x]), mpa(pt.peaks[x][0]), f"{pt.peaks[x][1]:.1f}"]
                    + (["–", "–"] if x == lab else
                       [mpa(p["max_abs_diff_pa"]), f"{p['liftoff_zone_overlap']:.3f}"])
                    for x in pt.labels
                    for p in [next((q for q in pt.pairs if q["a"] == lab and q["b"] == x), None)]]
            out.append(table(["case", "liftoff zones [deg]", "peak compression σN [MPa]", "at θ [deg]",
                              "max |ΔσN| vs Lagrange [MPa]", "zone IoU"], rows))
    if model is not None:
        out.append("<h2>Model</h2>")
        out.append(table(["quantity", "value"], [[esc(k), esc(v)] for k, v in model_rows(model)], left=2))
    out.append("<h2>Definitions</h2><ul class='note'>"
               "<li>σN at an azimuth: mean over the table slave nodes at that azimuth (through the wall); the "
               "'node peak' column is the most compressive single node over the whole load path.</li>"
               "<li>Compared load factors: end of step 1, first liftoff of any case, end of step 2 (or those "
               "requested); every k is compared with Lagrange on the same mesh at the same λ.</li>"
               "<li>max |ΔσN| / Lagrange peak: at each compared λ, over the Lagrange peak compression at that λ; "
               "the worst over λ is shown. A k-factor is within tol when that ratio ≤ tol at every λ; the "
               "recommended k-factor is the smallest such k.</li>"
               "<li>Zone IoU: length of the intersection over the union of the liftoff zones on the circle "
               "(1 when neither lifts off).</li>"
               "<li>Liftoff λ: onset at the first table slave node (gap opens), bisected by the solver.</li>"
               "<li>Max tension: penalty open gaps carry k_open × gap, a tension Lagrange never has.</li></ul>")
    out.append("</body></html>")
    return "\n".join(out)


def _drawn(pt, tol: float) -> bool:
    """A sigma_N figure is drawn unless every curve is within FIGURE_BELOW x tol of Lagrange's there."""
    lab = pt.labels[0]
    peak = abs(pt.peaks[lab][0])
    worst = max((p["max_abs_diff_pa"] for p in pt.pairs if p["a"] == lab), default=0.0)
    return peak == 0 or worst > FIGURE_BELOW * tol * peak


def _call(job):
    fn, args = job
    return fn(*args)
