"""Ceilings checked from the model and the options before any work is done (nothing is allocated).

Memory of a solve, estimated from the structured mesh alone: dof = 3 x n_theta x (n_z + 1) x (n_r + 1)
(an imported mesh, ``mesh.file``: 3 x its node count, the file read once for it)
and bytes = BASE_BYTES + BYTES_PER_DOF x dof, a line above the peak resident memory measured for the
reference solver (README: 0.25 GB at 20k dof, 0.96 GB at 100k, 3.8 GB at 400k, 10.5 GB at 1M dof).
A model whose estimate exceeds the memory available now (psutil when installed, else /proc/meminfo
MemAvailable) is refused with the estimate in the message, unless ``--allow-large`` is given or the
environment sets ``DECKBRIDGE_ALLOW_LARGE=1``. Even then, a mesh whose stiffness matrix alone
(FLOOR_BYTES_PER_DOF, well below the measured peak) exceeds the machine's memory and swap together is
refused naming the mesh keys: numpy would fail with "Unable to allocate ... EiB". Other caps bound work that memory does not: k-factors,
cases of a study, workers, liftoff tolerance (``steps.increments`` is capped in the model).
"""

from __future__ import annotations

import os

from .errors import InputError

BASE_BYTES = 0.15e9          # interpreter, numpy/scipy, pandas [bytes]
BYTES_PER_DOF = 10.5e3       # measured peak, factorisation + Schur complement included [bytes/dof]
FLOOR_BYTES_PER_DOF = 1e3    # the sparse stiffness alone (>= 81 nonzeros x 12 bytes per row) [bytes/dof]
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
    """Estimated peak memory of one reference solve of ``n_dofs`` degrees of freedom [bytes]."""
    return BASE_BYTES + BYTES_PER_DOF * float(n_dofs)


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


def check_memory(model, allow_large: bool = False, copies: int = 1, what: str = "") -> float:
    """Refuse ``model`` (one line, the estimate in it) when ``copies`` solves would not fit in memory.

    Returns the estimate [bytes]. Pure arithmetic: refuses n_theta = 10^6 in microseconds.
    """
    m = model.mesh
    n = dofs(m.n_theta, m.n_z, m.n_r)
    if getattr(m, "file", None) is not None:   # an imported mesh: 3 dof per node of the file (read once here)
        from .importers.read import read_mesh_file
        n = 3 * int(read_mesh_file(m.file).node_ids.size)
    need = copies * estimate_bytes(n)
    if allow_large or allow_large_from_env():
        total = total_bytes()
        if total is not None and copies * FLOOR_BYTES_PER_DOF * n > total:     # allow_large cannot help
            name = (f"mesh.file = {str(m.file)!r}" if getattr(m, "file", None) is not None else
                    f"mesh.n_theta x mesh.n_z x mesh.n_r = {m.n_theta} x {m.n_z} x {m.n_r}")
            raise InputError(f"{name}{what}: {n:,} dofs need at least {copies * FLOOR_BYTES_PER_DOF * n / 1e9:.3g} "
                             f"GB (the stiffness matrix alone), more than this machine's memory and swap "
                             f"({total / 1e9:.3g} GB), even with `allow_large`: use a coarser mesh")
        return need
    have = available_bytes()
    if have is not None and need > have:
        each = f" ({copies} at once)" if copies > 1 else ""
        name = m.file if getattr(m, "file", None) is not None else f"{m.n_theta}x{m.n_z}x{m.n_r}"
        raise InputError(f"mesh {name}{what}: {n:,} dofs need about {need / 1e9:.3g} GB{each}, "
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
