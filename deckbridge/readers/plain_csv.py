"""Reader of a plain CSV exported from a post-processor: node or azimuth, and a contact stress.

The header names say what a column holds, its sign and its unit, e.g.::

    node, CPRESS [MPa]            # compression positive (flipped on reading), MPa
    theta (deg), sigma_n_pa       # deckbridge convention: < 0 compression, Pa
    Node Label; CPRESS; COPEN [mm]; load_factor

Recognised columns (case-insensitive; unit in [..] or (..) or as a suffix _pa, _mpa, _deg, _mm):
node | azimuth/theta (deg or rad) | CPRESS/pressure (compression positive) or sigma_n/sn (< 0
compression) in Pa, kPa, MPa, GPa, N/mm2 (no unit: Pa) | optional COPEN/gap (m, mm, um),
load_factor/lambda, step, increment, status, surface, source, method. Node ids map to azimuth
through the model (the embedded default when none is given); an azimuth column is taken as is.
Without a load-factor column the file is the end of step 2 (lambda_max of the model, else 1).

Refused, with the file, line, column and value: a cell that is not a number; a node, step or increment
that is not a whole number (``12.5``); an azimuth outside [-360, 360] deg (``1e6``: a unit or export
error, not an angle to wrap); two rows of the same (source, method, step, increment, surface, node or
azimuth) — a duplicate would be averaged downstream.
"""

from __future__ import annotations

import csv
import re
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import DeckbridgeError
from ..results import REQUIRED as COLUMNS
from ..results import with_forces
from ._checks import checked
from ._nodemap import locate, slave_areas, surface_of

_STRESS_UNITS = {"pa": 1.0, "n/m2": 1.0, "n/m^2": 1.0, "kpa": 1e3, "mpa": 1e6, "n/mm2": 1e6, "n/mm^2": 1e6,
                 "gpa": 1e9, "bar": 1e5}
_LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "micron": 1e-6}
_ANGLE_UNITS = {"deg": 1.0, "degree": 1.0, "degrees": 1.0, "°": 1.0, "rad": 180.0 / np.pi, "radian": 180.0 / np.pi,
                "radians": 180.0 / np.pi}
_ROLES = {
    "node": {"node", "node_id", "nodeid", "node_label", "nodelabel", "node_number", "nid", "label", "grid"},
    "theta": {"theta", "azimuth", "azim", "angle", "azimut"},
    "cpress": {"cpress", "pressure", "contact_pressure", "p"},
    "sigma_n": {"sigma_n", "sigman", "sigma_nn", "sn", "σn", "σ_n", "normal_stress"},
    "gap": {"copen", "gap", "opening"},
    "load_factor": {"load_factor", "loadfactor", "lambda", "lf", "λ"},
    "step": {"step"}, "increment": {"increment", "inc"}, "status": {"status", "cstatus"},
    "surface": {"surface"}, "source": {"source"}, "method": {"method"},
}
_UNIT_KIND = {"theta": _ANGLE_UNITS, "cpress": _STRESS_UNITS, "sigma_n": _STRESS_UNITS, "gap": _LENGTH_UNITS}
_WHOLE = ("node", "step", "increment")           # roles that must hold whole numbers
THETA_LIMIT_DEG = 360.0                         # |azimuth| beyond this is refused, not wrapped
_BRACKET = re.compile(r"^(.*?)\s*[\[(]\s*([^\])]*)\s*[\])]\s*$")


def split_name(name: str) -> tuple[str, str | None]:
    """'CPRESS [MPa]' -> ('cpress', 'mpa'); 'sigma_n_pa' -> ('sigma_n', 'pa'); 'node' -> ('node', None)."""
    text = str(name).strip().lower()
    m = _BRACKET.match(text)
    if m:
        return re.sub(r"[\s-]+", "_", m.group(1).strip()), m.group(2).strip().replace(" ", "")
    base = re.sub(r"[\s-]+", "_", text)
    if base in {r for roles in _ROLES.values() for r in roles}:
        return base, None
    for units in (_STRESS_UNITS, _LENGTH_UNITS, _ANGLE_UNITS):
        for u in sorted(units, key=len, reverse=True):
            if base.endswith("_" + u.replace("/", "")) or base.endswith("_" + u):
                return base[: base.rfind("_")], u
    return base, None


def roles(columns) -> dict[str, tuple[str, str | None]]:
    """Map role -> (column name, unit) for the recognised columns of a header."""
    found: dict[str, tuple[str, str | None]] = {}
    for col in columns:
        base, unit = split_name(col)
        for role, names in _ROLES.items():
            if base in names and role not in found:
                found[role] = (col, unit)
    return found


def _header(path: Path) -> list[str]:
    try:
        with open(path, newline="", encoding="utf-8-sig", errors="replace") as fh:
            for line in fh:
                if line.strip() and not line.lstrip().startswith("#"):
                    try:
                        dialect = csv.Sniffer().sniff(line, delimiters=",;\t")
                        return [c.strip() for c in next(csv.reader([line], dialect))]
                    except csv.Error:
                        return line.split()
    except OSError:
        pass
    return []


def detect(path: Path) -> bool:
    """A .csv/.txt/.tsv file with a node or azimuth column and a contact-stress column (not the tidy schema)."""
    if not path.is_file() or path.suffix.lower() not in {".csv", ".txt", ".tsv"}:
        return False
    head = _header(path)
    if set(COLUMNS) <= set(head):
        return False
    r = roles(head)
    return ("node" in r or "theta" in r) and ("cpress" in r or "sigma_n" in r)


def _factor(path, col: str, unit: str | None, table: dict[str, float], default: str) -> float:
    if unit is None or unit == "":
        return table[default]
    key = unit.lower()
    if key not in table:
        raise DeckbridgeError(f"{str(path)!r}: column {col!r}: unit {unit!r} not understood "
                              f"(known: {', '.join(sorted(table))})")
    return table[key]


def _data_lines(path: Path, n: int) -> list[str]:
    """'line k' (1-based, in the file) of each of the ``n`` data rows: the lines after the header that
    are neither blank nor comments; 'data row k' if that count does not match (quoted line breaks)."""
    try:
        with open(path, newline="", encoding="utf-8-sig", errors="replace") as fh:
            kept = [i for i, line in enumerate(fh, 1) if line.strip() and not line.lstrip().startswith("#")]
    except OSError:
        kept = []
    if len(kept) == n + 1:
        return [f"line {k}" for k in kept[1:]]
    return [f"data row {k}" for k in range(1, n + 1)]


@checked("never")
def read(path: Path, model=None, mesh=None) -> pd.DataFrame:
    """Read a post-processor CSV export into the tidy table (sign and unit from the header)."""
    from ..model import load

    path = Path(path)
    try:
        df = pd.read_csv(path, sep=None, engine="python", comment="#", encoding="utf-8-sig",
                         keep_default_na=False, dtype=str)
    except (OSError, ValueError, pd.errors.ParserError, csv.Error) as exc:
        raise DeckbridgeError(f"{str(path)!r}: not a readable CSV ({str(exc).splitlines()[0]})") from None
    df.columns = [str(c).strip() for c in df.columns]
    r = roles(df.columns)
    if "cpress" not in r and "sigma_n" not in r:
        raise DeckbridgeError(f"{str(path)!r}: no contact-stress column (CPRESS or sigma_n) in {list(df.columns)}")
    if "node" not in r and "theta" not in r:
        raise DeckbridgeError(f"{str(path)!r}: needs a node or an azimuth (theta) column")
    if df.empty:
        raise DeckbridgeError(f"{str(path)!r}: no contact data (the table has no rows)")

    lines = _data_lines(path, len(df))

    def num(role: str) -> np.ndarray:
        col = r[role][0]
        vals = pd.to_numeric(df[col], errors="coerce").to_numpy(float)
        bad = np.isnan(vals)
        why = "is not a number"
        if role in _WHOLE and not bad.any():
            with np.errstate(invalid="ignore"):
                bad = ~np.isfinite(vals) | (vals != np.round(vals)) | (np.abs(vals) >= 2**63)
            why = "is not a whole number"
        if bad.any():
            i = int(np.argmax(bad))
            raise DeckbridgeError(f"{str(path)!r}: {lines[i]}, column {col!r}: {df[col].iloc[i]!r} {why}")
        return vals

    stress_role = "cpress" if "cpress" in r else "sigma_n"
    col, unit = r[stress_role]
    sigma = num(stress_role) * _factor(path, col, unit, _STRESS_UNITS, "pa")
    if stress_role == "cpress":
        sigma = -sigma
    n = len(df)
    model_used = model or load(None)
    nodes = num("node").astype(np.int64) if "node" in r else np.zeros(n, np.int64)
    z = r_ = np.full(n, np.nan)
    surface = np.full(n, "table", dtype=object)
    if "node" in r:
        located = locate(nodes, model_used, path, mesh=mesh if model is not None else None)
        z, r_ = located["z"].to_numpy(), located["r"].to_numpy()
        surface = surface_of(located)
        theta = located["theta_deg"].to_numpy()
    if "theta" in r:
        col, unit = r["theta"]
        theta = num("theta") * _factor(path, col, unit, _ANGLE_UNITS, "deg")
        far = ~(np.abs(theta) <= THETA_LIMIT_DEG)
        if far.any():
            i = int(np.argmax(far))
            raise DeckbridgeError(f"{str(path)!r}: {lines[i]}, column {col!r}: {df[col].iloc[i]!r} is outside "
                                  f"[-{THETA_LIMIT_DEG:g}, {THETA_LIMIT_DEG:g}] deg (a unit or export error?)")
        theta = np.mod(theta, 360.0)
        theta = np.where(theta >= 360.0, 0.0, theta)
    gap = np.full(n, np.nan)
    if "gap" in r:
        col, unit = r["gap"]
        gap = num("gap") * _factor(path, col, unit, _LENGTH_UNITS, "m")
    if "load_factor" in r:
        lam = num("load_factor")
        step = num("step").astype(np.int64) if "step" in r else np.where(lam == 0.0, 1, 2)
    else:
        lam = np.full(n, model_used.steps.lambda_max if model is not None else 1.0)
        step = num("step").astype(np.int64) if "step" in r else np.full(n, 2)
    if "increment" in r:
        inc = num("increment").astype(np.int64)
    else:
        inc = pd.DataFrame({"s": step, "l": lam}).groupby("s")["l"].rank(method="dense").to_numpy(np.int64)
    if "status" in r:
        word = df[r["status"][0]].astype(str).str.strip().str.upper()
        is_open = word.isin(["OPEN", "OP", "0", "FALSE"]).to_numpy()
    else:
        is_open = np.where(np.isnan(gap), sigma >= 0.0, gap > 0.0)
    if "surface" in r:
        surface = df[r["surface"][0]].astype(str).str.strip().str.lower().to_numpy()
    source = df[r["source"][0]].astype(str).to_numpy() if "source" in r else "csv"
    method = df[r["method"][0]].astype(str).to_numpy() if "method" in r else path.stem
    area = slave_areas(model_used, nodes, surface, mesh if model is not None else None) if "node" in r else np.full(n, np.nan)
    key = pd.DataFrame({"source": source, "method": method, "step": step, "increment": inc, "surface": surface,
                        "where": nodes if "node" in r else theta})
    dup = key.duplicated(keep=False).to_numpy()
    if dup.any():
        i, j = np.flatnonzero(dup & key.duplicated(keep="first").to_numpy())[0], np.flatnonzero(dup)[0]
        col = r["node"][0] if "node" in r else r["theta"][0]
        raise DeckbridgeError(f"{str(path)!r}: {lines[i]}, column {col!r}: {df[col].iloc[i]!r} repeats {lines[j]} "
                              f"(same source, method, step, increment and surface): duplicate rows are refused, "
                              "not averaged")
    return with_forces(pd.DataFrame({
        "source": source, "method": method, "step": step, "increment": inc, "load_factor": lam,
        "node": nodes, "surface": surface, "theta_deg": theta, "z": z, "r": r_,
        "sigma_n_pa": sigma, "gap_m": gap, "status": np.where(is_open, "open", "closed"),
        "origin": [f"{str(path)!r}: {line}" for line in lines],      # for the contact-law check
    }), area)
