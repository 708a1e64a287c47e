"""Work done on the Dask workers (or in process): condense a mesh variant once, solve cases on it.

Functions here take and return plain picklable data: the model as a dict, the condensed system
stripped of what only field recovery needs (the sparse factor, which cannot leave its process).
Errors are :class:`DeckbridgeError` with a one-line message; the ``*_or_error`` variants (the Dask
tasks) return them instead of raising.
"""

from __future__ import annotations

import dataclasses
import os
import socket
import time

import numpy as np
import pandas as pd

import reference_solver as rs

from .. import summary_keys as K
from ..errors import DeckbridgeError
from ..methods import PENALTY
from ..model import Model


@dataclasses.dataclass
class Condensed:
    """A mesh variant's mesh and condensed system, ready for any number of cases (no recovery)."""
    mesh: object
    system: object
    condense_s: float
    where: str
    model_dict: dict | None = None     # the model condensed: a case of this very model reuses ``mesh``


def one_blas_thread():
    """Context: BLAS / OpenMP pools limited to one thread (threadpoolctl).

    The contact iterations factor many small dense matrices (a few hundred rows): threads do not pay
    there, and on a busy machine OpenBLAS threads spinning for a core made one solve of the default
    model take 36-68 s instead of about 5 s (2 cores, measured).
    """
    from threadpoolctl import threadpool_limits
    return threadpool_limits(limits=1)


def where() -> str:
    return f"{socket.gethostname()}:{os.getpid()}"


def condense_variant(model_dict: dict, light: bool = True) -> Condensed:
    """Mesh, assemble, factor and condense once; the result serves every method and k-factor (and
    every variant with the same condense key). ``light``: without the sparse factor (it cannot leave
    its process), so without field recovery (no wall stress)."""
    from ..solve import condense_model

    t0 = time.perf_counter()
    model = Model.from_dict(model_dict)
    mesh, system = condense_model(model)
    if light:
        system = without_factor(system)
    return Condensed(mesh, system, time.perf_counter() - t0, where(), model_dict)


def without_factor(system):
    """``system`` without its sparse factor (no field recovery); a friction system keeps it in its
    frictionless ``base`` condensation."""
    if isinstance(system, rs.FrictionSystem):
        return dataclasses.replace(system, base=dataclasses.replace(system.base, schur=None), views={}, cache={})
    return dataclasses.replace(system, schur=None)


def has_factor(system) -> bool:
    """Whether ``system`` can recover fields (its sparse factor is there)."""
    return getattr(system, "base", system).schur is not None


def _bind(cond: Condensed, model: Model):
    """(mesh, system) of ``model`` on a condensation made for a variant with the same condense key:
    the case's contact stiffness, open ratio and tangential springs (re-bound on the retained dofs)."""
    from ..mesh import build_mesh
    from ..solve import build_problem
    from ..tangent_springs import rebind

    # the mesh carries the model's penalties: rebuilt only for a case whose model differs from the
    # condensed one (a --grid point of a solve-time key); a plain k-factor sweep reuses it
    same = cond.model_dict is not None and model.to_dict() == cond.model_dict
    mesh = cond.mesh if same else build_mesh(model)
    prob = build_problem(model, mesh)
    return mesh, rebind(cond.system, dataclasses.replace(cond.system.problem, contact_k=prob.contact_k,
                        k_open_ratio=prob.k_open_ratio, spring_k=prob.spring_k, contact_kt=prob.contact_kt,
                        kt_follows_k=prob.kt_follows_k))


def _system_for(system, method: str, k_factor: float, open_stiffness: str):
    """The system whose problem gives the open-gap stiffness the case asks for."""
    if method != PENALTY or open_stiffness == "scaled":
        return system
    p = system.problem
    ratio = p.k_open_ratio / k_factor          # KB = open_ratio * k_c at every k-factor
    if not 0 < ratio < 1:
        raise DeckbridgeError(f"`open_stiffness` fixed with k-factor {k_factor:g}: the open stiffness "
                              f"(open_ratio {p.k_open_ratio:g} x k_c) would not be below the closed one")
    return dataclasses.replace(system, problem=dataclasses.replace(p, k_open_ratio=ratio))


def solve_case(cond: Condensed, model_dict: dict, method: str, k_factor: float | None,
               open_stiffness: str = "scaled", wall: bool = True) -> tuple[pd.DataFrame, dict, dict]:
    """Solve one case on a condensed variant: (tidy contact table, solver summary, provenance).
    ``wall``: recover the base-wall table (provenance 'wall') when the factor is there; False: no recovery.

    A Lagrange case is the reference of the penalty cases, their limit k -> infinity: with k_t following
    k_n its circumferential springs are rigid (:func:`deckbridge.tangent_springs.follow_springs`, ``limit``),
    a fixed k_t is kept (summary 'k_tangent_rigid')."""
    from ..solve import solve_system

    from ..tangent_springs import follow_springs
    from ..wall_stress import reference_section_onset, reference_wall

    t0 = time.perf_counter()
    model = Model.from_dict(model_dict)
    kf = 1.0 if k_factor is None else float(k_factor)
    wall_table = None
    try:
        mesh, system = _bind(cond, model)
        system = follow_springs(_system_for(system, method, kf, open_stiffness), method, kf, limit=True)
        with one_blas_thread():
            df, summary, sol = solve_system(model, mesh, system, method, kf, recover=False)
            lam_s, th_s = reference_section_onset(system, mesh, sol)
            summary[K.SECTION_LIFTOFF_LOAD_FACTOR], summary[K.SECTION_LIFTOFF_THETA_DEG] = lam_s, th_s
            if wall and has_factor(system):
                wall_table = reference_wall(system, mesh, sol)
    except DeckbridgeError:
        raise
    except Exception as exc:        # anything else crosses the process boundary as one line
        raise DeckbridgeError(f"model {model.name!r}, {method}: {type(exc).__name__}: {exc}") from None
    summary[K.K_TANGENT_FOLLOWS_K] = bool(system.problem.kt_follows_k)
    summary["k_tangent_rigid"] = bool(system.info.get("spring_limit", False))
    if method == PENALTY:
        summary["open_stiffness"] = open_stiffness
        summary["k_open_ratio_used"] = float(system.problem.k_open_ratio)
    prov = {"wall_time_s": time.perf_counter() - t0, "condense_s": cond.condense_s,
            "condensed_on": cond.where, "solved_on": where(), "wall": wall_table}
    return df, summary, prov


# Dask tasks: an expected failure (a model that tips over, say) comes back as a value, not as a
# task error, so that workers do not log it and the other cases go on.
def condense_or_error(model_dict: dict) -> Condensed | DeckbridgeError:
    try:
        return condense_variant(model_dict)
    except DeckbridgeError as exc:
        return exc


def solve_or_error(cond: Condensed | DeckbridgeError, model_dict: dict, method: str, k_factor: float | None,
                   open_stiffness: str = "scaled"):
    """:func:`solve_case`, or the :class:`DeckbridgeError` of the condensation or of the solve."""
    if isinstance(cond, DeckbridgeError):
        return cond
    try:
        return solve_case(cond, model_dict, method, k_factor, open_stiffness)
    except DeckbridgeError as exc:
        return exc


def solve_variant_batch(model_dict: dict, jobs: list[tuple]) -> list:
    """Condense once (with the factor: wall stress recovered) and solve every job (case model dict,
    method, k_factor, open_stiffness) of one condense key, in order.

    Each item is the job's result, or the :class:`DeckbridgeError` it ended with.
    """
    try:
        cond = condense_variant(model_dict, light=False)
    except DeckbridgeError as exc:
        cond = exc
    return [solve_or_error(cond, *job) for job in jobs]
