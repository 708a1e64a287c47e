"""ccx face-to-face against its reference partner on 8-/6-node faces by the master ring's line forces.

There the two series' nodal sigma_N are two readings of one pressure field (ccx: CPRESS, extrapolated; the
reference: the hat-basis projection) that differ by up to a quarter of the peak at the contact edge while the
solutions agree (docs/ccx_f2f.md); the contact force on each azimuth line of the deck's clamped C3D8 master ring
is exact on both sides (:data:`deckbridge.quantities.DEFINITIONS` ``ring_line_force_n``). Sources carry it as
:attr:`deckbridge.results.SourceResult.ring_lines` (ccx: the calculix record's ``line_reader``; the reference:
:func:`deckbridge.reference_f2f.table_ring_lines`); this pairs two such sources state by state.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from .. import quantities as Q

LAMBDA_MATCH = 1e-6          # two sources' states are the same load factor within this


def ring_line_pairs(a: dict, b: dict) -> list[tuple[float, np.ndarray, np.ndarray]]:
    """(load factor, a's, b's line forces [N]) at every load factor of ``a`` that ``b`` also printed (within
    :data:`LAMBDA_MATCH`), ascending; ``a``, ``b``: {load factor: ring_line_force_n}."""
    out = []
    for lam in sorted(a):
        near = min(b, key=lambda x: abs(x - lam), default=None)
        if near is not None and abs(near - lam) <= LAMBDA_MATCH:
            out.append((float(lam), np.asarray(a[lam], float), np.asarray(b[near], float)))
    return out


def ring_line_comparison(labels: list[str], lines: dict[str, dict],
                         lift: Callable[[float], float | None]) -> dict | None:
    """The first two of ``labels`` (source order) that carry ring lines (``lines``: label -> {load factor:
    forces}), compared at their common states inside the small-strain range (``lift(lam)``: the largest lift / R
    there, None: unknown, kept): {'a', 'b', ring_line_force_max_diff (:func:`Q.ring_line_rel_diff`, the worst),
    'load_factor' (where), 'states' (how many)}; None when fewer than two carry them or no state is shared."""
    have = [lab for lab in labels if lines.get(lab)]
    if len(have) < 2:
        return None
    a, b = have[:2]
    worst, at, n = 0.0, None, 0
    for lam, fa, fb in ring_line_pairs(lines[a], lines[b]):
        v = lift(lam)
        if v is not None and v > Q.SMALL_STRAIN_LIFT:
            continue
        e = Q.ring_line_rel_diff(fa, fb)
        n += 1
        if at is None or e > worst:
            worst, at = e, lam
    return None if n == 0 else {"a": a, "b": b, Q.RING_LINE_FORCE_MAX_DIFF: worst, "load_factor": at, "states": n}


def ring_line_text(result) -> list[str]:
    """The console's and the report's lines on it (a :class:`~deckbridge.compare.result.ComparisonResult`): the
    pair's sigma_N difference through the wall at the headline, its ring-line difference and why they differ;
    [] without ring lines."""
    rl = getattr(result, "ring_lines", None)
    if not rl:
        return []
    a, b, pt = rl["a"], rl["b"], result.primary
    pair = next((p for p in pt.pairs if {p["a"], p["b"]} == {a, b}), None)
    peak = pt.peaks.get(a)
    sig = ("" if pair is None or not peak or not peak[0] else
           f"sigma_N through the wall differs by {pair['max_abs_diff_pa'] / 1e6:.3g} MPa "
           f"({pair['max_abs_diff_pa'] / abs(peak[0]):.2%} of the peak) at lambda = {pt.load_factor:.4g}; ")
    return [f"{b} vs {a}: {sig}the contact force on the master ring's azimuth lines by "
            f"{rl[Q.RING_LINE_FORCE_MAX_DIFF]:.3%} of the largest line force ({Q.RING_LINE_FORCE_MAX_DIFF}: worst of "
            f"{rl['states']} states with lift/R <= {Q.SMALL_STRAIN_LIFT:g}, at lambda = {rl['load_factor']:.4g})",
            f"  why: {Q.RING_LINE_WHY}"]
