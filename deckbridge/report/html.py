"""The self-contained report.html: figures as base64 PNG, tables, model summary; no external resource.

Every text that comes from a file or a model (labels, paths, names) is HTML-escaped. A few lines
of inline script record, after loading, how many images decoded and whether a script error
occurred (body attributes data-images, data-errors, data-figure-rect), for headless checks.
"""

from __future__ import annotations

import base64
import html
from importlib.metadata import PackageNotFoundError, version

from ..compare.result import ComparisonResult

_CSS = """
body{font-family:DejaVu Sans,Arial,sans-serif;margin:24px auto;max-width:1100px;color:#222;line-height:1.4}
h1{font-size:1.5em;border-bottom:2px solid #444}h2{font-size:1.2em;margin-top:1.8em;border-bottom:1px solid #aaa}
h3{font-size:1.05em}table{border-collapse:collapse;margin:8px 0 16px 0;font-size:.9em}
th,td{border:1px solid #bbb;padding:3px 8px;text-align:right}th{background:#eee}td.l,th.l{text-align:left}
img.figure,img.global{max-width:100%;border:1px solid #ddd}.note{color:#555;font-size:.88em}
"""

_SCRIPT = """
window.__errs=[];window.addEventListener('error',function(e){window.__errs.push(String(e.message));});
window.addEventListener('load',function(){var im=Array.prototype.slice.call(document.images);
var ok=im.filter(function(i){return i.complete&&i.naturalWidth>0;}).length;var b=document.body;
b.setAttribute('data-images',ok+'/'+im.length);var f=document.querySelector('img.figure');
if(f){var r=f.getBoundingClientRect();b.setAttribute('data-figure-rect',[r.left+window.scrollX,
r.top+window.scrollY,r.width,r.height].map(Math.round).join(','));}
b.setAttribute('data-errors',String(window.__errs.length));});
"""


def esc(x) -> str:
    return html.escape(str(x), quote=True)


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


def table(head: list[str], rows: list[list[str]], left: int = 1) -> str:
    """An HTML table; cells are already-escaped strings; the first ``left`` columns left-aligned."""
    th = "".join(f'<th class="l">{h}</th>' if i < left else f"<th>{h}</th>" for i, h in enumerate(head))
    body = "".join("<tr>" + "".join(f'<td class="l">{c}</td>' if i < left else f"<td>{c}</td>"
                                    for i, c in enumerate(r)) + "</tr>" for r in rows)
    return f"<table><tr>{th}</tr>{body}</table>"


def img(png: bytes, alt: str, cls: str = "figure") -> str:
    data = base64.b64encode(png).decode("ascii")
    return f'<img class="{cls}" alt="{esc(alt)}" src="data:image/png;base64,{data}">'


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
           inputs: dict | None = None, notes: list[str] | None = None, global_png: bytes | None = None) -> str:
    """The report as one HTML string (``figures``: PNG bytes per compared load factor)."""
    try:
        ver = version("deckbridge")
    except PackageNotFoundError:
        ver = "dev"
    glob, inputs, prim = glob or {}, inputs or {}, result.primary
    out = ["<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
           "<title>deckbridge: contact stress comparison</title>", f"<style>{_CSS}</style>",
           f"<script>{_SCRIPT}</script></head><body>",
           "<h1>Contact stress σN at the base: comparison of methods and solvers</h1>",
           f"<p class='note'>deckbridge {esc(ver)}. σN &lt; 0 compression, &gt; 0 tension / liftoff; "
           "azimuth θ in degrees counter-clockwise from +x. Differences are σN(b) − σN(a).</p>"]

    out.append(f"<h2>Summary at λ = {prim.load_factor:.4g} ({esc(prim.what)})</h2>")
    out.append(img(figures[-1], f"sigma_N vs azimuth at load factor {prim.load_factor:.4g}"))
    out.append(_source_table(prim))
    out.append(_pair_table(prim))

    out.append("<h2>Sources</h2>")
    rows = []
    for s in result.series:
        lo, hi = s.lf_range
        rows.append([esc(s.label), esc(inputs.get(s.label, s.origin or "–")), str(s.n_theta),
                     f"{lo:.4g} … {hi:.4g}", str(len(s.states)), fmt(result.liftoff[s.label])])
    out.append(table(["source", "input", "azimuths", "λ range", "states", "first liftoff λ"], rows, left=2))

    out.append("<h2>Model</h2>")
    if model is None:
        out.append("<p class='note'>No model given: node numbers mapped through the embedded default model "
                   "where a reader needed one.</p>")
    else:
        out.append(table(["quantity", "value"], [[esc(k), esc(v)] for k, v in model_rows(model)], left=2))

    out.append("<h2>σN along the azimuth</h2>")
    for pt, png in zip(result.points, figures):
        out.append(f"<h3>λ = {pt.load_factor:.4g}: {esc(pt.what)}</h3>")
        out.append(img(png, f"sigma_N vs azimuth at load factor {pt.load_factor:.4g}"))
        if pt.skipped:
            out.append(f"<p class='note'>Not compared here (load factor outside their range): "
                       f"{esc(', '.join(pt.skipped))}.</p>")
        out.append(_source_table(pt))
        out.append(_pair_table(pt))

    out.append("<h2>Global level</h2>")
    out.append("<p class='note'>Whole-model results where a source has them (reference solver: summary.json, "
               "result.vtu at its last step, i.e. λ_max).</p>")
    rows = []
    for s in result.series:
        gm = glob.get(s.label) or {}
        u = gm.get("max_displacement_m")
        rows.append([esc(s.label), mpa(gm.get("max_von_mises_pa")), "–" if u is None else f"{u * 1e3:.4g}",
                     esc(gm.get("from", "not available for this source"))])
    out.append(table(["source", "max von Mises [MPa]", "max |u| [mm]", "from"], rows, left=1))
    have = [(s.label, glob[s.label]) for s in result.series if glob.get(s.label, {}).get("max_von_mises_pa")]
    if len(have) >= 2:
        (la, ga), (lb, gb) = have[0], have[1]
        dv = (gb["max_von_mises_pa"] - ga["max_von_mises_pa"]) / ga["max_von_mises_pa"]
        out.append(f"<p>Max von Mises of {esc(lb)} differs from {esc(la)} by {dv * 100:+.2f} %.</p>")
    if global_png is not None:
        out.append(img(global_png, "von Mises maps and deformed base ring", cls="global"))

    out.append("<h2>Definitions</h2><ul class='note'>"
               "<li>σN at an azimuth: mean over the table slave nodes at that azimuth (through the wall).</li>"
               "<li>Sources are aligned on the union of their azimuths; where meshes differ a source is "
               "interpolated linearly and periodically over 360°. Between increments, σN is interpolated "
               "linearly in the load factor λ.</li>"
               "<li>Liftoff zone: azimuths with σN &gt; 0 or all nodes open; its ends where σN crosses 0 "
               "(linear interpolation). [a, b] with a &gt; b wraps through 0°.</li>"
               "<li>Zone overlap: length of the intersection over the length of the union of two zone sets "
               "on the circle (1 when neither source lifts off).</li>"
               "<li>rms: arc-length-weighted root mean square of σN(b) − σN(a) over the circle.</li>"
               "<li>First liftoff λ: onset, the load factor at which the first table slave node lifts off; "
               "each node's σN is extrapolated linearly to 0 from the last two states in full contact "
               "(kept between the last state without and the first with liftoff). Liftoff zones use the "
               "through-wall mean, so they may appear later.</li></ul>")
    for n in notes or []:
        out.append(f"<p class='note'>{esc(n)}</p>")
    out.append("</body></html>")
    return "\n".join(out)


def _source_table(pt) -> str:
    rows = [[esc(lab), zones_text(pt.zones[lab]), mpa(pt.peaks[lab][0]), f"{pt.peaks[lab][1]:.1f}"]
            for lab in pt.labels]
    return table(["source", "liftoff zones [deg]", "peak compression σN [MPa]", "at θ [deg]"], rows)


def _pair_table(pt) -> str:
    if not pt.pairs:
        return "<p class='note'>One source only: no pair to compare.</p>"
    rows = [[esc(p["b"]) + " − " + esc(p["a"]), mpa(p["max_abs_diff_pa"]), f"{p['theta_of_max_diff_deg']:.1f}",
             mpa(p["rms_diff_pa"]), f"{p['liftoff_zone_overlap']:.3f}"] for p in pt.pairs]
    return table(["pair (b − a)", "max |ΔσN| [MPa]", "at θ [deg]", "rms ΔσN [MPa]", "zone overlap (IoU)"], rows)
