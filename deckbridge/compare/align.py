"""Alignment of sources on azimuth: one common grid, periodic linear interpolation where meshes differ.

The common grid is the union of the sources' azimuths, so a source is never resampled at its own
nodes, and each source's own extrema stay on the grid. Linear interpolation of a smooth curve f
sampled every h radians errs by at most h^2/8 * max|f''|.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .series import THETA_DECIMALS, Profile


def periodic_interp(theta_src: np.ndarray, values: np.ndarray, theta_dst: np.ndarray) -> np.ndarray:
    """Linear interpolation of values on azimuths theta_src [deg], periodic over 360 deg."""
    theta_src = np.asarray(theta_src, float)
    if theta_src.size == 1:
        return np.full(np.shape(theta_dst), float(values[0]))
    return np.interp(np.asarray(theta_dst, float), theta_src, np.asarray(values, float), period=360.0)


def common_grid(profiles: list[Profile]) -> np.ndarray:
    """Union of the azimuths of the profiles, sorted in [0, 360)."""
    return np.unique(np.round(np.concatenate([p.theta for p in profiles]), THETA_DECIMALS) % 360.0)


def arc_weights(theta: np.ndarray) -> np.ndarray:
    """Arc length [deg] each azimuth of a sorted circular grid stands for (half the gaps either side)."""
    n = theta.size
    if n == 1:
        return np.array([360.0])
    fwd = np.mod(np.roll(theta, -1) - theta, 360.0)
    return 0.5 * (fwd + np.roll(fwd, 1))


def align(profiles: dict[str, Profile]) -> pd.DataFrame:
    """sigma_N [Pa] of every source on the common grid: index theta_deg, one column per label."""
    grid = common_grid(list(profiles.values()))
    data = {lab: periodic_interp(p.theta, p.sigma, grid) for lab, p in profiles.items()}
    return pd.DataFrame(data, index=pd.Index(grid, name="theta_deg"))
