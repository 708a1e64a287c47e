"""Nastran OP2 gap results (CGAP) -> the tidy contact table.

Tables read with pyNastran: gap forces ``OEF1X`` (element type 38, ``op2_results.force.cgap_force``,
columns fx, sfy, sfz, u, v, w, sv, sw) and, when no force table is present, nonlinear gap stresses
``OESNLXR`` (element type 86, ``nonlinear_cgap_stress``, columns compX, ..., axialU, ...). Result keys
are ints or superelement tuples whose first item is the subcase.

Sign conventions (MSC Nastran): fx / compX > 0 is compression; u / axialU is the gap's closure
displacement (uA - uB).x along GA->GB, so the gap is closed when u > U0 and the opening is
``U0 - u`` (U0 from the PGAP). Checked on the MSC examples: gap 101 of v10601s closed with
u = 1.1494e-4 and fx = 33333.33 = u * KA; gap 102 open with u = -0.5443; cc188b's preloaded gap
(F0 = 3.6e5) carries a force while open (u = 0.1889 < U0 = 0.2062).

In the tidy table sigma_n_pa = -force / tributary area of the gap's slave node (< 0 compression),
gap_m = U0 - u (> 0 open), status = closed when gap_m <= 0. Element ids map to slave nodes:

- with ``model`` (a deck written by deckbridge): through :func:`deckbridge.numbering.nastran.gap_layout`,
  areas and U0 from the mesh, load_factor = lambda_max times the fraction of subcase 2 done;
- without it: through the deck with the same stem beside the OP2 (.bdf/.dat/.nas): GA grid,
  its basic position (CP = 0 only, else NaN), U0 from the PGAP, surface 'stop' when the GA->GB
  axis is horizontal else 'table'; the **area is taken as 1 m^2, so sigma_n_pa holds the force in
  N**; load_factor is the fraction of the subcase's load (lambda_max unknown, taken as 1).

Units: a deckbridge deck states its units in a header line ``$ deckbridge-units: SI|mm``
(:mod:`deckbridge.units`). Results are converted back to SI (lengths /1e3, forces x1 for ``mm``)
by the units of the deck beside the results when it has that line, else by ``model.units`` when
a model is given, else SI (a foreign deck is taken as consistent SI).

SOL 106 load steps: subcase n is taken to run either over (0, 1] or cumulatively over
(n - 1, n]; both are mapped to the fraction done within the subcase.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd

from . import RECORD
from ...errors import DeckbridgeError
from ...methods import PENALTY
from ...azimuth import azimuth_deg
from ...mesh import build_mesh
from ...model import Model
from ...numbering.nastran import gap_layout
from ...units import Units, scale
from ...results import with_forces
from ...readers._checks import checked

_UNITS_LINE = re.compile(r"^\$\s*deckbridge-units:\s*(SI|mm)\s*$")

GAP_FORCE_COLUMNS = ["element", "subcase", "increment", "time", "table", "force_n", "axial_u_m",
                     "u0_m", "opening_m", "status"]


def _subcase(key) -> int:
    return int(key[0]) if isinstance(key, tuple) else int(key)


def _load_op2(path: Path):
    try:
        from pyNastran.op2.op2 import read_op2
        return read_op2(str(path), debug=None, log=None, mode=None)
    except FileNotFoundError:
        raise DeckbridgeError(f"{str(path)!r}: no such file") from None
    except Exception as exc:  # pyNastran raises many kinds on foreign or broken files
        raise DeckbridgeError(f"{str(path)!r}: not a readable OP2 ({type(exc).__name__}: "
                              f"{' '.join(str(exc).split())[:120]})") from None


def _frames(results: dict, table: str, force_col: int, u_col: int) -> list[pd.DataFrame]:
    out = []
    for key, res in results.items():
        times = np.asarray(res._times, float).reshape(-1)
        data = np.asarray(res.data)
        for it in range(data.shape[0]):
            out.append(pd.DataFrame({
                "element": np.asarray(res.element, np.int64), "subcase": _subcase(key),
                "increment": it + 1, "time": times[it] if it < times.size else np.nan, "table": table,
                "force_n": data[it, :, force_col].astype(float), "axial_u_m": data[it, :, u_col].astype(float),
            }))
    return out


def deck_units(deck: Path | None) -> str | None:
    """Units named by a deckbridge deck's header line ``$ deckbridge-units: SI|mm``; None without one."""
    if deck is None:
        return None
    try:
        with Path(deck).open(errors="replace") as fh:
            head = [fh.readline() for _ in range(20)]
    except OSError:
        return None
    for line in head:
        m = _UNITS_LINE.match(line)
        if m:
            return m.group(1)
    return None


def result_units(path: Path, model: Model | None) -> Units:
    """Units of the results at ``path``: the deck beside it, else ``model.units``, else SI."""
    name = deck_units(sibling_deck(path)) or (model.units if model is not None else "SI")
    return scale(name)


def read_gap_forces(path: str | Path, u0: float | dict | None = None, units: Units | None = None) -> pd.DataFrame:
    """Raw gap results of an OP2, one row per (table, subcase, increment, element).

    Columns: element, subcase, increment (1-based within the subcase), time (load step as
    stored), table (OEF1X or OESNLXR), force_n (> 0 compression, as in Nastran), axial_u_m
    (closure u), u0_m, opening_m = U0 - u, status (closed when opening_m <= 0). ``u0`` is a
    scalar or {element: U0}; by default the PGAP U0 of the deck beside the OP2 when it can be
    read, else 0 (so opening_m = -u). Forces and displacements are converted to SI by ``units``
    (default: :func:`result_units` without a model); a given ``u0`` is in metres.
    """
    path = Path(path)
    units = units or result_units(path, None)
    op2 = _load_op2(path)
    frames = _frames(op2.op2_results.force.cgap_force, "OEF1X", 0, 3)
    frames += _frames(op2.nonlinear_cgap_stress, "OESNLXR", 0, 3)
    if not frames:
        raise DeckbridgeError(f"{str(path)!r}: no gap results (OEF1X type 38 or OESNLXR type 86) in the OP2")
    df = pd.concat(frames, ignore_index=True)
    df["force_n"] = df["force_n"].to_numpy(float) / units.force
    df["axial_u_m"] = df["axial_u_m"].to_numpy(float) / units.length
    if u0 is None:
        u0 = _deck_u0(path)
    if isinstance(u0, dict):
        df["u0_m"] = df["element"].map(u0).fillna(0.0).to_numpy(float)
    else:
        df["u0_m"] = float(u0)
    df["opening_m"] = df["u0_m"].to_numpy() - df["axial_u_m"].to_numpy()
    df["status"] = np.where(df["opening_m"] <= 0.0, "closed", "open")
    return df[GAP_FORCE_COLUMNS]


# --- element id -> slave node ---------------------------------------------------------------------
def model_contact_map(model: Model, mesh=None) -> pd.DataFrame:
    """Contact elements of deckbridge decks of ``model``, index = element id.

    Columns node, surface, theta_deg, r, z, area, u0, dof_sign (master normal . the spring's
    DOF direction: +1 for table springs on z and an inner stop's springs on +r, -1 for an outer
    stop), f0 (PGAP preload [N], > 0 compression: 0 in deckbridge decks). ``mesh``: the model's, when built.
    """
    mesh = mesh if mesh is not None else build_mesh(model)
    lay = gap_layout(mesh)
    t = np.radians(lay.theta_deg)
    radial = np.stack([np.cos(t), np.sin(t), np.zeros_like(t)], axis=1)
    normal = -lay.axis
    dof = np.where((lay.surface == "table")[:, None], np.array([0.0, 0.0, 1.0]), radial)
    return pd.DataFrame({
        "node": lay.node, "surface": lay.surface.astype(str), "theta_deg": lay.theta_deg, "r": lay.r,
        "z": lay.z, "area": lay.area, "u0": lay.u0, "dof_sign": np.sign(np.sum(normal * dof, axis=1)),
        "f0": 0.0,
    }, index=pd.Index(lay.eid, name="element"))


def sibling_deck(path: Path) -> Path | None:
    """The deck beside a result file: same stem, suffix .bdf/.dat/.nas (any case)."""
    for p in sorted(path.parent.glob(f"{path.stem}.*")):
        if p.suffix.lower() in (".bdf", ".dat", ".nas") and p.is_file():
            return p
    return None


def deck_contact_map(deck: Path) -> pd.DataFrame:
    """Contact elements read from a deck (CGAP, or CELAS2 on components 1/3 of the linear deck).

    Same columns as :func:`model_contact_map` with area = 1 (so sigma_n is a force [N]); lengths
    converted to metres by the deck's units line (SI without one).
    """
    units = scale(deck_units(deck) or "SI")
    unit_length = units.length   # deck length per metre
    try:
        from pyNastran.bdf.bdf import read_bdf
        bdf = read_bdf(str(deck), xref=False, debug=None, validate=False)
    except Exception as exc:
        raise DeckbridgeError(f"{str(deck)!r}: deck not readable to map gap elements to nodes "
                              f"({type(exc).__name__}); pass the model instead") from None

    def xyz(nid):
        node = bdf.nodes.get(nid) if nid else None
        if node is None or node.cp not in (0, None):
            return np.full(3, np.nan)
        return np.asarray(node.xyz, float)

    rows = {}
    for eid, el in bdf.elements.items():
        if el.type == "CGAP":
            a, b = xyz(el.ga), xyz(el.gb)
            prop = bdf.properties.get(el.pid)
            u0 = float(prop.u0) / unit_length if prop is not None and prop.u0 is not None else 0.0
            f0 = float(getattr(prop, "f0", 0.0) or 0.0) / units.force if prop is not None else 0.0
            comp = None
        elif el.type == "CELAS2" and el.c1 in (1, 3) and el.nodes[0]:
            a, b = xyz(el.nodes[0]), xyz(el.nodes[1])
            u0, f0, comp = 0.0, 0.0, el.c1
        else:
            continue
        axis = b - a
        length = np.linalg.norm(axis)
        horizontal = np.isfinite(length) and length > 0 and abs(axis[2]) < 0.5 * length
        surface = "stop" if (comp == 1 or (comp is None and horizontal)) else "table"
        th = azimuth_deg(a[0], a[1]) if np.isfinite(a[:2]).all() else np.nan
        sign = 1.0
        if comp == 1 and np.isfinite(length) and length > 0:
            sign = float(np.sign(-(axis[0] * np.cos(np.radians(th)) + axis[1] * np.sin(np.radians(th))))) or 1.0
        rows[eid] = (int(el.ga if comp is None else el.nodes[0]), surface, th,
                     float(np.hypot(a[0], a[1])) / unit_length, float(a[2]) / unit_length, 1.0, u0, sign, f0)
    if not rows:
        raise DeckbridgeError(f"{str(deck)!r}: no CGAP or contact CELAS2 elements to map")
    df = pd.DataFrame.from_dict(rows, orient="index",
                                columns=["node", "surface", "theta_deg", "r", "z", "area", "u0", "dof_sign", "f0"])
    df.index.name = "element"
    return df


def contact_map(path: Path, model: Model | None, mesh=None) -> pd.DataFrame:
    """Element -> slave-node map from the model when given, else from the deck beside ``path``."""
    if model is not None:
        return model_contact_map(model, mesh)
    deck = sibling_deck(path)
    if deck is None:
        raise DeckbridgeError(f"{str(path)!r}: cannot map gap elements to nodes: pass the model, "
                              f"or keep the deck ({path.stem}.bdf) beside the results")
    return deck_contact_map(deck)


def _deck_u0(path: Path) -> dict:
    """{element: U0} from the deck beside ``path``; empty when there is none or it is unreadable."""
    deck = sibling_deck(path)
    if deck is None:
        return {}
    try:
        return deck_contact_map(deck)["u0"].to_dict()
    except DeckbridgeError:
        return {}


def _fraction(time: np.ndarray, step: np.ndarray) -> np.ndarray:
    """Fraction of a subcase's load done, for load steps stored per subcase or cumulatively."""
    t = np.nan_to_num(np.asarray(time, float), nan=1.0)
    cumulative = t > 1.0 + 1e-9
    return np.where(cumulative, t - (step - 1), t)


def tidy(raw: pd.DataFrame, cmap: pd.DataFrame, path: Path, source: str, method: str,
         lambda_max: float) -> pd.DataFrame:
    """Tidy rows from raw per-element results (element, subcase, increment, time, force_n, axial_u_m).

    ``force_n`` is compression positive along the gap axis; ``axial_u_m`` the closure. Extra columns
    for the contact-law check (:mod:`._contact_law`): ``origin`` (the record: table, element, subcase,
    increment) and ``preload_pa`` (-F0 / area).
    """
    missing = ~raw["element"].isin(cmap.index)
    if missing.any():
        raise DeckbridgeError(f"{str(path)!r}: gap element {int(raw.loc[missing, 'element'].iloc[0])} "
                              f"is not a contact element of the model or deck (results of another model?)")
    m = cmap.loc[raw["element"].to_numpy()]
    step = raw["subcase"].to_numpy(np.int64)
    frac = _fraction(raw["time"].to_numpy(), step)
    opening = m["u0"].to_numpy() - raw["axial_u_m"].to_numpy()
    return with_forces(pd.DataFrame({
        "source": source, "method": method, "step": step,
        "increment": raw["increment"].to_numpy(np.int64),
        "load_factor": np.where(step >= 2, lambda_max * frac, 0.0),
        "node": m["node"].to_numpy(np.int64), "surface": m["surface"].to_numpy(),
        "theta_deg": m["theta_deg"].to_numpy(), "z": m["z"].to_numpy(), "r": m["r"].to_numpy(),
        "sigma_n_pa": -raw["force_n"].to_numpy() / m["area"].to_numpy(),
        "gap_m": opening, "status": np.where(opening <= 0.0, "closed", "open"),
        "origin": [f"{str(path)!r}: {tab} record of gap element {e}, subcase {s}, increment {i}" for tab, e, s, i in
                   zip(raw.get("table", pd.Series("gap", index=raw.index)), raw["element"], raw["subcase"],
                       raw["increment"])],
        "preload_pa": -(m["f0"].to_numpy(float) if "f0" in m else 0.0) / m["area"].to_numpy(float),
    }), m["area"].to_numpy(float))


def detect(path: Path) -> bool:
    return path.is_file() and path.suffix.lower() == ".op2"


@checked(None)
def read(path: str | Path, model: Model | None = None, mesh=None) -> pd.DataFrame:
    """Tidy table of the gap results in a Nastran OP2 (force table preferred, else OESNLXR); ``mesh``: the
    model's, when built."""
    path = Path(path)
    raw = read_gap_forces(path, units=result_units(path, model))
    tables = set(raw["table"])
    raw = raw[raw["table"] == ("OEF1X" if "OEF1X" in tables else "OESNLXR")]
    cmap = contact_map(path, model, mesh)
    lam = model.steps.lambda_max if model is not None else 1.0
    return tidy(raw, cmap, path, RECORD.source, PENALTY, lam)
