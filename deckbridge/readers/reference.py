"""Reader of the reference solver's output: a folder with contact.csv + summary.json, or the csv.

contact.csv already follows the tidy schema of :mod:`deckbridge.results` (sigma_n_pa < 0
compression, gap_m > 0 open), so reading is checking: columns, dtypes, at least one row, and,
with a model, that every node is a contact slave node of that model at the azimuth the file says.

:func:`read_source` returns the :class:`~deckbridge.results.SourceResult` record: the table plus the
global figures of the folder, where it has them: max von Mises [Pa] and max displacement [m] from
summary.json (numeric entries whose key names von Mises or displacement, preferring those under the
source's method), result.vtu (meshio) for what the summary lacks. In result.vtu, fields named per
step (``displacement_step2_m``, ``von_mises_step2_pa``) are taken at the last step, i.e. at the end
of the load path (lambda_max). result.vtu is read once.
"""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import DeckbridgeError
from .. import friction_table as FT
from .. import wall_stress as WS
from ..results import REQUIRED as COLUMNS, ResultsError, SourceResult, conform
from ..methods import PENALTY
from ._checks import checked
from ._files import beside
from ._nodemap import build_mesh, locate

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


@checked(None)
def read(path: Path, model=None, mesh=None) -> pd.DataFrame:
    """Read contact.csv of a reference output folder (or the csv itself) into the tidy table (``mesh``:
    ``model``'s, when built)."""
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
        mesh = mesh if mesh is not None else build_mesh(model)
        check_against_model(out, model, src, mesh)
        if mesh.quadratic_faces:   # the face-integrated penalty's sigma_N: a projected pressure (_contact_law.py)
            out = out.assign(law_weighted=(out["method"] == PENALTY).to_numpy())
    return out.assign(origin=[f"{str(src)!r}: line {i + 2}" for i in range(len(out))])   # for the contact-law check


def check_against_model(df: pd.DataFrame, model, path, mesh=None) -> None:
    """Raise naming ``path`` unless every node is a slave node of ``model`` at the azimuth of the table."""
    nodes = df["node"].to_numpy()
    rows = locate(nodes, model, path, mesh=mesh)
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


def read_source(path, model=None, mesh=None) -> SourceResult:
    """The table of :func:`read` with the folder's global figures per method, its result.vtu fields,
    its summary.json (the solver's liftoff, reactions, timings) when that is a JSON object and its
    friction.csv (:mod:`deckbridge.friction_table`) when the solution had friction."""
    table = read(Path(path), model=model, mesh=mesh)
    summary = None
    folder = _folder(path)
    if folder is not None and (folder / "summary.json").is_file():
        try:
            summary = json.loads((folder / "summary.json").read_text())
        except (OSError, ValueError, RecursionError):
            summary = None
    return SourceResult(table, str(path), summary=summary if isinstance(summary, dict) else None,
                        wall=read_wall(folder), friction=read_friction(folder),
                        **read_globals(path, table["method"].unique()))


def read_wall(folder) -> pd.DataFrame | None:
    """wall_stress.csv (:mod:`deckbridge.wall_stress`) of a reference folder, None when absent."""
    p = beside(folder, WS.WALL_CSV)
    if p is None:
        return None
    df = pd.read_csv(p)
    return df if set(WS.WALL_COLUMNS) <= set(df.columns) else None


def read_friction(folder) -> pd.DataFrame | None:
    """friction.csv of a reference folder (or beside a contact.csv), None when absent or not one."""
    p = beside(folder, FT.FRICTION_CSV)
    if p is None:
        return None
    try:
        df = pd.read_csv(p)
    except (OSError, ValueError, pd.errors.ParserError):
        return None
    if not set(FT.COLUMNS) <= set(df.columns) or not df["stick_status"].isin(FT.STATUSES).all():
        return None
    return df[FT.COLUMNS]


def read_globals(origin, methods) -> dict:
    """{'globals': {method: global figures}, 'fields': result.vtu fields or None} beside ``origin``."""
    f = fields(origin)
    return {"globals": {str(m): global_metrics(origin, str(m), f) for m in methods}, "fields": f}


_MISES = re.compile(r"mises", re.IGNORECASE)
_DISP = re.compile(r"(^|_|\b)(disp|displacement|u_?max|max_?u)(_|\b|$)", re.IGNORECASE)
_STEP = re.compile(r"step_?(\d+)", re.IGNORECASE)


def _leaves(obj, path=()):
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield from _leaves(v, path + (str(k),))
    elif isinstance(obj, (int, float)) and not isinstance(obj, bool) and np.isfinite(obj):
        yield path, float(obj)


def _pick(leaves, pattern, method):
    hits = [(p, v) for p, v in leaves if pattern.search(p[-1])]
    if method:
        mine = [(p, v) for p, v in hits if any(method.lower() == x.lower() for x in p)]
        hits = mine or hits
    maxed = [(p, v) for p, v in hits if "max" in p[-1].lower()]
    hits = maxed or hits
    return max((abs(v) for _, v in hits), default=None)


def _folder(origin) -> Path | None:
    if origin is None:
        return None
    p = Path(str(origin))
    folder = p if p.is_dir() else p.parent
    return folder if (folder / "summary.json").is_file() or (folder / "result.vtu").is_file() else None


def _last_step(names, pattern) -> str | None:
    """The name matching ``pattern`` with the highest 'stepN' (a name without a step counts as 0)."""
    hits = [n for n in names if pattern.search(n)]
    if not hits:
        return None
    return max(hits, key=lambda n: int(m.group(1)) if (m := _STEP.search(n)) else 0)


def _read_vtu(path: Path):
    import contextlib
    import io

    import meshio
    try:
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            return meshio.read(path)    # on a corrupt file meshio prints "Error: ..." and calls sys.exit(1)
    except (Exception, SystemExit):     # an unreadable vtu only costs the global table its row
        return None


def fields(origin) -> dict | None:
    """Fields of result.vtu beside ``origin`` at its last step, None when absent.

    {'xyz': (n, 3) points, 'u': (n, 3) displacement [m] or None, 'vm_xyz': points of the von Mises
    values (nodes or cell centres), 'vm': von Mises [Pa] or None}.
    """
    folder = _folder(origin)
    if folder is None or not (folder / "result.vtu").is_file():
        return None
    mesh = _read_vtu(folder / "result.vtu")
    return None if mesh is None else fields_of_mesh(mesh)


def fields_of_mesh(mesh) -> dict | None:
    """:func:`fields` of a meshio mesh."""
    xyz = np.asarray(mesh.points, float)
    out = {"xyz": xyz, "u": None, "vm_xyz": None, "vm": None}
    vectors = [n for n, a in mesh.point_data.items() if np.ndim(a) == 2 and np.shape(a)[1] >= 3]
    key = _last_step(vectors, _DISP) or next((n for n in vectors if n.lower() in {"u", "displacement"}), None)
    if key is not None:
        out["u"] = np.asarray(mesh.point_data[key], float)[:, :3]
    key = _last_step(mesh.point_data, _MISES)
    if key is not None:
        out["vm"], out["vm_xyz"] = np.asarray(mesh.point_data[key], float).ravel(), xyz
    else:
        key = _last_step(mesh.cell_data, _MISES)
        if key is not None:
            cents = np.concatenate([xyz[np.asarray(c.data)].mean(axis=1) for c in mesh.cells])
            out["vm"] = np.concatenate([np.asarray(b, float).ravel() for b in mesh.cell_data[key]])
            out["vm_xyz"] = cents
    return out if (out["u"] is not None or out["vm"] is not None) else None


_UNREAD = object()


def global_metrics(origin, method: str | None = None, vtu_fields=_UNREAD) -> dict:
    """{'max_von_mises_pa', 'max_displacement_m', 'from'} found beside ``origin``; {} when none.

    ``vtu_fields``: :func:`fields` of the folder when already read (result.vtu is then not read again).
    """
    folder = _folder(origin)
    if folder is None:
        return {}
    out, used = {}, []
    summary = folder / "summary.json"
    if summary.is_file():
        try:
            leaves = list(_leaves(json.loads(summary.read_text())))
        except (OSError, ValueError, RecursionError):
            leaves = []
        vm, u = _pick(leaves, _MISES, method), _pick(leaves, _DISP, method)
        if vm is not None:
            out["max_von_mises_pa"] = vm
        if u is not None:
            out["max_displacement_m"] = u
        if out:
            used.append("summary.json")
    if "max_von_mises_pa" not in out or "max_displacement_m" not in out:
        extra = field_maxima(fields(folder) if vtu_fields is _UNREAD else vtu_fields)
        extra = {k: v for k, v in extra.items() if k not in out}
        if extra:
            out.update(extra)
            used.append("result.vtu")
    if out:
        out["from"] = " + ".join(used)
    return out


def field_maxima(f: dict | None) -> dict:
    """{'max_von_mises_pa', 'max_displacement_m'} of :func:`fields` (each when the field is there)."""
    out = {}
    if f is not None and f["vm"] is not None:
        out["max_von_mises_pa"] = float(np.nanmax(np.abs(f["vm"])))
    if f is not None and f["u"] is not None:
        out["max_displacement_m"] = float(np.nanmax(np.linalg.norm(f["u"], axis=1)))
    return out


def solution_globals(result_vtu_mesh, method: str) -> dict:
    """{'globals': {method: figures}, 'fields': fields} of a solution in memory: the meshio mesh that is its
    result.vtu (:func:`deckbridge.solve.result_mesh`; None without fields), the job's own outputs not read back."""
    f = None if result_vtu_mesh is None else fields_of_mesh(result_vtu_mesh)
    g = field_maxima(f)
    return {"globals": {method: {**g, "from": "result.vtu"} if g else {}}, "fields": f}
