"""Comparison of several sources at matching load factors: :func:`compare_tables` -> ComparisonResult.

Default load factors: the end of step 1 (N only, lambda = 0), the first common load factor at or
after the first liftoff of any source (the closest one when none is after it), the last common load
factor inside the small-strain range (every source's lift / R <= :data:`~deckbridge.quantities.SMALL_STRAIN_LIFT`,
issue 21) and the end of step 2 (the smallest lambda_max of the sources). The headline (:attr:`ComparisonResult.primary`)
is the largest default point inside the small-strain range: past it a small-strain and a large-displacement
analysis compare two idealisations, not two codes (REFERENCE.md §8); the post-liftoff points stay compared.
The sweep's per-case comparisons (:func:`compare_series` with ``headline=False``) keep the other three points.
Requested load factors replace the defaults (the headline is then the last); a source lacking one is
interpolated linearly between its increments, or refused when outside its range.
Pair differences are sigma_b - sigma_a, pairs taken in source order (a before b).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..errors import DeckbridgeError
from ..jsonable import json_clean
from ..results import SourceResult
from .align import align
from .. import quantities as Q
from .metrics import element_arc, liftoff_zones, pair_metrics, peak_compression, zone_iou, zone_iou_tol
from .onsets import best, onsets
from .profile import LAMBDA_TOL, Profile
from .ring_lines import ring_line_comparison
from .series import Series, split_tables


@dataclass
class PointResult:
    """Everything compared at one load factor."""
    load_factor: float
    what: str                                   # why this load factor ('end of step 1 (N only)', ...)
    labels: list[str]                           # sources compared here (others lack this load factor)
    profiles: dict[str, Profile]                # each source on its own azimuths
    aligned: pd.DataFrame                       # sigma_N [Pa] on the common grid, one column per label
    zones: dict[str, list[list[float]]]
    peaks: dict[str, tuple[float, float | None]]   # through-wall (sigma_N [Pa], theta [deg] or None: uniform)
    pairs: list[dict]
    skipped: list[str] = field(default_factory=list)
    node_peaks: dict[str, tuple[float, float] | None] = field(default_factory=dict)  # one node's (sigma_N, theta)
    extra: dict[str, dict] = field(default_factory=dict)    # per label: node values, wall sigma_zz, checks
    headline: bool = False                      # the report leads with this point (see the module doc)


@dataclass
class ComparisonResult:
    """Sources, the load factors they were compared at, and the metrics (see :meth:`summary`)."""
    series: list[Series]
    points: list[PointResult]
    onsets: dict[str, dict]                     # label -> compare.onsets.onsets(...) (first_node, section)
    sources: dict[str, SourceResult] = field(default_factory=dict)   # label -> the record it came from
    ring_lines: dict | None = None              # ccx f2f vs its reference on 8-/6-node faces (compare.ring_lines)

    @property
    def liftoff(self) -> dict[str, float | None]:
        """label -> first-node onset to place points by (exact, else interpolated, else bracket end);
        the labelled values are in :attr:`onsets`."""
        return {lab: best(o["first_node"]) for lab, o in self.onsets.items()}

    def source(self, label: str) -> SourceResult | None:
        """The record a series came from (its globals, fields, solver summary), None if not given."""
        return self.sources.get(label)

    @property
    def labels(self) -> list[str]:
        return [s.label for s in self.series]

    @property
    def primary(self) -> PointResult:
        """The point the top-level summary and the report lead with: the headline default point (the largest
        inside the small-strain range), else the last (largest) load factor."""
        return next((p for p in reversed(self.points) if p.headline), self.points[-1])

    def discrepancy(self) -> pd.DataFrame:
        """Per compared load factor and azimuth: sigma_N of each source and each pair's difference [Pa]."""
        frames = []
        for pt in self.points:
            df = pd.DataFrame({"load_factor": pt.load_factor, "theta_deg": pt.aligned.index.to_numpy()})
            for lab in self.labels:
                df[f"sigma_n_pa {lab}"] = pt.aligned[lab].to_numpy() if lab in pt.aligned else np.nan
            for a, b in itertools.combinations(self.labels, 2):
                ok = a in pt.aligned and b in pt.aligned
                df[f"diff_pa {b} - {a}"] = (pt.aligned[b] - pt.aligned[a]).to_numpy() if ok else np.nan
            frames.append(df)
        return pd.concat(frames, ignore_index=True)

    def summary(self) -> dict:
        """JSON-ready summary: per source and per pair at the primary load factor, then every point."""
        prim = self.primary
        sources = {}
        for s in self.series:
            lo, hi = s.lf_range
            sources[s.label] = {
                "source": s.source, "method": s.method, "input": s.origin, "n_theta": s.n_theta,
                "load_factor_range": [lo, hi],
                "onset_first_node": self.onsets[s.label]["first_node"],
                "onset_section": self.onsets[s.label]["section"],
                **_peak_keys(prim, s.label),
            }
        return json_clean({
            "conventions": "sigma_n < 0 compression, > 0 tension/liftoff [Pa]; theta [deg] CCW from +x; "
                           "pair differences are sigma_b - sigma_a; liftoff zones [start, end] CCW, "
                           "start > end wraps through 0; overlap = intersection over union on the circle; "
                           "onset_first_node: the first table slave node opens; onset_section: every through-wall "
                           "node of one azimuth open; each with exact (reference solver), bracket [lambda_i, "
                           "lambda_i+1] of the printed states, interpolated (estimate); zones and peak_compression "
                           "from the through-wall sigma_n = Sum sigma_n x area / Sum area per azimuth, peak_node = one node; "
                           "zones narrower than one element arc are dropped; liftoff_zone_overlap_tol = overlap "
                           "with a tolerance of one element arc (null: no zone in either)",
            "definitions": {k: {"unit": q.unit, "weighting": q.weighting, "definition": q.definition}
                            for k, q in Q.DEFINITIONS.items()},
            "load_factors": [p.load_factor for p in self.points],
            "primary_load_factor": prim.load_factor,
            **({} if not self.ring_lines else
               {Q.RING_LINE_FORCE_MAX_DIFF: self.ring_lines[Q.RING_LINE_FORCE_MAX_DIFF]}),
            "sources": sources,
            "pairs": prim.pairs,
            "comparisons": [{
                "load_factor": p.load_factor, "what": p.what, "sources_compared": p.labels,
                "sources_skipped": p.skipped,
                "sources": {lab: {"liftoff_zones": p.zones[lab], **_peak_keys(p, lab), **p.extra.get(lab, {})}
                            for lab in p.labels},
                "pairs": p.pairs,
            } for p in self.points],
        })


def _peak_keys(pt: PointResult, label: str) -> dict:
    peak, node = pt.peaks.get(label), pt.node_peaks.get(label)
    return {"peak_compression_pa": None if peak is None else peak[0],
            "peak_compression_theta_deg": None if peak is None else ("uniform" if peak[1] is None else peak[1]),
            "peak_node_sigma_n_pa": None if node is None else node[0],
            "peak_node_theta_deg": None if node is None else node[1]}


def _same(a: float, b: float) -> bool:
    return abs(a - b) <= LAMBDA_TOL * max(1.0, abs(a), abs(b))


def _common_load_factors(step2: list[Series], lam_max: float) -> list[float]:
    """The step-2 load factors in (0, lam_max] printed by every series of ``step2``, sorted."""
    common = None
    for s in step2:
        lfs = {round(float(x), 9) for x in s.load_factors if 0.0 < x <= lam_max * (1 + LAMBDA_TOL)}
        common = lfs if common is None else common & lfs
    return sorted(common or [])


def lift_over_radius(series: list[Series], lam: float) -> float | None:
    """Largest lift / R at ``lam`` over the series with a printed state there (None: no source says)."""
    vals = [Q.lift_over_radius(st.rows) for s in series
            if (st := s.state_at(lam)) is not None and st.rows is not None and "gap_m" in st.rows]
    return max(vals) if vals else None


def default_load_factors(series: list[Series], liftoff: dict[str, float | None],
                         headline: bool = True) -> list[tuple[float, str, bool]]:
    """(lambda, why, headline) of the default comparison points (see module doc); ``headline`` False: no
    small-strain point and no headline mark (the sweep's per-case comparisons keep their three points)."""
    pts: list[tuple[float, str]] = []
    if any(s.covers(0.0) for s in series):
        pts.append((0.0, "end of step 1 (N only)"))
    step2 = [s for s in series if s.lf_range[1] > LAMBDA_TOL]
    lam_max = min((s.lf_range[1] for s in step2), default=None)
    firsts = [v for v in liftoff.values() if v is not None]
    cands = _common_load_factors(step2, lam_max) if lam_max is not None else []
    if lam_max is not None and firsts:
        first = min(firsts)
        if LAMBDA_TOL < first < lam_max and not _same(first, lam_max):
            after = [c for c in cands if c >= first - LAMBDA_TOL * max(1.0, first)]
            if after:
                lam = after[0]
            elif cands:
                lam = min(cands, key=lambda c: abs(c - first))
            else:
                lam = first
            if not _same(lam, lam_max) and lam > LAMBDA_TOL:
                pts.append((float(lam), f"first liftoff of any source (lambda = {first:.4g})"))
    inside = [c for c in cands if headline and (v := lift_over_radius(series, c)) is not None
              and v <= Q.SMALL_STRAIN_LIFT]
    last_in = max(inside, default=None)
    if last_in is not None and lam_max is not None and not _same(last_in, lam_max) \
            and all(not _same(last_in, p) for p, _ in pts) and last_in > max((p for p, _ in pts), default=0.0):
        pts.append((float(last_in), f"last common load factor with lift/R <= {Q.SMALL_STRAIN_LIFT:g}"))
    if lam_max is not None:
        pts.append((float(lam_max), "end of step 2 (lambda_max)"))
    if not pts:
        raise DeckbridgeError("the sources share no load factor to compare at")
    return _headline(series, pts) if headline else [(lam, what, False) for lam, what in pts]


def _headline(series: list[Series], pts: list[tuple[float, str]]) -> list[tuple[float, str, bool]]:
    """Mark the largest point inside the small-strain range as the headline and say why in its text (none
    marked when no source gives gaps, or when the only ones inside are lambda = 0 and a later one exists)."""
    lift = [lift_over_radius(series, lam) for lam, _ in pts]
    if all(v is None for v in lift):
        return [(lam, what, False) for lam, what in pts]
    ok = [k for k, v in enumerate(lift) if v is not None and v <= Q.SMALL_STRAIN_LIFT and pts[k][0] > LAMBDA_TOL]
    lim = Q.SMALL_STRAIN_LIFT
    if not ok:
        k = len(pts) - 1
        why = (f"; leads the report although past the small-strain range (lift/R = {lift[k]:.3g} > {lim:g}): "
               "no compared load factor after step 1 is inside it") if lift[k] is not None else ""
    else:
        k = ok[-1]
        later = [(pts[j][0], lift[j]) for j in range(k + 1, len(pts)) if lift[j] is not None]
        why = (f"; the report leads with it: largest compared load factor inside the small-strain range "
               f"(lift/R = {lift[k]:.3g} <= {lim:g})"
               + (f"; past it (lambda {later[-1][0]:.4g}: lift/R = {later[-1][1]:.3g}) a small-strain and a "
                  "large-displacement analysis compare idealisations, not codes" if later else ""))
    return [(lam, what + (why if j == k else ""), j == k) for j, (lam, what) in enumerate(pts)]


def compare_at(series: list[Series], lam: float, what: str, strict: bool, records: dict | None = None) -> PointResult:
    """Compare the series at load factor ``lam``; ``strict``: a source lacking it is an error."""
    use, skipped = [], []
    for s in series:
        if s.covers(lam):
            use.append(s)
        elif strict:
            s.at(lam)          # raises the one-line LoadFactorError
        else:
            skipped.append(s.label)
    profiles = {s.label: s.at(lam) for s in use}
    aligned = align(profiles)
    zones = {lab: liftoff_zones(p) for lab, p in profiles.items()}
    peaks = {lab: peak_compression(p) for lab, p in profiles.items()}
    arcs = {lab: element_arc(p) for lab, p in profiles.items()}
    pairs = []
    grid = aligned.index.to_numpy()
    for a, b in itertools.combinations([s.label for s in use], 2):
        m = pair_metrics(grid, aligned[a].to_numpy(), aligned[b].to_numpy())
        pairs.append({"a": a, "b": b, "load_factor": lam, **m, "liftoff_zone_overlap": zone_iou(zones[a], zones[b]),
                      "liftoff_zone_overlap_tol": zone_iou_tol(zones[a], zones[b], max(arcs[a], arcs[b])),
                      "zone_tolerance_deg": max(arcs[a], arcs[b])})
    node_peaks, extra = {}, {}
    for s in use:
        st = s.state_at(lam)
        if st is not None and st.rows is not None:
            node_peaks[s.label] = Q.peak_node(st.rows)
            extra[s.label] = state_quantities(st.rows, (records or {}).get(s.label), st)
    return PointResult(lam, what, [s.label for s in use], profiles, aligned, zones, peaks, pairs, skipped,
                       node_peaks, extra)


def state_quantities(rows, record: SourceResult | None, st) -> dict:
    """Per-state quantities of one source (definitions in :mod:`deckbridge.quantities`)."""
    nodes = Q.sigma_n_nodes(rows)
    out = {"lifted_arc_deg": Q.lifted_arc_deg(rows), "lift_over_radius": Q.lift_over_radius(rows),
           **{k: v for k, v in Q.open_tension(rows).items() if k != "warn"},     # "warn": the equilibrium's
           **Q.free_penetration(rows),
           "contact_resultant_n": -Q.contact_resultant(rows),
           "sigma_n_nodes_pa": {"theta_deg": nodes.index.tolist(),
                                **{c: nodes[c].tolist() for c in ("inner", "mid", "outer")}}}
    tb = Q.table_rows(rows)
    r = tb["r"].to_numpy(float)
    if np.isfinite(r).all() and np.isfinite(tb["area_m2"].to_numpy(float)).all() and len(r):
        q = Q.line_load(rows, 0.5 * (r.min() + r.max()))          # at the mid-wall radius
        out["line_load_n_per_m"] = {"theta_deg": q.index.tolist(), "q": q.tolist()}
    wall = None if record is None else record.wall_at(st.step, st.increment, st.load_factor)
    if wall is not None and len(wall):
        out["szz_pa"] = {c: wall[c].tolist() for c in ("theta_deg", "szz_inner_pa", "szz_outer_pa",
                                                       "szz_mean_pa", "szz_bending_pa")}
        out.update(Q.equilibrium(wall, rows))
    return out


def compare_series(series: list[Series], load_factors: list[float] | None = None,
                   records: dict[str, SourceResult] | None = None, headline: bool = False) -> ComparisonResult:
    """Compare built series at the requested (or default) load factors; ``records``: label -> the
    source record (its solver summary gives the exact onsets, its wall table sigma_zz); ``headline``: add
    the small-strain point and lead with it (:func:`compare_tables`, the report's comparisons)."""
    if not series:
        raise DeckbridgeError("nothing to compare: no source given")
    records = records or {}
    ons = {s.label: onsets(s, getattr(records.get(s.label), "summary", None)) for s in series}
    liftoff = {lab: best(o["first_node"]) for lab, o in ons.items()}
    requested = sorted(set(float(x) for x in np.atleast_1d(load_factors))) if load_factors is not None else []
    if requested:
        pts = [(lam, "requested", False) for lam in requested]
        strict = True
    else:
        pts = default_load_factors(series, liftoff, headline)
        strict = False
    points = []
    for lam, what, head in pts:
        pt = compare_at(series, lam, what, strict, records)
        pt.headline = head
        points.append(pt)
    points = [p for p in points if p.labels]
    carried = {s.label: getattr(records.get(s.label), "ring_lines", None) for s in series}
    rl = ring_line_comparison([s.label for s in series], carried, lambda lam: lift_over_radius(
        [s for s in series if carried[s.label]], lam))
    return ComparisonResult(series, points, ons, dict(records), rl)


def compare_tables(tables: list, load_factors=None, origins=None, surface: str = "table") -> ComparisonResult:
    """Compare tidy contact tables (one or more (source, method) each) on azimuth.

    ``tables``: DataFrames or :class:`~deckbridge.results.SourceResult` records (their globals go to
    the report); ``load_factors``: lambda values to compare at (default: see module doc); ``origins``:
    the file or folder of each table (default: the records' own; labels of equal sources get its
    folder name); ``surface``: 'table' (vertical contact, liftoff) or 'stop'.
    """
    if isinstance(load_factors, (int, float)):
        load_factors = [float(load_factors)]
    tables = list(tables)
    origins = list(origins) if origins is not None else [getattr(t, "origin", None) for t in tables]
    if len(origins) != len(tables):
        raise ValueError("origins must match tables one to one")
    records = [SourceResult.wrap(t, o) for t, o in zip(tables, origins)]
    series = split_tables([r.table for r in records], origins, surface)
    by_origin = {}
    for r in records:
        by_origin.setdefault(r.origin, r)
    if sum(r.origin is None for r in records) > 1:
        by_origin.pop(None, None)          # several records without origin: no way to tell them apart
    return compare_series(series, load_factors, {s.label: by_origin[s.origin] for s in series if s.origin in by_origin},
                          headline=True)
