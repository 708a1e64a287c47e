"""The one tidy table every source of contact results lands in.

One row per (source, method, step, increment, slave node). sigma_n_pa < 0 is compression,
> 0 tension / liftoff; gap_m > 0 is open, < 0 penetration; status is 'closed' or 'open'.

Force and area: ``force_n`` is the normal force of the master on the node [N], **> 0 compressive**
(the solvers' own sign: Nastran CGAP, CPRESS x area, the reference solver's force), ``area_m2`` the
row's contact area [m^2] (definitions per face type: :mod:`deckbridge.quantities`). On 4- and 3-node faces
``sigma_n_pa = -force_n / area_m2`` row by row; on 8- and 6-node faces sigma_n_pa is the projected pressure
and force_n the consistent nodal force the solver applies (a corner of a pressed 8-node face pulls), so only
their sums agree: Sum force_n = -Sum sigma_n_pa x area_m2 per state (:func:`conform` checks that; NaN
force_n where the source prints no nodal force, e.g. ccx face-to-face on quadratic faces). A source that
knows no area (a bare CSV, an OP2 read without a model) has NaN in both.
``wall``: through-wall ring of the node at its azimuth, 0 = inner face .. n_r = outer face, the
dense rank of its radius among the rows of the same state and azimuth (a stop node on the outer face
gets n_r, on the inner face 0).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
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
    "area_m2",       # tributary contact area of the slave node [m^2] (NaN: unknown)
    "force_n",       # normal contact force on the node [N], > 0 compressive (= -sigma_n_pa x area_m2 on 4-/3-node faces)
    "wall",          # through-wall ring, 0 = inner face .. n_r = outer face
]
NEW_COLUMNS = ("area_m2", "force_n", "wall")      # filled by conform() when a table predates them
REQUIRED = [c for c in COLUMNS if c not in NEW_COLUMNS]   # what a table file must hold
FORCE_RTOL = 1e-9

DTYPES = {
    "source": "string", "method": "string", "step": "int64", "increment": "int64",
    "load_factor": "float64", "node": "int64", "surface": "string", "theta_deg": "float64",
    "z": "float64", "r": "float64", "sigma_n_pa": "float64", "gap_m": "float64", "status": "string",
    "area_m2": "float64", "force_n": "float64", "wall": "int64",
}


class ResultsError(ValueError):
    """A table that does not follow the schema."""


def empty() -> pd.DataFrame:
    return pd.DataFrame({c: pd.Series(dtype=DTYPES[c]) for c in COLUMNS})


def wall_index(df: pd.DataFrame) -> np.ndarray:
    """Through-wall ring (0 = inner) of each row: dense rank of its radius among the rows of the same
    (source, method, step, increment, azimuth); radii equal to 1e-9 m share a ring."""
    if df.empty:
        return np.zeros(0, np.int64)
    key = pd.DataFrame({
        "k": pd.factorize(pd.MultiIndex.from_arrays([
            df["source"].astype(str), df["method"].astype(str), df["step"], df["increment"],
            np.round(np.asarray(df["theta_deg"], float), 6) % 360.0]))[0],
        "r": np.round(np.asarray(df["r"], float), 9)})
    return key.groupby("k")["r"].rank(method="dense").fillna(1).to_numpy(np.int64) - 1


def with_forces(df: pd.DataFrame, area, force=None) -> pd.DataFrame:
    """``df`` with area_m2 = ``area`` [m^2] (per row, NaN where unknown), force_n = ``force`` [N] (per row, > 0
    compressive; NaN: not known) or, without it, -sigma_n_pa * area (the nodal law's force) and wall; what each
    reader calls at the point it builds its table."""
    out = df.copy()
    out["area_m2"] = np.broadcast_to(np.asarray(area, float), (len(out),)) if len(out) else np.zeros(0)
    out["force_n"] = (-out["sigma_n_pa"].to_numpy(float) * out["area_m2"].to_numpy(float) if force is None
                      else np.broadcast_to(np.asarray(force, float), (len(out),)))
    out["wall"] = wall_index(out)
    return out


def conform(df: pd.DataFrame) -> pd.DataFrame:
    """Return ``df`` with exactly the schema's columns, order and dtypes; raise on violations.

    A table without area_m2 / force_n (written before they existed) gets NaN (unknown), one without
    wall gets :func:`wall_index`. Checked: area_m2 > 0 where known, force_n only where area_m2 is known, and
    per state (source, method, step, increment) over its rows with both known Sum force_n = -Sum sigma_n_pa x
    area_m2 to 1e-9 of the state's Sum |force_n| (row by row on 4-/3-node faces, in sum on 8-/6-node faces:
    module doc).
    """
    df = df.copy() if any(c not in df.columns for c in NEW_COLUMNS) else df
    for c in ("area_m2", "force_n"):
        if c not in df.columns:
            df[c] = np.nan
    if "wall" not in df.columns and all(c in df.columns for c in ("source", "method", "step", "increment",
                                                                  "theta_deg", "r")):
        df["wall"] = wall_index(df)
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
    a, f, s = (out[c].to_numpy(float) for c in ("area_m2", "force_n", "sigma_n_pa"))
    known = np.isfinite(a)
    if (a[known] <= 0).any():
        raise ResultsError(f"area_m2 = {a[known][a[known] <= 0][0]!r}: must be > 0 (or NaN: unknown)")
    if (np.isfinite(f) & ~known).any():
        raise ResultsError("force_n given where area_m2 is not (NaN in both when unknown)")
    both = known & np.isfinite(f)
    if both.any():
        state = pd.factorize(pd.MultiIndex.from_arrays([out[c].to_numpy()[both] for c in
                                                        ("source", "method", "step", "increment")]))[0]
        err = np.abs(np.bincount(state, s[both] * a[both] + f[both]))
        scale = np.bincount(state, np.abs(f[both]))
        bad = err > FORCE_RTOL * np.maximum(scale, 1e-300) + 1e-300
        if bad.any():
            i = int(np.argmax(np.where(bad, err / np.maximum(scale, 1e-300), 0.0)))
            raise ResultsError(f"Sum force_n = {np.sum(f[both][state == i])!r} but -Sum sigma_n_pa x area_m2 = "
                               f"{-np.sum((s * a)[both][state == i])!r} in one state: force_n > 0 is compressive, "
                               "sigma_n_pa < 0 compression")
    if (out["wall"] < 0).any():
        raise ResultsError("wall must be >= 0 (0 = inner face)")
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
    wall: pd.DataFrame | None = None      # base-wall sigma_zz per state (deckbridge.wall_stress.WALL_COLUMNS)
    friction: pd.DataFrame | None = None  # tangential state per row and state (deckbridge.friction_table), if any
    ring_lines: dict | None = None        # {load factor: contact force [N] per azimuth line of the ccx f2f deck's
    #                                       master ring} (8-/6-node faces: quantities ring_line_force_n), if any

    def wall_at(self, step: int, increment: int, load_factor: float) -> pd.DataFrame | None:
        """Rows of :attr:`wall` of one state: step 1 its last increment, step 2 the same load factor."""
        w = self.wall
        if w is None or w.empty:
            return None
        if step == 1:
            s1 = w[w["step"] == 1]
            return s1[s1["increment"] == s1["increment"].max()] if len(s1) else None
        s2 = w[(w["step"] == 2) & (np.abs(w["load_factor"] - load_factor) <= 1e-9 * max(1.0, abs(load_factor)))]
        if s2.empty:
            return None
        return s2[s2["increment"] == s2["increment"].max()]

    @classmethod
    def wrap(cls, obj, origin=None) -> "SourceResult":
        """``obj`` itself when already a record, else a plain table wrapped with no globals."""
        if isinstance(obj, SourceResult):
            return obj if origin is None or obj.origin is not None else cls(obj.table, str(origin), obj.globals,
                                                                           obj.fields, obj.summary, obj.wall,
                                                                           obj.friction)
        return cls(obj, None if origin is None else str(origin))

    def globals_for(self, method: str) -> dict:
        """Global figures of ``method`` ({} when the source has none)."""
        return self.globals.get(method) or {}
