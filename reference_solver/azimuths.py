"""Azimuths grouped with a tolerance (imported meshes: nodes of one nominal azimuth differ by round-off).

Units: degrees, counter-clockwise, wrapped into [0, 360). Imports nothing from deckbridge.
"""

from __future__ import annotations

import numpy as np


def azimuth_clusters(theta_deg: np.ndarray, tol_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """Group azimuths that lie within ``tol_deg`` of a neighbour (chains, circular: 359.99999 joins 0).

    Returns (labels (n,) int: group of each azimuth, numbered by increasing centre; centres (g,) [deg,
    0..360): the circular mean of each group). ``tol_deg`` should be far below the element's angular
    size and far above the coordinates' round-off (e.g. 1e-3 of the smallest element's angular span).
    """
    th = np.mod(np.asarray(theta_deg, float), 360.0) % 360.0
    n = th.size
    if n == 0:
        return np.zeros(0, np.int64), np.zeros(0)
    order = np.argsort(th)
    s = th[order]
    lab = np.concatenate([[0], np.cumsum(np.diff(s) > tol_deg)])
    if lab[-1] > 0 and s[0] + 360.0 - s[-1] <= tol_deg:
        lab[lab == lab[-1]] = 0                       # the group across 0 deg
    labels = np.empty(n, np.int64)
    labels[order] = lab
    _, labels = np.unique(labels, return_inverse=True)
    g = labels.max() + 1
    rad = np.radians(th)
    c = np.zeros(g)
    s_ = np.zeros(g)
    np.add.at(c, labels, np.cos(rad))
    np.add.at(s_, labels, np.sin(rad))
    centres = np.mod(np.degrees(np.arctan2(s_, c)), 360.0) % 360.0
    rank = np.argsort(np.argsort(centres))
    return rank[labels], np.sort(centres)


def element_span_deg(theta_nodes_deg: np.ndarray) -> np.ndarray:
    """Angular span [deg] of each element from the azimuths (ne, k) of its nodes (across 0 deg too)."""
    th = np.asarray(theta_nodes_deg, float)
    d = (th - th[:, :1] + 180.0) % 360.0 - 180.0
    return np.ptp(d, axis=1)
