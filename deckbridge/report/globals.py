"""Global-level results of a source, where it has them: max von Mises [Pa], max displacement [m].

Read from a reference output folder: summary.json first (numeric entries whose key names von Mises
or displacement, preferring those under the source's method), result.vtu (meshio) for what the
summary lacks. In result.vtu, fields named per step (``displacement_step2_m``,
``von_mises_step2_pa``) are taken at the last step, i.e. at the end of the load path (lambda_max).
Other sources have none: the report says so.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np

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
    if mesh is None:
        return None
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


def global_metrics(origin, method: str | None = None) -> dict:
    """{'max_von_mises_pa', 'max_displacement_m', 'from'} found beside ``origin``; {} when none."""
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
        f = fields(folder)
        extra = {}
        if f is not None and f["vm"] is not None and "max_von_mises_pa" not in out:
            extra["max_von_mises_pa"] = float(np.nanmax(np.abs(f["vm"])))
        if f is not None and f["u"] is not None and "max_displacement_m" not in out:
            extra["max_displacement_m"] = float(np.nanmax(np.linalg.norm(f["u"], axis=1)))
        if extra:
            out.update(extra)
            used.append("result.vtu")
    if out:
        out["from"] = " + ".join(used)
    return out
