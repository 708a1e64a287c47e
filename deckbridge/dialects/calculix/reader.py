"""Reader of CalculiX 2.20 results of the deckbridge decks (``.frd`` CONTACT/DISP blocks, ``.dat`` prints).

Input: a job's ``.frd``, ``.dat`` or ``.inp``, or a folder holding one or more jobs (all are read; the
``method`` column tells them apart). What is read, per ccx increment:

- mortar (``*_ccx_lagrange``): table slaves from the ``.frd`` CONTACT block, sigma_n = -CPRESS (CPRESS is
  the nodal dual multiplier, compression-positive; times the consistent nodal area it is the node's
  force); radial-stop slaves from their GAPUNI gaps as below;
- GAPUNI gaps (penalty deck, and the stop of the mortar deck): ``.dat`` ``*NODE PRINT`` forces RF of the
  grounded node of each gap; the compressive force is F = RF . n (n = master normal pointing into the
  skirt) and sigma_n = -F / A with the neutral model's tributary area A;
- node-to-surface penalty (``analysis.nlgeom: false`` penalty deck): ``.dat`` ``*CONTACT PRINT`` CSTR
  (pressure p = K x penetration per contact element, in contact-pair order, lifted nodes left out):
  sigma_n = -p A_ccx / A (force k_c x penetration over the model's area; 0 for a node without a row);
- 8-/6-node faces (C3D20/C3D20R/C3D10/C3D15): table rows as :mod:`.face_rows` (mortar ccx's multipliers, f2f -CPRESS);
- gap = clearance + n . u from the slave node's displacement (``.dat`` or ``.frd`` DISP; COPEN: penetrations only),
  on 8-/6-node mortar rows projected, (D g) / d (quantities.projected_gap). status: closed where sigma_n < -1e-6
  max|sigma_n| of the increment (mortar's open nodes carry force noise ~1e-4 Pa; GAPUNI's the tension f_inf / A).

Nodes map to azimuth/area/normal through the model's mesh when ``model`` is given (ids must be slave nodes
of that model), else through the ``** deckbridge-slave`` lines the renderer writes into the ``.inp``.
Steps: ccx step 1 -> step 1 (load factor 0); step 2 -> load factor lambda_max * (step time / step
period); increments are numbered 1.. in time order within each step (the decks print at the time points
j / increments only: one per model increment). ``.dat`` prints carry only the total time: step = 1 for
t <= 1, else 2. Units: values are divided back to SI by the deck's ``** deckbridge-units:`` (else the model's).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd

from . import RECORD
from ...errors import DeckbridgeError
from ...methods import PENALTY
from ...mesh import build_mesh
from .face_rows import MORTAR_BASIS, TableProjection, column_neighbours, f2f_table_sigma, face_neighbours, law_gaps as face_law_gaps
from .numbering import ccx_ground_node_ids, ccx_n2f_groups, ccx_node_slave_areas, ccx_penalty_is_n2f
from ...numbering.skirt import mesh_node_index
from ...units import scale
from .result_files import _META_JOB, Slaves, _dat_blocks, _frd_blocks, _on_frd_time, _read_meta, _slaves_from_model  # noqa: F401
from ...readers._checks import checked, reading
from ...results import with_forces

SOURCE = RECORD.source   # "ccx"
STATUS_TOL = 1e-6   # closed: sigma_n < -STATUS_TOL * max |sigma_n| of the increment (mortar RF noise ~1e-11)


def detect(path: Path) -> bool:
    """A folder with a ccx job, or a ccx ``.frd`` / ``.dat`` / deckbridge ccx ``.inp`` file."""
    try:
        if path.is_dir():
            return bool(_jobs_in(path))
        if not path.is_file():
            return False
        suffix = path.suffix.lower()
        if suffix in (".frd", ".dat", ".inp"):
            with open(path, errors="replace") as fh:
                head = fh.read(65536 if suffix == ".dat" else 4096)
        if suffix == ".frd":
            return "CalculiX" in head
        if suffix == ".dat":
            return bool(re.search(r"(forces|displacements) \((fx|vx),.*for set .* and time", head))
        if suffix == ".inp":
            return _META_JOB in head and "CalculiX" in head
    except OSError:
        return False
    return False


def _jobs_in(folder: Path) -> list[Path]:
    """Job stems in ``folder`` with a ccx result file next to them."""
    stems = {p.with_suffix("") for p in folder.iterdir() if p.suffix.lower() in (".frd", ".dat")}
    return sorted(s for s in stems if any(detect(s.with_suffix(x)) for x in (".frd", ".dat")))


def _method_of(stem: Path, job: dict) -> str:
    if job.get("method") in (PENALTY, "mortar", "f2f"):
        return job["method"]
    name = stem.name.lower()
    if "lagrange" in name or "mortar" in name:
        return "mortar"
    if "penalty" in name or "gap" in name:
        return PENALTY
    raise DeckbridgeError(f"{str(stem)!r}: cannot tell penalty from mortar (no deckbridge deck beside it, "
                          "job name without 'penalty' or 'lagrange')")


def _step_of(t: float, step: int | None) -> tuple[int, float]:
    """(step, step-time fraction) of a total time; our decks have two steps of period 1."""
    if step is None:
        step = 1 if t <= 1.0 + 1e-9 else 2
    return step, t - (step - 1)


def _read_job(stem: Path, model, table_from: str = "rf", mesh=None) -> pd.DataFrame:
    """Contact table of one ccx job. Mortar table slaves: nodal contact force RF / area from the .dat
    (``table_from="rf"``, exact force balance) or -CPRESS from the .frd (``"cpress"``, or when the .dat
    has no RF of the table slaves)."""
    inp, dat, frd = stem.with_suffix(".inp"), stem.with_suffix(".dat"), stem.with_suffix(".frd")
    with reading(inp):
        job, meta_slaves, gaps = _read_meta(inp)
    method = _method_of(stem, job)
    if model is not None:
        mesh = mesh if mesh is not None else build_mesh(model)
        sl = _slaves_from_model(model, mesh)
        n_nodes = mesh.n_nodes
        if "n_nodes" in job and int(job["n_nodes"]) != n_nodes:
            raise DeckbridgeError(f"{str(inp)!r}: deck of a mesh with {job['n_nodes']} nodes, model "
                                  f"{model.name!r} has {n_nodes}: results of another model?")
        lam = model.steps.lambda_max
    elif meta_slaves is not None:
        sl = meta_slaves
        lam = float(job.get("lambda_max", 1.0))
    else:
        raise DeckbridgeError(f"{str(stem)!r}: no model given and no deckbridge deck ({inp.name}) beside the "
                              "results to map node ids to the skirt")
    u = scale(job.get("units") or (model.units if model is not None else "SI"))
    with reading(dat):
        dat_blocks = _dat_blocks(dat) if dat.is_file() else []
    with reading(frd):
        coords, frd_blocks = _frd_blocks(frd) if frd.is_file() else ({}, [])
    coords = {n: c / u.length for n, c in coords.items()}
    if model is not None and coords:
        _check_coords(frd, coords, sl, model)

    # per time point: node -> force (RF) and displacement, from the .dat and the .frd (back to SI)
    forces: dict[tuple[int, float], dict[int, np.ndarray]] = {}
    disp: dict[tuple[int, float], dict[int, np.ndarray]] = {}
    cpress: dict[tuple[int, float], dict[int, float]] = {}
    contact: dict[tuple[int, float], list] = {}
    contact_gap: dict[tuple[int, float], list] = {}     # ccx's own clearance per contact element (CDIS)
    where: dict[tuple[str, tuple[int, float]], dict[int, str]] = {}     # (what, key) -> node -> "file: line n"
    for b in frd_blocks:
        key = (b["step"], b["time"])
        if b["name"] == "CONTACT":
            cpress.setdefault(key, {}).update({n: v[3] / u.stress for n, v in b["values"].items()})
            where.setdefault(("cpress", key), {}).update({n: _at(frd, ln) for n, ln in b["line"].items()})
        elif b["name"] == "DISP":
            disp.setdefault(key, {}).update({n: v / u.length for n, v in b["values"].items()})
    frd_times = np.array(sorted({b["time"] for b in frd_blocks}))
    for b in dat_blocks:
        key = _key(_on_frd_time(b["time"], frd_times), None)
        if b["kind"] == "contact":
            contact.setdefault(key, []).extend((n, v[0] / u.stress, _at(dat, ln))
                                               for (n, v), ln in zip(b["rows"], b["row_lines"]))
        elif b["kind"] == "contact_gap":
            contact_gap.setdefault(key, []).extend((n, v[0] / u.length) for n, v in b["rows"])
        elif b["kind"] == "forces":
            forces.setdefault(key, {}).update({n: v / u.force for n, v in b["values"].items()})
            where.setdefault(("rf", key), {}).update({n: _at(dat, ln) for n, ln in b["line"].items()})
        else:
            disp.setdefault(key, {}).update({n: v / u.length for n, v in b["values"].items()})

    n2f = method == PENALTY and ("n2f_order" in job or (not gaps and model is not None
                                                          and ccx_penalty_is_n2f(model)))
    if n2f:
        sigmas, origins, law_gaps = _n2f_sigma(stem, sl, job, model, contact, contact_gap, mesh)
        return _frames(sl, method, lam, sigmas, disp, stem, origins, law_gaps)
    table = sl.surface == "table"
    quad = bool(mesh.quadratic_faces) if model is not None else bool(job.get("quadratic"))
    # forces from RF of another node: the grounded gap node, or (f2f) the matching master node under the slave;
    # a face-to-face deck on quadratic faces has no master node under its slaves: its table rows are -CPRESS
    f2f_cpress = method == "f2f" and quad
    gap_rows = (~table if f2f_cpress else np.ones(sl.node.size, bool)) if method in (PENALTY, "f2f") else ~table
    mortar_rows = ~gap_rows & ~(table & f2f_cpress)
    if mortar_rows.any():
        has_rf = any(int(sl.node[np.flatnonzero(mortar_rows)[0]]) in f for f in forces.values())
        if table_from == "cpress" or not has_rf or (quad and model is None):    # no faces: ccx's own pressure
            if not cpress:
                raise DeckbridgeError(f"{str(frd if frd.is_file() else stem)!r}: no CONTACT block (CPRESS) of a "
                                      "mortar job in the .frd, and no RF of the slave nodes in the .dat")
            table_from = "cpress"
    if f2f_cpress and not cpress:
        raise DeckbridgeError(f"{str(frd if frd.is_file() else stem)!r}: no CONTACT block (CPRESS) of a face-to-face "
                              "job on quadratic faces in the .frd")
    project = (TableProjection(mesh, sl.node, mortar_rows, MORTAR_BASIS) if quad and model is not None
               and mortar_rows.any() and table_from == "rf" else None)     # quadratic mortar: ccx's own multipliers
    if gap_rows.any() and not forces:
        raise DeckbridgeError(f"{str(dat if dat.is_file() else stem)!r}: no gap-element forces (*NODE PRINT RF "
                              "of the grounded nodes) in the .dat")
    ground = _ground_nodes(stem, sl, gap_rows, gaps, method, model, mesh)
    force_of = np.where(gap_rows, ground, sl.node)          # whose RF gives the contact force

    sigmas, origins, own, nodal = {}, {}, {}, {}
    unknown = (table & f2f_cpress) | (mortar_rows & quad & (table_from == "cpress"))   # a pressure, no nodal force
    near = (None if not quad else face_neighbours(mesh, sl.node, table) if model is not None
            else column_neighbours(sl.theta, table))
    for step, t in sorted(set(forces) | (set(cpress) if table_from == "cpress" or f2f_cpress else set())):
        f_t = forces.get((step, t), {})
        sigma = np.full(sl.node.size, np.nan)
        origin = np.full(sl.node.size, None, object)
        rf_at, cp_at = where.get(("rf", (step, t)), {}), where.get(("cpress", (step, t)), {})
        rf_rows = gap_rows | (mortar_rows if table_from == "rf" else False)
        for i in np.flatnonzero(rf_rows):
            rf = f_t.get(int(force_of[i]))
            if rf is None:
                raise DeckbridgeError(f"{str(dat)!r}: no force RF of node {int(force_of[i])} (for {sl.surface[i]} "
                                      f"slave node {int(sl.node[i])}) at time {t:g}: results of another model?")
            sigma[i] = -float(rf @ sl.normal[i]) / sl.area[i]
            origin[i] = rf_at.get(int(force_of[i]))
        force = np.where(unknown, np.nan, -sigma * sl.area)      # RF . n of the rows read from RF (NaN: not yet)
        if project is not None:         # the rows' normal forces r = -sigma A, projected to a pressure
            sigma[project.rows] = project.sigma(force[project.rows])
            cp = cpress.get((step, t))          # the law's own pressure, judged by the contact-law check
            own[(step, t)] = np.full(sl.node.size, np.nan)
            if cp is not None:
                own[(step, t)][project.rows] = [-cp.get(int(n), 0.0) for n in sl.node[project.rows]]
        if f2f_cpress:
            rows = np.flatnonzero(table)
            sigma[rows] = f2f_table_sigma(cpress.get((step, t), {}), sl.node[rows])
            origin[rows] = [where.get(("cpress", (step, t)), {}).get(int(n), _at(frd, 0)) for n in sl.node[rows]]
        if mortar_rows.any() and table_from == "cpress":
            cp = cpress.get((step, t), {})
            for i in np.flatnonzero(mortar_rows):
                if int(sl.node[i]) not in cp:
                    raise DeckbridgeError(f"{str(frd)!r}: slave node {int(sl.node[i])} has no CONTACT result at "
                                          f"time {t:g}: results of another model?")
                sigma[i] = -cp[int(sl.node[i])]
                origin[i] = cp_at.get(int(sl.node[i]))
        sigmas[(step, t)], origins[(step, t)] = sigma, origin
        nodal[(step, t)] = np.where(np.isnan(force) & ~unknown, -sigma * sl.area, force)    # CPRESS x A: 4-node
    sl = sl if project is None else project.slaves(sl)          # their areas: the multipliers' shares d
    return _frames(sl, method, lam, sigmas, disp, stem, origins, law_sigmas=own or None, near=near, forces=nodal, project=project)


def _n2f_sigma(stem: Path, sl: Slaves, job: dict, model, contact: dict, contact_gap: dict | None = None, mesh=None):
    """sigma_n per time of a node-to-surface penalty job: -CSTR x A_ccx / A (force k_c d over the model's area),
    the rows' origins and ccx's own gap of each row (the CDIS ``normal`` printed beside it, NaN without one).

    ccx prints one row per contact element, in contact-pair order, and leaves out slave nodes far from
    their master (lifted): rows are matched to the pairs' (node, surface) sequence in order; a node without
    a row carries no force (sigma_n = 0, open). CDIS and CSTR come from the same contact elements of the same
    solution, row for row; their gap is against the deck's own (faceted) master and the deck's node
    coordinates, which the table's gap_m (model clearance + n . u) is not: the contact-law check judges ccx's
    pressure against ccx's gap (column ``law_gap_m``, dropped after the check).
    """
    if "n2f_order" in job:
        order, area = job["n2f_order"], job["n2f_area"]
    else:
        mesh = mesh if mesh is not None else build_mesh(model)
        a_ccx = ccx_node_slave_areas(mesh)
        order = [(int(n), g.surface) for g in ccx_n2f_groups(mesh) for n in g.nodes]
        idx = dict(zip((n for n, _ in order), mesh_node_index(mesh, [n for n, _ in order]).tolist()))
        area = {(n, f): float(a_ccx[idx[n]]) for n, f in order}
    row_of = {(int(n), str(f)): i for i, (n, f) in enumerate(zip(sl.node, sl.surface))}
    if not contact:
        raise DeckbridgeError(f"{str(stem.with_suffix('.dat'))!r}: no contact stress block (*CONTACT PRINT CSTR) "
                              "of a node-to-surface penalty job")
    out, origins, law_gaps = {}, {}, {}
    for key, rows in contact.items():
        sigma = np.zeros(sl.node.size)
        origin = np.full(sl.node.size, None, object)
        law_gap = np.full(sl.node.size, np.nan)
        cdis = (contact_gap or {}).get(key, [])
        if [n for n, _ in cdis] != [n for n, _, _ in rows]:
            cdis = [(None, np.nan)] * len(rows)          # no CDIS block row for row: judged on gap_m
        k = 0
        for (node, press, at), (_, g) in zip(rows, cdis):
            while k < len(order) and order[k][0] != node:
                k += 1
            if k == len(order):
                raise DeckbridgeError(f"{str(stem.with_suffix('.dat'))!r}: contact row of node {node} out of the "
                                      f"deck's slave order at time {key[1]:g}: results of another deck?")
            i = row_of.get(order[k])
            if i is None:
                raise DeckbridgeError(f"{str(stem)!r}: {order[k][1]} slave node {node} is not a slave of the model")
            sigma[i] = -press * area[order[k]] / sl.area[i]
            origin[i] = at
            law_gap[i] = g
            k += 1
        out[key], origins[key], law_gaps[key] = sigma, origin, law_gap
    return out, origins, law_gaps


def _at(path: Path, line: int) -> str:
    """Where a value was read: ``'file': line n`` (the ``origin`` of :mod:`._contact_law`)."""
    return f"{str(path)!r}: line {line}"


def _frames(sl: Slaves, method: str, lam: float, sigmas: dict, disp: dict, stem: Path,
            origins: dict | None = None, law_gaps: dict | None = None, law_sigmas: dict | None = None,
            near: list | None = None, forces: dict | None = None, project=None) -> pd.DataFrame:
    """The tidy table from sigma_n per (step, time) and the slave displacements; ``forces``: per (step, time) the
    rows' force_n (default -sigma_n x area); ``origins``: per (step, time) the file and line of each row's value
    (column ``origin``, dropped after the checks);
    ``law_gaps`` / ``law_sigmas``: the solver's own gap / pressure per row for the contact-law check; ``near``:
    per row the rows of its table faces (law_gap_m, face_rows.law_gaps); ``project``: gap_m (D g) / d of its rows."""
    frames, counters = [], {}
    for step, t in sorted(sigmas):
        sigma, d_t = sigmas[(step, t)], disp.get((step, t), {})
        gap = np.full(sl.node.size, np.nan)
        for i in range(sl.node.size):
            u = d_t.get(int(sl.node[i]))
            if u is not None:
                gap[i] = sl.clearance[i] + float(u[:3] @ sl.normal[i])
        if project is not None:         # quadratic mortar rows: the gap ccx's law constrains
            gap[project.rows] = project.gaps(gap[project.rows])
        counters[step] = counters.get(step, 0) + 1
        law_gap = law_gaps[(step, t)] if law_gaps else (face_law_gaps(sigma, gap, near) if near else None)
        law_sigma = (law_sigmas or {}).get((step, t))
        frames.append(with_forces(pd.DataFrame({
            "source": SOURCE, "method": method, "step": step, "increment": counters[step],
            "load_factor": 0.0 if step == 1 else lam * (t - (step - 1)), "node": sl.node,
            "surface": sl.surface, "theta_deg": sl.theta, "z": sl.z, "r": sl.r, "sigma_n_pa": sigma,
            "gap_m": gap, "status": np.where(sigma < -STATUS_TOL * np.nanmax(np.abs(sigma)), "closed", "open"),
            **({"origin": origins[(step, t)]} if origins else {}),
            **({"law_gap_m": law_gap} if law_gap is not None else {}),
            **({"law_sigma_pa": law_sigma} if law_sigma is not None else {})}), sl.area, (forces or {}).get((step, t))))
    if not frames:
        raise DeckbridgeError(f"{str(stem)!r}: no contact results in the ccx files")
    return pd.concat(frames, ignore_index=True)


def _key(t: float, step: int | None) -> tuple[int, float]:
    s, _ = _step_of(t, step)
    return s, t


def _ground_nodes(stem: Path, sl: Slaves, rows: np.ndarray, gaps: dict, method: str, model, mesh=None) -> np.ndarray:
    """Grounded GAPUNI node of each slave row (0 where none): from the deck, else from the numbering."""
    out = np.zeros(sl.node.size, np.int64)
    if not rows.any():
        return out
    if not gaps:
        if model is None:
            raise DeckbridgeError(f"{str(stem)!r}: gap elements unknown (no deck beside the results, no model)")
        gaps = ccx_ground_node_ids(model, mesh if mesh is not None else build_mesh(model), method)
    for i in np.flatnonzero(rows):
        g = gaps.get((int(sl.node[i]), str(sl.surface[i])))
        if g is None:
            raise DeckbridgeError(f"{str(stem.with_suffix('.inp'))!r}: no gap element on {sl.surface[i]} slave "
                                  f"node {int(sl.node[i])}: deck of another model?")
        out[i] = g
    return out


def _check_coords(frd: Path, coords: dict, sl: Slaves, model) -> None:
    """Slave nodes of ``model`` must exist in the .frd at the model's places (the .frd keeps 6 digits)."""
    tol = 1e-4 * max(model.geometry.radius, model.geometry.height)
    for i in range(sl.node.size):
        c = coords.get(int(sl.node[i]))
        th = np.radians(sl.theta[i])
        want = np.array([sl.r[i] * np.cos(th), sl.r[i] * np.sin(th), sl.z[i]])
        if c is None or np.max(np.abs(c[:3] - want)) > tol:
            raise DeckbridgeError(f"{str(frd)!r}: node {int(sl.node[i])} is not the {sl.surface[i]} slave node "
                                  f"of model {model.name!r} (n_theta={model.mesh.n_theta}, n_r={model.mesh.n_r}, "
                                  f"n_z={model.mesh.n_z}): results of another model?")


@checked("ccx")
def read(path: Path, model=None, mesh=None) -> pd.DataFrame:
    """Contact table of the ccx job(s) at ``path`` (a .frd/.dat/.inp file or a folder); ``mesh``: the model's
    mesh when already built (else built here, once)."""
    path = Path(path)
    if path.is_dir():
        stems = _jobs_in(path)
        if not stems:
            raise DeckbridgeError(f"{str(path)!r}: no CalculiX results (.frd/.dat) in this folder")
    elif path.is_file():
        stems = [path.with_suffix("")]
        if not (stems[0].with_suffix(".frd").is_file() or stems[0].with_suffix(".dat").is_file()):
            raise DeckbridgeError(f"{str(path)!r}: no CalculiX results (.frd/.dat) beside it")
    else:
        raise DeckbridgeError(f"{str(path)!r}: no such file or folder")
    if model is not None and mesh is None:
        mesh = build_mesh(model)
    return pd.concat([_read_job(s, model, mesh=mesh) for s in stems], ignore_index=True)


def n2f_tangential_force(dat: Path, model) -> dict[float, dict[int, float]]:
    """|F_t| [N] per ccx total time and table slave node id of a node-to-surface penalty job with friction.

    ``*CONTACT PRINT`` CSTR gives per contact element (pair order, lifted nodes left out) the pressure and
    two shear stresses tang1, tang2 [stress] in the master face's axes; ccx's force is the stress times the
    node-based slave area A_ccx, so |F_t| = hypot(tang1, tang2) x A_ccx (a node without a row: 0, left out).
    """
    mesh = build_mesh(model)
    a_ccx = ccx_node_slave_areas(mesh)
    order = [(int(n), g.surface) for g in ccx_n2f_groups(mesh) for n in g.nodes]
    ids = [n for n, _ in order]
    area = dict(zip(ids, a_ccx[mesh_node_index(mesh, ids)].tolist()))     # deck node id -> A_ccx [m^2]
    u = scale(model.units)
    out: dict[float, dict[int, float]] = {}
    for b in _dat_blocks(Path(dat)):
        if b["kind"] != "contact":
            continue
        got, k = out.setdefault(b["time"], {}), 0
        for node, v in b["rows"]:
            while k < len(order) and order[k][0] != node:
                k += 1
            if k == len(order):
                raise DeckbridgeError(f"{str(dat)!r}: contact row of node {node} out of the deck's slave order")
            if order[k][1] == "table":
                got[node] = float(np.hypot(v[1], v[2]) / u.stress * area[node])
            k += 1
    return out
