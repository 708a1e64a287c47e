"""Reader of Abaqus/Standard ``.dat`` contact print tables (``*CONTACT PRINT``: CPRESS, COPEN, ...).

Layout read (one table per contact pair and printed increment)::

                                   INCREMENT     3 SUMMARY
     TIME INCREMENT COMPLETED  0.100    ,  FRACTION OF STEP COMPLETED  0.300
     ...
                                   C O N T A C T   O U T P U T
      CONTACT OUTPUT FOR SLAVE SURFACE  ASSEMBLY_BASE   AND MASTER SURFACE  ASSEMBLY_TABLE

        NODE   FOOT-  CPRESS       CSHEAR1      COPEN        CSLIP1
               NOTE
           1          5.6250E+06   0.000       -2.6786E-06   0.000

The step comes from the ``S T E P   n`` heading (or a ``STEP n INCREMENT m`` page header), the
increment from ``INCREMENT n SUMMARY``. Step 1 (N) has load factor 0; step 2 ramps T and M, so its
load factor is lambda_max * (fraction of step completed). CPRESS is compression-positive and is
flipped (sigma_n = -CPRESS); COPEN > 0 is open. Node labels (``INSTANCE.label`` too) map to azimuth
through the neutral model (the embedded default when none is given). Surface: 'stop' when the
pair's surface names mention STOP, 'table' when they mention TABLE, else from the model's slave sets.
Units: CPRESS and COPEN are divided back to SI by the units of the deck beside the ``.dat`` (its
``** deckbridge-units:`` line), else the model's (``units: mm`` decks are in N, mm, MPa). Method: 'augmented'
when the deck beside is deckbridge's augmented-Lagrange deck (its header line :data:`AUGMENTED_HEADER`), else
'lagrange'.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd

from . import RECORD
from ...errors import DeckbridgeError
from ...errors import read_text
from ...methods import AUGMENTED, LAGRANGE
from ...readers._files import inp_deck_units
from ...results import with_forces
from ...units import scale
from ...readers._checks import checked
from ...readers._nodemap import locate, slave_areas, surface_of

_NUM = r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[EeDd][-+]?\d+)?"
_NUM_RE = re.compile(rf"^{_NUM}$")
_LABEL_RE = re.compile(r"^(?:[A-Za-z0-9_-]+\.)?(\d+)$")
_STEP_HEAD = re.compile(r"S T E P\s+(\d+)")      # S T E P   2   S T A T I C   A N A L Y S I S
_STEP_PAGE = re.compile(r"^\s*STEP\s+(\d+)\s+INCREMENT\s+(\d+)")
_INC = re.compile(r"INCREMENT\s+(\d+)\s+SUMMARY")
_FRACTION = re.compile(rf"FRACTION OF STEP COMPLETED\s+({_NUM})")
_PAIR = re.compile(r"SLAVE\s+SURFACE\s+(\S+).*?MASTER\s+SURFACE\s+(\S+)", re.IGNORECASE)
_CONTACT_VARS = {"CPRESS", "COPEN", "CSHEAR1", "CSHEAR2", "CSLIP1", "CSLIP2", "CNORMF", "CAREA", "CSTATUS"}
_TEXT_VARS = {"CSTATUS"}
_OPEN_WORDS = {"OP", "OPEN"}
_CLOSED_WORDS = {"CL", "CLOSED", "ST", "STICK", "SL", "SLIP", "SLIPPING", "STICKING"}
_DETECT_BYTES = 64 << 20
AUGMENTED_HEADER = "** deckbridge Abaqus/Standard deck: augmented Lagrange contact"


def detect(path: Path) -> bool:
    """A .dat file written by Abaqus (its banner) or holding a contact output table."""
    if not path.is_file() or path.suffix.lower() != ".dat":
        return False
    try:
        with open(path, "r", errors="replace") as fh:
            head = fh.read(8192)
            if "Abaqus" in head or "ABAQUS" in head:
                return True
            seen = len(head)
            text = head
            while seen < _DETECT_BYTES:
                if "CONTACT OUTPUT FOR" in text or "C O N T A C T   O U T P U T" in text:
                    return True
                chunk = fh.read(1 << 20)
                if not chunk:
                    return False
                text = text[-200:] + chunk
                seen += len(chunk)
    except OSError:
        return False
    return False


def deck_method(path: Path) -> str:
    """'augmented' when the ``.inp`` beside ``path`` starts (first 40 lines) with :data:`AUGMENTED_HEADER`, else
    'lagrange' (deckbridge's Lagrange deck, or no deck)."""
    inp = Path(path).with_suffix(".inp")
    if inp.is_file():
        with open(inp, errors="replace") as fh:
            for _, line in zip(range(40), fh):
                if line.startswith(AUGMENTED_HEADER):
                    return AUGMENTED
    return LAGRANGE


def _float(tok: str) -> float:
    return float(tok.replace("D", "E").replace("d", "e"))


def parse(text: str, path) -> pd.DataFrame:
    """Raw rows of every contact table: step, increment, fraction, slave, master, node, variables, status,
    line (the row's line number in the file)."""
    rows: list[dict] = []
    step, inc, frac = 1, 0, 1.0
    pair: tuple[str, str] | None = None
    cols: list[str] | None = None
    for lineno, line in enumerate(text.splitlines(), 1):
        s = line.strip()
        if not s:
            continue
        m = _STEP_HEAD.search(line)
        if m:
            new = int(m.group(1))
            if new != step:
                step, inc, frac, pair = new, 0, 0.0, None
            cols = None
            continue
        m = _STEP_PAGE.match(line)
        if m:
            step = int(m.group(1))
            continue
        m = _INC.search(line)
        if m:
            inc, pair, cols = int(m.group(1)), None, None
            continue
        m = _FRACTION.search(line)
        if m:
            frac = _float(m.group(1))
            continue
        m = _PAIR.search(line)
        if m:
            pair, cols = (m.group(1).upper(), m.group(2).upper()), None
            continue
        toks = s.split()
        if toks[0] == "NODE" and any(t.startswith("FOOT") for t in toks):
            names = [t.upper() for t in toks[1:] if not t.upper().startswith("FOOT")]
            cols = names if (set(names) & _CONTACT_VARS) and "CPRESS" in names else None
            if cols is not None and pair is None:
                pair = ("", "")
            continue
        if cols is None:
            continue
        if toks == ["NOTE"]:
            continue
        lab = _LABEL_RE.match(toks[0])
        if not lab:
            cols = None       # MAXIMUM / MINIMUM lines or any text: the table ended
            continue
        nums = [t for t in toks[1:] if _NUM_RE.match(t)]
        words = [t.upper() for t in toks[1:] if not _NUM_RE.match(t)]
        numeric_cols = [c for c in cols if c not in _TEXT_VARS]
        if len(nums) != len(numeric_cols):
            raise DeckbridgeError(f"{str(path)!r}: line {lineno}: {len(nums)} values under "
                                  f"{len(numeric_cols)} columns ({' '.join(numeric_cols)})")
        row = {"step": step, "increment": inc, "fraction": frac, "slave": pair[0], "master": pair[1],
               "node": int(lab.group(1)), "line": lineno,
               "status_word": next((w for w in words if w in _OPEN_WORDS | _CLOSED_WORDS), "")}
        row.update({c: _float(v) for c, v in zip(numeric_cols, nums)})
        rows.append(row)
    return pd.DataFrame(rows)


def _surface(raw: pd.DataFrame, located: pd.DataFrame) -> np.ndarray:
    names = (raw["slave"] + " " + raw["master"]).str.upper().to_numpy()
    by_model = surface_of(located)
    hint = np.where([("STOP" in n) for n in names], "stop",
                    np.where([("TABLE" in n) for n in names], "table", ""))
    return np.where(hint == "", by_model, hint)


@checked(None)
def read(path: Path, model=None, mesh=None) -> pd.DataFrame:
    """Read the contact print tables of an Abaqus .dat file into the tidy table (``mesh``: ``model``'s, when built)."""
    from ...mesh import build_mesh
    from ...model import load

    path = Path(path)
    raw = parse(read_text(path), path)
    if raw.empty:
        raise DeckbridgeError(f"{str(path)!r}: no contact data (no CONTACT OUTPUT table with CPRESS)")
    bad = sorted(set(raw["step"]) - {1, 2})
    if bad:
        raise DeckbridgeError(f"{str(path)!r}: step {bad[0]} is not in the load path (1 = N, 2 = N + lambda (T, M))")
    if model is None:
        model, mesh = load(None), None
    mesh = mesh if mesh is not None else build_mesh(model)
    located = locate(raw["node"].to_numpy(), model, path, mesh=mesh)
    u = scale(inp_deck_units(path, model))
    cpress = raw["CPRESS"].to_numpy(float) / u.stress
    copen = (raw["COPEN"].to_numpy(float) / u.length) if "COPEN" in raw else np.full(len(raw), np.nan)
    word = raw["status_word"].to_numpy()
    is_open = np.where(word != "", np.isin(word, list(_OPEN_WORDS)),
                       np.where(np.isnan(copen), cpress <= 0.0, (copen > 0.0) & (cpress <= 0.0)))
    lam = np.where(raw["step"].to_numpy() == 1, 0.0, model.steps.lambda_max * raw["fraction"].to_numpy(float))
    surface = _surface(raw, located)
    return with_forces(pd.DataFrame({
        "source": RECORD.source, "method": deck_method(path),
        "step": raw["step"].to_numpy(), "increment": raw["increment"].to_numpy(),
        "load_factor": lam, "node": raw["node"].to_numpy(),
        "surface": surface,
        "theta_deg": located["theta_deg"].to_numpy(), "z": located["z"].to_numpy(), "r": located["r"].to_numpy(),
        "sigma_n_pa": -cpress, "gap_m": copen,
        "status": np.where(is_open, "open", "closed"),
        "origin": [f"{str(path)!r}: line {n}" for n in raw["line"]],      # for the contact-law check
    }), slave_areas(model, raw["node"].to_numpy(), surface, mesh))    # CPRESS x the mesh's tributary area
