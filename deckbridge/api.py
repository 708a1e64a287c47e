"""The public Python API of deckbridge (``import deckbridge``): the CLI's commands as functions returning
plain-data results whose tables are pandas DataFrames.

    model = deckbridge.load("skirt.yaml").with_overrides({"mesh.n_theta": 48})
    lag = deckbridge.solve(model, method="lagrange")
    lag.sigma_n_wall(1.0)            # sigma_N(theta) through the wall at lambda = 1 [Pa]
    lag.plot()

Units SI; sigma_n < 0 compression, > 0 tension; gap > 0 open; theta [deg] CCW from +x in [0, 360); lambda [-]
multiplies (T, M) in step 2 (step 1: N alone). Result objects: :class:`~deckbridge.api_results.Solution`
(``solve``), :class:`RunResult` (``run``), :class:`~deckbridge.api_studies.Comparison` (``compare``),
:class:`~deckbridge.api_studies.SweepResult` (``sweep``), :class:`~deckbridge.api_studies.LiftoffResult`
(``liftoff``). Summary keys are those of :mod:`deckbridge.summary_keys`. Errors: :class:`deckbridge.DeckbridgeError`
(one line naming the model key or argument and its value).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterable

from . import summary_keys as K
from .api_results import Solution
from .api_studies import Comparison, LiftoffResult, SweepResult
from .errors import DeckbridgeError
from .methods import K_METHODS, LAGRANGE, METHODS as REGISTRY, NAMES, PENALTY
from .model import Model, load

METHODS = NAMES                      # the method registry (deckbridge/methods.py)
PAIR = (PENALTY, LAGRANGE)            # what run and liftoff solve unless told


def default_model() -> Model:
    """The embedded default JAR model (Ariane booster rear skirt on its launch table), the model that
    ``deckbridge run`` runs without argument. Change it with :meth:`Model.with_overrides`."""
    return load(None)


def _check_method(method: str) -> None:
    if method not in METHODS:
        raise DeckbridgeError(f"method = {method!r}: must be one of {', '.join(METHODS)}")


def solve(model: Model, method: str = LAGRANGE, *, k_factor: float = 1.0, alpha: float | None = None,
          algorithm: str | None = None, on_increment: Callable[[int, int, float], None] | None = None,
          mesh=None, release: bool = False) -> Solution:
    """Solve ``model`` with the reference solver and one contact method; what ``deckbridge solve`` computes.

    ``method``: 'penalty' (gap springs k_c = alpha A^2 K / V per node, CGAP/PGAP semantics) or 'lagrange'
    (exact, no penetration). Penalty only: ``k_factor`` multiplies the model's normal stiffness, ``alpha``
    replaces contact.penalty.alpha. Lagrange only: ``algorithm`` 'active-set' (default) or 'gauss-seidel'.
    ``on_increment(step, increment, lambda)`` reports progress. The load path: step 1 N, step 2 N +
    lambda (T, M) up to steps.lambda_max, liftoff onsets bisected. Fields for :meth:`Solution.to_paraview`
    are recovered when ``model.outputs.vtu`` is true. ``mesh``: the model's mesh when already built
    (:func:`deckbridge.mesh.build_mesh`), else built here. ``release``: drop the sparse factor and the dense
    condensed blocks once every field is recovered (``deckbridge solve`` does, before writing its VTUs: at
    millions of dofs the factor is most of the memory); the Solution still writes its files and VTUs
    (:meth:`Solution.write`, :meth:`Solution.to_paraview`) but recovers nothing more (:meth:`Solution.wall_stress`
    gives None unless already filled).
    """
    from .solve import bind, condense_timed, solve_bound
    from .wall_stress import reference_section_onset

    _check_method(method)
    if not REGISTRY[method].uses_k and (alpha is not None or k_factor != 1.0):
        raise DeckbridgeError(f"alpha/k_factor: only for method {' or '.join(K_METHODS)} (Lagrange has no penalty "
                              "stiffness)")
    if algorithm is not None and algorithm not in REGISTRY[method].algorithms:
        raise DeckbridgeError(f"algorithm = {algorithm!r}: only for method lagrange")
    mesh, system, t0 = condense_timed(model, k_factor, alpha, mesh)
    kf, system = bind(model, system, method, k_factor, alpha)          # the penalty factor and springs, once
    if release and not hasattr(system, "base"):      # the laws run on S_c; the recovery reads the factor
        system = system.without_S()
    df, summary, sol, system = solve_bound(model, mesh, system, kf, method, algorithm=algorithm,
                                           on_increment=on_increment, recover=False)
    every = None
    if model.outputs.vtu:       # ONE recovery of every state: the step-end fields and, later, the VTUs
        from reference_solver.recover import path_fields

        from .paraview import step_end_fields
        every = path_fields(system, sol)
        sol.fields.update(step_end_fields(sol, every))
    summary[K.SECTION_LIFTOFF_LOAD_FACTOR], summary[K.SECTION_LIFTOFF_THETA_DEG] = \
        reference_section_onset(system, mesh, sol)
    summary[K.WALL_TIME_S] = time.perf_counter() - t0
    fric = None
    if model.contact.tangential == "friction":
        from .friction_table import friction_table
        fric = friction_table(df, sol, model.contact.friction, system.problem.contact_normals)
    if release:
        system = _released(system)
    return Solution(model, method, df, summary, friction=fric, _solved=(mesh, system, sol), _every_state=every)


def _released(system):
    """``system`` without its sparse factor and dense blocks (:meth:`reference_solver.CondensedSystem.released`);
    a friction system keeps its factor in its frictionless ``base``."""
    import dataclasses

    import numpy as np
    if hasattr(system, "base"):
        return dataclasses.replace(system, base=system.base.released(), S=np.zeros((0, 0)), views={}, cache={})
    return system.released()



@dataclass
class RunResult:
    """What ``deckbridge run`` wrote into ``out``: the two reference solutions, the comparison and the report.

    ``penalty``, ``lagrange``: :class:`~deckbridge.api_results.Solution` (their files in
    ``out/reference_<method>/``); ``comparison``: :class:`~deckbridge.api_studies.Comparison` of every source
    (with ``with_ccx`` the CalculiX jobs too); ``report``: the path of ``out/report.html``; ``out``: the folder.
    """
    penalty: Solution | None
    lagrange: Solution | None
    comparison: Comparison
    report: Path
    out: Path
    others: dict = field(default_factory=dict)     # the other methods asked for ('augmented': Solution)

    def solutions(self) -> dict[str, Solution]:
        """{'penalty': ..., 'lagrange': ..., and any other method solved}."""
        return {k: v for k, v in {PENALTY: self.penalty, LAGRANGE: self.lagrange, **self.others}.items()
                if v is not None}


def run(model: Model | None = None, out: str | Path = "jar-report", *, with_ccx: bool = False,
        solvers: Iterable[str] = (), echo: Callable[[str], None] | None = None,
        methods: Iterable[str] = PAIR) -> RunResult:
    """The main job (``deckbridge run``): decks of every dialect, the reference solver with penalty and
    Lagrange, with ``with_ccx`` CalculiX on its decks (``solvers``: the dialects whose solver runs on its
    decks, e.g. ``("calculix", "mystran")``; ``with_ccx`` = ``"calculix"`` among them), the comparison and
    ``out/report.html``. All or
    nothing: a failed run leaves ``out`` as it was. ``model`` None: the default model. ``echo``: where the
    progress lines go (default: nowhere)."""
    from .job import run_job
    from .solve import penalty_factor

    model = default_model() if model is None else model
    penalty_factor(model)                       # the model's own penalty in range, before any work
    methods = tuple(dict.fromkeys(methods))
    for m in methods:
        _check_method(m)
    res = run_job(model, out, with_ccx=with_ccx, solvers=tuple(solvers), echo=echo or (lambda line: None),
                  methods=methods)
    comp = res["comparison"]
    sols = {}
    for label, rec in comp.sources.items():
        sm = rec.summary or {}
        if sm.get(K.SOURCE) == "reference" and sm.get(K.METHOD) in METHODS:
            sols[sm[K.METHOD]] = Solution(model, sm[K.METHOD], rec.table, sm, wall=rec.wall, friction=rec.friction,
                                          _folder=Path(rec.origin))
    return RunResult(sols.pop(PENALTY, None), sols.pop(LAGRANGE, None), Comparison(comp, model), Path(res["report"]),
                     Path(out), sols)


def compare(*sources, model: Model | None = None, load_factors: Iterable[float] | None = None,
            surface: str = "table", out: str | Path | None = None) -> Comparison:
    """Compare the contact stresses of ``sources`` (what ``deckbridge compare`` does): each a
    :class:`~deckbridge.api_results.Solution`, a result folder or file of any supported format (detected),
    or a tidy DataFrame. ``model``: the model the results belong to (maps node ids of solver files to azimuth).
    ``load_factors``: compare there instead of the defaults (end of step 1, first liftoff, end of step 2).
    ``out``: also write the report there (report.html, sigma_n.png, discrepancy.csv, summary.json)."""
    from .compare import compare_tables
    from .results import SourceResult

    if not sources:
        raise DeckbridgeError("compare: give at least one source")
    records, origins = [], []
    for i, src in enumerate(sources):
        if isinstance(src, Solution):
            src.wall_stress()                               # the base-wall quantities are compared too
            origin = str(src._folder) if src._folder is not None else src.method
            origin = origin if origin not in origins else f"{origin}-{i + 1}"    # two solutions of one method
            records.append(SourceResult(src.table, origin, summary=src.summary, wall=src.wall, friction=src.friction))
            model = model or src.model
        elif isinstance(src, (str, Path)):
            records.append(_read(src, model))
            origin = str(src)
        else:
            records.append(src)
            origin = f"table {i + 1}"
        origins.append(origin)
    lfs = None if load_factors is None else [float(x) for x in load_factors]
    comp = Comparison(compare_tables(records, load_factors=lfs, origins=origins, surface=surface), model)
    if out is not None:
        comp.write_report(out)
    return comp


def _read(src, model):
    from .readers import read_result
    return read_result(src, model=model)


def sweep(model: Model, k_factors: Iterable[float], out: str | Path, *, meshes: list[dict] | None = None,
          grid: list[dict] | None = None, tol: float = 0.02, load_factors: Iterable[float] | None = None,
          open_stiffness: str = "scaled", report: bool = True) -> SweepResult:
    """Penalty-factor sweep against Lagrange (``deckbridge sweep``), in this process, resumable in ``out``.

    ``k_factors``: factors on the model's normal contact stiffness k_c; ``meshes``: mesh variants, e.g.
    ``[{"n_theta": 48}, {"n_theta": 96}]``; ``grid``: variants of other model keys (dotted keys);
    ``tol``: a k-factor reproduces Lagrange when max |d sigma_n| <= tol x |Lagrange peak compression| at every
    compared load factor; ``open_stiffness``: 'scaled' (k_open = open_ratio x k) or 'fixed'."""
    from .studies.sweep import run_sweep
    res = run_sweep(model, [float(k) for k in k_factors], out, meshes=meshes, tol=tol,
                    load_factors=None if load_factors is None else [float(x) for x in load_factors],
                    open_stiffness=open_stiffness, progress=False, report=report, grid=grid)
    return SweepResult(res["summary"], res["variants"], res["quantities"], Path(out))


def liftoff(model: Model, methods: Iterable[str] = PAIR, *, tol: float = 1e-3, k_factor: float = 1.0,
            ) -> LiftoffResult:
    """Critical load factor lambda_c of liftoff per method (``deckbridge liftoff``): the smallest lambda on
    (T, M) in step 2 at which a table node opens, bisected to ``tol`` (absolute in lambda), and its azimuth;
    the search goes beyond steps.lambda_max (up to 100 x) when nothing lifts there."""
    from .limits import check_liftoff_tol
    from .studies.liftoff import critical_load
    methods = tuple(methods)
    for m in methods:
        _check_method(m)
    check_liftoff_tol(tol, model.steps.lambda_max)
    return LiftoffResult(critical_load(model, methods, tol=tol, k_factor=k_factor))
