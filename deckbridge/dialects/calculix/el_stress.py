"""CalculiX 2.20 element stresses (``*EL PRINT, ELSET=<set>`` with ``S``) from a ``.dat`` file.

Layout written by ccx 2.20 (checked on real runs), one block per print request and time point::

    <blank>
     stresses (elem, integ.pnt.,sxx,syy,szz,sxy,sxz,syz) for set EBASE and time  0.1500000E+01
    <blank>
             1   1 -1.454338E+04 -1.915426E+05 -2.589921E+06  3.799410E+04 -3.116772E+04  2.112074E+05
             1   2 ...

Rows: element id, integration point (1..8 for C3D8/C3D8I, xi fastest, then eta, then zeta: the order of
:data:`reference_solver.stress.GAUSS`), then sxx, syy, szz, sxy, sxz, syz [Pa, model units] in the global
frame, tension > 0 (ccx's shear order xy, xz, yz: not the reference solver's xy, yz, zx). The time is
ccx's total time (deckbridge decks: step 1 ends at t = 1, step 2 at t = 1 + (lambda / lambda_max)).
The set name is upper case. Values such as ``1.234567-100`` (three-digit exponent without ``E``) are read.

Not a result format (the ``calculix`` reader returns the contact table): :func:`read_el_stress`
gives the raw table, :func:`base_wall_table` the wall's axial stress at the base (inner, outer, membrane,
bending) per time and azimuth, by the same Gauss-to-corner extrapolation and nodal averaging as the reference
solver (:mod:`reference_solver.stress`), and :func:`read_base_wall` does both for a deckbridge ccx job (the
``EBASE`` set every deckbridge inp deck prints), in SI, with step and load factor. Never ccx's ``.frd`` nodal
stresses: at nodes a GAPUNI touches, ccx averages them with the gap's zeros.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pandas as pd

from reference_solver.stress import extrapolate_to_corners, nodal_average

from ...errors import DeckbridgeError
from ...azimuth import snap_deg
from ...base_wall import CCX_TO_VOIGT, base_wall
from ...mesh_data import base_wall_areas
from ...numbering.skirt import bottom_row_index, elem_ids
from ...readers._files import inp_deck_units
from ...wall_stress import AREA, WALL_COLUMNS

COLUMNS = ["sxx", "syy", "szz", "sxy", "sxz", "syz"]     # ccx order, [Pa]
N_IP = 8
_HEAD = re.compile(r"^\s*stresses \(elem, integ\.pnt\.,sxx,syy,szz,sxy,sxz,syz\) for set (\S+) and time\s+(\S+)\s*$")
_OTHER_HEAD = re.compile(r"^\s*\S.* for set \S+ and time\s+\S+\s*$")
_FORTRAN_EXP = re.compile(r"(\d)([+-]\d{3})$")


def _num(tok: str) -> float:
    return float(_FORTRAN_EXP.sub(r"\1E\2", tok))


def read_el_stress(path: str | Path) -> pd.DataFrame:
    """Every stress block of a ccx ``.dat``: columns time, set, element, ip, sxx..syz [Pa] (ccx order).

    Raise :class:`DeckbridgeError` (one line naming the file and the line) on a non-finite value, a
    row that is not (int, int, 6 numbers), an element without its 8 integration points in order, a
    header without rows, or no stress block at all.
    """
    path = Path(path)
    try:
        lines = path.read_text(errors="replace").splitlines()
    except OSError as exc:
        raise DeckbridgeError(f"{str(path)!r}: cannot read ({exc.strerror})") from None
    recs: list[tuple] = []
    elems_of_set: dict[str, list[int]] = {}
    k = 0
    while k < len(lines):
        m = _HEAD.match(lines[k])
        if not m:
            k += 1
            continue
        head_no, name, time = k + 1, m.group(1).upper(), _num(m.group(2))
        k += 1
        while k < len(lines) and not lines[k].strip():
            k += 1
        rows = []
        while k < len(lines) and lines[k].strip() and not _OTHER_HEAD.match(lines[k]):
            rows.append(_row(path, k + 1, lines[k]))
            k += 1
        if not rows:
            raise DeckbridgeError(f"{path}: line {head_no}: stress block for set {name} at time {time:g} has no rows")
        _check_points(path, rows, trailing=k >= len(lines))
        elems = [r[0] for r in rows[::N_IP]]
        if elems_of_set.setdefault(name, elems) != elems:
            raise DeckbridgeError(f"{path}: line {head_no}: set {name} at time {time:g} lists other elements "
                                  f"({len(elems)}) than its first block ({len(elems_of_set[name])}): truncated?")
        recs += [(time, name, e, ip, *v) for e, ip, v, _ in rows]
    if not recs:
        raise DeckbridgeError(f"{path}: no '*EL PRINT' stress block (stresses (elem, integ.pnt., ...))")
    return pd.DataFrame(recs, columns=["time", "set", "element", "ip", *COLUMNS])


def _row(path: Path, line_no: int, line: str) -> tuple:
    tok = line.split()
    try:
        if len(tok) != 8:
            raise ValueError
        e, ip = int(tok[0]), int(tok[1])
        vals = [_num(t) for t in tok[2:]]
    except ValueError:
        raise DeckbridgeError(f"{path}: line {line_no}: expected 'element, point, 6 stresses', "
                              f"got {line.strip()[:80]!r}") from None
    if not all(math.isfinite(v) for v in vals):
        raise DeckbridgeError(f"{path}: line {line_no}: non-finite stress in {line.strip()[:80]!r}")
    return e, ip, vals, line_no


def _check_points(path: Path, rows: list, trailing: bool) -> None:
    """Each element lists integration points 1..8 in order; a short last element is a truncated file."""
    for s in range(0, len(rows), N_IP):
        chunk = rows[s:s + N_IP]
        e = chunk[0][0]
        if [r[1] for r in chunk] != list(range(1, N_IP + 1)) or any(r[0] != e for r in chunk):
            bad = next((r for r, want in zip(chunk, range(1, N_IP + 1)) if r[0] != e or r[1] != want), chunk[-1])
            what = "truncated" if trailing and s + N_IP > len(rows) else "integration points out of order"
            raise DeckbridgeError(f"{path}: line {bad[3]}: element {e}: {what} "
                                  f"(expected points 1..{N_IP} of each element)")


def corner_values(block: pd.DataFrame, element_ids: np.ndarray) -> np.ndarray:
    """Stresses (ne, 8, 6) [Pa] extrapolated to the corners of ``element_ids``, reference Voigt order
    (xx, yy, zz, xy, yz, zx), from one time's rows of :func:`read_el_stress` (estimate)."""
    b = block.drop_duplicates(["element", "ip"]).set_index(["element", "ip"]).sort_index()
    want = pd.MultiIndex.from_product([np.asarray(element_ids, np.int64), np.arange(1, N_IP + 1)])
    missing = want.difference(b.index)
    if len(missing):
        raise DeckbridgeError(f"element {missing[0][0]}: no stress at integration point {missing[0][1]} "
                              "(the *EL PRINT set must hold the whole bottom element row)")
    g = b.loc[want, COLUMNS].to_numpy().reshape(len(element_ids), N_IP, 6)[:, :, CCX_TO_VOIGT]
    return extrapolate_to_corners(g)


def base_wall_table(stress: pd.DataFrame, mesh) -> pd.DataFrame:
    """Axial stress across the wall at the base per time and azimuth from :func:`read_el_stress` rows.

    ``mesh``: the :class:`deckbridge.mesh.SkirtMesh` of the deck (element id = hex index + 1; the bottom
    row is the first n_r * n_theta hexes). Corner stresses of the bottom row are averaged over the row's
    elements sharing a node, then reduced across the wall by :func:`deckbridge.base_wall.base_wall`:
    columns time, theta_deg, szz_inner_pa, szz_outer_pa, szz_mean_pa (trapezoid over the node radii
    / thickness), szz_bending_pa ((outer - inner) / 2), tension > 0, area_m2 the azimuth's base area
    (:func:`deckbridge.mesh_data.base_wall_areas`). Values are Gauss-point
    extrapolations (estimates).
    """
    bottom = bottom_row_index(mesh)   # imported mesh: the hexahedra standing on the base plane, user ids
    out = []
    for time, block in stress.groupby("time", sort=True):
        avg, _ = nodal_average(corner_values(block, elem_ids(mesh, bottom)), mesh.hexes[bottom], mesh.n_nodes)
        bw = base_wall(mesh.nodes, mesh.hexes[bottom], avg[:, 2], "z")
        out.append(pd.DataFrame({"time": time, "theta_deg": bw.theta_deg, "szz_inner_pa": bw.inner,
                                 "szz_outer_pa": bw.outer, "szz_mean_pa": bw.mean,
                                 "szz_bending_pa": bw.bending,
                                 "area_m2": base_wall_areas(mesh.nodes, mesh.hexes[bottom], bw.nodes)}))
    return pd.concat(out, ignore_index=True)


def read_base_wall(path: str | Path, model, mesh=None) -> pd.DataFrame:
    """Base wall stresses of the deckbridge ccx job at ``path`` (its ``.dat``, ``.inp`` or stem) of ``model``.

    Columns: step, load_factor (0 in step 1; lambda_max x step time in step 2), time, theta_deg,
    szz_inner_pa, szz_outer_pa, szz_mean_pa, szz_bending_pa [Pa, SI whatever the deck units], tension > 0.
    """
    from ...mesh import build_mesh
    from ...units import scale

    dat = Path(path).with_suffix(".dat")
    stress = read_el_stress(dat)
    stress = stress[stress["set"] == "EBASE"]
    if stress.empty:
        raise DeckbridgeError(f"{dat}: no '*EL PRINT, ELSET=EBASE' stress block")
    stress = stress.copy()
    stress[COLUMNS] = stress[COLUMNS] / scale(inp_deck_units(dat, model)).stress
    table = base_wall_table(stress, mesh if mesh is not None else build_mesh(model))
    step = np.where(table["time"] <= 1.0 + 1e-9, 1, 2)
    table.insert(0, "load_factor", np.where(step == 1, 0.0, model.steps.lambda_max * (table["time"] - 1.0)))
    table.insert(0, "step", step)
    return table


def ccx_wall(result: str | Path, model, mesh=None) -> pd.DataFrame | None:
    """The dialect record's wall reader: wall table (:mod:`deckbridge.wall_stress` columns, SI whatever the deck's
    units) of the ccx job whose result file is ``result``, from its ``.dat`` *EL PRINT S blocks
    (:func:`read_base_wall`); None when the job printed none, for a folder of jobs, without a ``.dat``, or for
    a mesh of 10-, 15- or 20-node cells (their integration points are not read yet)."""
    p = Path(str(result))
    dat = p.with_suffix(".dat")
    if p.is_dir() or not dat.is_file():
        return None
    if model is not None:
        from ...mesh import build_mesh
        mesh = mesh if mesh is not None else build_mesh(model)
        if mesh.hexes.shape[1] != N_IP or mesh.blocks:   # 10-/15-/20-node cells, mixed: not read yet
            return None
    try:
        t = read_base_wall(dat, model, mesh=mesh)
    except DeckbridgeError as exc:
        if "no '*EL PRINT" in str(exc) or "cannot read" in str(exc):
            return None
        raise
    inc = pd.Series(t["time"]).groupby(t["step"].to_numpy()).rank(method="dense").to_numpy(np.int64)
    t = t.assign(increment=inc, theta_deg=snap_deg(t["theta_deg"]))
    return t[WALL_COLUMNS + [c for c in (AREA,) if c in t]]
