"""ParaView time series of the reference solver's load path: ``<base>.pvd`` + one ``<base>_NNN.vtu`` per state.

One VTU per row of the reference :class:`~reference_solver.Solution` (the end of step 1, then every
increment j = 0..increments of step 2), all on the skirt mesh (node id = mesh index + 1, element id =
hexahedron index + 1). The ``.pvd`` (ParaView's XML collection) lists them in load-path order with the
pseudo-time t = (step - 1) + lambda / lambda_max for step 2 and t = 0 for step 1 (monotone, one time per
state; step 2 ends at t = 2), the convention of CalculiX's total time; a comment before each DataSet
says ``step S increment I load_factor L`` (increment j of step 2 is at lambda = j lambda_max / increments).

Point data (SI; 0 off the contact, never NaN there):
  ``displacement_m`` (n, 3); ``node_id``; ``<surface>_sigma_n_pa`` contact stress of the table / stop slave
  (sigma_N = -force / area, < 0 compression); ``<surface>_gap_m`` (> 0 open); ``<surface>_status``
  (1 closed, 0 open, -1 not a slave of that surface); ``<surface>_area_m2`` tributary area;
  ``tangential_force_n``: circumferential tangential force on the table node along e_theta
  (counter-clockwise seen from +z, [N]): the spring force with ``tangential: springs``, the
  circumferential component of the friction force with ``tangential: friction``;
  ``friction_force_n`` (n, 3): friction force of the table on the node (global xyz [N]; 0 with springs); masks ``table_slave``, ``stop_slave``, ``top_ring`` (1/0);
  ``stress_nodal_pa`` (n, 6) Gauss-point stresses extrapolated to the corners and averaged over the
  elements sharing the node (an estimate), ``von_mises_nodal_pa``.
Cell data: ``element_id``; ``bottom_row`` (1 for the element row on the table); ``stress_pa`` (ne, 6)
  element volume average by its 2 x 2 x 2 Gauss quadrature; ``von_mises_pa`` of that average.
Stress tensors: Voigt order (xx, yy, zz, xy, yz, zx) [Pa], tension > 0.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from reference_solver.recover import path_fields, states_stress

from .mesh import SkirtMesh
from .numbering.skirt import bottom_row_index, elem_ids, mesh_node_ids

VOIGT = "xx yy zz xy yz zx"
SURFACES = ("table", "stop")


def pseudo_time(step: np.ndarray, load_factor: np.ndarray, lambda_max: float) -> np.ndarray:
    """t = 0 for step 1, (step - 1) + lambda / lambda_max for step 2 [-]."""
    step = np.asarray(step)
    return np.where(step == 1, 0.0, (step - 1) + np.asarray(load_factor, float) / lambda_max)


def state_label(step: int, increment: int, load_factor: float) -> str:
    """The pvd comment before a state's DataSet: 'step S increment I load_factor L'."""
    return f"step {int(step)} increment {int(increment)} load_factor {float(load_factor):.12g}"


def mesh_data(mesh: SkirtMesh) -> tuple[dict, dict]:
    """Point and cell data that every state shares: ids, named-set masks, tributary areas [m^2]."""
    n, ne = mesh.n_nodes, mesh.hexes.shape[0]
    point: dict = {"node_id": mesh_node_ids(mesh, np.arange(n)).astype(np.int64)}
    for s in mesh.slave_sets:
        mask = np.zeros(n, np.uint8)
        mask[s.nodes] = 1
        area = np.zeros(n)
        area[s.nodes] = s.area
        point[f"{s.surface}_slave"] = mask
        point[f"{s.surface}_area_m2"] = area
    top = np.zeros(n, np.uint8)
    top[mesh.top_nodes] = 1
    point["top_ring"] = top
    bottom = np.zeros(ne, np.uint8)
    bottom[bottom_row_index(mesh)] = 1
    cell = {"element_id": elem_ids(mesh, np.arange(ne)).astype(np.int64), "bottom_row": bottom}
    return point, cell


def contact_data(n_nodes: int, nodes: np.ndarray, surface: np.ndarray, sigma_n: np.ndarray,
                 gap: np.ndarray, closed: np.ndarray) -> dict:
    """Point data of one state's contact rows: ``<surface>_sigma_n_pa``, ``_gap_m``, ``_status``.

    ``nodes`` 0-based mesh indices of the rows, ``surface`` their labels, ``sigma_n`` [Pa] (< 0
    compression), ``gap`` [m] (> 0 open), ``closed`` bool. Off the surface's slaves: 0, status -1.
    """
    out = {}
    for surf in SURFACES:
        rows = np.asarray(surface) == surf
        if not rows.any():
            continue
        sig, g = np.zeros(n_nodes), np.zeros(n_nodes)
        st = np.full(n_nodes, -1, np.int8)
        idx = np.asarray(nodes)[rows]
        sig[idx], g[idx] = np.asarray(sigma_n)[rows], np.asarray(gap)[rows]
        st[idx] = np.asarray(closed)[rows].astype(np.int8)
        out.update({f"{surf}_sigma_n_pa": sig, f"{surf}_gap_m": g, f"{surf}_status": st})
    return out


def _comment(text: str) -> ET.Comment:
    return ET.Comment(f" {text.replace('--', '- -')} ")


def write_pvd(path: Path, files: list[str], times: np.ndarray, comment: str, labels: list[str]) -> Path:
    """ParaView collection file listing ``files`` (names relative to ``path``) at ``times``, each
    preceded by a comment ``labels[k]`` (its step, increment and load factor)."""
    root = ET.Element("VTKFile", type="Collection", version="0.1", byte_order="LittleEndian")
    root.append(_comment(comment))
    coll = ET.SubElement(root, "Collection")
    for name, t, label in zip(files, times, labels):
        coll.append(_comment(label))
        ET.SubElement(coll, "DataSet", timestep=repr(float(t)), group="", part="0", file=name)
    ET.indent(root)
    path.write_bytes(b'<?xml version="1.0"?>\n' + ET.tostring(root) + b"\n")
    return path


def vtk_cells(cells: np.ndarray) -> tuple[str, np.ndarray]:
    """(meshio cell type, cells) of the skirt's cells (m, k) by their node count (issue 23; CalculiX and VTK
    share the node order). 15-node wedges go as their 6 corners: meshio 5.3 cannot hold 'wedge15'."""
    cells = np.asarray(cells, np.int64)
    kind = {8: "hexahedron", 20: "hexahedron20", 10: "tetra10", 15: "wedge", 4: "tetra"}[cells.shape[1]]
    return kind, (cells[:, :6] if cells.shape[1] == 15 else cells)


def write_states(folder: Path, base: str, nodes: np.ndarray, hexes: np.ndarray, states: list[dict],
                 times: np.ndarray, comment: str) -> list[Path]:
    """Write ``base_NNN.vtu`` per state and ``base.pvd``; each state {'point', 'cell', 'label'}."""
    import meshio
    files = []
    for k, st in enumerate(states):
        name = f"{base}_{k:03d}.vtu"
        meshio.write(folder / name, meshio.Mesh(nodes, [vtk_cells(hexes)], point_data=st["point"],
                                                cell_data={k2: [v] for k2, v in st["cell"].items()}))
        files.append(name)
    pvd = write_pvd(folder / f"{base}.pvd", files, times, comment, [st["label"] for st in states])
    return [pvd] + [folder / f for f in files]


def tangential_point_data(p, sol, row: int) -> tuple[np.ndarray, np.ndarray]:
    """(circumferential tangential force per node [N], friction force per node (n, 3) [N]) at ``row``."""
    fric = np.zeros((p.n_nodes, 3))
    if sol.tangential_force is None:
        tang = np.zeros(p.n_nodes)
        tang[p.spring_nodes] = sol.spring_force[row]
        return tang, fric
    np.add.at(fric, p.contact_nodes, sol.tangential_force[row])
    t = np.arctan2(p.nodes[:, 1], p.nodes[:, 0])
    return fric[:, 0] * -np.sin(t) + fric[:, 1] * np.cos(t), fric


def reference_states(model, mesh: SkirtMesh, system, sol) -> tuple[list[dict], np.ndarray]:
    """Point and cell data of every row of ``sol`` and their pseudo-times (see the module doc)."""
    p = system.problem
    U = path_fields(system, sol)                            # one solve for every row
    base_point, base_cell = mesh_data(mesh)
    states = []
    for r, s in enumerate(states_stress(p, U)):
        tang, fric = tangential_point_data(p, sol, r)
        point = {**base_point, "displacement_m": U[r],
                 **contact_data(p.n_nodes, p.contact_nodes, p.contact_surface, sol.sigma_n[r], sol.gap[r],
                                sol.closed[r]),
                 "tangential_force_n": tang, "friction_force_n": fric, "stress_nodal_pa": s["nodal"],
                 "von_mises_nodal_pa": s["nodal_von_mises"]}
        cell = {**base_cell, "stress_pa": s["cell"], "von_mises_pa": s["cell_von_mises"]}
        states.append({"point": point, "cell": cell,
                       "label": state_label(sol.step[r], sol.increment[r], sol.load_factor[r])})
    return states, pseudo_time(sol.step, sol.load_factor, model.steps.lambda_max)


def write_reference_series(folder: str | Path, model, mesh: SkirtMesh, system, sol,
                           base: str = "result") -> list[Path]:
    """Write ``base.pvd`` and ``base_NNN.vtu`` of the reference load path into ``folder`` (a staging
    folder: the caller makes the writing atomic); returns the written paths, the pvd first."""
    states, times = reference_states(model, mesh, system, sol)
    comment = (f"deckbridge reference solver ({sol.method}), model {model.name}: one VTU per state; "
               "timestep = 0 for step 1, (step - 1) + lambda / lambda_max for step 2; "
               f"lambda_max = {model.steps.lambda_max!r}; stresses Voigt ({VOIGT}) [Pa], sigma_N < 0 compression")
    return write_states(Path(folder), base, mesh.nodes, mesh.hexes, states, times, comment)
