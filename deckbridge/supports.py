"""Discrete support pads under the skirt base (``contact.pads``) and the face selection they imply.

``contact.pads`` null: the base rests on a continuous ring. Otherwise ``count`` equal pads of angular
width ``width_deg`` [deg], the first centred at azimuth ``first_deg`` [deg, CCW from +x], the others
every 360/count deg; ``radial`` (optional) limits them to ``{inner: r_i, outer: r_o}`` [m] or
``full`` (the whole wall, the default).

The pads are meshed on element boundaries: each pad edge moves to the nearest element boundary (the
console says which pads moved and to what span; an edge half-way between two boundaries is refused),
and a base face belongs to a pad when its centre lies between the snapped edges (and in the radial
band). The contact area is that of the selected faces (:func:`pad_face_mask`), and a pad narrower
than one element is refused rather than silently lost. Radially, a face is on the band when the mean
radius of its corners is.
"""

from __future__ import annotations

import warnings
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

    ``dtheta_deg`` is the angular size of one element. Each pad edge (centre -+ width / 2) moves to the
    nearest element boundary (half-way between face-centre columns); a pad whose edges move is kept
    and the move is warned (one ``UserWarning`` naming every snapped pad's span, shown by the CLI);
    an edge half-way between two boundaries, a pad narrower than one element, and pads that overlap
    once snapped are refused (ModelError naming the key). Issue 26: the rule used to keep every face
    whose centre lay inside the pad, so a 15 deg pad centred on a face boundary took both faces.
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
    col, centres = _columns(th, dtheta_deg)
    gaps = np.mod(np.roll(centres, -1) - centres, 360.0)
    bounds = np.mod(centres + gaps / 2, 360.0)                       # boundary after each column
    tol = 1e-6 * dtheta_deg
    on, moved = np.zeros(nf, bool), []
    for k, centre in enumerate(pads.centres_deg):
        lo, hi = (_snap(centre + s * pads.width_deg / 2, bounds, tol, ModelError, pads) for s in (-1, 1))
        span = np.mod(hi[0] - lo[0], 360.0)
        if span <= tol:
            raise ModelError("contact.pads.width_deg", pads.width_deg,
                             f"pad {k + 1} holds no whole element once its edges snap to the element "
                             f"boundaries ({dtheta_deg:g} deg elements): widen it or refine mesh.n_theta")
        mine = np.mod(centres - lo[0], 360.0) < span
        if np.any(on & mine[col]):
            raise ModelError("contact.pads.width_deg", pads.width_deg,
                             "pads overlap once their edges snap to the element boundaries")
        on |= mine[col]
        if lo[1] or hi[1]:
            moved.append(f"pad {k + 1} {lo[0]:.6g}-{hi[0]:.6g} deg ({span:.6g} deg)")
    if moved:
        warnings.warn(f"contact.pads: {pads.width_deg:g} deg pads do not land on element boundaries "
                      f"({dtheta_deg:g} deg elements); snapped to the nearest: " + ", ".join(moved), stacklevel=2)
    if pads.inner is not None:
        on &= r >= pads.inner
    if pads.outer is not None:
        on &= r <= pads.outer
    if not on.any():
        raise ModelError("contact.pads", f"{pads.count} x {pads.width_deg:g} deg",
                         "no base face centre lies on a pad (check radial inner/outer against the wall)")
    return on


def _columns(th: np.ndarray, dtheta_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """Face-centre azimuths [deg] grouped into columns (equal to 1e-3 of an element, across 0/360):
    the column of each face and the sorted column azimuths."""
    order = np.argsort(th)
    s = th[order]
    tol = 1e-3 * dtheta_deg
    col_sorted = np.cumsum(np.r_[True, np.diff(s) > tol]) - 1
    if col_sorted[-1] > 0 and s[0] + 360.0 - s[-1] <= tol:           # the last column wraps onto the first
        col_sorted[col_sorted == col_sorted[-1]] = 0
    col = np.empty_like(col_sorted)
    col[order] = col_sorted
    first = np.unique(col_sorted, return_index=True)[1]
    return col, s[first]


def _snap(edge: float, bounds: np.ndarray, tol: float, ModelError, pads: Pads) -> tuple[float, bool]:
    """The element boundary [deg] nearest to a pad ``edge`` [deg] and whether the edge moved; an edge
    half-way between two boundaries is refused (no nearest span)."""
    d = np.abs(np.mod(edge - bounds + 180.0, 360.0) - 180.0)
    i = np.argsort(d)[:2]
    if d[i[1]] - d[i[0]] <= tol:
        raise ModelError("contact.pads.first_deg", pads.first_deg,
                         f"a {pads.width_deg:g} deg pad edge at {np.mod(edge, 360.0):.6g} deg lies half-way between "
                         f"the element boundaries {bounds[i[0]]:.6g} and {bounds[i[1]]:.6g} deg: move "
                         "first_deg or change width_deg so that the edges land on (or nearer to) a boundary")
    return float(bounds[i[0]]), bool(d[i[0]] > tol)
