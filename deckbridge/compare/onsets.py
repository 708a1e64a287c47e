"""Liftoff onsets, two per source: the first table node (lambda_c) and the whole section (every
through-wall node of one azimuth open).

One function, :func:`onsets`, gives every number the console, summary.json, the report and the
README quote. Each onset is a dict with separate keys, never one key for two kinds of value:

- ``exact``: the reference solver's own value (it follows the piecewise-linear path; the first-node
  one is its ``liftoff_load_factor``, the section one ``section_liftoff_load_factor`` written by
  ``deckbridge run``), taken from the source's summary.json when the source has one for this method;
- ``bracket``: [lambda_i, lambda_i+1], the last printed state without and the first with the event
  (lambda_i = lambda_i+1 when the first state already has it); always given where the event occurs;
- ``interpolated`` (first node only): each node's sigma_N extrapolated linearly to 0 from the last two
  states without liftoff, an estimate (exact only while sigma_N is linear in lambda up to the onset);
- ``theta_deg``: where (exact: the solver's; else the first lifted azimuth of the bracket's upper state).
"""

from __future__ import annotations

import numpy as np

from .. import summary_keys as K
from .metrics import _nodes_lifted, liftoff_load_factor
from .series import Series


def _bracket(series: Series, event) -> tuple[list[float] | None, float | None]:
    prev = None
    for st in series.states:
        where = event(st)
        if where is not None:
            lo = float(st.load_factor) if prev is None else float(prev.load_factor)
            return [lo, float(st.load_factor)], where
        prev = st
    return None, None


def _first_node(st) -> float | None:
    up = _nodes_lifted(st.nodes)
    if not up.any():
        return None
    th = st.nodes.index.get_level_values("theta").to_numpy(float)[up]
    sig = st.nodes["sigma"].to_numpy(float)[up]
    return float(th[int(np.argmax(sig))])


def _section(st) -> float | None:
    up = np.flatnonzero(st.profile.all_open)
    return None if up.size == 0 else float(st.profile.theta[up[int(np.argmax(st.profile.sigma[up]))]])


def _exact(summary: dict | None, method: str, key: str):
    if not isinstance(summary, dict) or summary.get("method") not in (None, method) or key not in summary:
        return None
    v = summary.get(key)
    return float(v) if isinstance(v, (int, float)) else None


def onsets(series: Series, summary: dict | None = None) -> dict:
    """{'first_node': {...}, 'section': {...}} of one series (see the module doc); ``summary``: the
    source's solver summary (reference folders), None for an external solver."""
    out = {}
    for name, event, exact_key, theta_key in (
            ("first_node", _first_node, K.LIFTOFF_LOAD_FACTOR, K.LIFTOFF_THETA_DEG),
            ("section", _section, K.SECTION_LIFTOFF_LOAD_FACTOR, K.SECTION_LIFTOFF_THETA_DEG)):
        bracket, where = _bracket(series, event)
        exact = _exact(summary, series.method, exact_key)
        o = {"exact": exact, "bracket": bracket, "theta_deg": where}
        if exact is not None and summary.get(theta_key) is not None:
            o["theta_deg"] = float(summary[theta_key])
        if name == "first_node":
            o["interpolated"] = liftoff_load_factor(series) if bracket is not None else None
        out[name] = o
    return out


def best(onset: dict) -> float | None:
    """The value to place a comparison point by: exact, else interpolated, else the bracket's upper end."""
    if onset.get("exact") is not None:
        return onset["exact"]
    if onset.get("interpolated") is not None:
        return onset["interpolated"]
    return None if onset.get("bracket") is None else onset["bracket"][1]


def describe(onset: dict) -> str:
    """One line for the console and the report: 'lambda = 0.5880 (exact)' or 'lambda in [0.5, 0.6]
    (interpolated 0.5909)', 'none' when it does not happen."""
    if onset.get("exact") is not None:
        return f"λ = {onset['exact']:.4f} (exact)"
    if onset.get("bracket") is None:
        return "none"
    lo, hi = onset["bracket"]
    s = f"λ in [{lo:.4g}, {hi:.4g}]"
    return s + (f" (interpolated {onset['interpolated']:.4f})" if onset.get("interpolated") is not None else "")
