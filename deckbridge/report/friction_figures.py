"""The report's 'Friction' section: data (summary.json ``friction``) and figures, for the sources whose
record carries friction.csv (:mod:`deckbridge.friction_table`; reference solver, contact.tangential: friction).

Per source label (:func:`friction_data`):
- ``tau_wall``: at each compared load factor the path has as a state, tau(theta) [Pa] through the wall
  (:func:`deckbridge.quantities.tangential_traction`), drawn beside sigma_N around the tension side;
- ``stick_map``: theta x lambda status of the table nodes per azimuth, 0 = stick (every node sticks or
  is open, not all open), 1 = slip (some node slips), 2 = open (every node open); states: the end of
  step 1 (lambda = 0) and the increments of step 2;
- ``resultant``: per state the vector sum of the tangential forces [N] (table on body, global xyz) of
  the table rows and of every row, its component along -e_T (``along_t_n``, e_T the direction of the
  applied shear T), the whole contact force F_n n + F_t of every row (``contact_xyz_n``,
  ``contact_along_t_n``) and the applied shear T lambda [N] (``applied_t_n``, model known). The whole
  contact force always balances T lambda (reactions); the tangential forces alone do with no stop in
  contact (a stop in contact takes part of T by its normal forces). Without a model: |horizontal part|.
"""

from __future__ import annotations

import numpy as np
from matplotlib.colors import ListedColormap

from .. import quantities as Q
from ..azimuth import snap_deg
from ..compare.load_path import centred
from ..friction_table import state_rows, states
from .figures import colours, plain_text
from .load_path_figures import _fig, theta_lambda_map_figure

STICK, SLIP, OPEN = 0, 1, 2
CODES = {"0": "stick", "1": "slip", "2": "open"}


def stick_code(rows) -> tuple[np.ndarray, np.ndarray]:
    """(azimuths [deg], code per azimuth) of one state's table rows (codes: module doc)."""
    r = Q.table_rows(rows)
    th = snap_deg(r["theta_deg"].to_numpy(float))
    st = r["stick_status"].to_numpy(str)
    keys = np.unique(th)
    code = [OPEN if np.all(st[th == k] == "open") else SLIP if np.any(st[th == k] == "slip") else STICK for k in keys]
    return keys, np.array(code, int)


def _path_states(df):
    """States of the map and the resultant: end of step 1, then step 2 from increment 1."""
    all_states = list(states(df))
    s1 = [s for s in all_states if s[0] == 1][-1:]
    return s1 + [s for s in all_states if s[0] == 2 and s[1] > 0]


def friction_data(records: dict, labels: list[str], load_factors: list[float], model=None) -> dict:
    """{label: {'tau_wall', 'stick_map', 'resultant'}} for the labels whose record has friction ({} if none)."""
    e_t, t_size = None, None
    if model is not None and model.loads.T > 0:
        tv = np.asarray(model.load_vectors()["T_force"], float)
        t_size, e_t = float(np.linalg.norm(tv)), tv / np.linalg.norm(tv)
    out = {}
    for lab in labels:
        fr = getattr(records.get(lab), "friction", None)
        if fr is None or fr.empty:
            continue
        tau = []
        for lam in load_factors:
            rows = state_rows(fr, float(lam))
            if rows is not None:
                tw = Q.tangential_traction(rows)
                tau.append({"load_factor": float(lam), "theta_deg": tw.index.tolist(), "tau_pa": tw.tolist()})
        smap = {"theta_deg": None, "load_factor": [], "status": [], "codes": CODES}
        res = {k: [] for k in ("step", "increment", "load_factor", "table_xyz_n", "all_xyz_n", "along_t_n",
                               "contact_xyz_n", "contact_along_t_n", "applied_t_n")}
        for step, inc, lam, rows in _path_states(fr):
            th, code = stick_code(rows)
            smap["theta_deg"] = th.tolist()
            smap["load_factor"].append(lam)
            smap["status"].append(code.tolist())
            f_all = Q.tangential_resultant(rows)
            res["step"].append(step)
            res["increment"].append(inc)
            res["load_factor"].append(lam)
            res["table_xyz_n"].append(Q.tangential_resultant(Q.table_rows(rows)).tolist())
            res["all_xyz_n"].append(f_all.tolist())
            f_c = Q.contact_resultant_vector(rows)
            res["contact_xyz_n"].append(f_c.tolist())
            res["along_t_n"].append(float(-f_all @ e_t) if e_t is not None else float(np.linalg.norm(f_all[:2])))
            res["contact_along_t_n"].append(float(-f_c @ e_t) if e_t is not None else float(np.linalg.norm(f_c[:2])))
            res["applied_t_n"].append(None if t_size is None else t_size * lam)
        out[lab] = {"tau_wall": tau, "stick_map": smap, "resultant": res}
    return out


@plain_text
def tau_sigma_figure(point, labels: list[str], data: dict, azimuth_deg: float):
    """Two panels at one load factor around the tension side: sigma_N [MPa] and tau [MPa] through the wall."""
    fig = _fig(11.0, 4.0)
    ax_s, ax_t = fig.subplots(1, 2)
    col = colours(labels)
    for lab in labels:
        p = point.profiles.get(lab)
        if p is not None:
            rel, s = centred(p.theta, p.sigma, azimuth_deg)
            ax_s.plot(rel, s / 1e6, "o-", ms=2.5, color=col[lab], label=lab)
        tw = next((t for t in data.get(lab, {}).get("tau_wall", [])
                   if abs(t["load_factor"] - point.load_factor) <= 1e-9 * max(1.0, point.load_factor)), None)
        if tw is not None:
            rel, t = centred(np.asarray(tw["theta_deg"]), np.asarray(tw["tau_pa"]), azimuth_deg)
            ax_t.plot(rel, t / 1e6, "o-", ms=2.5, color=col[lab], label=lab)
    for ax, name in ((ax_s, "σN [MPa] (< 0 compression)"), (ax_t, "τ = Σ|F_t| / Σ area through the wall [MPa]")):
        ax.axhline(0, color="black", lw=0.8)
        ax.set_xlim(-180, 180)
        ax.set_xticks(np.arange(-180, 181, 45))
        ax.set_xlabel(f"θ − {azimuth_deg:g}° (0 = tension side) [deg]")
        ax.set_title(name, fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


@plain_text
def stick_map_figure(data: dict, labels: list[str]):
    """theta x lambda stick / slip / open of the table per source."""
    maps = {lab: data[lab]["stick_map"] for lab in labels if lab in data}
    return theta_lambda_map_figure(maps, labels, ListedColormap(["#2ca02c", "#ff7f0e", "#7f7f7f"]), -0.5, 2.5,
                                   "table friction: green stick, orange slip (some node), grey open through the wall")


@plain_text
def resultant_figure(data: dict, labels: list[str]):
    """-Sum F_t along T [N] against lambda per source, the applied T lambda dashed black."""
    fig = _fig(7.0, 4.0)
    ax = fig.add_subplot(1, 1, 1)
    col = colours(labels)
    applied = None
    for lab in labels:
        if lab not in data:
            continue
        r = data[lab]["resultant"]
        ax.plot(r["load_factor"], r["along_t_n"], "o-", ms=3, color=col[lab], label=f"{lab}: −Σ F_t along T")
        ax.plot(r["load_factor"], r["contact_along_t_n"], "x:", ms=4, color=col[lab],
                label=f"{lab}: −Σ (F_n n + F_t) along T (with the stop)")
        if r["applied_t_n"] and r["applied_t_n"][0] is not None:
            applied = r
    if applied is not None:
        ax.plot(applied["load_factor"], applied["applied_t_n"], "k--", lw=1, label="applied T·λ")
    ax.set_xlabel("load factor λ")
    ax.set_ylabel("[N]")
    ax.set_title("resultant of the tangential forces against the applied shear", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig
