"""ParaView time series of the reference solver's load path: ``<base>.pvd`` + one ``<base>_NNN.vtu`` per state.

One VTU per row of the reference :class:`~reference_solver.Solution` (the end of step 1, then every
increment j = 0..increments of step 2), all on the skirt mesh (node id = mesh index + 1, element id =
hexahedron index + 1). The ``.pvd`` (ParaView's XML collection) lists them in load-path order with the
pseudo-time t = (step - 1) + lambda / lambda_max for step 2 and t = 0 for step 1 (monotone, one time per
state; step 2 ends at t = 2), the convention of CalculiX's total time; a comment before each DataSet
says ``step S increment I load_factor L`` (increment j of step 2 is at lambda = j lambda_max / increments).

Point data (SI; 0 off the contact, never NaN there):
  ``displacement_m`` (n, 3); ``node_id``; ``<surface>_sigma_n_pa`` contact stress of the table / stop slave
  (sigma_N = -force / area on 4-/3-node faces, the projected pressure on 8-/6-node faces; < 0 compression);
  ``<surface>_gap_m`` (> 0 open; the table's gap_m, :func:`deckbridge.quantities.law_gaps`); ``<surface>_status``
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

Cost (issue 22, bench/README.md): every state's displacement comes from ONE recover call (one
multi-right-hand-side back substitution) and every state's stresses from the displacement gradients at the
Gauss points, all states at once (:func:`reference_solver.recover.states_stress`); result.vtu (:func:`result_mesh`)
takes its step ends from the same displacements and their centre stresses in one product
(:func:`reference_solver.recover.centre_stress`). Each VTU is meshio's binary XML, zlib-compressed block by
block at :data:`ZLIB_LEVEL` (meshio has no option for the level), blocks that hardly deflate (the float64
results) stored at level 0, several files at once on :func:`writer_threads` threads (zlib releases the GIL
while it compresses).
"""

from __future__ import annotations

import contextlib
import os
import threading
import xml.etree.ElementTree as ET
import zlib
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

from reference_solver.kinematics import von_mises
from reference_solver.recover import centre_stress, path_fields, states_stress

from .mesh import SkirtMesh
from .numbering.skirt import bottom_row_index, elem_ids, mesh_node_ids
from .quantities import law_gaps

VOIGT = "xx yy zz xy yz zx"
SURFACES = ("table", "stop")
# zlib level of the VTUs' blocks. Measured on the 100k-dof default skirt (160 x 70 x 2, one state, 9.6 MB of
# arrays): level 6 (zlib's and meshio's default) 0.57 s and 4.79 MB, level 1 0.33 s and 4.84 MB
# (1 % larger, 1.7x faster), no compression 0.10 s and 13.3 MB (base64).
ZLIB_LEVEL = 1
# Blocks whose first STORE_SAMPLE bytes deflate to more than STORE_RATIO of their size are stored (zlib level 0:
# a valid zlib stream of stored deflate blocks, read as any other): the float64 results (displacements,
# stresses, von Mises) deflate to only 0.81-0.87 at level 1, and took 94 % of a state's zlib time (100k dof,
# 160 x 70 x 2: 104 of 111 ms per state) for 13-19 % of their bytes.
STORE_SAMPLE = 4096
STORE_RATIO = 0.75
_PATCH = threading.Lock()


class _LeveledZlib:
    """The zlib module with ``compress`` at a fixed level (what meshio's VTU writer calls per block); blocks
    that hardly deflate (judged on their first :data:`STORE_SAMPLE` bytes) are stored, level 0.

    A block met a second time within one batch of files is compressed once more and remembered; from
    its third time on the remembered bytes are returned (zlib is deterministic: the same bytes as
    compressing it). The series' states repeat their mesh (points, connectivity, ids, sets, areas: about
    40 % of a state's bytes) and their all-zero blocks. Only a block whose first :data:`STORE_SAMPLE`
    bytes were met before is hashed whole (a block of results costs the hash of its sample)."""

    def __init__(self, level: int):
        self._level = level
        self._heads: set[int] = set()
        self._seen: set[int] = set()
        self._memo: dict[bytes, bytes] = {}

    def _compress(self, block: bytes) -> bytes:
        if len(block) > 2 * STORE_SAMPLE and self._level > 0:
            sample = block[:STORE_SAMPLE]
            if len(zlib.compress(sample, self._level)) > STORE_RATIO * len(sample):
                return zlib.compress(block, 0)
        return zlib.compress(block, self._level)

    def compress(self, block: bytes) -> bytes:
        head = hash(block[:STORE_SAMPLE])
        if head not in self._heads:           # the first block with these first bytes: no whole-block hash
            self._heads.add(head)
            return self._compress(block)
        hit = self._memo.get(block)
        if hit is not None:
            return hit
        out = self._compress(block)
        key = hash(block)
        if key in self._seen:                 # the second time (or a hash collision: one more entry)
            self._memo[block] = out
        else:
            self._seen.add(key)
        return out

    def __getattr__(self, name):
        return getattr(zlib, name)


@contextlib.contextmanager
def zlib_level(level: int = ZLIB_LEVEL):
    """Inside: meshio's VTU writer compresses at ``level`` (its module's ``zlib`` name swapped for
    :class:`_LeveledZlib`; left alone when meshio no longer calls it so). Not re-entrant across threads:
    hold it around a whole batch of writes."""
    import meshio.vtu._vtu as vtu
    with _PATCH:
        saved = getattr(vtu, "zlib", None)
        if saved is not zlib:
            yield
            return
        vtu.zlib = _LeveledZlib(level)
        try:
            yield
        finally:
            vtu.zlib = saved


def writer_threads(n_files: int) -> int:
    """Threads writing VTUs at once: the cores this process may use, at most 2 and at most ``n_files``."""
    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cores = os.cpu_count() or 1
    return max(1, min(2, cores, n_files))


def write_vtus(jobs: list[tuple[Path, object]]) -> None:
    """Write meshio meshes ``[(path, mesh), ...]`` as zlib-compressed binary VTUs, several at once."""
    import meshio
    with zlib_level():
        write = lambda job: meshio.write(job[0], job[1], file_format="vtu", binary=True,  # noqa: E731
                                         compression="zlib")
        n = writer_threads(len(jobs))
        if n == 1:
            for job in jobs:
                write(job)
            return
        with ThreadPoolExecutor(n) as pool:
            list(pool.map(write, jobs))


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
    kind = {8: "hexahedron", 20: "hexahedron20", 10: "tetra10", 15: "wedge", 6: "wedge", 4: "tetra"}[cells.shape[1]]
    return kind, (cells[:, :6] if cells.shape[1] == 15 else cells)


def vtk_blocks(cells: np.ndarray) -> list[tuple[str, np.ndarray]]:
    """:func:`vtk_cells` of each block of ``cells``: (m, k), or a mixed mesh's cells padded with -1
    (``SkirtMesh.hexes``; consecutive rows with one node count are one block)."""
    cells = np.asarray(cells, np.int64)
    n = (cells >= 0).sum(axis=1)
    cut = np.flatnonzero(np.diff(n)) + 1
    return [vtk_cells(c[:, :int(k[0])]) for c, k in zip(np.split(cells, cut), np.split(n, cut))]


def by_block(blocks, values: np.ndarray) -> list[np.ndarray]:
    """Per-cell ``values`` split into meshio's one array per cell block of ``blocks`` [(kind, cells), ...]."""
    return np.split(np.asarray(values), np.cumsum([len(c) for _, c in blocks])[:-1])


def state_mesh(nodes: np.ndarray, hexes: np.ndarray, state: dict):
    """meshio mesh of one state {'point', 'cell', ...} on the cells (any type of :func:`vtk_cells`; a mixed mesh's
    padded cells as one block per type)."""
    import meshio
    blocks = vtk_blocks(hexes)
    return meshio.Mesh(nodes, blocks, point_data=state["point"],
                       cell_data={k: by_block(blocks, v) for k, v in state["cell"].items()})


def write_states(folder: Path, base: str, nodes: np.ndarray, hexes: np.ndarray, states: list[dict],
                 times: np.ndarray, comment: str) -> list[Path]:
    """Write ``base_NNN.vtu`` per state and ``base.pvd``; each state {'point', 'cell', 'label'}."""
    files = [f"{base}_{k:03d}.vtu" for k in range(len(states))]
    write_vtus([(folder / name, state_mesh(nodes, hexes, st)) for name, st in zip(files, states)])
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


def reference_states(model, mesh: SkirtMesh, system, sol, U: np.ndarray | None = None,
                     ) -> tuple[list[dict], np.ndarray]:
    """Point and cell data of every row of ``sol`` and their pseudo-times (see the module doc); ``U``
    (rows, n, 3) [m] the displacements of every row when already recovered (:func:`path_fields`)."""
    p = system.problem
    U = path_fields(system, sol) if U is None else U        # one solve for every row
    gaps = law_gaps(p, sol)                                 # the table's gap_m (quantities.law_gaps)
    base_point, base_cell = mesh_data(mesh)
    states = []
    for r, s in enumerate(states_stress(p, U)):
        tang, fric = tangential_point_data(p, sol, r)
        point = {**base_point, "displacement_m": U[r],
                 **contact_data(p.n_nodes, p.contact_nodes, p.contact_surface, sol.sigma_n[r], gaps[r],
                                sol.closed[r]),
                 "tangential_force_n": tang, "friction_force_n": fric, "stress_nodal_pa": s["nodal"],
                 "von_mises_nodal_pa": s["nodal_von_mises"]}
        cell = {**base_cell, "stress_pa": s["cell"], "von_mises_pa": s["cell_von_mises"]}
        states.append({"point": point, "cell": cell,
                       "label": state_label(sol.step[r], sol.increment[r], sol.load_factor[r])})
    return states, pseudo_time(sol.step, sol.load_factor, model.steps.lambda_max)


def series_comment(model, sol) -> str:
    return (f"deckbridge reference solver ({sol.method}), model {model.name}: one VTU per state; "
            "timestep = 0 for step 1, (step - 1) + lambda / lambda_max for step 2; "
            f"lambda_max = {model.steps.lambda_max!r}; stresses Voigt ({VOIGT}) [Pa], sigma_N < 0 compression")


def write_reference_series(folder: str | Path, model, mesh: SkirtMesh, system, sol,
                           base: str = "result", U: np.ndarray | None = None) -> list[Path]:
    """Write ``base.pvd`` and ``base_NNN.vtu`` of the reference load path into ``folder`` (a staging
    folder: the caller makes the writing atomic); returns the written paths, the pvd first. ``U``: every
    row's displacements when already recovered."""
    states, times = reference_states(model, mesh, system, sol, U)
    return write_states(Path(folder), base, mesh.nodes, mesh.hexes, states, times, series_comment(model, sol))


def step_end_fields(sol, U: np.ndarray) -> dict:
    """{step: (n, 3) displacements [m]} at the end of steps 1 and 2: rows of ``U`` (rows, n, 3) [m], every
    row of ``sol`` (:func:`reference_solver.recover.path_fields`)."""
    return {s: U[int(np.flatnonzero(sol.step == s)[-1])] for s in (1, 2)}


def result_mesh(p, sol, U: np.ndarray | None = None):
    """meshio mesh of result.vtu: displacement, element-centre von Mises and contact stress and pressure
    at the end of each step. ``U`` (rows, n, 3) [m]: every row's displacements (the step ends are taken
    from it); without it, the Solution's own step-end ``fields``."""
    import meshio
    point, cell = {}, {}
    ends = {s: int(np.flatnonzero(sol.step == s)[-1]) for s in (1, 2)}
    fields = sol.fields if U is None else step_end_fields(sol, U)
    steps = sorted(fields)
    centre = von_mises(centre_stress(p, np.stack([fields[s] for s in steps])))    # both step ends at once
    for s, vm in zip(steps, centre):
        u, last = fields[s], ends[s]
        point[f"displacement_step{s}_m"] = u
        for surf in np.unique(p.contact_surface):
            rows = p.contact_surface == surf
            sig = np.zeros(p.n_nodes)
            sig[p.contact_nodes[rows]] = sol.sigma_n[last, rows]
            point[f"{surf}_sigma_n_step{s}_pa"] = sig
            point[f"{surf}_contact_pressure_step{s}_pa"] = np.maximum(-sig, 0.0)
        cell[f"von_mises_step{s}_pa"] = vm
    blocks = [vtk_cells(b.cells) for b in p.blocks]
    return meshio.Mesh(p.nodes, blocks, point_data=point, cell_data={k: by_block(blocks, v) for k, v in cell.items()})


def write_reference_vtus(folder: str | Path, model, mesh: SkirtMesh, system, sol, base: str = "result",
                         U: np.ndarray | None = None) -> list[Path]:
    """result.vtu and the series ``base.pvd`` + ``base_NNN.vtu`` from ONE recovery of every row's
    displacements (``U`` (rows, n, 3) [m] when the caller already holds it), all VTUs written in one batch
    (:func:`write_vtus`); returns the paths, result.vtu first, then the pvd and the series."""
    folder = Path(folder)
    U = path_fields(system, sol) if U is None else U
    states, times = reference_states(model, mesh, system, sol, U)
    files = [f"{base}_{k:03d}.vtu" for k in range(len(states))]
    jobs = [(folder / "result.vtu", result_mesh(system.problem, sol, U))]
    jobs += [(folder / name, state_mesh(mesh.nodes, mesh.hexes, st)) for name, st in zip(files, states)]
    write_vtus(jobs)
    pvd = write_pvd(folder / f"{base}.pvd", files, times, series_comment(model, sol), [st["label"] for st in states])
    return [folder / "result.vtu", pvd] + [folder / f for f in files]
