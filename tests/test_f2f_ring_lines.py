"""The master ring's line weights of the face-to-face comparison on quadratic faces
(:func:`deckbridge.reference_f2f.ring_lines`, docs/ccx_f2f.md) against the C3D8 face's own bilinear map: a point
of a ring face, mapped from natural coordinates (s, t) by the face's four corners (the ring's nodes at azimuths
360 j / n and 360 (j + 1) / n, radii r_in and r_out), gets back face j and s."""

import numpy as np

from deckbridge.reference_f2f import ring_lines


def test_ring_lines_invert_the_bilinear_face():
    n, r_in, r_out = 16, 1.47, 1.53
    rng = np.random.default_rng(23)
    j = rng.integers(0, n, 200)
    s, t = rng.random(200), rng.random(200)
    a0, a1 = 2 * np.pi * j / n, 2 * np.pi * (j + 1) / n
    e0 = np.stack([np.cos(a0), np.sin(a0)], 1)
    e1 = np.stack([np.cos(a1), np.sin(a1)], 1)
    corners = [r_in * e0, r_in * e1, r_out * e1, r_out * e0]            # bilinear shape functions in (s, t)
    w = [(1 - s) * (1 - t), s * (1 - t), s * t, (1 - s) * t]
    xy = sum(wk[:, None] * c for wk, c in zip(w, corners))
    jj, ss = ring_lines(np.c_[xy, np.zeros(200)], n)
    assert (jj == j).all()
    assert np.abs(ss - s).max() <= 1e-12
