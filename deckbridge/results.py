"""The one tidy table every source of contact results lands in.

One row per (source, method, step, increment, slave node). sigma_n_pa < 0 is compression,
> 0 tension / liftoff; gap_m > 0 is open, < 0 penetration; status is 'closed' or 'open'.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import pandas as pd

COLUMNS = [
    "source",        # who computed it: reference, ccx, mystran, nastran, abaqus, csv
    "method",        # penalty | lagrange | mortar | linear
    "step",          # 1 (N) or 2 (N + lambda (T, M))
    "increment",     # 0 at the start of a step, 1..n
    "load_factor",   # lambda on T and M (0 throughout step 1)
    "node",          # deck node id (1-based)
    "surface",       # table | stop
    "theta_deg",     # azimuth in [0, 360)
    "z",             # [m]
    "r",             # [m]
    "sigma_n_pa",    # contact normal stress [Pa], < 0 compression
    "gap_m",         # normal gap [m], > 0 open
    "status",        # closed | open
]

DTYPES = {
    "source": "string", "method": "string", "step": "int64", "increment": "int64",
    "load_factor": "float64", "node": "int64", "surface": "string", "theta_deg": "float64",
    "z": "float64", "r": "float64", "sigma_n_pa": "float64", "gap_m": "float64", "status": "string",
}


class ResultsError(ValueError):
    """A table that does not follow the schema."""


def empty() -> pd.DataFrame:
    return pd.DataFrame({c: pd.Series(dtype=DTYPES[c]) for c in COLUMNS})


def conform(df: pd.DataFrame) -> pd.DataFrame:
    """Return ``df`` with exactly the schema's columns, order and dtypes; raise on violations."""
    missing = [c for c in COLUMNS if c not in df.columns]
    if missing:
        raise ResultsError(f"contact table lacks columns {missing}")
    out = df[COLUMNS].astype(DTYPES)
    bad = out.loc[~out["status"].isin(["closed", "open"]), "status"]
    if len(bad):
        raise ResultsError(f"status = {bad.iloc[0]!r}: must be closed or open")
    bad = out.loc[~out["surface"].isin(["table", "stop"]), "surface"]
    if len(bad):
        raise ResultsError(f"surface = {bad.iloc[0]!r}: must be table or stop")
    th = out["theta_deg"]
    if ((th < 0) | (th >= 360)).any():
        raise ResultsError("theta_deg outside [0, 360)")
    return out.reset_index(drop=True)


@dataclass
class SourceResult:
    """One source's results: the tidy table, where it came from, and its global figures where it has them.

    ``globals``: per method, {'max_von_mises_pa' [Pa], 'max_displacement_m' [m], 'from'} ({} where none);
    ``fields``: whole-model fields at the last step, {'xyz' (n, 3) [m], 'u' (n, 3) [m] or None, 'vm_xyz',
    'vm' [Pa] or None}, or None; ``summary``: the solver's summary dict (liftoff, reactions, timings), if any.
    """
    table: pd.DataFrame
    origin: str | None = None
    globals: dict[str, dict] = field(default_factory=dict)
    fields: dict | None = None
    summary: dict | None = None

    @classmethod
    def wrap(cls, obj, origin=None) -> "SourceResult":
        """``obj`` itself when already a record, else a plain table wrapped with no globals."""
        if isinstance(obj, SourceResult):
            return obj if origin is None or obj.origin is not None else cls(obj.table, str(origin), obj.globals,
                                                                           obj.fields, obj.summary)
        return cls(obj, None if origin is None else str(origin))

    def globals_for(self, method: str) -> dict:
        """Global figures of ``method`` ({} when the source has none)."""
        return self.globals.get(method) or {}
