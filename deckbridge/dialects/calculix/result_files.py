"""CalculiX 2.20 files of the deckbridge decks: the deck's ``** deckbridge-...`` slave table and job metadata,
the ``.dat`` ``*NODE PRINT`` / ``*CONTACT PRINT`` blocks and the ``.frd`` DISP/CONTACT blocks, as written
(deck units; :mod:`.reader` scales them to SI and assembles the contact table).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import DeckbridgeError
from ...mesh import build_mesh
from ...numbering.skirt import mesh_node_ids
from ...errors import read_text
from ...readers._files import INP_UNITS_TAG
from ...units import scale
from .face_rows import QUADRATIC_TYPES

_DAT_HEAD = re.compile(r"^\s*(forces|displacements) \((?:fx|vx)[^)]*\) for set (\S+) and time\s+(\S+)")
_DAT_CONTACT = re.compile(r"^\s*contact stress \(slave node,press,tang1,tang2\) for all contact elements and time\s+(\S+)")
_DAT_CDIS = re.compile(r"^\s*relative contact displacement \(slave node,normal,tang1,tang2\) for all contact elements "
                       r"and time\s+(\S+)")
_META_N2F = "** deckbridge-n2f "
_META_UNITS = INP_UNITS_TAG
_META_JOB = "** deckbridge-job"
_META_SLAVE = "** deckbridge-slave "
_META_F2F = "** deckbridge-f2f-master "      # face-to-face deck: table slave node, master node under it


# --- slave table -------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Slaves:
    """One row per slave (node, surface): geometry and what turns forces into stresses."""
    node: np.ndarray
    surface: np.ndarray
    theta: np.ndarray
    r: np.ndarray
    z: np.ndarray
    area: np.ndarray
    normal: np.ndarray      # (n, 3)
    clearance: np.ndarray


def _slaves_from_model(model, mesh=None) -> Slaves:
    mesh = mesh if mesh is not None else build_mesh(model)
    sets = mesh.slave_sets
    cat = lambda f: np.concatenate([f(s) for s in sets])  # noqa: E731
    return Slaves(node=cat(lambda s: mesh_node_ids(mesh, s.nodes)), surface=cat(lambda s: np.full(s.nodes.size, s.surface)),
                  theta=cat(lambda s: s.theta_deg), r=cat(lambda s: s.r), z=cat(lambda s: s.z),
                  area=cat(lambda s: s.area), normal=np.vstack([s.normal for s in sets]),
                  clearance=cat(lambda s: s.clearance))


def _read_meta(inp: Path) -> tuple[dict, Slaves | None, dict]:
    """Job metadata, slave table and GAPUNI (slave, ground) pairs of a deckbridge ccx deck.

    ``job["quadratic"]``: the skirt has 8- or 6-node faces (C3D20/C3D20R/C3D10/C3D15 elements).
    Node-to-surface penalty decks add ``job["n2f_order"]`` ((node, surface) in contact-pair order) and
    ``job["n2f_area"]`` ({(node, surface): ccx's slave area [m^2]}); ``job["units"]`` the deck units.
    """
    job: dict = {}
    rows = []
    gaps: dict[tuple[int, str], int] = {}
    if not inp.is_file():
        return job, None, gaps
    lines = read_text(inp).splitlines()
    in_gap = in_node_surface = False
    order, area = [], {}
    for line in lines:
        if line.startswith(_META_JOB):
            job.update(kv.split("=", 1) for kv in line[len(_META_JOB):].split() if "=" in kv)
        elif line.startswith(_META_UNITS):
            job["units"] = line[len(_META_UNITS):].strip()
        elif line.startswith(_META_N2F) and not line.startswith(_META_N2F + "node"):
            n, surf, a = line[len(_META_N2F):].split()[:3]
            area[(int(n), surf)] = float(a)
        elif line.startswith(_META_F2F) and not line.startswith(_META_F2F + "slave"):
            slave, master = (int(v) for v in line[len(_META_F2F):].split()[:2])
            gaps[(slave, "table")] = master          # its RF is the slave's force, as a grounded gap node's
        elif line.startswith(_META_SLAVE) and not line.startswith(_META_SLAVE + "node"):
            rows.append(line[len(_META_SLAVE):].split())
        elif line.startswith("*"):
            up = line.upper().replace(" ", "")
            in_gap = up.startswith("*ELEMENT") and "TYPE=GAPUNI" in up
            et = re.match(r"\*ELEMENT,.*TYPE=(C3D\w+)", up)
            if et and et.group(1) in QUADRATIC_TYPES:
                job["quadratic"] = True          # 8- or 6-node slave faces (face_rows.py)
            m = re.search(r"ELSET=GAP_(TABLE|STOP)_", up)
            surface = m.group(1).lower() if (in_gap and m) else None
            ns = re.match(r"\*SURFACE,NAME=SLAVE_(TABLE|STOP)\d+,TYPE=NODE$", up)
            in_node_surface = ns is not None
            if ns:
                n2f_surface = ns.group(1).lower()
        elif in_gap and line.strip():
            _, slave, ground = (int(v) for v in line.split(",")[:3])
            gaps[(slave, surface)] = ground
        elif in_node_surface and line.strip() and not line.startswith("**"):
            order.append((int(line.split(",")[0]), n2f_surface))
    if order:
        job["n2f_order"], job["n2f_area"] = order, area
    slaves = None
    if rows:
        try:
            a = np.array([[float(v) for v in (r[:1] + r[2:])] for r in rows])
        except ValueError:
            raise DeckbridgeError(f"{str(inp)!r}: malformed '** deckbridge-slave' line") from None
        slaves = Slaves(node=a[:, 0].astype(np.int64), surface=np.array([r[1] for r in rows]), theta=a[:, 1],
                        r=a[:, 2], z=a[:, 3], area=a[:, 4], normal=a[:, 5:8], clearance=a[:, 8])
    return job, slaves, gaps


# --- ccx files ----------------------------------------------------------------------------------------
def _dat_blocks(path: Path) -> list[dict]:
    """``*NODE PRINT`` blocks of a ccx ``.dat``: kind, set, time, {node: (3,) values}, {node: line number}
    (contact blocks also ``rows`` [(node, values)] and ``row_lines``, in file order: ``contact`` the CSTR
    block, ``contact_gap`` the CDIS block, whose ``normal`` is ccx's own clearance, > 0 open)."""
    blocks, cur = [], None
    for line_no, line in enumerate(read_text(path).splitlines(), 1):
        m = _DAT_HEAD.match(line)
        if m:
            cur = {"kind": m.group(1), "set": m.group(2).upper(), "time": float(m.group(3)), "values": {},
                   "line": {}}
            blocks.append(cur)
            continue
        m = _DAT_CONTACT.match(line) or _DAT_CDIS.match(line)
        if m:
            cur = {"kind": "contact" if m.re is _DAT_CONTACT else "contact_gap", "set": "",
                   "time": float(m.group(1)), "values": {}, "line": {}, "rows": [], "row_lines": []}
            blocks.append(cur)
            continue
        parts = line.split()
        if cur is None or not parts:
            continue
        if len(parts) == 4 and parts[0].isdigit():
            try:
                v = np.array([float(x) for x in parts[1:]])
                cur["values"][int(parts[0])] = v
                cur["line"][int(parts[0])] = line_no
                if "rows" in cur:
                    cur["rows"].append((int(parts[0]), v))
                    cur["row_lines"].append(line_no)
            except ValueError:
                raise DeckbridgeError(f"{str(path)!r}: line {line_no}: unreadable {line.strip()!r}") from None
        elif parts[0].isdigit():      # a node's row with a value too many or too few: not the end of the block
            raise DeckbridgeError(f"{str(path)!r}: line {line_no}: {len(parts) - 1} values where the block has 3 "
                                  f"({line.strip()[:80]!r})")
        else:
            cur = None
    return blocks


_LAST_FRD: list = []     # (key, parsed) of the last .frd parsed: the reader and the ParaView series share it


def _frd_blocks(path: Path) -> tuple[dict, list[dict]]:
    """Node coordinates and DISP/CONTACT result blocks of an ASCII ``.frd`` (read-only: shared).

    Each block: name, step, inc (ccx increment within the step), time, {node: values}, {node: line number}.
    A job's ``.frd`` is parsed once: the last file parsed is kept (same path, size and modification time)
    for the next caller (the ``run --with calculix`` contact table, then its ParaView series).
    """
    try:
        st = Path(path).stat()
        key = (str(Path(path).resolve()), st.st_size, st.st_mtime_ns)
    except OSError:
        key = None
    if key is not None and _LAST_FRD and _LAST_FRD[0] == key:
        return _LAST_FRD[1]
    parsed = _parse_frd(path)
    _LAST_FRD[:] = [key, parsed] if key is not None else []
    return parsed


def _parse_frd(path: Path) -> tuple[dict, list[dict]]:
    coords: dict[int, np.ndarray] = {}
    blocks: list[dict] = []
    try:
        fh = open(path, errors="replace")
    except OSError as exc:
        raise DeckbridgeError(f"{str(path)!r}: cannot read ({exc.strerror})") from None
    with fh:
        mode, cur, step, inc, time, width = None, None, 0, 0, 0.0, 10
        for line_no, line in enumerate(fh, 1):
            if line.startswith("    2C"):
                mode, width = "coords", (5 if line.split()[-1] == "0" else 10)
            elif line.startswith("    1PSTEP"):
                f = line.split()
                inc, step = int(f[2]), int(f[3])
            elif line.startswith("  100C"):
                time = float(line[12:24])
                width = 5 if line.split()[-1] == "0" else 10
            elif line.startswith(" -4 "):
                cur = {"name": line[5:13].strip(), "step": step, "inc": inc, "time": time, "values": {}, "line": {}}
                blocks.append(cur)
                mode = "result"
            elif line.startswith(" -3"):
                mode, cur = None, None
            elif line.startswith(" -1") and mode is not None:
                try:
                    node = int(line[3:3 + width])
                    body = line[3 + width:].rstrip("\n")
                    vals = np.array([float(body[i:i + 12]) for i in range(0, len(body.rstrip()), 12)])
                except ValueError:
                    raise DeckbridgeError(f"{str(path)!r}: line {line_no}: unreadable {line.strip()!r}") from None
                if mode == "coords":
                    coords[node] = vals
                else:
                    cur["values"][node] = vals
                    cur["line"][node] = line_no
    return coords, blocks


TIME_DIGITS_TOL = 2e-6   # the .dat prints a time to 7 significant digits, the .frd to 10: the same point [s]


def _on_frd_time(t: float, frd_times: np.ndarray) -> float:
    """The ``.frd``'s time of the point a ``.dat`` time ``t`` [s] names (within TIME_DIGITS_TOL x max(1, t)),
    else ``t``: one state per ccx time point, not two (a 1/3 increment is 1.333333 in one, 1.333333333 in the
    other; keyed apart, a state's forces and its displacements or CPRESS fell into two half-empty states)."""
    if frd_times.size:
        k = int(np.abs(frd_times - t).argmin())
        if abs(frd_times[k] - t) <= TIME_DIGITS_TOL * max(1.0, abs(t)):
            return float(frd_times[k])
    return t


MASTER_SETS = ("NMTOP", "NMCOPY")      # the f2f deck's clamped master nodes whose RF it prints (templates/calculix)


def _master_reactions(inp):
    """(ccx time [s] on the ``.frd``'s clock, node coordinates (n, 3) [m], reactions RF (n, 3) [N]) of each printed
    block of the face-to-face deck's clamped master ring (``inp``: its deck; :data:`MASTER_SETS`), SI; raises
    when the ``.dat`` has none."""
    inp = Path(inp)
    u = scale(_read_meta(inp)[0].get("units") or "SI")
    coords, frd_blocks = _frd_blocks(inp.with_suffix(".frd"))
    times = np.array(sorted({b["time"] for b in frd_blocks}))
    blocks = [b for b in _dat_blocks(inp.with_suffix(".dat"))
              if b["kind"] == "forces" and b["set"] in MASTER_SETS and b["values"]]
    if not blocks:
        raise DeckbridgeError(f"{str(inp.with_suffix('.dat'))!r}: no RF of the master ring (*NODE PRINT of "
                              f"{' / '.join(MASTER_SETS)}) of a face-to-face job")
    for b in blocks:
        nodes = list(b["values"])
        yield (_on_frd_time(b["time"], times), np.array([coords[n] for n in nodes]) / u.length,
               np.array([b["values"][n] for n in nodes]) / u.force)


def f2f_master_resultant(inp) -> dict[float, tuple[np.ndarray, np.ndarray]]:
    """The exact contact resultant of a face-to-face job (``inp``: its deck; the ``.dat`` and ``.frd`` beside it)
    on 8-/6-node faces, per printed ccx time [s] (the ``.frd``'s): (force (3,) [N], moment (3,) [N m] about the
    origin), SI, the table's force on the skirt (z > 0 pushes it up: = Sum of the rows' nodal forces).

    ccx prints no nodal contact force of the slave nodes; the master ring (NMTOP, NMCOPY) has every node fixed,
    so its elements stay unstrained and the reactions RF at its nodes are the contact forces on the master,
    consistent over its bilinear faces: their sum and moment are the contact resultant's to the printed digits.
    Needs the deck's ``*NODE PRINT`` RF of both sets."""
    out: dict[float, tuple[np.ndarray, np.ndarray]] = {}
    for t, x, f in _master_reactions(inp):
        F, M = out.get(t, (np.zeros(3), np.zeros(3)))
        out[t] = (F + f.sum(axis=0), M + np.cross(x, f).sum(axis=0))
    return out


def f2f_master_lines(inp, n_theta: int) -> dict[float, np.ndarray]:
    """Per printed ccx time [s]: the contact force [N] (> 0 pressing the skirt up) on each azimuth line j
    (360 j / n_theta deg) of a face-to-face job's master ring on 8-/6-node faces (``inp``: its deck): the z RF
    of the ring's top nodes (NMTOP, NMCOPY) at that azimuth summed, SI. Exact like
    :func:`f2f_master_resultant` (clamped ring: RF is the contact force on its nodes), and what the reference
    gives as :func:`deckbridge.reference_f2f.ring_line_forces`; unlike CPRESS, no extrapolation."""
    out: dict[float, np.ndarray] = {}
    for t, x, f in _master_reactions(inp):
        j = np.rint((np.arctan2(x[:, 1], x[:, 0]) % (2 * np.pi)) * n_theta / (2 * np.pi)).astype(int) % n_theta
        np.add.at(out.setdefault(t, np.zeros(n_theta)), j, f[:, 2])
    return out


def f2f_ring_lines(result_file, model, mesh) -> dict[float, np.ndarray] | None:
    """The calculix record's ``line_reader``: {load factor: :func:`f2f_master_lines` at that state} of the
    face-to-face job whose result is ``result_file`` (its deck beside it) on 8-/6-node faces; None for any other
    job or face. Load factor: step 1's end 0, step 2 lambda_max (t - 1) (the decks' two steps of period 1)."""
    inp = Path(result_file).with_suffix(".inp")
    if not (mesh.quadratic_faces and inp.name.endswith("_ccx_f2f.inp") and inp.is_file()):
        return None
    lam_max = model.steps.lambda_max
    return {(0.0 if t <= 1.0 + 1e-9 else lam_max * (t - 1.0)): f
            for t, f in sorted(f2f_master_lines(inp, mesh.n_theta).items()) if t >= 1.0 - 1e-9}
