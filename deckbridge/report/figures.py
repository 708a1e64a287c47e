"""Figures of the report (matplotlib Agg, no pyplot state): sigma_N vs azimuth in the style of FIG. 4.

One curve per source on its own azimuths (closed over 360 deg), liftoff zones shaded in the
source's colour, sigma_N in MPa (< 0 compression), the zero line marking liftoff.
"""

from __future__ import annotations

import io

import matplotlib
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.tri import Triangulation

from ..azimuth import azimuth_deg
from ..compare.metrics import zone_intervals
from ..compare.result import PointResult

_MARKERS = ["o", "s", "^", "D", "v", "P", "X", "*"]


def plain_text(func):
    """Decorator of every function that builds or draws a report figure: matplotlib's mathtext is off
    while it runs, so user text (source and method names, model titles, file names) is drawn as written:
    a name holding ``$\\frac{`` is text, not a formula that fails to parse. Text objects keep the
    setting they were made with; tick labels are made when the figure is drawn (:func:`png_bytes`)."""
    return matplotlib.rc_context({"text.parse_math": False})(func)


def colours(labels: list[str]) -> dict[str, str]:
    """A fixed colour per source label (tab10 cycle), the same in every figure."""
    cycle = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
             "#bcbd22", "#17becf"]
    return {lab: cycle[i % len(cycle)] for i, lab in enumerate(labels)}


def _azimuth_axis(ax) -> None:
    """x: azimuth 0..360 deg, ticks every 30 deg; a black zero line (liftoff / no displacement)."""
    ax.axhline(0.0, color="black", lw=0.8)
    ax.set_xlim(0.0, 360.0)
    ax.set_xticks(np.arange(0, 361, 30))
    ax.set_xlabel("azimuth θ [deg]")


@plain_text
def sigma_n_figure(point: PointResult, labels: list[str], title: str | None = None) -> Figure:
    """sigma_N [MPa] vs azimuth [deg] at one load factor, one curve per source, liftoff zones shaded."""
    fig = Figure(figsize=(9.0, 4.8), dpi=110)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    col = colours(labels)
    lo = min((float(np.min(p.sigma)) for p in point.profiles.values()), default=-1.0) / 1e6
    hi = max((float(np.max(p.sigma)) for p in point.profiles.values()), default=0.0) / 1e6
    lo, hi = min(lo, 0.0), max(hi, 0.0)
    pad = 0.05 * (hi - lo if hi > lo else 1.0)
    ax.set_ylim(lo - pad, hi + pad + 0.045 * (len(labels) + 1) * (hi - lo + 2 * pad))
    for k, lab in enumerate(labels):
        if lab not in point.profiles:
            continue
        p = point.profiles[lab]
        th = np.append(p.theta, p.theta[0] + 360.0)
        s = np.append(p.sigma, p.sigma[0]) / 1e6
        n = p.theta.size
        ax.plot(th, s, color=col[lab], lw=1.6, marker=_MARKERS[k % len(_MARKERS)],
                ms=3.5 if n <= 120 else 0, markevery=max(1, n // 72), label=lab)
        spans = [(a, max(b - a, 0.5)) for a, b in zone_intervals(point.zones[lab])]
        for a, w in spans:
            ax.axvspan(a, a + w, color=col[lab], alpha=0.13, lw=0)
        if spans:   # a bar per source along the top tells overlapping zones apart
            ax.broken_barh(spans, (0.99 - 0.035 * (k + 1), 0.025), transform=ax.get_xaxis_transform(),
                           color=col[lab], lw=0)
    _azimuth_axis(ax)
    ax.set_ylabel("σN [MPa]  (< 0 compression, > 0 liftoff)")
    ax.grid(True, lw=0.4, alpha=0.6)
    ax.set_title(title or f"σN at the base vs azimuth, λ = {point.load_factor:.4g} ({point.what})", fontsize=10)
    ax.legend(loc="best", fontsize=8, title="shaded: liftoff zones", title_fontsize=7)
    fig.tight_layout()
    return fig


@plain_text
def png_bytes(fig: Figure) -> bytes:
    """The figure as PNG bytes."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    return buf.getvalue()


@plain_text
def global_figure(fields: dict[str, dict], labels: list[str]) -> Figure | None:
    """Global level (cf. the paper's FIG. 3): von Mises on the unrolled wall (theta, z) per source, and
    the vertical displacement of the base ring vs azimuth (its deformed shape), one curve per source.

    ``fields``: label -> :func:`deckbridge.readers.reference.fields` output (a record's ``fields``). None when nothing to draw.
    """
    vm_src = [lab for lab in labels if fields.get(lab) and fields[lab]["vm"] is not None][:4]
    u_src = [lab for lab in labels if fields.get(lab) and fields[lab]["u"] is not None]
    if not vm_src and not u_src:
        return None
    rows = (1 if vm_src else 0) + (1 if u_src else 0)
    fig = Figure(figsize=(9.0, 3.6 * rows + 0.4), dpi=100, layout="constrained")
    FigureCanvasAgg(fig)
    grid = fig.add_gridspec(rows, max(1, len(vm_src)))
    col = colours(labels)
    r = 0
    if vm_src:
        top = max(float(np.nanmax(fields[lab]["vm"])) for lab in vm_src) / 1e6
        for k, lab in enumerate(vm_src):
            f = fields[lab]
            xyz, vm = f["vm_xyz"], f["vm"] / 1e6
            rad = np.hypot(xyz[:, 0], xyz[:, 1])
            outer = rad >= np.median(rad)                  # outer half of the wall: one layer in the map
            th = azimuth_deg(xyz[outer, 0], xyz[outer, 1])
            zz, vv = xyz[outer, 2], vm[outer]
            seam = th < 1e-6                                # repeat the 0 deg column at 360 deg
            th, zz, vv = np.append(th, th[seam] + 360.0), np.append(zz, zz[seam]), np.append(vv, vv[seam])
            ax = fig.add_subplot(grid[0, k])
            sc = _wall_map(ax, th, zz, vv, top)
            ax.set_xlim(0, 360)
            ax.set_xticks(np.arange(0, 361, 90))
            ax.set_xlabel("θ [deg]")
            if k == 0:
                ax.set_ylabel("z [m]")
            ax.set_title(f"von Mises: {lab}", fontsize=8)
        fig.colorbar(sc, ax=fig.axes[: len(vm_src)], label="von Mises [MPa]", shrink=0.9)
        r = 1
    if u_src:
        ax = fig.add_subplot(grid[r, :])
        for lab in u_src:
            f = fields[lab]
            xyz, u = f["xyz"], f["u"]
            base = np.abs(xyz[:, 2] - xyz[:, 2].min()) < 1e-9 * max(1.0, float(np.ptp(xyz[:, 2])))
            th = np.round(azimuth_deg(xyz[base, 0], xyz[base, 1]), 6)
            uz = (np.bincount(np.unique(th, return_inverse=True)[1], weights=u[base, 2])
                  / np.bincount(np.unique(th, return_inverse=True)[1]))
            t1 = np.unique(th)
            ax.plot(np.append(t1, t1[0] + 360.0), np.append(uz, uz[0]) * 1e3, color=col[lab], lw=1.5, label=lab)
        _azimuth_axis(ax)
        ax.set_ylabel("u_z at the base [mm]")
        ax.set_title("deformed shape: vertical displacement of the base ring (> 0 lifts)", fontsize=9)
        ax.grid(True, lw=0.4, alpha=0.6)
        ax.legend(fontsize=8)
    return fig


def _wall_map(ax, th: np.ndarray, zz: np.ndarray, vv: np.ndarray, top: float):
    """Colour map of ``vv`` [MPa] over the unrolled wall (θ [deg], z [m]); return the mappable.

    Gouraud triangles over a Delaunay triangulation where one exists; points coloured by value where the
    set is degenerate for Qhull (one row of points: ``mesh.n_z = 1``; collinear or repeated points), so
    the report is drawn whatever the mesh, with the fallback said in the axes."""
    span = max(float(np.ptp(zz)), 1e-12)
    finite = np.isfinite(th) & np.isfinite(zz) & np.isfinite(vv)
    th, zz, vv = th[finite], zz[finite], vv[finite]
    pts = np.unique(np.round(np.column_stack([th / 360.0, zz / span]), 9), axis=0)
    if len(pts) >= 3 and np.linalg.matrix_rank(pts[1:] - pts[0], tol=1e-9) == 2:
        try:
            tri = Triangulation(th / 360.0, zz / span)
            return ax.tripcolor(Triangulation(th, zz, tri.triangles), vv, shading="gouraud", cmap="viridis",
                                vmin=0.0, vmax=top)
        except (RuntimeError, ValueError):     # Qhull: singular or flat input after all
            pass
    ax.text(0.5, 0.02, "points (no surface: degenerate point set)", transform=ax.transAxes, ha="center",
            fontsize=7)
    return ax.scatter(th, zz, c=vv, s=12, cmap="viridis", vmin=0.0, vmax=top)

