"""Report of a comparison: report.html (self-contained), sigma_n.png, discrepancy.csv, summary.json.

``write_report(result, outdir, model=None, extra=None)`` writes the four files atomically. The report
reads no input file: it draws what the comparison's source records carry
(:class:`deckbridge.results.SourceResult`: global figures and fields, see
:func:`deckbridge.readers.reference.read_source`). ``extra`` (optional dict): 'inputs' {label: text
shown as the input}, 'global' {label: {'max_von_mises_pa', 'max_displacement_m', 'from'}} (replaces
the records' figures), 'notes' [lines added to the report].
"""

from __future__ import annotations

import json
from pathlib import Path

from ..dialects import solver_versions
from ..compare.result import ComparisonResult
from ..jsonable import json_clean
from ..outdir import staged
from ..compare.load_path import load_path, status_map
from .caveats import banners, caveat_lines, deck_options, provenance
from .figures import global_figure, png_bytes, sigma_n_figure
from .html import render
from .friction_figures import friction_data, resultant_figure, stick_map_figure, tau_sigma_figure
from .load_path_figures import centred_figure, load_path_figure, status_map_figure, through_wall_figure

__all__ = ["write_report", "sigma_n_figure"]


def write_report(result: ComparisonResult, outdir, model=None, extra: dict | None = None) -> list[Path]:
    """Write report.html, sigma_n.png, discrepancy.csv and summary.json into ``outdir``; return their paths."""
    extra = dict(extra or {})
    glob = dict(extra.get("global") or {})
    records = {s.label: result.source(s.label) for s in result.series}
    for s in result.series:
        if s.label not in glob:
            glob[s.label] = {} if records[s.label] is None else records[s.label].globals_for(s.method)
    figures = [png_bytes(sigma_n_figure(pt, result.labels)) for pt in result.points]
    gfig = global_figure({lab: r and r.fields for lab, r in records.items()}, result.labels)
    az = model.loads.azimuth if model is not None else 0.0
    paths = {s.label: load_path(s, model, az) for s in result.series}
    maps = {s.label: status_map(s) for s in result.series}
    path_pngs = [("σN along the load path", png_bytes(load_path_figure(paths, result.labels))),
                 ("contact status, θ × λ", png_bytes(status_map_figure(maps, result.labels)))]
    for pt in result.points:
        path_pngs.append((f"σN around the tension side, λ = {pt.load_factor:.4g}",
                          png_bytes(centred_figure(pt, result.labels, az))))
        path_pngs.append((f"through the wall (inner / mid / outer nodes), λ = {pt.load_factor:.4g}",
                          png_bytes(through_wall_figure(pt, result.labels, az))))
    fric = friction_data(records, result.labels, [pt.load_factor for pt in result.points], model)
    fric_pngs = []
    if fric:
        for pt in result.points:
            fric_pngs.append((f"τ beside σN around the tension side, λ = {pt.load_factor:.4g}",
                              png_bytes(tau_sigma_figure(pt, result.labels, fric, az))))
        fric_pngs.append(("stick / slip / open, θ × λ", png_bytes(stick_map_figure(fric, result.labels))))
        fric_pngs.append(("resultant of the tangential forces against T·λ", png_bytes(resultant_figure(fric, result.labels))))
    options = {lab: deck_options(r.origin if r is not None else None) for lab, r in records.items()}
    cav = {lab: (r.summary or {}).get("caveats") for lab, r in records.items() if r is not None and r.summary}
    warnings = banners(options)
    cav_lines = [ln for lab, c in cav.items() if c for ln in caveat_lines(lab, c)]
    prov = provenance(model, {lab: {"analysis": options[lab], "method": s.method,
                                    "solver_options": _solver_options(records[lab])}
                              for lab, s in zip(result.labels, result.series)},
                      solver_versions=solver_versions({s.source for s in result.series}))
    text = render(result, figures, model=model, glob=glob, inputs=extra.get("inputs"), notes=extra.get("notes"),
                  global_png=None if gfig is None else png_bytes(gfig), path_pngs=path_pngs,
                  banners=warnings, caveats=cav_lines, provenance=prov, friction_pngs=fric_pngs)
    summary = result.summary()
    summary["load_path"] = json_clean(paths)
    summary["status_map"] = json_clean(maps)
    if fric:                                    # only when a source has friction (friction.csv)
        summary["friction"] = json_clean(fric)
    summary["caveats"] = json_clean({"banners": warnings, "reference": cav, "lines": cav_lines})
    summary["provenance"] = json_clean(prov)
    summary["global"] = json_clean({lab: glob.get(lab) or None for lab in result.labels})
    summary["model"] = None if model is None else model.to_dict()
    names = ["report.html", "sigma_n.png", "discrepancy.csv", "summary.json"]
    with staged(outdir) as stage:
        (stage / "report.html").write_text(text, encoding="utf-8")
        (stage / "sigma_n.png").write_bytes(figures[result.points.index(result.primary)])   # the headline
        result.discrepancy().to_csv(stage / "discrepancy.csv", index=False, float_format="%.9g")
        (stage / "summary.json").write_text(json.dumps(summary, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
    return [Path(outdir) / n for n in names]


def _solver_options(record) -> dict | None:
    """Analysis options a reference summary records (method, algorithm, penalty factors, coupling)."""
    sm = getattr(record, "summary", None) or {}
    keys = ("method", "algorithm", "load_introduction", "penalty_k", "solver")
    return {k: sm[k] for k in keys if k in sm} or None
