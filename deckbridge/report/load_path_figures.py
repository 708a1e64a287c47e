"""Report figures against the load factor and around the tension side (matplotlib Agg, no pyplot state).

Every figure draws data that summary.json also holds (``load_path``, ``status_map``, the points'
``sigma_n_nodes_pa``), so a test can check the data, not only the image. sigma_N in MPa, < 0 compression.
"""

from __future__ import annotations

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ..compare.load_path import centred
from .figures import colours, plain_text


def _fig(w: float, h: float) -> Figure:
    fig = Figure(figsize=(w, h), dpi=100)
    FigureCanvasAgg(fig)
    return fig


@plain_text
def load_path_figure(paths: dict[str, dict], labels: list[str]) -> Figure:
    """Four panels against lambda: lifted arc; sigma_N at the tension and compression side; peak sigma_N
    through the wall and at one node; beam theory dashed (black) where the model is known."""
    fig = _fig(11.0, 7.0)
    axs = fig.subplots(2, 2)
    col = colours(labels)
    beam = None
    for lab in labels:
        d = paths.get(lab)
        if not d:
            continue
        lam = np.asarray(d["load_factor"])
        axs[0, 0].plot(lam, d["lifted_arc_deg"], "o-", ms=3, color=col[lab], label=lab)
        axs[0, 1].plot(lam, np.asarray(d["tension_side_pa"]) / 1e6, "o-", ms=3, color=col[lab], label=f"{lab} tension side")
        axs[0, 1].plot(lam, np.asarray(d["compression_side_pa"]) / 1e6, "s--", ms=3, color=col[lab], label=f"{lab} compression side")
        axs[1, 0].plot(lam, np.asarray(d["peak_wall_pa"]) / 1e6, "o-", ms=3, color=col[lab], label=f"{lab} through the wall")
        axs[1, 0].plot(lam, np.asarray(d["peak_node_pa"]) / 1e6, "x:", ms=4, color=col[lab], label=f"{lab} one node")
        if "beam_tension_side_pa" in d:
            beam = d
    if beam is not None:
        lam = np.asarray(beam["load_factor"])
        axs[0, 1].plot(lam, np.asarray(beam["beam_tension_side_pa"]) / 1e6, "k--", lw=1, label="beam theory")
        axs[0, 1].plot(lam, np.asarray(beam["beam_compression_side_pa"]) / 1e6, "k--", lw=1)
        axs[1, 0].plot(lam, np.asarray(beam["beam_compression_side_pa"]) / 1e6, "k--", lw=1, label="beam theory")
        for ax in (axs[0, 0], axs[0, 1]):
            if beam["beam_theory_liftoff_load_factor"] is not None:     # None: no liftoff (M = T = 0)
                ax.axvline(beam["beam_theory_liftoff_load_factor"], color="grey", lw=0.8, ls=":")
    titles = ["lifted arc [deg]", "σN at the tension / compression side [MPa]", "peak compression σN [MPa]"]
    for ax, t in zip((axs[0, 0], axs[0, 1], axs[1, 0]), titles):
        ax.set_title(t, fontsize=9)
        ax.set_xlabel("load factor λ")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6)
    axs[1, 1].axis("off")
    axs[1, 1].text(0.0, 0.9, "σN < 0 compression.\nDashed black: beam theory\n−N/(2πRt) ± λ M_b/(πR²t);\n"
                   "dotted grey: beam-theory liftoff.", fontsize=9, va="top")
    fig.tight_layout()
    return fig


@plain_text
def theta_lambda_map_figure(maps: dict[str, dict], labels: list[str], cmap, vmin: float, vmax: float,
                            title: str) -> Figure:
    """One theta x lambda map per source of ``labels`` found in ``maps`` ({'theta_deg', 'load_factor',
    'status'} each), coloured by ``cmap`` over [vmin, vmax], under the suptitle ``title``."""
    have = [lab for lab in labels if lab in maps]
    fig = _fig(4.0 * max(1, len(have)), 3.4)
    axs = np.atleast_1d(fig.subplots(1, max(1, len(have))))
    for ax, lab in zip(axs, have):
        m = maps[lab]
        ax.pcolormesh(np.asarray(m["theta_deg"]), np.asarray(m["load_factor"]), np.asarray(m["status"]),
                      shading="nearest", cmap=cmap, vmin=vmin, vmax=vmax)
        ax.set_title(lab, fontsize=8)
        ax.set_xlabel("θ [deg]")
        ax.set_ylabel("λ")
        ax.set_xticks(np.arange(0, 361, 90))
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    return fig


@plain_text
def status_map_figure(maps: dict[str, dict], labels: list[str]) -> Figure:
    """theta x lambda contact status per source: 0 closed, 1 partly open through the wall, 2 open."""
    return theta_lambda_map_figure(maps, labels, "RdYlGn_r", 0, 2,
                                   "contact status: green closed, yellow partly open, red open through the wall")


@plain_text
def centred_figure(point, labels: list[str], azimuth_deg: float) -> Figure:
    """sigma_N(theta) with theta relative to the tension side in [-180, 180), a small polar inset."""
    fig = _fig(9.0, 4.6)
    ax = fig.add_subplot(1, 1, 1)
    col = colours(labels)
    for lab in labels:
        p = point.profiles.get(lab)
        if p is None:
            continue
        rel, s = centred(p.theta, p.sigma, azimuth_deg)
        ax.plot(rel, s / 1e6, "o-", ms=2.5, color=col[lab], label=lab)
    ax.axhline(0, color="black", lw=0.8)
    ax.set_xlim(-180, 180)
    ax.set_xticks(np.arange(-180, 181, 45))
    ax.set_xlabel(f"θ − {azimuth_deg:g}° (0 = tension side) [deg]")
    ax.set_ylabel("σN [MPa]")
    ax.legend(fontsize=7, loc="lower left")
    ax.grid(alpha=0.3)
    ins = fig.add_axes([0.80, 0.62, 0.16, 0.3], projection="polar")
    for lab in labels:
        p = point.profiles.get(lab)
        if p is not None:
            th = np.radians(np.append(p.theta, p.theta[0]))
            ins.plot(th, np.append(-p.sigma, -p.sigma[0]) / 1e6, color=col[lab], lw=1)
    ins.plot([np.radians(azimuth_deg)] * 2, [0, ins.get_ylim()[1]], "k-", lw=0.8)
    ins.set_xticks(np.radians([0, 90, 180, 270]))
    ins.set_yticklabels([])
    ins.tick_params(labelsize=6)
    return fig


@plain_text
def through_wall_figure(point, labels: list[str], azimuth_deg: float) -> Figure:
    """Node sigma_N inner / mid / outer along the azimuth (tension side centred), one panel per source."""
    have = [lab for lab in labels if "sigma_n_nodes_pa" in point.extra.get(lab, {})]
    fig = _fig(4.2 * max(1, len(have)), 3.4)
    axs = np.atleast_1d(fig.subplots(1, max(1, len(have))))
    for ax, lab in zip(axs, have):
        d = point.extra[lab]["sigma_n_nodes_pa"]
        for ring, style in (("inner", "b-"), ("mid", "g--"), ("outer", "r-.")):
            v = np.asarray(d[ring], float)
            if np.isfinite(v).any():
                rel, s = centred(d["theta_deg"], v, azimuth_deg)
                ax.plot(rel, s / 1e6, style, lw=1.2, label=ring)
        lo = min(0.0, ax.get_ylim()[0])
        ax.set_ylim(lo * 1.05 if lo < 0 else -1.0, max(0.0, ax.get_ylim()[1]) + 0.02 * abs(lo or 1.0))
        ax.ticklabel_format(axis="y", useOffset=False)          # round-off must not look like a profile
        ax.set_title(f"{lab}, λ = {point.load_factor:.4g}", fontsize=8)
        ax.set_xlim(-180, 180)
        ax.set_xlabel("θ from the tension side [deg]")
        ax.set_ylabel("node σN [MPa]")
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig
