"""MYSTRAN F06 of the linear deck (``<name>_mystran.bdf``) -> the tidy contact table.

Reads the "ELEMENT ENGINEERING FORCES FOR ELEMENT TYPE ELAS2" blocks (element id, force pairs).
Every gap of the penalty deck is a CELAS2 there, with the same element id, from the base node's
DOF (cylindrical z for the table, radial for the stop) to a grounded node.

Sign: MYSTRAN 18 prints the ELAS2 force as k (u2 - u1), which for a spring from the skirt node
(G1) to a grounded node (G2) is the spring's force *on the skirt node* along G1's DOF (it equals
the SPC force at the grounded node; checked in tests/test_mystran.py against beam theory and
the vertical force balance). The contact pressure is then
sigma_n = -(force . master normal) / area = -dof_sign * F / area  (< 0 compression).
gap_m is the node's displacement along the master normal, -(force . normal) / k (< 0 when
pressed in), when the model gives k; else NaN. Every spring is a closed contact: status =
closed. Rows: source mystran, method linear, step 2, increment 1, load_factor = lambda_max
(NaN without the model).

Without ``model`` the element -> node map comes from the deck beside the F06 (same stem), with
area = 1 m^2 (sigma_n_pa then holds a force in N); see :mod:`.nastran_op2`. Forces are converted
to SI by the deck's units line, else ``model.units`` (:func:`.nastran_op2.result_units`).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd

from . import RECORD
from ...errors import DeckbridgeError
from ...mesh import build_mesh
from ...model import Model
from ...numbering.nastran import gap_layout
from ...errors import read_text
from ...results import with_forces
from ..nastran.reader import contact_map, result_units
from ...readers._checks import checked

_HEADER = re.compile(r"F O R\s+E L E M E N T\s+T Y P E\s+E L A S 2\b")
_SUBCASE = re.compile(r"OUTPUT FOR SUBCASE\s+(\d+)")
_PAIR = re.compile(r"(\d+)\s+([-+]?\d*\.?\d+(?:[EeDd][-+]?\d+)?)")
_ROW = re.compile(r"^\s*(\d+\s+[-+]?\d*\.?\d+(?:[EeDd][-+]?\d+)?\s*)+$")


def read_spring_forces(path: str | Path) -> pd.DataFrame:
    """ELAS2 element forces of a MYSTRAN F06: columns subcase, element, force_n (as printed)."""
    path = Path(path)
    lines = read_text(path).splitlines()
    rows: list[tuple[int, int, float]] = []
    subcase, i = 1, 0
    while i < len(lines):
        m = _SUBCASE.search(lines[i])
        if m:
            subcase = int(m.group(1))
        if _HEADER.search(lines[i]):
            i += 1
            while i < len(lines) and not _ROW.match(lines[i]):   # column titles
                if lines[i].strip().startswith("---"):
                    break
                i += 1
            while i < len(lines) and _ROW.match(lines[i]):
                rows += [(subcase, int(e), float(f.replace("D", "E").replace("d", "e")))
                         for e, f in _PAIR.findall(lines[i])]
                i += 1
            continue
        i += 1
    if not rows:
        raise DeckbridgeError(f"{str(path)!r}: no ELAS2 element forces in the F06 (ELFORCE = ALL requested?)")
    return pd.DataFrame(rows, columns=["subcase", "element", "force_n"])


def detect(path: Path) -> bool:
    if not (path.is_file() and path.suffix.lower() == ".f06"):
        return False
    with path.open(errors="replace") as fh:
        return "MYSTRAN" in fh.read(4096)


@checked(None, unknown_load_factor=True)
def read(path: str | Path, model: Model | None = None, mesh=None) -> pd.DataFrame:
    """Tidy table of the contact springs of a MYSTRAN linear run; ``mesh``: the model's, when built."""
    path = Path(path)
    raw = read_spring_forces(path)
    raw["force_n"] = raw["force_n"] / result_units(path, model).force
    if model is not None and mesh is None:
        mesh = build_mesh(model)
    cmap = contact_map(path, model, mesh)
    raw = raw[raw["element"].isin(cmap.index)]
    if raw.empty:
        raise DeckbridgeError(f"{str(path)!r}: no contact spring forces (element ids of another model?)")
    m = cmap.loc[raw["element"].to_numpy()]
    force_on_normal = m["dof_sign"].to_numpy() * raw["force_n"].to_numpy()   # > 0 pushes the skirt off the master
    if model is not None:
        lay = gap_layout(mesh)
        k = pd.Series(lay.k, index=lay.eid).loc[raw["element"].to_numpy()].to_numpy()
        gap = -force_on_normal / k
        lam = model.steps.lambda_max
    else:
        gap = np.full(len(raw), np.nan)
        lam = np.nan
    return with_forces(pd.DataFrame({
        "source": RECORD.source, "method": "linear", "step": 2, "increment": 1, "load_factor": lam,
        "node": m["node"].to_numpy(np.int64), "surface": m["surface"].to_numpy(),
        "theta_deg": m["theta_deg"].to_numpy(), "z": m["z"].to_numpy(), "r": m["r"].to_numpy(),
        "sigma_n_pa": -force_on_normal / m["area"].to_numpy(), "gap_m": gap, "status": "closed",
    }), m["area"].to_numpy(float))
