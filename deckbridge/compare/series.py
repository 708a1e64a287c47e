"""One source's sigma_N(theta) along the load path, from the tidy table.

A *profile* is sigma_N [Pa] at each azimuth of the table surface at one state: the through-wall
value Sum sigma_N x area / Sum area of the slave nodes at that azimuth (:func:`deckbridge.quantities.sigma_n_wall`),
with the flag 'every node there is open'. Each state also keeps its rows (node values, areas).
A *series* is one (source, method): its profiles ordered by load factor lambda, starting with the
end of step 1 (N only, lambda = 0) and followed by the increments of step 2 (lambda > 0).
Profiles between two increments are interpolated linearly in lambda.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ..azimuth import THETA_DECIMALS, snap_deg
from ..errors import DeckbridgeError
from ..quantities import sigma_n_wall
from ..results import ResultsError, conform
from .profile import LAMBDA_TOL, Profile  # noqa: F401 (LAMBDA_TOL re-exported)


class LoadFactorError(DeckbridgeError):
    """A requested load factor outside a source's load path."""


@dataclass(frozen=True)
class State:
    """One printed state: its load factor, the azimuth profile and the node-level sigma_N / open flags
    (``nodes`` indexed by (node, theta) so that node-less exports stay distinct)."""
    load_factor: float
    step: int
    increment: int
    profile: Profile
    nodes: pd.DataFrame | None = None
    rows: pd.DataFrame | None = None


@dataclass
class Series:
    """One (source, method) along its load path; ``origin`` is the file or folder it came from."""
    label: str
    source: str
    method: str
    states: list[State]
    origin: str | None = None
    theta: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def n_theta(self) -> int:
        return int(self.theta.size)

    @property
    def load_factors(self) -> np.ndarray:
        return np.array([s.load_factor for s in self.states])

    @property
    def lf_range(self) -> tuple[float, float]:
        lf = self.load_factors
        return float(lf.min()), float(lf.max())

    def covers(self, lam: float) -> bool:
        lo, hi = self.lf_range
        tol = LAMBDA_TOL * max(1.0, abs(lam))
        return lo - tol <= lam <= hi + tol

    def state_at(self, lam: float) -> State | None:
        """The printed state at load factor ``lam`` (the last one when several), None between states."""
        tol = LAMBDA_TOL * max(1.0, abs(lam))
        hit = np.flatnonzero(np.abs(self.load_factors - lam) <= tol)
        return self.states[int(hit[-1])] if hit.size else None

    def at(self, lam: float) -> Profile:
        """Profile at load factor ``lam`` (a state's own, or linear between the two around it)."""
        if not self.covers(lam):
            lo, hi = self.lf_range
            where = f" ({self.origin})" if self.origin else ""
            raise LoadFactorError(f"{self.label}{where}: load factor {lam:g} outside its range [{lo:g}, {hi:g}]")
        lf = self.load_factors
        tol = LAMBDA_TOL * max(1.0, abs(lam))
        hit = np.flatnonzero(np.abs(lf - lam) <= tol)
        if hit.size:
            return self.states[int(hit[-1])].profile
        j = int(np.searchsorted(lf, lam))
        a, b = self.states[j - 1], self.states[j]
        w = (lam - a.load_factor) / (b.load_factor - a.load_factor)
        return Profile(self.theta, (1.0 - w) * a.profile.sigma + w * b.profile.sigma,
                       a.profile.all_open & b.profile.all_open)


def profile_of(rows: pd.DataFrame) -> Profile:
    """Per-azimuth through-wall sigma_N (area-weighted, :func:`~deckbridge.quantities.sigma_n_wall`) and
    all-open flag of the rows of one state."""
    th = snap_deg(rows["theta_deg"].to_numpy(float))
    o = pd.Series(rows["status"].to_numpy() == "open", index=th).groupby(level=0).all().sort_index()
    s = sigma_n_wall(rows).reindex(o.index)
    return Profile(o.index.to_numpy(float), s.to_numpy(float), o.to_numpy(bool))


def nodes_of(rows: pd.DataFrame) -> pd.DataFrame:
    """Node-level sigma_N [Pa] and open flag of one state, indexed by (node, rounded theta)."""
    key = pd.MultiIndex.from_arrays([rows["node"].to_numpy(np.int64),
                                     np.round(rows["theta_deg"].to_numpy(float), THETA_DECIMALS)],
                                    names=["node", "theta"])
    out = pd.DataFrame({"sigma": rows["sigma_n_pa"].to_numpy(float),
                        "open": rows["status"].to_numpy() == "open"}, index=key)
    return out[~out.index.duplicated(keep="last")]


def series_of(df: pd.DataFrame, label: str, origin: str | None = None, surface: str = "table") -> Series:
    """Build the series of one (source, method) sub-table."""
    where = f" ({origin})" if origin else ""
    rows = df[df["surface"] == surface]
    if rows.empty:
        raise DeckbridgeError(f"{label}{where}: no contact data on the {surface} surface")
    steps = set(int(s) for s in rows["step"].unique())
    if not steps <= {1, 2}:
        bad = sorted(steps - {1, 2})[0]
        raise DeckbridgeError(f"{label}{where}: step {bad} is not in the load path (1 = N, 2 = N + lambda (T, M))")
    states: list[State] = []
    s1 = rows[rows["step"] == 1]
    if not s1.empty:
        last = int(s1["increment"].max())
        rows1 = s1[s1["increment"] == last]
        states.append(State(0.0, 1, last, profile_of(rows1), nodes_of(rows1), rows1))
    s2 = rows[rows["step"] == 2]
    by_lam: dict[float, State] = {}
    for inc, g in s2.groupby("increment", sort=True):
        lam = float(np.median(g["load_factor"].to_numpy(float)))
        if not np.isfinite(lam) or lam < 0:
            raise DeckbridgeError(f"{label}{where}: step 2 increment {inc}: load factor {lam!r} must be >= 0")
        if states and lam <= LAMBDA_TOL:
            continue                      # start of step 2 = end of step 1
        by_lam[round(lam, 12)] = State(lam, 2, int(inc), profile_of(g), nodes_of(g), g)
    states += [by_lam[k] for k in sorted(by_lam)]
    theta = np.unique(np.concatenate([s.profile.theta for s in states]))
    states = [State(s.load_factor, s.step, s.increment, s.profile.resample(theta), s.nodes, s.rows) for s in states]
    return Series(label, str(rows["source"].iloc[0]), str(rows["method"].iloc[0]), states, origin, theta)


def _folder_name(origin) -> str:
    p = Path(str(origin))
    return p.name if p.is_dir() or not p.suffix else (p.parent.name or p.name)


def split_tables(tables: list[pd.DataFrame], origins: list | None = None, surface: str = "table") -> list[Series]:
    """Every (source, method) of every table as a series, labelled 'source/method'.

    Equal labels get the folder name of their origin appended ('reference/penalty (run_b)'), then
    '#2', '#3' if still equal.
    """
    origins = list(origins) if origins is not None else [None] * len(tables)
    if len(origins) != len(tables):
        raise ValueError("origins must match tables one to one")
    found: list[tuple[str, str | None, pd.DataFrame]] = []
    for df, origin in zip(tables, origins):
        try:
            df = conform(df)
        except (ResultsError, ValueError, TypeError) as exc:
            raise DeckbridgeError(f"{origin or 'table'}: {str(exc).splitlines()[0]}") from None
        if df.empty:
            raise DeckbridgeError(f"{origin or 'table'}: no contact data (the table has no rows)")
        for (src, meth), g in df.groupby(["source", "method"], sort=False):
            found.append((f"{src}/{meth}", None if origin is None else str(origin), g))
    counts = pd.Series([f[0] for f in found]).value_counts()
    labels = [lab if counts[lab] == 1 or origin is None else f"{lab} ({_folder_name(origin)})"
              for lab, origin, _ in found]
    seen: dict[str, int] = {}
    unique = []
    for lab in labels:
        seen[lab] = seen.get(lab, 0) + 1
        unique.append(lab if seen[lab] == 1 else f"{lab}#{seen[lab]}")
    return [series_of(g, lab, origin, surface) for lab, (_, origin, g) in zip(unique, found)]
