"""Reader of the reference solver's output: a folder with contact.csv + summary.json, or the csv.

contact.csv already follows the tidy schema of :mod:`deckbridge.results` (sigma_n_pa < 0
compression, gap_m > 0 open), so reading is checking: columns, dtypes, at least one row, and,
with a model, that every node is a contact slave node of that model at the azimuth the file says.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import DeckbridgeError
from ..results import COLUMNS, ResultsError, conform
from . import register
from ._checks import checked
from ._nodemap import locate

THETA_TOL_DEG = 1e-3


def contact_csv(path: Path) -> Path:
    """The contact.csv of a reference output folder, or ``path`` itself when it is a file."""
    return path / "contact.csv" if path.is_dir() else path


def _header(path: Path) -> list[str]:
    try:
        with open(path, newline="", encoding="utf-8", errors="replace") as fh:
            return [c.strip() for c in next(csv.reader(fh), [])]
    except (OSError, UnicodeDecodeError):
        return []


def detect(path: Path) -> bool:
    """A folder holding contact.csv and summary.json, or a .csv whose header has every schema column."""
    if path.is_dir():
        return (path / "contact.csv").is_file() and (path / "summary.json").is_file()
    if path.suffix.lower() != ".csv" or not path.is_file():
        return False
    return set(COLUMNS) <= set(_header(path))


@register("reference", detect=detect)
@checked(None)
def read(path: Path, model=None) -> pd.DataFrame:
    """Read contact.csv of a reference output folder (or the csv itself) into the tidy table."""
    src = contact_csv(Path(path))
    if not src.is_file():
        raise DeckbridgeError(f"{str(src)!r}: no such file (a reference output folder holds contact.csv)")
    try:
        df = pd.read_csv(src)
    except (OSError, ValueError, pd.errors.ParserError) as exc:
        raise DeckbridgeError(f"{str(src)!r}: not a readable CSV ({str(exc).splitlines()[0]})") from None
    missing = [c for c in COLUMNS if c not in df.columns]
    if missing:
        raise DeckbridgeError(f"{str(src)!r}: not a deckbridge contact table (lacks columns {', '.join(missing)})")
    if df.empty:
        raise DeckbridgeError(f"{str(src)!r}: no contact data (the table has no rows)")
    try:
        out = conform(df)
    except (ResultsError, ValueError, TypeError) as exc:
        raise DeckbridgeError(f"{str(src)!r}: {str(exc).splitlines()[0]}") from None
    if not np.isfinite(out["sigma_n_pa"].to_numpy()).all():
        raise DeckbridgeError(f"{str(src)!r}: sigma_n_pa holds non-finite values")
    if model is not None:
        check_against_model(out, model, src)
    return out


def check_against_model(df: pd.DataFrame, model, path) -> None:
    """Raise naming ``path`` unless every node is a slave node of ``model`` at the azimuth of the table."""
    nodes = df["node"].to_numpy()
    rows = locate(nodes, model, path)
    d = np.abs(rows["theta_deg"].to_numpy() - df["theta_deg"].to_numpy())
    d = np.minimum(d, 360.0 - d)
    if (d > THETA_TOL_DEG).any():
        i = int(np.argmax(d))
        raise DeckbridgeError(
            f"{str(path)!r}: node {int(nodes[i])} at theta {df['theta_deg'].iloc[i]:.4f} deg, "
            f"but model {model.name!r} puts it at {rows['theta_deg'].iloc[i]:.4f} deg: results of another model?")
    r_file, r_model = df["r"].to_numpy(float), rows["r"].to_numpy(float)
    ok = np.isfinite(r_file)
    if ok.any():
        ratio = float(np.median(r_file[ok] / r_model[ok]))
        if not 0.99 < ratio < 1.01:
            raise DeckbridgeError(
                f"{str(path)!r}: node radii are {ratio:.4g} times those of model {model.name!r} "
                f"(r = {np.median(r_file[ok]):.6g} vs {np.median(r_model[ok]):.6g} m): different units or another model")
