"""The load path of each source against lambda: the data the report's load-path figures draw.

Per series and printed state (:func:`load_path`): load_factor, lifted arc [deg] (every table node at
the azimuth open), through-wall sigma_N [Pa] at the tension side (``azimuth_deg``, the side M and T H
lift) and at the compression side (+180 deg), peak sigma_N through the wall and at one node [Pa], and
the beam-theory values sigma = -N / (2 pi R t) -+ lambda M_b / (pi R^2 t) at both sides when the model is
given. :func:`status_map`: theta x lambda contact status, 0 = every node closed, 1 = some open,
2 = every node open. Definitions of the quantities: :mod:`deckbridge.quantities`.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import quantities as Q
from ..azimuth import snap_deg
from .series import Series


def beam_sides(model, lam: np.ndarray) -> dict:
    """Beam theory (full contact) sigma [Pa] at the tension and compression side along lambda."""
    g = model.geometry
    t = Q.beam_theory_sigma(model.loads.N, np.asarray(lam, float) * model.base_moment, g.radius, g.thickness, 0.0)
    c = Q.beam_theory_sigma(model.loads.N, np.asarray(lam, float) * model.base_moment, g.radius, g.thickness, 180.0)
    return {"beam_tension_side_pa": t.tolist(), "beam_compression_side_pa": c.tolist(),
            "beam_theory_liftoff_load_factor": model.beam_theory_liftoff()}


def load_path(series: Series, model=None, azimuth_deg: float | None = None) -> dict:
    """Columns of the load path of one series (lists, JSON-ready; see the module doc)."""
    az = (model.loads.azimuth if model is not None else 0.0) if azimuth_deg is None else azimuth_deg
    cols = {k: [] for k in ("load_factor", "lifted_arc_deg", "tension_side_pa", "compression_side_pa",
                            "peak_wall_pa", "peak_node_pa")}
    for st in series.states:
        if st.rows is None:
            continue
        sides = Q.section_sides(st.rows, az)
        cols["load_factor"].append(float(st.load_factor))
        cols["lifted_arc_deg"].append(Q.lifted_arc_deg(st.rows))
        cols["tension_side_pa"].append(sides["tension_side_pa"])
        cols["compression_side_pa"].append(sides["compression_side_pa"])
        cols["peak_wall_pa"].append(float(np.min(st.profile.sigma)))
        cols["peak_node_pa"].append(Q.peak_node(st.rows)[0])
    out = {"tension_side_azimuth_deg": float(az), **cols}
    if model is not None:
        out.update(beam_sides(model, np.array(cols["load_factor"])))
    return out


def status_map(series: Series) -> dict:
    """{'theta_deg': [...], 'load_factor': [...], 'status': [[per theta] per state]} (0/1/2, module doc)."""
    theta = series.theta
    rows = []
    for st in series.states:
        r = Q.table_rows(st.rows)
        g = pd.Series(r["status"].to_numpy() == "open", index=snap_deg(r["theta_deg"].to_numpy(float))).groupby(level=0)
        code = (g.any().astype(int) + g.all().astype(int)).reindex(theta).fillna(0).astype(int)
        rows.append(code.tolist())
    return {"theta_deg": theta.tolist(), "load_factor": series.load_factors.tolist(), "status": rows}


def centred(theta_deg: np.ndarray, values: np.ndarray, azimuth_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """Azimuths relative to the tension side in [-180, 180) with the values, sorted (for plots)."""
    rel = (np.asarray(theta_deg, float) - azimuth_deg + 180.0) % 360.0 - 180.0
    o = np.argsort(rel)
    return rel[o], np.asarray(values, float)[o]
