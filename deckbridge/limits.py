"""Ceilings checked from the model and the options before any work is done.

Memory of a solve (``check_memory``), in two tiers:
- ``quick_estimate``, arithmetic on the mesh keys (nothing allocated, microseconds): dof = 3 x n_theta x
  (n_z + 1) x (n_r + 1) (an imported mesh, ``mesh.file``: 3 x its node count, the file read once for it),
  bytes = 250 MiB + BYTES_PER_DOF x dof + DENSE_BYTES x nr^2 with nr <= n_theta (2 (n_r + 1) + 1)
  retained dofs (table and stop normals, tangential springs; twice that with friction), plus with
  ``outputs.vtu`` the strain operator for dof / 3 hexahedra. Meant as an upper bound: a model under it
  starts at once.
- ``symbolic_estimate``, from the mesh's own symbolic factorisation (CHOLMOD ``analyze`` of its node
  graph gives the factor's entries before any numeric work; :mod:`reference_solver.estimate`) plus the
  arrays the command holds: the load path (the factor and PATH_DENSE_ARRAYS nr x nr arrays of the condensed
  contact problem) and, with ``outputs.vtu``, the VTU stage (every state's displacements, the Gauss-point
  strain operator being built, the states' fields; `deckbridge solve` has released the factor and the
  dense blocks by then). Run only when the quick bound does not fit (it builds the mesh and its graph:
  seconds at 1M dof, minutes at 3M).
A model whose estimate exceeds the memory available now (psutil when installed, else /proc/meminfo
MemAvailable) is refused with one line naming the mesh keys and the estimate, unless ``--allow-large``
is given or the environment sets ``DECKBRIDGE_ALLOW_LARGE=1``. Even then, a mesh whose stiffness matrix
alone (FLOOR_BYTES_PER_DOF, well below the measured peak) exceeds the machine's memory and swap
together is refused naming the mesh keys: numpy would fail with "Unable to allocate ... EiB". Other caps
bound work that memory does not: k-factors, cases of a study, workers, liftoff tolerance
(``steps.increments`` is capped in the model).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np

from .errors import InputError

BASE_BYTES = 0.15e9          # interpreter, numpy/scipy, pandas [bytes]
BYTES_PER_DOF = 10.5e3       # measured peak, factorisation + Schur complement included [bytes/dof]
FLOOR_BYTES_PER_DOF = 1e3    # the sparse stiffness alone (>= 81 nonzeros x 12 bytes per row) [bytes/dof]
QUICK_BASE_BYTES = 250 * 2**20   # reference_solver.estimate.BASE_BYTES (not imported: the quick bound imports nothing)
DENSE_BYTES = 10 * 8         # about ten nr x nr float64 arrays of the condensed contact problem [bytes/entry]
SYMBOLIC_MAX_DOFS = 30e6     # above: refused on the quick estimate alone (the symbolic analysis itself would take GBs)
# VTU stage (outputs.vtu), per element of one chunk of STRESS_CHUNK elements (reference_solver.recover.
# STRESS_CHUNK, 2048) on each of STRESS_THREADS threads: the displacement gradients, stresses and nodal values
# of every state (Element.displacement_gradients: about 1.6-1.9 kB per state and 8-node hexahedron, 21-28 kB at
# 13 states), counted in units of the (8 Gauss points, 6, 24) float64 strain operator that was built before
STRAIN_OPERATOR_BYTES = 8 * 6 * 24 * 8
STRAIN_OPERATOR_COPIES = 3.0      # fitted: the peak at 102k dof fell by 33 MiB when the operator (4 copies) went
# every state's VTU data is held until the files are written: per node displacement 3, contact 8 (2
# surfaces), tangential and friction 4, nodal stress and von Mises 7, the writer's copies; per element
# stress and von Mises. Fitted on `deckbridge solve` at 102k and 205k dof after the stress recovery went
# by chunks (peak 899 and 1492 MiB): about 29 floats per node and state.
STATE_POINT_FLOATS = 29
STATE_CELL_FLOATS = 7
STRESS_CHUNK = 2048               # reference_solver.recover.STRESS_CHUNK (not imported: a test checks they agree)
STRESS_THREADS = 2                # reference_solver.recover.STRESS_THREADS: chunks recovered at once
# the symbolic estimate's other terms (solve_estimate), fitted on the measured peaks of bench/memory_guard.py
PROCESS_BYTES = 170 * 2**20        # interpreter, NumPy/SciPy/pandas/CHOLMOD, deckbridge
FACTOR_BYTES_PER_ENTRY = 1.1 * 8   # the factor's values, its integer part and CHOLMOD's workspace
SPLIT_BYTES_PER_NODE = 230 * 27    # node-pair blocks, their indices and the permuted CSC triangle
# nr x nr float64 arrays alive at once beside the factor in `deckbridge solve` (counted, bench/README.md "Dense
# blocks at the peak"): the Schur step's trailing block L_rr and L_rr L_rr^T (2), then S with S_c, G_s (ns x nc)
# and the dense factor of S_c's contact rows (1.8), S dropped for the path (0.9) and the recovery (1.6); 2.2
# fitted on the dense-dominated 800x16x2 (nr 5,600: estimate / peak 1.07) for the Schur step's other arrays
PATH_DENSE_ARRAYS = 2.2
VTU_DENSE_ARRAYS = 0               # `deckbridge solve` releases the factor and the dense blocks before its VTUs
# a command that keeps the condensed system for later solves (`deckbridge run`: both methods, the report's
# verdict) holds S, S_c, G_s throughout, the factor through its VTUs: counted 2.6 nr^2 on the path (S + S_c +
# G_s + L_rr re-read while recovering), 1.6 beside the factor in the VTU stage (not measured at the peak)
KEPT_PATH_DENSE_ARRAYS = 2.6
KEPT_VTU_DENSE_ARRAYS = 1.6
ESTIMATE_MARGIN = 1.05             # for what the fit does not hold (allocator, the other method): 1.08-1.14 x measured
ALLOW_ENV = "DECKBRIDGE_ALLOW_LARGE"
MAX_K_FACTORS = 100
MAX_CASES = 2000             # cases of one study (mesh variants x (k-factors + 1))
MAX_MESH_VARIANTS = 50
MAX_GRID_CASES = 200          # grid points of one study (product of the --grid values)
MAX_WORKERS_PER_CORE = 4
MAX_LOAD_FACTORS = 100
TOL_REL_MIN = 1e-9           # liftoff --tol >= TOL_REL_MIN x lambda_max: the bisection then stops


def dofs(n_theta: int, n_z: int, n_r: int) -> int:
    """Degrees of freedom of the structured hexahedral mesh (3 per node)."""
    return 3 * int(n_theta) * (int(n_z) + 1) * (int(n_r) + 1)


def estimate_bytes(n_dofs: int) -> float:
    """Peak memory of one reference solve of ``n_dofs`` degrees of freedom from the dof count alone
    [bytes] (the line of the first measurements; :func:`quick_estimate` adds the dense contact block)."""
    return BASE_BYTES + BYTES_PER_DOF * float(n_dofs)


def _imported(model) -> bool:
    return getattr(model.mesh, "file", None) is not None


def retained_bound(model) -> int:
    """Upper bound of the retained (condensed) dofs of a structured mesh: per azimuth the table's and the
    stop's normals and the tangential springs of the n_r + 1 base nodes; x2 with friction. 0 for an
    imported mesh (its sets are not known without reading them)."""
    if _imported(model):
        return 0
    m = model.mesh
    per_azimuth = 2 * (int(m.n_r) + 1) + 1
    friction = getattr(model.contact, "tangential", "") == "friction"
    return int(m.n_theta) * per_azimuth * (2 if friction else 1)


def contact_rows_floor(model) -> int:
    """Lower bound of the condensed contact rows of a structured mesh: every base node of the ring (n_theta x
    (n_r + 1)), or with pads at least count x (floor(width_deg / 360 x n_theta) - 1) (snapping, radial band of
    one node). 0 for an imported mesh. Its dense block (8 bytes per entry) is memory no solve can avoid."""
    if _imported(model):
        return 0
    m = model.mesh
    pads = getattr(model.contact, "pads", None)
    if pads is None:
        return int(m.n_theta) * (int(m.n_r) + 1)
    return int(pads.count) * max(0, int(np.floor(float(pads.width_deg) / 360.0 * int(m.n_theta))) - 1)


def model_dofs(model) -> int:
    """Dofs of the model's mesh: arithmetic for the structured mesh, 3 x the node count of an imported file."""
    m = model.mesh
    if _imported(model):           # an imported mesh: 3 dof per node of the file (read once here)
        from .importers.read import read_mesh_file
        return 3 * int(read_mesh_file(m.file).node_ids.size)
    return dofs(m.n_theta, m.n_z, m.n_r)


def quick_estimate(model, n_dofs: int | None = None) -> float:
    """Arithmetic upper estimate of one solve's peak memory [bytes] (see the module doc); with
    ``outputs.vtu`` the strain operator of the VTU stage on top (hexahedra <= nodes = dofs / 3)."""
    n = model_dofs(model) if n_dofs is None else n_dofs
    vtu = STRAIN_OPERATOR_COPIES * STRAIN_OPERATOR_BYTES * n / 3.0 if model.outputs.vtu else 0.0
    return (QUICK_BASE_BYTES + BYTES_PER_DOF * float(n)
            + DENSE_BYTES * float(retained_bound(model)) ** 2 + vtu)


@dataclass
class Estimate:
    """Peak memory of a solve from the mesh's symbolic factorisation: ``bytes`` the peak, ``parts`` the
    stages it is the largest of [bytes], ``factor_entries`` of the Cholesky factor."""
    bytes: float
    dofs: int
    retained: int
    factor_entries: int
    parts: dict = field(default_factory=dict)


def symbolic_estimate(model, mesh=None, released: bool = True) -> Estimate:
    """Peak memory of ``deckbridge solve`` on ``model`` from its mesh's own symbolic factorisation;
    ``released`` False: of a command that keeps the factor and the dense blocks (``deckbridge run``)."""
    from reference_solver import estimate
    from .mesh import build_mesh
    from .solve import build_problem
    p = build_problem(model, mesh or build_mesh(model))
    nr = int(p.n_contacts + p.n_springs)
    cells = [b.cells for b in p.blocks]              # every block (a mixed mesh's hexes alone are not all)
    nL = estimate.factor_entries(cells, p.n_nodes)
    if nL is None:                                  # no CHOLMOD: the shell fit of reference_solver.estimate
        nL = int(26.0 * 3 * p.n_nodes * max(1.0, float(np.log2(max(3 * p.n_nodes, 2)))))   # its shell fit
    nL += nr * (nr + 1) // 2                        # the retained dofs are ordered last: a dense trailing block
    rows = int(model.steps.increments) + 2          # states of the series (end of step 1, increments 0..n)
    return solve_estimate(p.n_nodes, sum(len(c) for c in cells), nr, nL, rows, bool(model.outputs.vtu), released)


def solve_estimate(n_nodes: int, n_hex: int, n_retained: int, factor_entries: int, states: int,
                   vtu: bool = True, released: bool = True) -> Estimate:
    """The peak [bytes] of a solve of ``n_nodes`` nodes, ``n_hex`` hexahedra, ``n_retained`` retained
    dofs and a factor of ``factor_entries`` entries, writing ``states`` VTUs when ``vtu``: the largest of
    the split (K as node-pair blocks and its permuted triangle), the load path (the factor, about
    PATH_DENSE_ARRAYS nr x nr arrays) and the VTU stage (every state's fields, the strain operator of one
    chunk of elements being built; ``deckbridge solve`` has released the factor and the dense blocks by then).
    Monotone in every argument. Fitted on `deckbridge solve` (penalty) at 100k-200k dof, every proportion
    of bench/README.md "Dense blocks at the peak" (estimate / measured peak there)."""
    n, N, nr2 = int(n_nodes), 3 * int(n_nodes), float(n_retained) ** 2
    base = PROCESS_BYTES + 200 * n + 130 * n_hex                 # interpreter and libraries, mesh, problem
    factor = FACTOR_BYTES_PER_ENTRY * float(factor_entries)
    dense = PATH_DENSE_ARRAYS if released else max(PATH_DENSE_ARRAYS, KEPT_PATH_DENSE_ARRAYS)
    parts = {"split": base + SPLIT_BYTES_PER_NODE * n, "load_path": base + factor + dense * 8 * nr2}
    if vtu:
        fields = states * 8 * (STATE_POINT_FLOATS * n + STATE_CELL_FLOATS * n_hex)     # every state's VTU data
        operator = STRAIN_OPERATOR_COPIES * STRAIN_OPERATOR_BYTES * min(n_hex, STRESS_THREADS * STRESS_CHUNK)
        kept = 0.0 if released else factor + KEPT_VTU_DENSE_ARRAYS * 8 * nr2        # solve: released
        parts["vtu"] = base + kept + VTU_DENSE_ARRAYS * 8 * nr2 + fields + operator
    return Estimate(ESTIMATE_MARGIN * max(parts.values()), N, int(n_retained), int(factor_entries), parts)


def available_bytes() -> float | None:
    """Memory available to a new process now [bytes]; None when it cannot be told."""
    try:
        import psutil
        return float(psutil.virtual_memory().available)
    except Exception:  # noqa: BLE001  (psutil absent or failing: fall back to /proc)
        pass
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except OSError:
        return None
    return None


def total_bytes() -> float | None:
    """Physical memory plus swap of this machine [bytes]: what no process can exceed; None when unknown."""
    total = 0.0
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith(("MemTotal:", "SwapTotal:")):
                    total += float(line.split()[1]) * 1024.0
    except (OSError, ValueError, IndexError):
        return None
    return total or None


def allow_large_from_env() -> bool:
    return os.environ.get(ALLOW_ENV, "").strip().lower() in ("1", "true", "yes")


def _mesh_name(model) -> str:
    m = model.mesh
    if _imported(model):
        return f"mesh {m.file}"
    return f"mesh.n_theta x mesh.n_z x mesh.n_r = {m.n_theta} x {m.n_z} x {m.n_r}"


def check_memory(model, allow_large: bool = False, copies: int = 1, what: str = "", mesh=None,
                 released: bool = True) -> float:
    """Refuse ``model`` (one line naming the mesh keys, the estimate in it) when ``copies`` solves would
    not fit in the memory available now; returns the estimate [bytes].

    The quick arithmetic bound first (refuses n_theta = 10^6 in microseconds); when it does not fit, the
    estimate from the mesh's symbolic factorisation decides (:func:`symbolic_estimate`, ``mesh`` when
    already built, or a function building it, called only then), so that a model that fits is not refused
    on the bound alone. ``released``: the command frees the factor and the dense blocks before its VTUs
    (``deckbridge solve``); False for one that keeps them (``deckbridge run``).
    """
    m = model.mesh
    n = model_dofs(model)
    if allow_large or allow_large_from_env():
        total = total_bytes()
        if total is not None and copies * FLOOR_BYTES_PER_DOF * n > total:     # allow_large cannot help
            name = (f"mesh.file = {str(m.file)!r}" if _imported(model) else
                    f"mesh.n_theta x mesh.n_z x mesh.n_r = {m.n_theta} x {m.n_z} x {m.n_r}")
            raise InputError(f"{name}{what}: {n:,} dofs need at least {copies * FLOOR_BYTES_PER_DOF * n / 1e9:.3g} "
                             f"GB (the stiffness matrix alone), more than this machine's memory and swap "
                             f"({total / 1e9:.3g} GB), even with `allow_large`: use a coarser mesh")
        return copies * quick_estimate(model, n)
    have = available_bytes()
    need, how = copies * quick_estimate(model, n), "arithmetic bound"
    floor = copies * 8.0 * float(contact_rows_floor(model)) ** 2
    if have is not None and floor > have:           # no symbolic analysis (seconds to minutes) to refuse this
        need, how = max(need, floor), "its dense contact block alone"
    elif have is not None and need > have and n <= SYMBOLIC_MAX_DOFS and copies * FLOOR_BYTES_PER_DOF * n <= have:
        need, how = copies * symbolic_estimate(model, mesh() if callable(mesh) else mesh, released).bytes, \
            "from its symbolic factorisation"
    if have is not None and need > have:
        each = f" ({copies} at once)" if copies > 1 else ""
        raise InputError(f"{_mesh_name(model)}{what}: {n:,} dofs need about {need / 1e9:.3g} GB{each} ({how}), "
                         f"{have / 1e9:.3g} GB available: use a coarser mesh, or `allow_large` "
                         f"(or {ALLOW_ENV}=1) to try anyway")
    return need


def check_count(option: str, n: int, cap: int, unit: str) -> None:
    """Refuse more than ``cap`` ``unit`` for ``option``."""
    if n > cap:
        raise InputError(f"{option}: {n} {unit}, at most {cap} are allowed")


def check_workers(workers: int | None) -> None:
    """Worker processes: positive and at most MAX_WORKERS_PER_CORE per core."""
    if workers is None:
        return
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise InputError(f"`workers` = {workers!r}: must be a positive integer")
    cap = MAX_WORKERS_PER_CORE * max(1, os.cpu_count() or 1)
    if workers > cap:
        raise InputError(f"`workers` = {workers}: at most {cap} ({MAX_WORKERS_PER_CORE} per core) are allowed")


def check_liftoff_tol(tol: float, lambda_max: float) -> None:
    """The bisection on lambda must be able to reach ``tol``: tol >= TOL_REL_MIN x lambda_max."""
    floor = TOL_REL_MIN * lambda_max
    if isinstance(tol, (int, float)) and tol == tol and 0 < tol < floor:
        raise InputError(f"`tol` = {tol!r}: must be at least {floor:g} ({TOL_REL_MIN:g} x steps.lambda_max): "
                         "finer than the bisection can resolve in double precision")
