"""Result objects of the Python API's comparison and studies (:func:`deckbridge.compare`,
:func:`deckbridge.sweep`, :func:`deckbridge.liftoff`): plain data, tables as pandas DataFrames, no -0.0.

Conventions as in :mod:`deckbridge.api_results`: SI, unit in the column name, sigma_n < 0 compression,
theta [deg] CCW from +x, lambda [-] on (T, M) in step 2; differences are sigma_b - sigma_a.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from . import summary_keys as K
from .api_results import _axes
from .errors import DeckbridgeError
from .methods import PENALTY
from .jsonable import json_clean, plain_frame


@dataclass
class Comparison:
    """Sources compared on azimuth at a few load factors (:class:`deckbridge.compare.result.ComparisonResult`
    underneath, as ``result``). ``labels``: the sources' labels; ``load_factors``: where they were compared."""
    result: object
    model: object = None

    @property
    def labels(self) -> list[str]:
        return list(self.result.labels)

    @property
    def load_factors(self) -> list[float]:
        return [p.load_factor for p in self.result.points]

    @property
    def summary(self) -> dict:
        """The comparison's summary, as ``summary.json`` of ``deckbridge compare`` holds it (without the
        report's figures data)."""
        return json_clean(self.result.summary())

    def _point(self, load_factor: float | None):
        if load_factor is None:
            return self.result.primary
        for p in self.result.points:
            if abs(p.load_factor - load_factor) <= 1e-9 * max(1.0, abs(load_factor)):
                return p
        raise DeckbridgeError(f"load_factor = {load_factor!r}: not compared (compared at "
                              f"{', '.join(f'{x:.6g}' for x in self.load_factors)})")

    def sigma_n_wall(self, load_factor: float | None = None) -> pd.DataFrame:
        """Through-wall sigma_n [Pa] of every source on the common azimuth grid at one compared load factor
        (default: the primary one, which the report leads with); index ``theta_deg``, one column per label."""
        return plain_frame(self._point(load_factor).aligned.copy())

    def pairs(self, load_factor: float | None = None) -> pd.DataFrame:
        """One row per pair (a, b) at one compared load factor: max |sigma_b - sigma_a| [Pa] and where
        [deg], arc-weighted rms [Pa], liftoff-zone overlap (intersection over union, [-])."""
        return plain_frame(pd.DataFrame(self._point(load_factor).pairs))

    @property
    def discrepancy(self) -> pd.DataFrame:
        """Per compared load factor and azimuth: sigma_n of each source and each pair's difference [Pa]
        (``discrepancy.csv``)."""
        return plain_frame(self.result.discrepancy())

    @property
    def onsets(self) -> pd.DataFrame:
        """Liftoff onsets per source: one row per (label, onset in first_node | section) with ``exact`` (the
        reference solver's own), ``bracket_low``/``bracket_high`` (the printed states around it),
        ``interpolated`` (first node only, an estimate) and ``theta_deg``; NaN where not known."""
        rows = []
        for lab, ons in self.result.onsets.items():
            for kind, o in ons.items():
                br = o.get("bracket") or [np.nan, np.nan]
                rows.append({"label": lab, "onset": kind, "exact": o.get("exact"), "bracket_low": br[0],
                             "bracket_high": br[1], "interpolated": o.get("interpolated"),
                             "theta_deg": o.get("theta_deg")})
        return plain_frame(pd.DataFrame(rows).astype({c: float for c in ("exact", "bracket_low", "bracket_high",
                                                                          "interpolated", "theta_deg")}))

    def plot(self, load_factor: float | None = None, ax=None):
        """sigma_n through the wall of every source against theta at one compared load factor [MPa]; the Axes."""
        ax = _axes(ax)
        pt = self._point(load_factor)
        for lab in pt.aligned.columns:
            ax.plot(pt.aligned.index, pt.aligned[lab].to_numpy() / 1e6, label=lab)
        ax.set_xlabel("theta [deg]")
        ax.set_ylabel("sigma_N through the wall [MPa] (< 0 compression)")
        ax.set_title(f"lambda = {pt.load_factor:.4g}")
        ax.legend()
        return ax

    def write_report(self, out: str | Path) -> list[Path]:
        """Write report.html, sigma_n.png, discrepancy.csv and summary.json into ``out``; the paths."""
        from .studies.verdict import write_report_with_verdict
        return write_report_with_verdict(self.result, out, model=self.model)


@dataclass
class SweepResult:
    """A penalty-factor sweep (:func:`deckbridge.sweep`): ``summary`` as ``out/summary.json``; ``table``
    (``sweep.csv``): per mesh, k-factor and compared load factor the difference to Lagrange (max_abs_diff_pa,
    rel_diff [-] of the Lagrange peak, liftoff_zone_iou, peak_compression_pa, within_tol, liftoff_load_factor);
    ``quantities`` (``quantities.csv``): every compared quantity per azimuth; ``out``: the study folder."""
    summary: dict
    variants: list = field(repr=False)
    quantities: pd.DataFrame | None = field(repr=False)
    out: Path

    def __post_init__(self):
        from .studies.sweep import sweep_frame
        self.summary = json_clean(self.summary)
        self.table = plain_frame(sweep_frame(self.variants))
        self.quantities = None if self.quantities is None else plain_frame(self.quantities)

    @property
    def recommended_k_factor(self) -> float | None:
        """The smallest k-factor within tol of Lagrange at every compared load factor (on every mesh), or None."""
        return self.summary.get("recommended_k_factor")

    def plot(self, ax=None):
        """Largest rel_diff over the compared load factors against the k-factor (log-log), one line per mesh."""
        ax = _axes(ax)
        t = self.table[self.table["method"] == PENALTY]
        for mesh, g in t.groupby("mesh", sort=False):
            worst = g.groupby("k_factor")["rel_diff"].max()
            ax.loglog(worst.index, worst.to_numpy(), marker="o", label=str(mesh))
        ax.set_xlabel("k-factor on k_c")
        ax.set_ylabel("max |d sigma_n| / |Lagrange peak| [-]")
        ax.legend()
        return ax


@dataclass
class LiftoffResult:
    """Critical load factor of liftoff per method (:func:`deckbridge.liftoff`); ``summary`` as the
    ``liftoff -o DIR`` summary.json (keys of :mod:`deckbridge.summary_keys`)."""
    summary: dict

    def __post_init__(self):
        self.summary = json_clean(self.summary)

    @property
    def table(self) -> pd.DataFrame:
        """One row per method (index): lambda_c [-] (NaN: no liftoff found), theta_deg, the bracket
        [bracket_low, bracket_high] the onset lies in, whether the search went beyond steps.lambda_max,
        and the base moment M_b at lambda_c [N m]."""
        rows = {}
        for m in self.summary[K.METHODS]:
            r = self.summary[m]
            br = r.get("bracket") or [None, None]
            rows[m] = {"lambda_c": r["lambda_c"], "theta_deg": r["theta_deg"], "bracket_low": br[0],
                       "bracket_high": br[1], "expanded": bool(r["expanded"]),
                       "base_moment_at_lambda_c_nm": r["base_moment_at_lambda_c_nm"]}
        out = pd.DataFrame.from_dict(rows, orient="index")
        out = out.astype({c: float for c in out.columns if c != "expanded"})
        out.index.name = "method"
        return plain_frame(out)

    @property
    def beam_theory(self) -> float | None:
        """Beam-theory liftoff N R / (2 (M + T H)) of the model [-], None when M + T H <= 0."""
        return self.summary.get(K.BEAM_THEORY_LIFTOFF_LOAD_FACTOR)
