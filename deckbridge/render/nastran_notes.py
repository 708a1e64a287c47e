"""Explanatory header of the Nastran-family decks: units, analysis, penalty, sets (template values).

The first comment line ``$ deckbridge-units: SI|mm`` is machine-readable: the readers
(:mod:`deckbridge.dialects.nastran.reader`, :mod:`deckbridge.dialects.mystran.reader`) convert results
back to SI by it (:func:`deckbridge.dialects.nastran.reader.deck_units`).
"""

from __future__ import annotations

import numpy as np

from ..mesh import SkirtMesh
from ..model import Model
from ..numbering.nastran import SET_BOTTOM_ROW, bottom_row_elements, gap_layout, ground_distance
from ..units import UNIT_LABEL, scale

UNITS_TAG = "deckbridge-units:"


def _range(values: np.ndarray) -> str:
    lo, hi = float(np.min(values)), float(np.max(values))
    return f"{lo:.4g}" if np.isclose(lo, hi, rtol=1e-6) else f"{lo:.4g} .. {hi:.4g}"


def axial_stiffness_ratio(model: Model, mesh: SkirtMesh) -> np.ndarray:
    """KA / (E A / L) per gap: L = size of the neighbouring element along the gap axis (first-row
    height h for the table, radial element width t / n_r for the stop), A = the node's tributary
    area; E A / L is that element's axial stiffness over the node's share [-]."""
    lay = gap_layout(mesh)
    length = np.where(lay.surface == "table", ground_distance(mesh), model.geometry.thickness / mesh.n_r)
    return lay.k * length / (model.material.E * lay.area)


def context(model: Model, mesh: SkirtMesh) -> dict:
    """Template values of the header comments and the stress-output set (SI quantities in deck units)."""
    u = scale(model.units)
    lay = gap_layout(mesh)
    ratio = axial_stiffness_ratio(model, mesh)
    k_unit = "N/m" if model.units == "SI" else "N/mm"
    surfaces = []
    for s in ("table", "stop"):
        sel = lay.surface == s
        if sel.any():
            surfaces.append({"name": s, "n": int(sel.sum()), "ka": _range(lay.k[sel] * u.stiffness),
                             "ratio": _range(ratio[sel])})
    pen = model.contact.penalty
    rows = bottom_row_elements(mesh)
    return {
        "units_tag": f"{UNITS_TAG} {model.units}", "unit_label": UNIT_LABEL[model.units], "k_unit": k_unit,
        "length_unit": "m" if model.units == "SI" else "mm",
        "penalty_rule": (f"KA = contact.penalty.k_normal = {pen.k_normal:g} N/m (explicit)" if pen.k_normal
                         else f"KA = k_c = alpha A K / h, alpha = {pen.alpha:g}, K = E / (3 (1 - 2 nu))"),
        "surfaces": surfaces, "open_ratio": f"{mesh.k_open_ratio:g}",
        "below_guidance": f"{1e3 / float(np.median(ratio)):.0e}",
        "nlgeom": model.analysis.nlgeom, "n_top": int(mesh.top_nodes.size),
        "stress_set": SET_BOTTOM_ROW, "stress_first": int(rows[0]), "stress_last": int(rows[-1]),
        "n_stress": int(rows.size), "stress_list": id_ranges(rows),
    }


def id_ranges(ids, width: int = 64) -> str:
    """Case-control SET members: ``a THRU b`` runs of consecutive ids, comma separated, lines of at
    most ``width`` characters ending with a comma when continued (the user's ids of an imported mesh
    need not be consecutive; the structured mesh's are one run)."""
    ids = np.unique(np.asarray(ids, np.int64))
    cut = np.flatnonzero(np.diff(ids) != 1) + 1
    items = [f"{r[0]} THRU {r[-1]}" if r.size > 1 else f"{r[0]}" for r in np.split(ids, cut)]
    lines, cur = [], ""
    for it in items:
        if cur and len(cur) + len(it) + 2 > width:
            lines.append(cur + ",")
            cur = it
        else:
            cur = f"{cur}, {it}" if cur else it
    return "\n".join(lines + [cur])

