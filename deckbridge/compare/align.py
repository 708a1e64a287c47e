"""Alignment of sources on azimuth: one common grid, periodic linear interpolation where meshes differ.

The common grid is the union of the sources' azimuths, so a source is never resampled at its own
nodes, and each source's own extrema stay on the grid. Linear interpolation of a smooth curve f
sampled every h radians errs by at most h^2/8 * max|f''|.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..azimuth import arc_weights, periodic_interp, snap_deg  # noqa: F401 (re-exported)
from .profile import Profile


def common_grid(profiles: list[Profile]) -> np.ndarray:
    """Union of the azimuths of the profiles, sorted in [0, 360)."""
    return np.unique(snap_deg(np.concatenate([p.theta for p in profiles])))


def align(profiles: dict[str, Profile]) -> pd.DataFrame:
    """sigma_N [Pa] of every source on the common grid: index theta_deg, one column per label."""
    grid = common_grid(list(profiles.values()))
    data = {lab: periodic_interp(p.theta, p.sigma, grid) for lab, p in profiles.items()}
    return pd.DataFrame(data, index=pd.Index(grid, name="theta_deg"))
