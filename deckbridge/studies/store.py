"""On-disk store of finished cases: ``DIR/cases/<case_id>.csv`` (the tidy contact table) and
``DIR/cases/<case_id>.json`` (its spec, summary and provenance), each written atomically; with field
recovery also ``DIR/cases/<case_id>.wall.csv`` (base-wall sigma_zz per state and azimuth,
:mod:`deckbridge.wall_stress`), whose sha256 the JSON names too.

The JSON is written last and names the table's row count and sha256, so a case counts as done
only when both files are whole and match the case's spec; anything else is recomputed. A case
whose solve failed with a one-line error (a load that tips the skirt over, say) is recorded with
that error and no table: it is deterministic, so it is not retried. Tables are
CSV with shortest round-trip floats, read back with ``float_precision='round_trip'``: a stored
case reads back bit for bit. ``DIR/cases/log.jsonl`` gets one line per case computed (run id,
case id, wall time), so a resumed study can show what it recomputed.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import time
from pathlib import Path

import pandas as pd

from ..errors import DeckbridgeError
from ..outdir import cannot_write, prepare, write_file, write_text
from ..results import conform
from .cases import Case


def csv_text(frame: pd.DataFrame) -> str:
    """A case table as the store writes it (schema columns, shortest round-trip floats)."""
    return conform(frame).to_csv(index=False, lineterminator="\n")


def _read_exact(source) -> pd.DataFrame:
    """A CSV the store wrote, read back with every float exactly as written (``source``: path or stream)."""
    return pd.read_csv(source, float_precision="round_trip")


def table_of(source) -> pd.DataFrame:
    """A stored case table read back (``source``: a path or a text stream), exactly as computed."""
    return conform(_read_exact(source))


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


class CaseStore:
    """Finished cases of a study under ``root/cases``."""

    def __init__(self, root: str | Path):
        self.root = prepare(root)
        self.dir = prepare(self.root / "cases")

    def table_path(self, case: Case) -> Path:
        return self.dir / f"{case.case_id}.csv"

    def meta_path(self, case: Case) -> Path:
        return self.dir / f"{case.case_id}.json"

    def meta(self, case: Case) -> dict | None:
        """The stored record of ``case`` when complete and valid, else None."""
        mp, tp = self.meta_path(case), self.table_path(case)
        if not mp.is_file():
            return None
        try:
            rec = json.loads(mp.read_text())
        except (OSError, ValueError):
            return None
        if rec.get("spec") != json.loads(json.dumps(case.spec)):
            return None
        if rec.get("error"):                       # a case that failed for good (e.g. tips over)
            return rec
        if not tp.is_file() or rec.get("table_sha256") != _sha256(tp):
            return None
        ws = rec.get("wall_table_sha256")
        if ws is not None and (not self.wall_path(case).is_file() or _sha256(self.wall_path(case)) != ws):
            return None
        return rec

    def has(self, case: Case) -> bool:
        return self.meta(case) is not None

    def wall_path(self, case: Case) -> Path:
        return self.dir / f"{case.case_id}.wall.csv"

    def _write_csv(self, path: Path, frame: pd.DataFrame | str) -> None:
        """Write a table atomically (:func:`deckbridge.outdir.write_file`: mode of a plain open(), path named
        on any OSError)."""
        write_file(path, (lambda fh: fh.write(frame)) if isinstance(frame, str) else
                   (lambda fh: frame.to_csv(fh, index=False)), newline="", encoding="utf-8")

    def _log(self, entry: dict) -> None:
        path = self.dir / "log.jsonl"
        try:
            with open(path, "a") as fh:
                fh.write(json.dumps(entry) + "\n")
        except OSError as exc:
            raise cannot_write(path, exc) from None

    def put(self, case: Case, table: pd.DataFrame, summary: dict, run_id: str, extra: dict | None = None,
            wall: pd.DataFrame | None = None, text: str | None = None) -> Path:
        """Store one finished case: table (and base-wall table) first (temp file + rename), then its
        JSON record. ``text``: the table already as :func:`csv_text` (made on a worker), written as is."""
        tp = self.table_path(case)
        self._write_csv(tp, csv_text(table) if text is None else text)
        wp = self.wall_path(case)
        if wall is not None:
            self._write_csv(wp, wall)
        else:
            with contextlib.suppress(OSError):
                wp.unlink()
        rec = {"wall_table_sha256": None if wall is None else _sha256(wp),"case_id": case.case_id, "label": case.label, "mesh": case.mesh.label,
               "spec": case.spec, "summary": summary, "rows": int(len(table)), "table": tp.name,
               "table_sha256": _sha256(tp), "run_id": run_id, "stored_at": time.time(), **(extra or {})}
        write_text(self.meta_path(case), json.dumps(rec, indent=1, default=str) + "\n")
        self._log({"run_id": run_id, "case_id": case.case_id, "wall_time_s": (extra or {}).get("wall_time_s")})
        return tp

    def put_failed(self, case: Case, error: str, run_id: str) -> Path:
        """Record a case whose solve failed with a one-line (deterministic) error: not retried."""
        with contextlib.suppress(OSError):
            self.table_path(case).unlink()
        rec = {"case_id": case.case_id, "label": case.label, "mesh": case.mesh.label, "spec": case.spec,
               "error": str(error), "run_id": run_id, "stored_at": time.time()}
        write_text(self.meta_path(case), json.dumps(rec, indent=1, default=str) + "\n")
        self._log({"run_id": run_id, "case_id": case.case_id, "error": str(error)})
        return self.meta_path(case)

    def table(self, case: Case) -> pd.DataFrame:
        """The stored contact table of ``case`` (exactly as computed)."""
        path = self.table_path(case)
        try:
            df = _read_exact(path)
        except (OSError, ValueError) as exc:
            raise DeckbridgeError(f"{path}: cannot read the stored case table ({exc})") from None
        return conform(df)

    def wall(self, case: Case) -> pd.DataFrame | None:
        """The stored base-wall sigma_zz table of ``case`` (None when the case was solved without
        field recovery, e.g. --strategy split on a cluster)."""
        path = self.wall_path(case)
        if not path.is_file():
            return None
        return _read_exact(path)

    def log(self) -> list[dict]:
        """Every line of the computation log, oldest first."""
        path = self.dir / "log.jsonl"
        if not path.is_file():
            return []
        return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
