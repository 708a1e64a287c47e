"""ParaView time series of a CalculiX job of a deckbridge deck: ``<job>.pvd`` + ``<job>_NNN.vtu``.

One VTU per ccx increment that the job's ``.frd`` holds a DISP block for (every increment ccx wrote),
on the skirt mesh of the model (ccx's extra nodes and elements, master blocks and grounded gap nodes, are
left out). The pvd timestep is ccx's total time (step 1 in (0, 1], step 2 in (1, 2], t = 1 + lambda /
lambda_max), the pseudo-time of :mod:`deckbridge.paraview` for step 2 (ccx's step 1 ends at t = 1, where the
reference's step-1 state is at t = 0); a comment before each DataSet says ``step S increment I load_factor L``
(ccx's increment within the step).

Fields, where ccx gives them (names and units as :mod:`deckbridge.paraview`, SI whatever the deck's
``units``: the .frd's deck-unit values are divided by the factors of :mod:`deckbridge.units`):
  ``displacement_m`` (the .frd DISP block) [m], ``node_id``, named-set masks and tributary areas;
  ``<surface>_sigma_n_pa``, ``<surface>_gap_m``, ``<surface>_status`` at the slave nodes from the
  CalculiX reader (:mod:`.reader`: GAPUNI forces or mortar RF / CPRESS; sigma_N < 0
  compression, gap > 0 open, status 1 closed, 0 open, -1 not a slave); a state the reader has no contact
  result for gets NaN sigma_N and gap and status 0 at the slave nodes (0 elsewhere);
  ``stress_nodal_pa`` (n, 6) [Pa] Voigt (xx, yy, zz, xy, yz, zx) and ``von_mises_nodal_pa`` from the .frd
  STRESS block (the decks write ``*EL FILE`` S): ccx's own extrapolation to the nodes averaged over the
  elements at a node, the reference series' definition; at nodes a GAPUNI element touches (the NLGEOM
  penalty deck, the mortar deck's stop) it is averaged with the gap's zeros (use the ``*EL PRINT``
  recovery for numbers there, see el_stress.py).
No tangential spring force (ccx does not print it for these decks) and no cell stress.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from reference_solver.elements import von_mises

from ...errors import DeckbridgeError
from ...numbering.skirt import mesh_node_ids
from ...outdir import staged
from ...units import scale
from ...paraview import contact_data, mesh_data, state_label, write_states
from .result_files import _frd_blocks

LF_TOL = 1e-6   # relative agreement of the reader's load factor with the .frd time of the same increment


def _frd_states(frd: Path, mesh, units: str = "SI") -> list[dict]:
    """Per ccx increment with a DISP block, in time order: step, inc, time, u (n, 3) [m], stress (n, 6) [Pa]
    or None. Rows in mesh node order; the .frd's node ids are the deck's (the user's ids of an imported
    mesh), its values in the deck's ``units`` (converted to SI here)."""
    u = scale(units)
    to_si = {"DISP": 1.0 / u.length, "STRESS": 1.0 / u.stress}
    _, blocks = _frd_blocks(frd)
    n_nodes = mesh.n_nodes
    index_of = dict(zip(mesh_node_ids(mesh, np.arange(n_nodes)).tolist(), range(n_nodes)))
    states: dict[tuple[int, int], dict] = {}
    for b in blocks:
        if b["name"] not in ("DISP", "STRESS"):
            continue
        st = states.setdefault((b["step"], b["inc"]), {"step": b["step"], "inc": b["inc"], "time": b["time"],
                                                      "u": None, "stress": None})
        a = np.zeros((n_nodes, 3 if b["name"] == "DISP" else 6))
        for node, v in b["values"].items():
            i = index_of.get(node)
            if i is not None:
                a[i] = v[: a.shape[1]]
        st["u" if b["name"] == "DISP" else "stress"] = a * to_si[b["name"]]
    out = sorted((s for s in states.values() if s["u"] is not None), key=lambda s: s["time"])
    if not out:
        raise DeckbridgeError(f"{str(frd)!r}: no DISP block in the .frd (the deck needs *NODE FILE U)")
    return out


def write_ccx_series(job_path: str | Path, model, outdir: str | Path, mesh=None,
                     table: pd.DataFrame | None = None) -> list[Path]:
    """Write ``<job>.pvd`` and ``<job>_NNN.vtu`` of the ccx job ``job_path`` (its .inp/.frd/.dat, any
    suffix) into ``outdir``, atomically; returns the written paths, the pvd first. Called after the job ran
    (the dialect record's series writer) with the model's ``mesh`` and the job's contact ``table`` already
    read (:mod:`.reader`; the .frd is parsed once, :func:`.result_files._frd_blocks`); both are made here
    when not given."""
    stem = Path(job_path).with_suffix("")
    frd = stem.with_suffix(".frd")
    if not frd.is_file():
        raise DeckbridgeError(f"{str(frd)!r}: no such file (run ccx first)")
    if mesh is None:
        from ...mesh import build_mesh
        mesh = build_mesh(model)
    if table is None:
        from ...readers import read
        table = read(frd, fmt="calculix", model=model, mesh=mesh)
    rows = mesh.contact_rows
    key = pd.Series(np.arange(rows.size), index=pd.MultiIndex.from_arrays([mesh_node_ids(mesh, rows.nodes), rows.surface]))
    groups = {k: g for k, g in table.groupby(["step", "increment"])}
    base_point, base_cell = mesh_data(mesh)
    lam = model.steps.lambda_max
    states, times, count = [], [], {}
    for fs in _frd_states(frd, mesh, model.units):
        count[fs["step"]] = count.get(fs["step"], 0) + 1
        lf = 0.0 if fs["step"] == 1 else lam * (fs["time"] - (fs["step"] - 1))
        g = groups.get((fs["step"], count[fs["step"]]))
        if g is not None and abs(float(g["load_factor"].iloc[0]) - lf) > LF_TOL * lam:
            g = None                                  # the reader's k-th increment is another time point
        sig, gap, closed = (np.full(rows.size, np.nan) for _ in range(3))
        if g is not None:
            at = key.loc[list(zip(g["node"], g["surface"]))].to_numpy()
            sig[at], gap[at] = g["sigma_n_pa"].to_numpy(), g["gap_m"].to_numpy()
            closed[at] = (g["status"] == "closed").to_numpy()
        point = {**base_point, "displacement_m": fs["u"],
                 **contact_data(mesh.n_nodes, rows.nodes, rows.surface, sig, gap,
                                np.where(np.isnan(closed), 0, closed).astype(bool))}
        if fs["stress"] is not None:
            point.update(stress_nodal_pa=fs["stress"], von_mises_nodal_pa=von_mises(fs["stress"]))
        states.append({"point": point, "cell": dict(base_cell), "label": state_label(fs["step"], fs["inc"], lf)})
        times.append(fs["time"])
    comment = (f"deckbridge: CalculiX job {stem.name}, model {model.name}: one VTU per ccx increment; "
               f"timestep = ccx total time = (step - 1) + lambda / lambda_max for step 2; "
               f"lambda_max = {lam!r}; sigma_N < 0 compression")
    with staged(outdir) as stage:
        written = write_states(stage, stem.name, mesh.nodes, mesh.hexes, states, np.array(times), comment)
    return [Path(outdir) / w.name for w in written]
