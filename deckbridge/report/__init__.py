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

from ..compare.result import ComparisonResult
from ..jsonable import json_clean
from ..outdir import staged
from .figures import global_figure, png_bytes, sigma_n_figure
from .html import render

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
    text = render(result, figures, model=model, glob=glob, inputs=extra.get("inputs"), notes=extra.get("notes"),
                  global_png=None if gfig is None else png_bytes(gfig))
    summary = result.summary()
    summary["global"] = json_clean({lab: glob.get(lab) or None for lab in result.labels})
    summary["model"] = None if model is None else model.to_dict()
    names = ["report.html", "sigma_n.png", "discrepancy.csv", "summary.json"]
    with staged(outdir) as stage:
        (stage / "report.html").write_text(text, encoding="utf-8")
        (stage / "sigma_n.png").write_bytes(figures[-1])
        result.discrepancy().to_csv(stage / "discrepancy.csv", index=False, float_format="%.9g")
        (stage / "summary.json").write_text(json.dumps(summary, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
    return [Path(outdir) / n for n in names]
