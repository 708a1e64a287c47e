"""Discrete support pads under the skirt base (``contact.pads``) and the face selection they imply.

``contact.pads`` null: the base rests on a continuous ring. Otherwise ``count`` equal pads of angular
width ``width_deg`` [deg], the first centred at azimuth ``first_deg`` [deg, CCW from +x], the others
every 360/count deg; ``radial`` (optional) limits them to ``{inner: r_i, outer: r_o}`` [m] or
``full`` (the whole wall, the default).

The pads are meshed on element boundaries: a base face belongs to a pad when its centre lies inside
the pad's angular window (and radial band). Pad edges are thus snapped to the azimuthal grid; the
contact area is that of the selected faces (:func:`pad_face_mask`), and a pad narrower than one
element is refused rather than silently lost. Radially, a face is on the band when the mean radius of
its corners is.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .azimuth import azimuth_deg

__all__ = ["Pads", "pads_from", "pad_face_mask"]


@dataclass(frozen=True)
class Pads:
    """Equal pads: ``count``, angular ``width_deg``, ``first_deg`` centre of the first, radial band [m]."""
    count: int
    width_deg: float
    first_deg: float = 0.0
    inner: float | None = None     # radial band [m]; None = the wall's inner face
    outer: float | None = None     # None = the wall's outer face

    @property
    def centres_deg(self) -> np.ndarray:
        return np.mod(self.first_deg + 360.0 * np.arange(self.count) / self.count, 360.0)


def pads_from(value: Any, ModelError, _int, _num) -> Pads | None:
    """Validate ``contact.pads`` (a mapping, a :class:`Pads` or None) with the model's checkers
    (passed in: this module does not import the model); ModelError names the key."""
    if value is None or isinstance(value, Pads):
        return value
    if not isinstance(value, dict):
        raise ModelError("contact.pads", value, "must be null or a mapping with count, width_deg, first_deg, radial")
    known = {"count", "width_deg", "first_deg", "radial", "inner", "outer"}
    for key in value:
        if key not in known:
            raise ModelError(f"contact.pads.{key}", value[key], "unknown key")
    for key in ("count", "width_deg"):      # no defaults: first_deg 0 and radial full have
        if key not in value:
            raise ModelError(f"contact.pads.{key}", None, "required when contact.pads is set (no default)")
    count = _int("contact.pads.count", value["count"], ge=1, le=10**4)   # issue 13: bounded before any work
    width = _num("contact.pads.width_deg", value["width_deg"], gt=0)
    if count * width >= 360.0:
        raise ModelError("contact.pads.width_deg", value["width_deg"],
                         f"{count} pads of this width cover the whole ring (use contact.pads: null)")
    first = _num("contact.pads.first_deg", value.get("first_deg", 0.0), ge=0, lt=360)
    inner = value.get("inner")
    outer = value.get("outer")
    radial = value.get("radial")
    if radial is not None and radial not in ("full", "full wall"):
        if not isinstance(radial, dict) or set(radial) - {"inner", "outer"}:
            raise ModelError("contact.pads.radial", radial, "must be 'full' or a mapping {inner: r, outer: r} [m]")
        inner, outer = radial.get("inner"), radial.get("outer")
    inner = None if inner is None else _num("contact.pads.radial.inner", inner, gt=0)
    outer = None if outer is None else _num("contact.pads.radial.outer", outer, gt=0)
    if inner is not None and outer is not None and not outer > inner:
        raise ModelError("contact.pads.radial.outer", outer, f"must exceed radial.inner = {inner:g}")
    return Pads(count=count, width_deg=width, first_deg=first, inner=inner, outer=outer)


def pad_face_mask(pads: Pads | None, face_xyz: np.ndarray, dtheta_deg: float, ModelError=ValueError) -> np.ndarray:
    """Which base faces (``face_xyz`` (nf, 4, 3) [m]) lie on a pad; all of them when ``pads`` is None.

    ``dtheta_deg`` is the angular size of one element: a pad narrower than it is refused (ModelError).
    """
    nf = face_xyz.shape[0]
    if pads is None:
        return np.ones(nf, bool)
    if pads.width_deg < dtheta_deg * (1 - 1e-9):
        raise ModelError("contact.pads.width_deg", pads.width_deg,
                         f"narrower than one element ({dtheta_deg:g} deg): refine mesh.n_theta")
    c = face_xyz.mean(axis=1)
    th = azimuth_deg(c[:, 0], c[:, 1])
    r = np.hypot(face_xyz[:, :, 0], face_xyz[:, :, 1]).mean(axis=1)   # mean corner radius (not the chord's)
    on = np.zeros(nf, bool)
    half = pads.width_deg / 2 * (1 + 1e-9)
    for centre in pads.centres_deg:
        d = np.abs((th - centre + 180.0) % 360.0 - 180.0)
        on |= d <= half
    if pads.inner is not None:
        on &= r >= pads.inner
    if pads.outer is not None:
        on &= r <= pads.outer
    if not on.any():
        raise ModelError("contact.pads", f"{pads.count} x {pads.width_deg:g} deg",
                         "no base face centre lies on a pad (check radial inner/outer against the wall)")
    per_pad = [np.count_nonzero(np.abs((th[on] - c0 + 180.0) % 360.0 - 180.0) <= half) for c0 in pads.centres_deg]
    if min(per_pad) == 0:
        raise ModelError("contact.pads.width_deg", pads.width_deg,
                         "a pad holds no element face centre: widen it or refine mesh.n_theta")
    return on
