"""The reference solver run on the neutral model: Model + SkirtMesh -> reference_solver -> tidy table.

``solve_path`` is the one call of the reference solver's load path (``solve``, ``run``, ``sweep`` and
``liftoff`` all go through it); ``solve_model`` returns the contact table (schema of :mod:`deckbridge.results`, source 'reference')
and a summary dict; ``write_outputs`` writes DIR/contact.csv, DIR/summary.json, DIR/result.vtu and the
ParaView series DIR/result.pvd + DIR/result_NNN.vtu atomically. ``build_problem`` and ``condense_model``
expose the translation and the reusable condensed system (factor once, then sweep methods and penalty
factors with ``solve_system``).
Sign conventions: sigma_n_pa < 0 compression, gap_m > 0 open; theta in degrees CCW from +x.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd

import reference_solver as rs

from .errors import DeckbridgeError
from . import summary_keys
from .friction_table import FRICTION_CSV, friction_table
from .jsonable import json_clean
from .azimuth import wrap_deg
from .mesh import SkirtMesh, build_mesh
from .mesh_data import element_key
from .model import Model, ModelError
from .outdir import staged
from .numbering.skirt import mesh_node_ids
from .paraview import result_mesh, write_reference_vtus  # noqa: F401  (result_mesh: solve's public name)
from .results import conform, with_forces
from .methods import method as method_of
from .quantities import law_gaps
from .tangent_springs import follow_springs

SOURCE = "reference"


def check_solvable(model: Model, mesh: SkirtMesh) -> None:
    """Refuse (ModelError naming ``contact.stop.side``) what deckbridge's reference solve does not run on this mesh:
    friction on quadratic contact faces with the radial stop (:data:`deckbridge.mesh_order.QUADRATIC_REFUSED`: the
    face-weighted friction law of reference_solver/friction_face.py cannot weigh a base corner's tangential axis that
    is the stop's normal). Friction on those faces without the stop solves (penalty, Lagrange, augmented). Called by
    :func:`build_problem` and by the job before it writes anything."""
    if mesh.quadratic_faces and model.contact.tangential == "friction" and model.contact.stop.side != "none":
        from .mesh_order import QUADRATIC_REFUSED
        raise ModelError("contact.stop.side", model.contact.stop.side,
                         f"{QUADRATIC_REFUSED} ({'='.join(element_key(model, mesh))})")


def build_problem(model: Model, mesh: SkirtMesh | None = None) -> rs.Problem:
    """Translate the model and its mesh into the solver's arrays (the mesh's element type). Quadratic contact
    faces get the face-weighted laws (``contact_weighting='face'``: Lagrange through the mortar matrix, penalty
    integrated over the faces, reference_solver/face_penalty.py; with the radial stop friction is refused by
    :func:`check_solvable`; the friction problem takes CalculiX's dual basis, ``'face-dual'`` with its shares as the rows'
    areas: reference_solver/friction_face.py)."""
    mesh = mesh or build_mesh(model)
    weighting = "face" if mesh.quadratic_faces else "nodal"   # issue 23: face_law.py, face_penalty.py
    check_solvable(model, mesh)
    rows = mesh.contact_rows
    th = np.radians(mesh.table.theta_deg)
    lv = model.load_vectors()
    z3 = (0.0, 0.0, 0.0)
    fric = model.contact.tangential == "friction"   # issue 14: friction replaces the springs
    kt = np.concatenate([mesh.k_tangent] + [s.k for s in mesh.slave_sets[1:]])
    p = rs.Problem(
        nodes=mesh.nodes, hexes=None if mesh.blocks else mesh.hexes, E=model.material.E, nu=model.material.nu,
        element=mesh.cell_blocks[0][0], blocks=tuple(rs.ElementBlock(n, c) for n, c in mesh.blocks),
        contact_nodes=rows.nodes, contact_normals=rows.normals, contact_area=rows.area,
        contact_k=rows.k, contact_clearance=rows.clearance, contact_surface=rows.surface,
        spring_nodes=mesh.table.nodes[:0 if fric else None],
        spring_dirs=np.stack([-np.sin(th), np.cos(th), np.zeros_like(th)], axis=1)[:0 if fric else None],
        spring_k=mesh.k_tangent[:0 if fric else None],
        ref_point=mesh.ref_point, coupling=model.load_introduction,
        coupling_nodes=mesh.top_nodes, coupling_weights=mesh.top_weights,
        loads={"N": (*lv["N_force"], *z3), "T": (*lv["T_force"], *z3), "M": (*z3, *lv["M_moment"])},
        k_open_ratio=mesh.k_open_ratio, friction=model.contact.friction,
        tangential=model.contact.tangential, contact_kt=kt, kt_follows_k=model.contact.penalty.k_tangent_follows,
        contact_weighting=weighting,
    )
    if mesh.quadratic_faces and fric:     # friction on 8-/6-node faces: ccx's dual basis (friction_face.py)
        from reference_solver.friction_face import dual_shares
        p = dual_shares(p)
    return p


def condense_model(model: Model, mesh: SkirtMesh | None = None, **kw) -> tuple[SkirtMesh, rs.CondensedSystem]:
    """Mesh, translate and condense once; ``kw`` goes to :func:`reference_solver.condense`."""
    mesh = mesh or build_mesh(model)
    try:
        return mesh, rs.condense(build_problem(model, mesh), **kw)
    except rs.ReferenceSolverError as exc:
        raise DeckbridgeError(f"model {model.name!r}: {exc}") from None


def penalty_factor(model: Model, k_factor: float = 1.0, alpha: float | None = None) -> float:
    """Factor on the model's penalty stiffness; ``alpha`` re-scales the alpha A^2 K / V rule.

    Refused before any work (ModelError naming the argument ``k_factor`` or ``alpha``, which the CLI
    shows as its flag): a factor that is not a positive number, and one that puts the penalty
    stiffness outside :data:`PENALTY_RATIO` (:func:`penalty_ratio`)."""
    if not (isinstance(k_factor, (int, float)) and math.isfinite(k_factor) and k_factor > 0):
        raise ModelError("k_factor", k_factor, "must be a positive number")
    if alpha is None:
        return _in_range(model, float(k_factor), "k_factor", k_factor)
    if not (math.isfinite(alpha) and alpha > 0):
        raise ModelError("alpha", alpha, "must be a positive number")
    pen = model.contact.penalty
    if pen.k_normal is not None:
        raise ModelError("alpha", alpha, f"the model sets contact.penalty.k_normal = {pen.k_normal!r}, "
                         "so alpha is not used (use the k-factor, or set k_normal null)")
    return _in_range(model, float(k_factor) * alpha / pen.alpha, "alpha", alpha)


# The penalty stiffness over the element's axial stiffness, rho = k_c / (E A / h) = alpha K / E (the
# decks' header; with contact.penalty.k_normal: k_normal h / (E A), h = H / n_z, A = 2 pi R t / (n_theta n_r)).
# Measured (24 x 6 x 1 and the default 72 x 30 x 2 JAR, fixed k_t, node forces against Lagrange at
# lambda = 1): the penalty error falls like 1/rho to 6e-4 / 2.4e-3 at rho = 833, then round-off takes
# over and grows like rho (7.5 % at 8.3e4, 49 % at 8.3e5 on the default mesh); below, rho = 2.5e-5
# reports a false tip-over (N R > M + T H) and below 1e-5 "no contact possible" or a LinAlgError.
PENALTY_RATIO = (5.0e-5, 1.0e4)


def penalty_ratio(model: Model, kf: float) -> float:
    """rho = k_c / (E A / h) of the model's penalty at factor ``kf`` [-] (see :data:`PENALTY_RATIO`)."""
    pen, mat = model.contact.penalty, model.material
    if pen.k_normal is None:
        return pen.alpha * kf * mat.bulk_modulus / mat.E
    g, ms = model.geometry, model.mesh
    area = 2.0 * math.pi * g.radius * g.thickness / (ms.n_theta * ms.n_r)
    return pen.k_normal * kf * (g.height / ms.n_z) / (mat.E * area)


def _in_range(model: Model, kf: float, key: str, value: float) -> float:
    rho = penalty_ratio(model, kf)
    lo, hi = PENALTY_RATIO
    if not lo <= penalty_ratio(model, 1.0) <= hi:        # the model's own penalty: name its key
        pen = model.contact.penalty
        key, value = ("contact.penalty.alpha", pen.alpha) if pen.k_normal is None else \
            ("contact.penalty.k_normal", pen.k_normal)
        rho = penalty_ratio(model, 1.0)
    if not lo <= rho <= hi:
        raise ModelError(key, value, f"puts the penalty stiffness at {rho:.3g} x the element's axial stiffness "
                         f"E A / h, outside [{lo:g}, {hi:g}]: beyond, round-off (stiffer) or a near-free "
                         "contact (softer) gives wrong contact stresses")
    return kf


def bind(model: Model, system: rs.CondensedSystem, method: str, k_factor: float = 1.0,
         alpha: float | None = None) -> tuple[float, rs.CondensedSystem]:
    """The one place the penalty factor and the tangential springs are applied: (final k-factor, the system
    the solve runs on). ``k_factor``/``alpha`` checked by :func:`penalty_factor`; the springs re-bound by
    :func:`deckbridge.tangent_springs.follow_springs` (a small dense solve on the spring dofs when they
    change; none when the system is already bound to this method and factor)."""
    method_of(method)
    kf = penalty_factor(model, k_factor, alpha)
    return kf, follow_springs(system, method, kf)


def solve_path(model: Model, system: rs.CondensedSystem, method: str, k_factor: float = 1.0, *,
               lambda_max: float | None = None, liftoff_tol: float | None = None, algorithm: str | None = None,
               on_increment: Callable[[int, int, float], None] | None = None,
               recover: bool = True) -> rs.Solution:
    """The model's load path: step 1 N, step 2 N + lambda (T, M) up to ``lambda_max`` (default the
    model's steps.lambda_max) in steps.increments, liftoff onset located on the table to ``liftoff_tol``
    (relative to lambda_max; default the solver's). ``k_factor`` is the final penalty factor (see
    :func:`penalty_factor`); the springs are bound here unless ``system`` is already bound (:func:`bind`);
    ``on_increment(step, increment, lambda)`` reports progress."""
    system = follow_springs(system, method, k_factor)     # k_t = k_factor x k_c when k_t follows k_n
    return _path(model, system, method, k_factor, lambda_max=lambda_max, liftoff_tol=liftoff_tol,
                 algorithm=algorithm, on_increment=on_increment, recover=recover)


def _path(model, system, method, k_factor, *, lambda_max=None, liftoff_tol=None, algorithm=None,
          on_increment=None, recover=True) -> rs.Solution:
    kw = {} if liftoff_tol is None else {"liftoff_tol": liftoff_tol}
    try:
        return rs.solve_path(system, method, k_factor, base={"N": 1.0}, ramp={"T": 1.0, "M": 1.0},
                             lambda_max=model.steps.lambda_max if lambda_max is None else lambda_max,
                             increments=model.steps.increments, algorithm=algorithm, liftoff_surface="table",
                             recover=recover, on_increment=on_increment, **kw)
    except rs.ReferenceSolverError as exc:
        raise DeckbridgeError(f"model {model.name!r}, method {method}: {exc}{_past_tipping(model, lambda_max)}") from None


def _past_tipping(model: Model, lambda_max: float | None) -> str:
    """'; steps.lambda_max = ... is past the tipping load ...' when it is (the likely cause of a failure), else ''."""
    lam, tip = model.steps.lambda_max if lambda_max is None else lambda_max, model.tipping_load_factor()
    if tip is None or lam < tip:
        return ""
    return (f"; steps.lambda_max = {lam:g} is past the tipping load of a compression-only base, lambda = "
            f"N (R + t/2) / (M + T H) = {tip:.4g}: no equilibrium beyond it (lower steps.lambda_max or the loads)")


def solve_system(model: Model, mesh: SkirtMesh, system: rs.CondensedSystem, method: str,
                 k_factor: float = 1.0, alpha: float | None = None, algorithm: str | None = None,
                 on_increment: Callable[[int, int, float], None] | None = None,
                 recover: bool = True) -> tuple[pd.DataFrame, dict, rs.Solution]:
    """Run the load path of ``model`` on an existing condensed system; (table, summary, solution)."""
    return solve_bound(model, mesh, *bind(model, system, method, k_factor, alpha)[::-1], method,
                       algorithm=algorithm, on_increment=on_increment, recover=recover)[:3]


def solve_bound(model: Model, mesh: SkirtMesh, system: rs.CondensedSystem, kf: float, method: str, *,
                algorithm: str | None = None, on_increment=None,
                recover: bool = True) -> tuple[pd.DataFrame, dict, rs.Solution, rs.CondensedSystem]:
    """The load path on a system :func:`bind` returned (factor ``kf`` applied); (table, summary, solution, system)."""
    t0 = time.perf_counter()
    sol = _path(model, system, method, kf, algorithm=algorithm, on_increment=on_increment, recover=recover)
    df = contact_table(system.problem, mesh, sol)
    summary = make_summary(model, mesh, system, sol, df, kf)
    summary["wall_time_s"] = system.info.get("total_s", 0.0) + (time.perf_counter() - t0)
    return df, summary, sol, system


def condense_timed(model: Model, k_factor: float = 1.0, alpha: float | None = None,
                   mesh: SkirtMesh | None = None) -> tuple[SkirtMesh, rs.CondensedSystem, float]:
    """Check the penalty options, then mesh and condense; (mesh, system, start time) with
    ``system.info['total_s']`` the seconds so far (bad factors fail before any work)."""
    t0 = time.perf_counter()
    penalty_factor(model, k_factor, alpha)
    mesh, system = condense_model(model, mesh)
    system.info["total_s"] = time.perf_counter() - t0
    return mesh, system, t0


def solve_model(model: Model, method: str, k_factor: float = 1.0, alpha: float | None = None,
                algorithm: str | None = None, on_increment=None, recover: bool = True,
                ) -> tuple[pd.DataFrame, dict]:
    """Mesh, condense and solve ``model`` with ``method``; returns (tidy table, summary dict)."""
    mesh, system, _ = condense_timed(model, k_factor, alpha)
    df, summary, _ = solve_system(model, mesh, system, method, k_factor, alpha, algorithm,
                                  on_increment, recover)
    return df, summary


def contact_table(p: rs.Problem, mesh: SkirtMesh, sol: rs.Solution) -> pd.DataFrame:
    """One row per (increment, contact row) in the tidy schema."""
    ni, nc = sol.sigma_n.shape
    rows = mesh.contact_rows
    rep = lambda a: np.repeat(a, nc)  # noqa: E731
    til = lambda a: np.tile(a, ni)    # noqa: E731
    df = with_forces(pd.DataFrame({
        "source": SOURCE, "method": sol.method, "step": rep(sol.step), "increment": rep(sol.increment),
        "load_factor": rep(sol.load_factor), "node": til(mesh_node_ids(mesh, p.contact_nodes)),
        "surface": til(p.contact_surface), "theta_deg": til(wrap_deg(rows.theta)),
        "z": til(rows.z), "r": til(rows.r), "sigma_n_pa": sol.sigma_n.ravel(), "gap_m": law_gaps(p, sol).ravel(),
        "status": np.where(sol.closed.ravel(), "closed", "open"),
    }), til(p.contact_area), sol.force.ravel())   # the solver's own nodal force (> 0 compressive): -sigma_n x area
    return conform(df)                          # on nodal laws, D^T lambda on face-weighted ones (quantities.py)


def _stats(a: np.ndarray) -> dict | None:
    if a is None or a.size == 0:
        return None
    return {"min": float(a.min()), "max": float(a.max()), "mean": float(a.mean()), "count": int(a.size)}


def reactions(p: rs.Problem, sol: rs.Solution, row: int) -> tuple[np.ndarray, np.ndarray]:
    """Resultant force [N] and moment about the reference point [N m] of the contact reactions (normal and,
    with friction, tangential: the table's force on the body) and the spring reactions."""
    f = sol.force[row][:, None] * p.contact_normals
    if getattr(sol, "tangential_force", None) is not None:
        f = f + sol.tangential_force[row]
    fs = sol.spring_force[row][:, None] * p.spring_dirs
    F = f.sum(axis=0) + fs.sum(axis=0)
    M = (np.cross(p.nodes[p.contact_nodes] - p.ref_point, f).sum(axis=0)
         + np.cross(p.nodes[p.spring_nodes] - p.ref_point, fs).sum(axis=0))
    return F, M


def contact_row_theta(mesh: SkirtMesh, row: int) -> float:
    """Azimuth [deg, 0..360) of the node of contact row ``row``."""
    return float(mesh.contact_rows.theta[row])


def make_summary(model: Model, mesh: SkirtMesh, system: rs.CondensedSystem, sol: rs.Solution,
                 df: pd.DataFrame, k_factor: float) -> dict:
    p = system.problem
    lift_theta = None if sol.liftoff_row is None else contact_row_theta(mesh, sol.liftoff_row)
    ends = {s: int(np.flatnonzero(sol.step == s)[-1]) for s in (1, 2)}
    react = {str(s): reactions(p, sol, i) for s, i in ends.items()}
    pen = None
    if method_of(sol.method).uses_k:
        pen = {"k_factor": k_factor, "alpha": (model.contact.penalty.alpha * k_factor
                                               if model.contact.penalty.k_normal is None else None),
               "k_open_ratio": p.k_open_ratio,
               **{s: _stats(sol.penalty_k[p.contact_surface == s]) for s in ("table", "stop")}}
    out = {
        "source": SOURCE, "method": sol.method, "algorithm": sol.algorithm, "model": model.name,
        "load_introduction": model.load_introduction,
        "dofs": int(3 * p.n_nodes), "reduced_dofs": int(system.dofs),
        "condensed_dofs": int(system.info["retained"]), "contact_rows": int(p.n_contacts),
        "liftoff_load_factor": sol.liftoff_load_factor, "liftoff_theta_deg": lift_theta,
        summary_keys.BEAM_THEORY_LIFTOFF_LOAD_FACTOR: model.beam_theory_liftoff(),
        "min_sigma_n_pa": float(df["sigma_n_pa"].min()), "max_sigma_n_pa": float(df["sigma_n_pa"].max()),
        "reaction_force_n": {s: v[0].tolist() for s, v in react.items()},
        "reaction_moment_nm": {s: v[1].tolist() for s, v in react.items()},
        "penalty_k": pen,
        summary_keys.AUGMENTED: _augmented_summary(sol),
        "k_tangent": _stats(p.spring_k),
        "friction": sol.friction_check(p, p.friction) if p.friction > 0 else None,
        "tangential": p.tangential,
        "gross_slip_load_factor": getattr(sol, "gross_slip_load_factor", None),
        "solver": {"sparse": system.info["schur"], "contact": sol.algorithm,
                   "increments": int(sol.step.size), "iterations": int(sol.iterations.sum())},
        "timings_s": {k: float(v) for k, v in system.info.items() if k.endswith("_s")}
        | {"load_path_s": float(sol.wall_time_s)},
        "wall_time_s": None,
    }
    return out


def _augmented_summary(sol: rs.Solution) -> dict | None:
    """The augmented Lagrangian's work and accuracy: augmentations (total, largest per increment) and the
    final penetration against its tolerance [m]; None for the other methods."""
    if sol.augmentations is None:
        return None
    return {"augmentations": int(sol.augmentations.sum()), "augmentations_max": int(sol.augmentations.max()),
            "penetration_m": float(sol.penetration.max()), "penetration_tol_m": sol.penetration_tol}


_COMPUTE = object()     # write_outputs: the friction table not given, computed there


def write_outputs(outdir: str | Path, model: Model, system: rs.CondensedSystem, sol: rs.Solution,
                  df: pd.DataFrame, summary: dict, mesh: SkirtMesh | None = None,
                  U: np.ndarray | None = None, fric=_COMPUTE) -> list[Path]:
    """Write contact.csv, summary.json, with friction friction.csv (:mod:`deckbridge.friction_table`), and (outputs.vtu) result.vtu plus the ParaView series result.pvd,
    result_NNN.vtu (one per increment, :mod:`deckbridge.paraview`) into ``outdir`` atomically. ``U`` (rows, n, 3) [m]:
    every row's displacements when the caller already recovered them (else recovered here, once); ``fric``: the
    friction table when the caller already made it (None: no friction), else made here."""
    names = ["contact.csv", "summary.json"]
    with staged(outdir) as stage:
        df.to_csv(stage / "contact.csv", index=False)
        (stage / "summary.json").write_text(json.dumps(json_clean(summary), indent=2) + "\n")
        if fric is _COMPUTE:        # only with contact.tangential: friction
            fric = friction_table(df, sol, model.contact.friction, system.problem.contact_normals)
        if fric is not None:
            fric.to_csv(stage / FRICTION_CSV, index=False, float_format="%.17g")
            names.append(FRICTION_CSV)
        if model.outputs.vtu:       # result.vtu + the series, from one recovery of every row (deckbridge.paraview)
            names += [f.name for f in write_reference_vtus(stage, model, mesh or build_mesh(model), system, sol, U=U)]
    return [Path(outdir) / n for n in names]


def run_solve(model: Model, method: str, outdir: str | Path, k_factor: float = 1.0,
              alpha: float | None = None, algorithm: str | None = None,
              on_increment=None) -> tuple[list[Path], dict]:
    """The ``deckbridge solve`` job: solve and write; returns (written paths, summary)."""
    mesh, system, t0 = condense_timed(model, k_factor, alpha)
    kf, system = bind(model, system, method, k_factor, alpha)
    df, summary, sol, system = solve_bound(model, mesh, system, kf, method, algorithm=algorithm,
                                           on_increment=on_increment, recover=False)  # write_outputs recovers every row once
    summary["wall_time_s"] = time.perf_counter() - t0
    return write_outputs(outdir, model, system, sol, df, summary, mesh), summary


from .api_callable import make_callable  # noqa: E402  (deckbridge.solve(model, ...) is the API call)
make_callable(__name__)
