"""Figures of the paper's claims in a study (:mod:`deckbridge.studies.claims`), one per variant.

Left: contact sigma_N through the wall against the azimuth at the claims' load factor, Lagrange and
every penalty k (claim 1: sigma_N > 0 in the penalty lifted zones). Right: peak |sigma| over the
azimuth against the k-factor (log axis) for each compared quantity, Lagrange as dashed lines (claim 2).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter

from ..quantities import CLAIM_QUANTITIES as QUANTITIES
from ..methods import LAGRANGE, PENALTY
from .figures import plain_text

_COLOURS = {"sigma_n_wall_pa": "#1f77b4", "szz_inner_pa": "#d62728", "szz_outer_pa": "#2ca02c",
            "szz_mean_pa": "#ff7f0e"}
_NAMES = {"sigma_n_wall_pa": "contact σN", "szz_inner_pa": "σzz inner", "szz_outer_pa": "σzz outer",
          "szz_mean_pa": "σzz mean"}


@plain_text
def claims_figure(verdict: dict, q: pd.DataFrame, title: str = "") -> Figure:
    """The two panels of one variant; ``q``: its rows of the tidy quantities table."""
    fig = Figure(figsize=(10.0, 3.6), dpi=80)
    FigureCanvasAgg(fig)
    a, b = fig.subplots(1, 2)
    fig.subplots_adjust(left=0.07, right=0.99, bottom=0.14, top=0.88, wspace=0.22)
    sn = q[(q["quantity"] == "sigma_n_wall_pa") & (q["theta_deg"] != "peak")]
    cmap = __import__("matplotlib").colormaps["viridis"]
    pens = sorted({float(k) for k in sn.loc[sn["method"] == PENALTY, "k_factor"]})
    for method, k in [(LAGRANGE, None)] + [(PENALTY, k) for k in pens]:
        s = sn[(sn["method"] == method) & ((sn["k_factor"] == k) if k is not None else True)]
        th = s["theta_deg"].astype(float).to_numpy()
        o = np.argsort(th)
        if method == LAGRANGE:
            a.plot(th[o], s["value"].to_numpy(float)[o] / 1e6, "k-", lw=2.2, label="Lagrange")
        else:
            c = cmap(pens.index(k) / max(1, len(pens) - 1))
            a.plot(th[o], s["value"].to_numpy(float)[o] / 1e6, "-", color=c, lw=1.1, label=f"penalty k={k:g}")
    a.axhline(0.0, color="grey", lw=0.6)
    a.set_xlabel("azimuth θ [deg]")
    a.set_ylabel("contact σN through the wall [MPa]")
    a.set_title(f"claim 1: σN(θ) at λ = {verdict.get('load_factor', float('nan')):.3g}", fontsize=9)
    a.legend(fontsize=6, ncol=2)
    for qn, v in verdict.get("claim2", {}).items():
        col = _COLOURS[qn]
        b.semilogx(v["k_factors"], np.array(v["peak_abs_pa"]) / 1e6, "o-", color=col, ms=3,
                   label=f"{_NAMES[qn]}: {v['direction']}")
        b.axhline(v["lagrange_peak_abs_pa"] / 1e6, color=col, ls="--", lw=0.9)
    b.xaxis.set_major_formatter(FuncFormatter(lambda x, _: f"{x:g}"))
    b.set_xlabel("k-factor (× model k_c)")
    b.set_ylabel("peak |σ| over θ [MPa]")
    b.set_title("claim 2: peak |σ| against k (dashed: Lagrange)", fontsize=9)
    b.legend(fontsize=6)
    for ax in (a, b):
        ax.grid(True, lw=0.4, alpha=0.6)
    if title:
        fig.suptitle(title, fontsize=9)
    return fig


def claims_quantity_names() -> dict:
    return {k: _NAMES[k] for k in QUANTITIES}
