"""The self-contained report.html: figures as base64 PNG, tables, model summary; no external resource.

Rendered from the jinja2 template ``templates/comparison.html.j2`` (package data, found through
importlib.resources) with autoescape: every text that comes from a file or a model (labels, paths,
names) is HTML-escaped by the template. Python here only shapes the view (rows of plain text,
numbers formatted). A few lines of inline script (``templates/_page.html.j2``) record, after loading,
how many images decoded and whether a script error occurred (body attributes data-images,
data-errors, data-figure-rect), for headless checks.
"""

from __future__ import annotations

import base64
from importlib.metadata import PackageNotFoundError, version

import jinja2

from .. import quantities as Q
from ..compare.onsets import describe
from ..compare.result import ComparisonResult
from ..compare.ring_lines import ring_line_text


def env() -> jinja2.Environment:
    """The templates' environment: package data of deckbridge.report, autoescape on."""
    e = jinja2.Environment(loader=jinja2.PackageLoader("deckbridge.report", "templates"), autoescape=True,
                           trim_blocks=True, lstrip_blocks=True, undefined=jinja2.StrictUndefined)
    e.filters["fmt"] = lambda v, spec: format(v, spec)
    e.filters["b64"] = lambda png: base64.b64encode(png).decode("ascii")
    return e


def deckbridge_version() -> str:
    try:
        return version("deckbridge")
    except PackageNotFoundError:
        return "dev"


def mpa(v) -> str:
    return "–" if v is None else f"{v / 1e6:.3f}"


def fmt(v, spec=".4g") -> str:
    return "–" if v is None else format(v, spec)


def zones_text(zones) -> str:
    if zones is None:
        return "–"
    if not zones:
        return "none"
    return "; ".join(f"[{a:.1f}, {b:.1f}]" for a, b in zones)


def model_rows(model) -> list[tuple[str, str]]:
    """(quantity, value) lines of the model summary, with the beam-theory liftoff anchor."""
    g, m, mat, ld, st, pen = model.geometry, model.mesh, model.material, model.loads, model.steps, model.contact.penalty
    lam_c = model.beam_theory_liftoff()
    return [
        ("name / title", f"{model.name} / {model.title}"),
        ("geometry", f"R = {g.radius:g} m, H = {g.height:g} m, t = {g.thickness:g} m, top radius = {g.r_top:g} m"),
        ("mesh", f"{m.n_theta} × {m.n_z} × {m.n_r} hexahedra (θ × z × r)"),
        ("material", f"{mat.name}: E = {mat.E:.4g} Pa, ν = {mat.nu:g}"),
        ("contact", f"table + stop ({model.contact.stop.side}), friction μ = {model.contact.friction:g}; penalty "
                    + (f"k = {pen.k_normal:.4g} N/m" if pen.k_normal else f"α = {pen.alpha:g} (k = α A² K / V)")
                    + f", open ratio {pen.open_ratio:g}"),
        ("load introduction", model.load_introduction),
        ("loads", f"N = {ld.N:.4g} N (step 1), T = {ld.T:.4g} N, M = {ld.M:.4g} N·m at λ = 1 (step 2), "
                  f"tension side at {ld.azimuth:g}°; M_b = M + T·H = {model.base_moment:.4g} N·m"),
        ("steps", f"λ_max = {st.lambda_max:g} in {st.increments} increments"),
        ("beam theory (rigid section)", "liftoff at λ = N·R / (2 M_b) = " + fmt(lam_c)),
    ]


def render(result: ComparisonResult, figures: list[bytes], model=None, glob: dict | None = None,
           inputs: dict | None = None, notes: list[str] | None = None, global_png: bytes | None = None,
           path_pngs: list | None = None, banners: list[str] | None = None, caveats: list[str] | None = None,
           provenance: dict | None = None, friction_pngs: list | None = None, verdict: dict | None = None) -> str:
    """The report as one HTML string (``figures``: PNG bytes per compared load factor)."""
    glob, inputs = glob or {}, inputs or {}
    points = [_point(pt, png) for pt, png in zip(result.points, figures)]
    sources = []
    for s in result.series:
        lo, hi = s.lf_range
        sources.append([s.label, inputs.get(s.label, s.origin or "–"), str(s.n_theta),
                        f"{lo:.4g} … {hi:.4g}", str(len(s.states)), onset_text(result.onsets[s.label]["first_node"]),
                        onset_text(result.onsets[s.label]["section"])])
    rows = []
    for s in result.series:
        gm = glob.get(s.label) or {}
        u = gm.get("max_displacement_m")
        rows.append([s.label, mpa(gm.get("max_von_mises_pa")), "–" if u is None else f"{u * 1e3:.4g}",
                     gm.get("from", "not available for this source")])
    have = [(s.label, glob[s.label]) for s in result.series if glob.get(s.label, {}).get("max_von_mises_pa")]
    pair = None
    if len(have) >= 2:
        (la, ga), (lb, gb) = have[0], have[1]
        pct = (gb["max_von_mises_pa"] - ga["max_von_mises_pa"]) / ga["max_von_mises_pa"] * 100
        pair = {"a": la, "b": lb, "pct": pct}
    return env().get_template("comparison.html.j2").render(
        ver=deckbridge_version(), primary=_point(result.primary, figures[result.points.index(result.primary)]),
        points=points, sources=sources, source_head=SOURCE_HEAD,
        model_rows=None if model is None else model_rows(model), global_rows=rows, von_mises_pair=pair,
        global_png=global_png, notes=list(notes or []), path_pngs=list(path_pngs or []),
        banners=list(banners or []), caveats=list(caveats or []), friction_pngs=list(friction_pngs or []),
        verdict=verdict, ring_lines=ring_line_text(result),
        provenance=[(k, str(v)) for k, v in (provenance or {}).items() if k != "sources"],
        definitions=[f"{k} [{q.unit}], weighting {q.weighting}: {q.definition}" for k, q in Q.DEFINITIONS.items()])


def onset_text(onset: dict) -> str:
    """The onset as the console prints it, with its azimuth."""
    s = describe(onset)
    return s if onset.get("theta_deg") is None else f"{s} at θ = {onset['theta_deg']:.1f}°"


def _point(pt, png: bytes) -> dict:
    """One compared load factor: its figure, the per-source rows and the pair rows (plain text)."""
    return {"load_factor": pt.load_factor, "what": pt.what, "png": png, "skipped": pt.skipped,
            "sources": source_rows(pt, pt.labels),
            "pairs": [[p["b"] + " − " + p["a"], mpa(p["max_abs_diff_pa"]), f"{p['theta_of_max_diff_deg']:.1f}",
                       mpa(p["rms_diff_pa"]), f"{p['liftoff_zone_overlap']:.3f}",
                       "no zone" if p["liftoff_zone_overlap_tol"] is None else f"{p['liftoff_zone_overlap_tol']:.3f}"]
                      for p in pt.pairs]}


SOURCE_HEAD = ["source", "liftoff zones [deg]", "peak σN through the wall [MPa]", "at θ [deg]", "peak node σN [MPa]",
               "at θ [deg]", "lifted arc [deg]", "checks"]        # the columns of source_rows


def source_rows(pt, labels) -> list[list[str]]:
    """Per source at one point: label, liftoff zones, peak compression through the wall and of one node
    [MPa] with their azimuths, the lifted arc, and the checks that warn."""
    rows = []
    for lab in labels:
        node = pt.node_peaks.get(lab)
        ex = pt.extra.get(lab, {})
        checks = []
        if ex.get("szz_resultant_residual") is not None:
            checks.append(("WARNING " if ex.get("warn") else "") + f"σzz equilibrium residual {ex['szz_resultant_residual']:.2%}")
        if ex.get("open_tension_ratio", 0.0) > Q.TENSION_WARN:
            checks.append(f"WARNING open-gap tension {ex['open_tension_ratio']:.1%} of the peak (kept, not clipped)")
        if ex.get("free_penetration_warn"):
            checks.append(f"WARNING node(s) {ex['free_penetration_nodes']} penetrate the table up to "
                          f"{ex['free_penetration_m'] * 1e3:.3g} mm with no contact force (contact search miss?)")
        rows.append([lab, zones_text(pt.zones[lab]), mpa(pt.peaks[lab][0]), theta_text(pt.peaks[lab][1]),
                     mpa(None if node is None else node[0]), "–" if node is None else theta_text(node[1]),
                     fmt(ex.get("lifted_arc_deg"), ".1f"), "; ".join(checks) or "–"])
    return rows


def theta_text(theta) -> str:
    return "uniform" if theta is None else f"{theta:.1f}"
