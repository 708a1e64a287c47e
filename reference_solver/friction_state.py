"""The converged (or trial) state of an increment (every contact law) and the laws' errors."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import ReferenceSolverError


class GrossSlip(ReferenceSolverError):
    """No equilibrium because every closed friction row slips: the load slides the body."""


class NotConverged(ReferenceSolverError):
    """An increment's iterations did not settle (the path cuts the increment back)."""


class Runaway(NotConverged):
    """Not settled because the iterates run away with rows still sticking: no bounded equilibrium in sight
    (not gross slip); where the path's bisection closes in on it, the load tips the body over."""


@dataclass
class State:
    """A converged (or trial) contact state: retained displacements and contact forces."""
    x: np.ndarray                 # (nr,) [m]
    p: np.ndarray                 # (nc,) normal force [N], > 0 compressive
    t: np.ndarray                 # (nf, 2) tangential force [N], in the rows' tangent axes
    active: np.ndarray            # (nc,) closed rows
    slip: np.ndarray              # (nf,) slipping friction rows (closed and on the cone)
    iterations: int = 0
    augmentations: int = 0        # augmented Lagrangian: multiplier updates of the increment
    penetration: float = 0.0      # augmented Lagrangian: largest penetration max(0, -g) at the end [m]
