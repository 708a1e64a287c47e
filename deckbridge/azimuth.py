"""Azimuth conventions in one leaf: theta in degrees, counter-clockwise from +x, in [0, 360).

Imported by the mesh, the solver front end, the readers, the comparator and the figures; imports
nothing from deckbridge.
"""

from __future__ import annotations

import numpy as np

THETA_DECIMALS = 6          # azimuths equal to 1e-6 deg are the same azimuth


def azimuth_deg(x, y):
    """Azimuth of points (x, y) in degrees, counter-clockwise from +x, in [0, 360)."""
    return np.mod(np.degrees(np.arctan2(y, x)), 360.0)


def wrap_deg(theta):
    """Angles [deg] wrapped into [0, 360) (the second mod maps a -0-ish 360.0 back to 0)."""
    return np.mod(theta, 360.0) % 360.0


def snap_deg(theta):
    """Azimuths [deg] rounded to THETA_DECIMALS and wrapped into [0, 360): the comparison key."""
    return np.round(np.asarray(theta, float), THETA_DECIMALS) % 360.0


def periodic_interp(theta_src: np.ndarray, values: np.ndarray, theta_dst: np.ndarray) -> np.ndarray:
    """Linear interpolation of values on azimuths theta_src [deg], periodic over 360 deg."""
    theta_src = np.asarray(theta_src, float)
    if theta_src.size == 1:
        return np.full(np.shape(theta_dst), float(values[0]))
    return np.interp(np.asarray(theta_dst, float), theta_src, np.asarray(values, float), period=360.0)


def arc_weights(theta: np.ndarray) -> np.ndarray:
    """Arc length [deg] each azimuth of a sorted circular grid stands for (half the gaps either side)."""
    n = theta.size
    if n == 1:
        return np.array([360.0])
    fwd = np.mod(np.roll(theta, -1) - theta, 360.0)
    return 0.5 * (fwd + np.roll(fwd, 1))
