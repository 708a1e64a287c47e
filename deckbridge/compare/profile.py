"""The leaf of the comparator: one azimuth profile of sigma_N and the load-factor tolerance.

Imported by :mod:`.series`, :mod:`.align`, :mod:`.metrics` and :mod:`.result`; imports only
:mod:`deckbridge.azimuth`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..azimuth import periodic_interp

LAMBDA_TOL = 1e-9           # load factors equal within this (relative to max(1, |lambda|)) are the same


@dataclass(frozen=True)
class Profile:
    """sigma_N along the azimuth: theta [deg] sorted in [0, 360), sigma [Pa] (< 0 compression), all_open."""
    theta: np.ndarray
    sigma: np.ndarray
    all_open: np.ndarray

    def resample(self, theta: np.ndarray) -> "Profile":
        """This profile at other azimuths: periodic linear interpolation (identity on its own azimuths)."""
        if self.theta.shape == theta.shape and np.array_equal(self.theta, theta):
            return self
        own = {t: o for t, o in zip(self.theta, self.all_open)}
        return Profile(theta, periodic_interp(self.theta, self.sigma, theta),
                       np.array([own.get(t, False) for t in theta], bool))
