"""What the report must say about each analysis: how it differs from the reference's, and its limits.

:func:`deck_options` reads a source's deck (the ``.inp`` / ``.bdf`` beside its results): NLGEOM
(``*STEP, NLGEOM`` in CalculiX, ``NLGEOM=YES`` in Abaqus, ``PARAM,LGDISP`` >= 0 in Nastran), the skirt's
element type, and the deck units (``** deckbridge-units: mm`` header line; SI when absent).
:func:`banners` compares them with the reference solver's analysis (small strain, C3D8I, SI).
:func:`provenance`: date, command line, model hash, versions. Thresholds are stated in :data:`SMALL_STRAIN`.
"""

from __future__ import annotations

import datetime as _dt
import hashlib
import re
import sys
from pathlib import Path

from .. import quantities as Q
from ..methods import PENALTY

REFERENCE_ANALYSIS = {"nlgeom": False, "element": "C3D8I", "units": "SI"}
SMALL_STRAIN = {"lift_over_radius": Q.SMALL_STRAIN_LIFT, "rotation_rad": 0.01}   # flag above these


def _deck_of(origin) -> Path | None:
    if origin is None:
        return None
    p = Path(str(origin))
    for suffix in (".inp", ".bdf", ".dat", ".nas"):
        q = p.with_suffix(suffix)
        if q.is_file() and (suffix != ".dat" or q.read_text(errors="replace")[:4096].lstrip().startswith(("SOL", "$"))):
            return q
    return None


def deck_options(origin) -> dict | None:
    """{'deck', 'nlgeom', 'element', 'units'} of the deck beside ``origin``; None without a deck."""
    deck = _deck_of(origin)
    if deck is None:
        return None
    text = deck.read_text(errors="replace")
    up = text.upper()
    if deck.suffix.lower() == ".inp":
        nl = bool(re.search(r"^\*STEP[^\n]*NLGEOM(?!\s*=\s*NO)", up, re.M))
    else:
        m = re.search(r"^PARAM\s*,\s*LGDISP\s*,\s*(-?\d+)", up, re.M)
        nl = bool(m and int(m.group(1)) >= 0)
    el = re.search(r"TYPE\s*=\s*(C3D8I?|C3D20R?)\b[^\n]*ELSET\s*=\s*ESKIRT", up)
    el = el.group(1) if el else ("CHEXA" if "CHEXA" in up else None)
    units = re.search(r"^\*\*\s*deckbridge-units:\s*(\S+)", text, re.M | re.I)
    return {"deck": str(deck), "nlgeom": nl, "element": el, "units": units.group(1) if units else "SI"}


def banners(options: dict[str, dict | None]) -> list[str]:
    """One line per source whose analysis differs from the reference solver's."""
    out = []
    for lab, o in options.items():
        if not o:
            continue
        diff = []
        if o["nlgeom"]:
            diff.append("NLGEOM (large displacements; the reference is small-strain)")
        if o["element"] and o["element"] not in ("C3D8I", "CHEXA"):
            diff.append(f"element {o['element']} (reference C3D8I)")
        if str(o["units"]).upper() != "SI":
            diff.append(f"deck units {o['units']} (read back to SI)")
        if diff:
            out.append(f"{lab}: analysis differs from the reference: " + "; ".join(diff) + f" [{Path(o['deck']).name}]")
    return out


def reference_caveats(model, mesh, system, sol) -> dict:
    """Limits of a reference solution at lambda_max: springs on lifted nodes, radial stop on nodes lifted
    more than the wall thickness, where T goes (springs vs stop), k_c, small-strain flag."""
    import numpy as np
    p, last = system.problem, -1
    table = p.contact_surface == "table"
    lift = np.zeros(p.n_nodes)
    lift[p.contact_nodes[table]] = np.maximum(sol.gap[last, table], 0.0)
    lifted_nodes = np.flatnonzero(lift > 0)
    on_lifted = np.isin(p.spring_nodes, lifted_nodes)
    ft = sol.spring_force[last]
    stop = p.contact_surface == "stop"
    high = stop & (lift[p.contact_nodes] > model.geometry.thickness)
    t_vec = np.asarray(model.load_vectors()["T_force"], float) * float(sol.load_factor[last])
    t_hat = t_vec / (np.linalg.norm(t_vec) or 1.0)
    springs_t = float(np.sum(ft[:, None] * p.spring_dirs, axis=0) @ t_hat)
    stop_t = float(np.sum(sol.force[last, stop][:, None] * p.contact_normals[stop], axis=0) @ t_hat) if stop.any() else 0.0
    max_lift = float(lift.max())
    rot = max_lift / (2.0 * model.geometry.radius)
    k = p.contact_k[table] * (sol.k_factor or 1.0)
    pen = model.contact.penalty
    return {
        "load_factor": float(sol.load_factor[last]),
        "springs_on_lifted_nodes_kn": float(np.abs(ft[on_lifted]).sum()) / 1e3,
        "stop_force_on_nodes_lifted_beyond_t_kn": float(np.abs(sol.force[last, high]).sum()) / 1e3,
        "t_into_springs_kn": -springs_t / 1e3, "t_into_stop_kn": -stop_t / 1e3, "t_applied_kn": float(np.linalg.norm(t_vec)) / 1e3,
        "k_c_n_per_m": None if sol.method != PENALTY else {"min": float(k.min()), "max": float(k.max())},
        "alpha": None if sol.method != PENALTY or pen.k_normal is not None else pen.alpha * (sol.k_factor or 1.0),
        "n_z": model.mesh.n_z, "element_height_m": model.geometry.height / model.mesh.n_z,
        "max_lift_m": max_lift, "lift_over_radius": max_lift / model.geometry.radius, "rotation_rad": rot,
        "small_strain_exceeded": bool(max_lift / model.geometry.radius > SMALL_STRAIN["lift_over_radius"]
                                      or rot > SMALL_STRAIN["rotation_rad"]),
        "thresholds": dict(SMALL_STRAIN),
    }


def caveat_lines(label: str, c: dict) -> list[str]:
    """The report's sentences for one reference source's caveats."""
    out = [f"{label} at λ = {c['load_factor']:.4g}: circumferential springs still act on lifted nodes, "
           f"Σ|F_t| = {c['springs_on_lifted_nodes_kn']:.3g} kN; radial-stop force on nodes lifted more than the wall "
           f"thickness: {c['stop_force_on_nodes_lifted_beyond_t_kn']:.3g} kN; T = {c['t_applied_kn']:.4g} kN goes "
           f"{c['t_into_springs_kn']:.4g} kN into the springs and {c['t_into_stop_kn']:.4g} kN into the stop."]
    if c.get("k_c_n_per_m"):
        out.append(f"{label}: k_c = {c['k_c_n_per_m']['min']:.4g} … {c['k_c_n_per_m']['max']:.4g} N/m per node"
                   + (f" (α = {c['alpha']:g}" if c.get("alpha") is not None else " (explicit k")
                   + f", n_z = {c['n_z']}, element height {c['element_height_m']:.4g} m: k_c scales with 1/element height).")
    if c["small_strain_exceeded"]:
        out.append(f"{label}: the base lifts by {c['max_lift_m'] * 1e3:.3g} mm (lift/R = {c['lift_over_radius']:.3g}, "
                   f"rotation ≈ lift/2R = {c['rotation_rad']:.3g} rad), past the small-strain range "
                   f"(flag above lift/R {SMALL_STRAIN['lift_over_radius']:g} or {SMALL_STRAIN['rotation_rad']:g} rad).")
    return out


def provenance(model=None, sources: dict | None = None, solver_versions: dict | None = None) -> dict:
    """Date (UTC), command line, model hash (sha256 of its YAML), deckbridge version, solver versions
    (``solver_versions``: {source label: version} of the external solvers whose results are compared,
    :func:`deckbridge.dialects.solver_versions`), per-source analysis options."""
    from .html import deckbridge_version
    return {
        "date_utc": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "command_line": " ".join(sys.argv),
        "model_sha256": None if model is None else hashlib.sha256(model.to_yaml().encode()).hexdigest(),
        "deckbridge_version": deckbridge_version(),
        "solvers": {"reference_solver": deckbridge_version(), "python": sys.version.split()[0],
                    **(solver_versions or {})},
        "sources": sources or {},
    }
