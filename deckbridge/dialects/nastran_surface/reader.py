"""Nastran surface-contact results (OP2 tables OQGCF1, OBC1, OSPDS1/OSPDSI1) -> the tidy contact table.

The tables are read by our own record reader, :mod:`.op2_tables` (pyNastran 1.4.1 stores
the OBC1 pressures as zeros: it never adds the records it unpacks). The deck beside the OP2 (same stem,
.bdf/.dat/.nas), or the one given, is read with pyNastran for what the OP2 does not hold: the source
faces (``BCTSET`` source regions -> ``BSURFS`` element faces), the grids' positions and the faces' shares.

Rows: one per source grid (a grid of a ``BSURFS`` face of a ``BCTSET`` source region), source region and state; node ids
as in the file; step = subcase, increment = the block's order in its subcase, load_factor 0 in step 1
and ``steps.lambda_max`` (1 without a model) in later subcases (SOL 101 subcases carry total loads).

Signs and quantities, as measured on the Simcenter 2019.2 SOL 101 file of ``../shared/data/nx_surface_contact``:

- OBC1 pressure > 0 is compressive: the 24 grids that carry contact force all have pressure > 0, none < 0.
  ``sigma_n_pa = -pressure`` (< 0 compression).
- The grid pressure is the **average of the face pressures of the source faces around the grid** (open faces
  count 0), not force / share: grid 37 (one face) reads 131.28, grid 38 (that face and an open one) 65.64 =
  131.28 / 2. Per grid, OQGCF1's force differs from pressure x share by up to a factor 3; per contact region
  the sums agree to float32 precision (region 3: |sum F| = 3095.615 N, sum pressure x share = 3095.615,
  1.2e-8 apart; the target region carries the opposite force). ``area_m2`` is the grid's share of its source
  faces (integral of the bilinear shape function; linear faces only, else NaN) and ``force_n = pressure x
  area`` (the table's identity); OQGCF1 is kept in :func:`contact_tables`.
- A face is in contact when one of its grids has separation <= 0; a grid is ``closed`` when one of its source
  faces is (that is where it carries pressure: grid 38, separation +0.0097, sits on a face whose grid 184
  penetrates, -0.00012); ``gap_m`` is the grid's own final separation (OSPDS1), and the contact law is judged
  on the face gap (the smallest separation of the faces around the grid). Without OSPDS1, closed = pressure > 0.
- ``surface``: ``stop`` where the source faces' mean normal is horizontal (|n_z| < 0.5), else ``table``.

Units: a deckbridge deck's ``$ deckbridge-units:`` line, else ``model.units``, else SI (a foreign deck is
taken as consistent SI; the Simcenter test model is in N and mm, so its "Pa" are MPa, its "m" mm).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ...azimuth import azimuth_deg
from ...errors import InputError
from ...model import Model
from ...results import with_forces
from ...units import scale
from ...readers._checks import checked, reading
from . import RECORD
from .op2_tables import COLUMNS, TABLES, read_tables
from ..nastran.reader import deck_units, sibling_deck

FORMAT = "nastran_contact"
# corner faces of the linear solids (indices into the element's corner grids), outward order irrelevant here
FACES = {8: ((0, 1, 2, 3), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)),
         6: ((0, 1, 2), (3, 4, 5), (0, 1, 4, 3), (1, 2, 5, 4), (2, 0, 3, 5)),
         4: ((0, 1, 2), (0, 1, 3), (1, 2, 3), (2, 0, 3))}
CORNERS = {"CHEXA": 8, "CPENTA": 6, "CTETRA": 4}
_GAUSS = np.array([-1.0, 1.0]) / np.sqrt(3.0)


@dataclass
class SourceFaces:
    """Source faces of a deck (deck units), per source region: each face's grids; per (region, grid) its share
    and mean normal; per grid its position. A grid on two source regions (a skirt corner on the table and the
    stop) has a row in each, with the one OBC1 pressure Simcenter writes per grid."""
    faces: list[tuple[int, tuple[int, ...]]]      # (region, grid ids of the face: 3 or 4 corners, then mid-sides)
    xyz: dict[int, np.ndarray]                    # grid -> basic position
    share: dict[tuple[int, int], float]           # (region, grid) -> sum of its face shares [length^2] (NaN: quadratic)
    normal: dict[tuple[int, int], np.ndarray]     # (region, grid) -> mean unit normal of its faces


def _face_shares(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Shares (integral of each corner's shape function) and unit normal of a flat-or-warped face."""
    if len(x) == 3:
        n = np.cross(x[1] - x[0], x[2] - x[0])
        return np.full(3, np.linalg.norm(n) / 6.0), n / np.linalg.norm(n)
    s, nsum = np.zeros(4), np.zeros(3)
    for xi in _GAUSS:
        for eta in _GAUSS:
            shape = 0.25 * np.array([(1 - xi) * (1 - eta), (1 + xi) * (1 - eta), (1 + xi) * (1 + eta), (1 - xi) * (1 + eta)])
            dxi = 0.25 * np.array([-(1 - eta), 1 - eta, 1 + eta, -(1 + eta)]) @ x
            deta = 0.25 * np.array([-(1 - xi), -(1 + xi), 1 + xi, 1 - xi]) @ x
            n = np.cross(dxi, deta)
            s += shape * np.linalg.norm(n)
            nsum += n
    return s, nsum / np.linalg.norm(nsum)


def _face_midsides(nids: list, n_corners: int, face: tuple[int, ...]) -> tuple[int, ...]:
    """The mid-side grids of a quadratic solid's face (``face``: its corner positions) from the card's grid list
    ``nids`` in Nastran order: CalculiX's edge of each mid-side (:func:`importers.node_order.midside_edges`) at its
    Nastran place (:data:`importers.node_order.NASTRAN_TO_CCX`, its own inverse)."""
    from ...importers.node_order import NASTRAN_TO_CCX, midside_edges
    k = len(nids)
    perm = NASTRAN_TO_CCX.get(k, list(range(k)))
    ccx = {20: "c3d20", 15: "c3d15", 10: "c3d10"}[k]
    on = set(face)
    return tuple(int(nids[perm[m]]) for m, a, b in midside_edges(ccx) if a in on and b in on)


def source_faces(deck: Path) -> SourceFaces:
    """The faces of the ``BCTSET`` source regions of ``deck`` (``BSURFS``: element + three of its grids)."""
    from pyNastran.bdf.bdf import read_bdf
    with reading(deck):
        bdf = read_bdf(str(deck), xref=True, debug=None, validate=False)
    sids = sorted({int(s) for b in bdf.bctsets.values() for s in b.sids})
    if not sids:
        raise InputError(f"{str(deck)!r}: no BCTSET source regions: cannot place the contact grids")
    faces, xyz, share, normal = [], {}, {}, {}
    for sid in sids:
        bs = bdf.bsurfs.get(sid)
        if bs is None:
            raise InputError(f"{str(deck)!r}: BCTSET source region {sid} has no BSURFS (only solid faces are read)")
        for eid, *three in zip(bs.eids, bs.g1s, bs.g2s, bs.g3s):
            el = bdf.elements.get(int(eid))
            if el is None or el.type not in CORNERS:
                raise InputError(f"{str(deck)!r}: BSURFS {sid} element {eid}: not a CHEXA, CPENTA or CTETRA")
            nids = list(el.node_ids)
            corners = nids[:CORNERS[el.type]]
            hit = [f for f in FACES[len(corners)] if set(three) <= {corners[i] for i in f}]
            if len(hit) != 1:
                raise InputError(f"{str(deck)!r}: BSURFS {sid}: grids {three} are not on one face of element {eid}")
            grids = tuple(int(corners[i]) for i in hit[0])
            x = np.array([bdf.nodes[g].get_position() for g in grids], float)
            s, n = _face_shares(x)
            if any(v is not None for v in nids[len(corners):]):
                grids = grids + _face_midsides(nids, len(corners), hit[0])   # quadratic: the mid-side grids too
                x = np.array([bdf.nodes[g].get_position() for g in grids], float)
                s = np.full(len(grids), np.nan)        # quadratic element: shares not the corner rule
            faces.append((sid, grids))
            for g, si, xg in zip(grids, s, x):
                xyz[g] = xg
                share[sid, g] = share.get((sid, g), 0.0) + float(si)
                normal[sid, g] = normal.get((sid, g), np.zeros(3)) + n
    normal = {k: v / max(np.linalg.norm(v), 1e-300) for k, v in normal.items()}
    return SourceFaces(faces, xyz, share, normal)


def contact_tables(path: str | Path) -> pd.DataFrame:
    """Every contact table of the OP2, one row per (subcase, increment, grid), file units and file signs.

    Columns: subcase, increment (1-based within the subcase), step_value (load set, or time for nonlinear
    statics), node, then fx fy fz mx my mz (OQGCF1), pressure s1 s2 s3 (OBC1), separation (OSPDS1),
    separation_initial (OSPDSI1); NaN where a table lacks the grid or is absent.
    """
    op2 = read_tables(path)
    merged = None
    for tab in TABLES:
        frames = []
        for sub in sorted({b.subcase for b in op2.blocks.get(tab, [])}):
            for inc, b in enumerate([b for b in op2.blocks[tab] if b.subcase == sub], 1):
                f = pd.DataFrame(b.values, columns=list(COLUMNS[tab]))
                f.insert(0, "node", b.grids)
                f.insert(0, "step_value", b.step)
                f.insert(0, "increment", inc)
                f.insert(0, "subcase", sub)
                frames.append(f)
        if frames:
            df = pd.concat(frames, ignore_index=True)
            merged = df if merged is None else merged.merge(df, how="outer", on=["subcase", "increment", "node"],
                                                            suffixes=("", "_" + tab))
    for c in [c for cols in COLUMNS.values() for c in cols]:
        if c not in merged.columns:
            merged[c] = np.nan
    merged = merged.drop(columns=[c for c in merged.columns if c.startswith("step_value_")])
    return merged.sort_values(["subcase", "increment", "node"], ignore_index=True)


def _units(path: Path, deck: Path, model: Model | None):
    return scale(deck_units(deck) or (model.units if model is not None else "SI"))


def tidy(raw: pd.DataFrame, sf: SourceFaces, path: Path, model: Model | None, units) -> pd.DataFrame:
    """Tidy rows of the source grids from :func:`contact_tables` and the deck's source faces."""
    keys = sorted(sf.share)                                  # (region, grid)
    grids = np.array(sorted(sf.xyz), np.int64)
    raw = raw[raw["node"].isin(grids)]
    if raw.empty:
        raise InputError(f"{str(path)!r}: none of the OP2's contact grids is on a source face of the deck "
                         "(results of another model?)")
    lam = model.steps.lambda_max if model is not None else 1.0
    out = []
    for (sub, inc), g in raw.groupby(["subcase", "increment"], sort=True):
        g = g.set_index("node").reindex(grids)
        p = g["pressure"].to_numpy(float)
        sep = g["separation"].to_numpy(float)
        own = dict(zip(grids.tolist(), sep))
        face_gap = {}
        for rid, f in sf.faces:
            m = min(own[n] for n in f)
            for n in f:
                face_gap[rid, n] = min(face_gap.get((rid, n), np.inf), m)
        row = np.searchsorted(grids, [n for _, n in keys])
        p, sep = p[row], sep[row]
        law = np.array([face_gap[k] for k in keys])
        has_sep = np.isfinite(sep).any()
        closed = (law <= 0.0) if has_sep else (np.nan_to_num(p) > 0.0)
        nodes = [n for _, n in keys]
        x = np.array([sf.xyz[n] for n in nodes]) / units.length
        nz = np.array([abs(sf.normal[k][2]) for k in keys])
        step = int(sub)
        out.append(pd.DataFrame({
            "source": RECORD.source, "method": "penalty", "step": step,
            "increment": int(inc), "load_factor": 0.0 if step == 1 else lam, "node": nodes,
            "surface": np.where(nz < 0.5, "stop", "table"),
            "theta_deg": azimuth_deg(x[:, 0], x[:, 1]), "z": x[:, 2], "r": np.hypot(x[:, 0], x[:, 1]),
            "sigma_n_pa": -p / units.stress + 0.0, "gap_m": sep / units.length,
            "status": np.where(closed, "closed", "open"),
            "law_gap_m": np.where(np.isfinite(law), law, np.nan) / units.length,
            "origin": [f"{str(path)!r}: OBC1 grid {n}, subcase {sub}, increment {inc}" for n in nodes],
            "area_m2": np.array([sf.share[k] for k in keys]) / units.length ** 2,
        }))
    df = pd.concat(out, ignore_index=True)
    return with_forces(df.drop(columns="area_m2"), df["area_m2"].to_numpy(float))


def _deck_of(path: Path, deck: str | Path | None) -> Path:
    d = Path(deck) if deck is not None else sibling_deck(path)
    if d is None or not d.is_file():
        raise InputError(f"{str(path)!r}: no deck beside it ({path.stem}.bdf) to place the contact grids: keep the "
                         "deck beside the OP2 or pass deck=")
    return d


def detect(path: Path) -> bool:
    """An .op2 holding a contact table (a cheap look for the table names; the reader checks the rest)."""
    if not (path.is_file() and path.suffix.lower() == ".op2"):
        return False
    try:
        read_tables(path)
    except InputError:
        return False
    return True


@checked(None)
def read(path: str | Path, model: Model | None = None, deck: str | Path | None = None) -> pd.DataFrame:
    """Tidy table of a Nastran surface-contact OP2 (the deck beside it gives faces and positions)."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{str(path)!r}: no such file")
    d = _deck_of(path, deck)
    raw = contact_tables(path)
    if raw["pressure"].isna().all():
        raise InputError(f"{str(path)!r}: no OBC1 contact pressures (BCRESULTS without TRACTION)")
    return tidy(raw, source_faces(d), path, model, _units(path, d, model))



def read_contact(path: str | Path, deck: str | Path | None = None, model: Model | None = None) -> pd.DataFrame:
    """The tidy contact table (:data:`deckbridge.results.COLUMNS`) of a Nastran surface-contact OP2.

    Any model: node ids as in the file; ``deck`` (default: the .bdf/.dat/.nas with the OP2's stem beside it)
    gives the source faces and positions. One-line :class:`deckbridge.errors.DeckbridgeError` on an OP2
    without contact tables, a truncated or garbled file, or non-finite values.
    """
    from ...results import conform
    return conform(read(path, model=model, deck=deck))
