"""Comparison metrics: liftoff zones on the circle, their overlap, differences of sigma_N curves.

Conventions: sigma_N < 0 compression, > 0 tension / liftoff; azimuths in degrees in [0, 360).
An azimuth is *lifted* when its sigma_N is positive (beyond 1e-9 of the profile's largest |sigma_N|)
or when every node there is open (Lagrange: open nodes carry exactly 0).
A liftoff zone is [theta_start, theta_end] counter-clockwise; it wraps through 0 when start > end
(e.g. [350, 10]); the whole circle is [0, 360]. Zone ends sit where sigma_N crosses 0, found by
linear interpolation between the last lifted and the first closed azimuth (at the lifted azimuth
itself when its sigma_N is 0, e.g. open Lagrange nodes).
"""

from __future__ import annotations

import numpy as np

from ..azimuth import arc_weights
from .profile import Profile
from .series import Series

LIFT_RTOL = 1e-9
ZONE_DECIMALS = 6


def lifted(profile: Profile) -> np.ndarray:
    """Boolean per azimuth: sigma_N > 0 (relative tolerance) or every node open."""
    scale = float(np.max(np.abs(profile.sigma))) if profile.sigma.size else 0.0
    return (profile.sigma > LIFT_RTOL * scale) | profile.all_open


def element_arc(profile: Profile) -> float:
    """The widest arc between neighbouring azimuths of a profile [deg] (one element arc)."""
    th = np.sort(profile.theta)
    return 360.0 if th.size < 2 else float(np.max(np.mod(np.roll(th, -1) - th, 360.0)))


def liftoff_zones(profile: Profile, min_width_deg: float | None = None) -> list[list[float]]:
    """Liftoff zones of a profile as [[theta_start, theta_end], ...] in degrees (see module doc).

    Zones narrower than ``min_width_deg`` (default one element arc, :func:`element_arc`) are not
    zones (a single open node at a crossing, round-off); a zone through 0 deg is one zone."""
    zones = _raw_zones(profile)
    width = element_arc(profile) if min_width_deg is None else min_width_deg
    return [z for z in zones if _width(z) >= width * (1 - 1e-9)]


def _width(z) -> float:
    a, b = z
    return 360.0 if (a == 0.0 and b == 360.0) else (b - a) % 360.0


def _raw_zones(profile: Profile) -> list[list[float]]:
    th, s, up = profile.theta, profile.sigma, lifted(profile)
    n = th.size
    if not up.any():
        return []
    if up.all():
        return [[0.0, 360.0]]
    first_closed = int(np.flatnonzero(~up)[0])
    order = [(first_closed + k) % n for k in range(n)]
    runs: list[list[int]] = []
    for i in order:
        if up[i]:
            if runs and runs[-1][-1] == (i - 1) % n and up[(i - 1) % n]:
                runs[-1].append(i)
            else:
                runs.append([i])
    zones = []
    for run in runs:
        i0, i1 = run[0], run[-1]
        prev, nxt = (i0 - 1) % n, (i1 + 1) % n
        left = th[i0]
        if s[i0] > 0 and s[i0] > s[prev]:
            d = (th[i0] - th[prev]) % 360.0
            left = th[prev] + d * min(1.0, max(0.0, -s[prev] / (s[i0] - s[prev])))
        right = th[i1]
        if s[i1] > 0 and s[i1] > s[nxt]:
            d = (th[nxt] - th[i1]) % 360.0
            right = th[i1] + d * min(1.0, max(0.0, s[i1] / (s[i1] - s[nxt])))
        zones.append([round(float(left % 360.0), ZONE_DECIMALS) % 360.0,
                      round(float(right % 360.0), ZONE_DECIMALS) % 360.0])
    return zones


def zone_intervals(zones: list[list[float]]) -> list[tuple[float, float]]:
    """Zones as merged, non-wrapping intervals within [0, 360]."""
    parts: list[tuple[float, float]] = []
    for a, b in zones:
        a, b = float(a), float(b)
        if a == 0.0 and b == 360.0:
            parts.append((0.0, 360.0))
        elif a <= b:
            parts.append((a, b))
        else:
            parts += [(a, 360.0), (0.0, b)]
    parts.sort()
    merged: list[tuple[float, float]] = []
    for a, b in parts:
        if merged and a <= merged[-1][1]:
            merged[-1] = (merged[-1][0], max(merged[-1][1], b))
        else:
            merged.append((a, b))
    return merged


def _length(iv: list[tuple[float, float]]) -> float:
    return float(sum(b - a for a, b in iv))


def zone_iou(za: list[list[float]], zb: list[list[float]]) -> float:
    """Intersection over union of two zone sets on the circle [deg/deg]; 1 when neither has a zone."""
    ia, ib = zone_intervals(za), zone_intervals(zb)
    union = _length(zone_intervals([list(x) for x in ia + ib]))
    if union == 0.0:
        return 1.0
    inter = 0.0
    for a0, a1 in ia:
        for b0, b1 in ib:
            inter += max(0.0, min(a1, b1) - max(a0, b0))
    return inter / union


UNIFORM_RTOL = 1e-6


def peak_compression(profile: Profile) -> tuple[float, float | None]:
    """Most negative sigma_N [Pa] of a profile and its azimuth [deg]; the azimuth is None ('uniform')
    when the profile's spread is below UNIFORM_RTOL of its largest |sigma_N| (no location to tell)."""
    i = int(np.argmin(profile.sigma))
    scale = float(np.max(np.abs(profile.sigma))) if profile.sigma.size else 0.0
    if float(np.ptp(profile.sigma)) <= UNIFORM_RTOL * scale:
        return float(profile.sigma[i]), None
    return float(profile.sigma[i]), float(profile.theta[i])


def _grow(iv: list[tuple[float, float]], tol: float) -> list[list[float]]:
    out = []
    for a, b in iv:
        if b - a + 2 * tol >= 360.0:
            return [[0.0, 360.0]]
        out.append([(a - tol) % 360.0, (b + tol) % 360.0])
    return out


def zone_iou_tol(za: list[list[float]], zb: list[list[float]], tol_deg: float) -> float | None:
    """Overlap of two zone sets with a tolerance: (|A in B grown by tol| + |B in A grown by tol|) /
    (|A| + |B|), grown = each interval widened by ``tol_deg`` at both ends; None when neither has a
    zone ('no zone'); 1.0 for zones that differ by less than the tolerance."""
    ia, ib = zone_intervals(za), zone_intervals(zb)
    la, lb = _length(ia), _length(ib)
    if la + lb == 0.0:
        return None

    def inside(x, y):
        return sum(max(0.0, min(a1, b1) - max(a0, b0)) for a0, a1 in x for b0, b1 in y)
    num = inside(ia, zone_intervals(_grow(ib, tol_deg))) + inside(ib, zone_intervals(_grow(ia, tol_deg)))
    return min(1.0, num / (la + lb))


def pair_metrics(theta: np.ndarray, sigma_a: np.ndarray, sigma_b: np.ndarray) -> dict:
    """Differences d = sigma_b - sigma_a on a common grid [Pa]: max |d|, where, arc-weighted rms."""
    d = np.asarray(sigma_b, float) - np.asarray(sigma_a, float)
    i = int(np.argmax(np.abs(d)))
    w = arc_weights(np.asarray(theta, float))
    return {
        "max_abs_diff_pa": float(abs(d[i])),
        "theta_of_max_diff_deg": float(theta[i]),
        "rms_diff_pa": float(np.sqrt(np.sum(w * d * d) / np.sum(w))),
    }


def _nodes_lifted(nodes) -> np.ndarray:
    scale = float(np.max(np.abs(nodes["sigma"].to_numpy()))) if len(nodes) else 0.0
    return (nodes["sigma"].to_numpy() > LIFT_RTOL * scale) | nodes["open"].to_numpy()


def liftoff_load_factor(series: Series) -> float | None:
    """Load factor at which the first table slave node lifts off (onset), None if none does.

    Before liftoff the base is fully in contact and the response is linear in lambda, so each
    node's sigma_N is extrapolated linearly to 0 from the last two states without liftoff; the
    smallest such lambda, kept between the last state without and the first state with liftoff,
    is the onset. With a single state before, node sigma_N is interpolated between it and the
    first lifted state instead. Both are exact when sigma_N is linear in lambda up to liftoff
    (past liftoff open nodes carry ~0, so the lifted state's values are not extrapolated from).
    """
    before = []
    for st in series.states:
        if not _nodes_lifted(st.nodes).any():
            before.append(st)
            continue
        lam_b = float(st.load_factor)
        if not before:
            return lam_b
        a1 = before[-1]
        lam_1 = float(a1.load_factor)
        if len(before) >= 2:
            a0 = before[-2]
            s0, s1 = a0.nodes["sigma"].align(a1.nodes["sigma"], join="inner")
            rising = (s1 > s0).to_numpy()
            if rising.any():
                d_lam = lam_1 - float(a0.load_factor)
                cand = lam_1 - s1.to_numpy()[rising] * d_lam / (s1 - s0).to_numpy()[rising]
                return float(min(max(cand.min(), lam_1), lam_b))
        sa, sb = a1.nodes["sigma"].align(st.nodes["sigma"], join="inner")
        up = (sb > 0).to_numpy() & (sa < 0).to_numpy()
        if up.any():
            cand = lam_1 + (lam_b - lam_1) * (-sa.to_numpy()[up]) / (sb - sa).to_numpy()[up]
            return float(cand.min())
        return lam_b
    return None
