"""The one load-path driver: step 1 (base load), step 2 (base + lambda * ramp) along targets, any contact law.

Every increment is one call of the law (:mod:`reference_solver.laws`): from the previous converged state
(path-dependent laws, friction) or warm-started from it (path-independent ones). An increment that does
not converge is cut back into halves (up to ``CUTBACKS`` times); one that slides the body ends the path
at the bisected onset of gross slip. The liftoff onset (first watched row that opens) is bracketed by the
increments and located by :func:`reference_solver.onset.first_opening` (exact for path-independent
laws). Each converged increment is an :class:`Increment` record.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import Callable, Mapping, Sequence

import numpy as np

from .contact import Unbounded
from .errors import ReferenceSolverError, no_equilibrium
from .friction_state import GrossSlip, NotConverged, State
from .laws import make_law
from .onset import first_opening, is_open, reach, widest_open
from .onset import section_onset as _section_onset
from .solution import Solution  # noqa: F401  (re-exported: reference_solver.path.Solution)
from .threads import with_blas_threads

CUTBACKS = 5             # an increment that does not converge is halved up to this many times
ONSETS = ("auto", "bisection", "off")
SECTION_TOL = 1e-9       # the whole-section onset's tolerance on lambda (path-independent laws: exact pieces)


@dataclass
class Increment:
    """One converged increment of the path."""
    step: int                     # 1 (base load) or 2 (base + lambda * ramp)
    index: int                    # increment number within the step (step 2 starts at 0: lambda = 0)
    load_factor: float            # lambda [-]
    coeffs: np.ndarray            # (ncase,) load-case coefficients
    state: State                  # the law's converged state


def _secant(r0: Increment, r1: Increment, lam: float) -> np.ndarray | None:
    """Linear estimate of x at ``lam`` through two converged step-2 increments, else None."""
    if r0.step != 2 or r1.step != 2 or r0.load_factor == r1.load_factor:
        return None
    return r1.state.x + (lam - r1.load_factor) / (r1.load_factor - r0.load_factor) * (r1.state.x - r0.state.x)


def _advance(law, prev: State, co: Callable, lam: float, lam_prev: float, depth: int, guess) -> State:
    """One increment to ``lam`` (coefficients ``co(lam)``), cut back into halves when it does not converge."""
    try:
        return law.increment(prev, co(lam), guess=guess, depth=depth)
    except NotConverged:
        if depth >= CUTBACKS:
            raise
        mid = 0.5 * (lam_prev + lam)
        half = None if guess is None else 0.5 * (prev.x + guess)
        return _advance(law, _advance(law, prev, co, mid, lam_prev, depth + 1, half), co, lam, mid, depth + 1, guess)


@with_blas_threads
def solve_path(system, method: str = "penalty", k_factor: float = 1.0, *,
               base: Mapping[str, float] | None = None, ramp: Mapping[str, float] | None = None,
               lambda_max: float = 1.0, increments: int = 10, targets: Sequence[float] | None = None,
               algorithm: str | None = None, liftoff_surface: str | None = None, liftoff_tol: float = 1e-6,
               onset: str = "auto", recover: bool = True, on_increment: Callable[[int, int, float], None] | None = None,
               on_gross_slip: str = "raise", corner: str | None = None) -> Solution:
    """Run step 1 (``base``) and step 2 (``base + lambda * ramp``) with the contact law ``method``.

    Step 2 visits ``targets`` in order (default ``[lambda_max]``), ``increments`` equal increments per
    leg. ``k_factor`` multiplies the problem's penalty stiffness (laws that use one). Defaults: base
    {'N': 1}, ramp {'T': 1, 'M': 1}. The onset hook ``liftoff_surface``: the contact surface whose first
    opening row is the liftoff onset (None: every row); ``onset`` 'auto' (exact where the law tracks it,
    else bisection to ``liftoff_tol`` x lambda_max), 'bisection' or 'off'. ``on_gross_slip`` 'raise'
    (:class:`GrossSlip`, with the onset as ``err.load_factor``) or 'stop' (the path ends at the last
    converged increment, the onset in ``gross_slip_load_factor``); ``corner`` a friction corner rule.
    """
    t0 = time.perf_counter()
    p = system.problem
    if onset not in ONSETS:
        raise ReferenceSolverError(f"onset = {onset!r}: must be one of {', '.join(ONSETS)}")
    if on_gross_slip not in ("raise", "stop"):
        raise ReferenceSolverError(f"on_gross_slip = {on_gross_slip!r}: must be raise or stop")
    law = make_law(system, method, k_factor, algorithm, **({} if corner is None else {"corner": corner}))
    targets = [float(lambda_max)] if targets is None else [float(v) for v in targets]
    if increments < 1 or not (lambda_max > 0) or not targets or not all(np.isfinite(targets)):
        raise ReferenceSolverError("increments must be >= 1, lambda_max > 0 and targets finite load factors")
    cb = system.coeffs({"N": 1.0} if base is None else base)
    cr = system.coeffs({"T": 1.0, "M": 1.0} if ramp is None else ramp)
    co = lambda lam: cb + lam * cr  # noqa: E731
    watch = np.ones(p.n_contacts, bool) if liftoff_surface is None else p.contact_surface == liftoff_surface
    watch = law.onset_watch(watch) if hasattr(law, "onset_watch") else watch   # rows whose opening is a lift
    c0 = p.contact_clearance
    scale = max(abs(v) for v in targets + [lambda_max])

    def run(prev: State, lam: float, lam_prev: float | None, guess=None, step: int = 2) -> State:
        """The state at ``lam``; cutbacks from ``lam_prev`` (None: none, a sub-increment of an onset)."""
        try:
            return _advance(law, prev, co, lam, lam if lam_prev is None else lam_prev,
                            CUTBACKS if lam_prev is None else 0, guess)
        except Unbounded:
            raise no_equilibrium(step, lam) from None

    def done(r: Increment) -> None:
        rows.append(r)
        if on_increment:
            on_increment(r.step, r.index, r.load_factor)

    rows: list[Increment] = []
    first = run(law.start(), 0.0, None, step=1)
    done(Increment(1, 1, 0.0, cb, first))
    done(Increment(2, 0, 0.0, cb, replace(first, iterations=0, augmentations=0)))
    lift = slide = None
    if onset != "off" and is_open(first, c0, watch, law):
        lift = (0.0, widest_open(first, c0, watch, law), None)
    lam_prev, j = 0.0, 0
    for target in targets:
        for m in range(1, increments + 1):
            lam = lam_prev + (target - lam_prev) * m / increments if m < increments else target
            lo = rows[-1]
            st, slide = reach(lambda a_st, b, a, g: run(a_st, b, a, g), lo.state, lo.load_factor, lam,
                              _secant(rows[-2], lo, lam), scale, lambda b: no_equilibrium(2, b))
            if slide is not None:
                if on_gross_slip == "raise":
                    err = GrossSlip(f"step 2, load factor {lam:.6g}: the load slides the body (gross slip from "
                                    f"load factor {slide:.6g}; friction cannot carry the tangential load)")
                    err.load_factor = slide
                    raise err from None
                break
            if law.tips_open and watch.any() and not np.any(st.active & watch):
                raise ReferenceSolverError(f"step 2, load factor {lam:.6g}: the load tips the body over "
                                           f"(every {liftoff_surface or 'contact'} row is open)")
            if lift is None and onset != "off" and is_open(st, c0, watch, law):
                back = rows[-2] if rows[-2].step == 2 and rows[-2].load_factor != lo.load_factor else None
                lift = first_opening(law, lambda a_st, b, g: run(a_st, b, None, g), (lo.load_factor, lo.state),
                                     (lam, st), None if back is None else (back.load_factor, back.state), co, cr, watch,
                                     tol=liftoff_tol, scale=scale, exact=onset == "auto")
            j += 1
            done(Increment(2, j, lam, co(lam), st))
        else:
            lam_prev = target
            continue
        break

    states = [r.state for r in rows]
    C = np.array([r.coeffs for r in rows])
    arrays = law.arrays(states, C)
    sigma = law.sigma_n(arrays["force"]) if hasattr(law, "sigma_n") else 0.0 - arrays["force"] / p.contact_area
    sol = Solution(
        method=law.name, algorithm=law.algorithm, k_factor=k_factor if law.uses_k else None,
        penalty_k=law.penalty_k, step=np.array([r.step for r in rows]), increment=np.array([r.index for r in rows]),
        load_factor=np.array([r.load_factor for r in rows]), coeffs=C, sigma_n=sigma,
        liftoff_load_factor=None if lift is None else float(lift[0]), liftoff_row=None if lift is None else lift[1],
        liftoff_method=None if lift is None else lift[2], gross_slip_load_factor=slide, **arrays,
        path_states=[(r.load_factor, r.state) for r in rows if r.step == 2] if law.stateful else None)
    if recover:
        sol.recover_step_ends(system, law.retained(states))
    sol.wall_time_s = time.perf_counter() - t0
    return sol


def _restarted_state_at(system, sol: Solution, base, ramp) -> tuple[Callable[[float], tuple], object]:
    """(``state_at(lam)``, the law) of a path-dependent law along ``sol``: one increment (cut back like
    :func:`solve_path`'s, gross slip raised the same way) from the converged state at the largest load factor
    below ``lam`` among ``sol``'s step-2 increments (never from another search point: a chain of them would
    make the state depend on the search's order, not on ``lam`` alone)."""
    law = make_law(system, sol.method, sol.k_factor or 1.0, sol.algorithm)
    cb = system.coeffs({"N": 1.0} if base is None else base)
    cr = system.coeffs({"T": 1.0, "M": 1.0} if ramp is None else ramp)
    co = lambda lam: cb + lam * cr  # noqa: E731
    known = sol.path_states

    def run(a_st: State, lam: float, a: float, guess) -> State:
        try:
            return _advance(law, a_st, co, lam, a, 0, guess)
        except Unbounded:
            raise no_equilibrium(2, lam) from None

    def state_at(lam: float):
        below = sorted(((lf, st) for lf, st in known if lf < lam), key=lambda r: r[0])
        (a, a_st), back = below[-1], below[-2] if len(below) > 1 and below[-2][0] < below[-1][0] else None
        guess = None if back is None else a_st.x + (lam - a) / (a - back[0]) * (a_st.x - back[1].x)
        st, slide = reach(run, a_st, a, lam, guess, abs(lam), lambda b: no_equilibrium(2, b))
        if slide is not None:
            err = GrossSlip(f"step 2, load factor {lam:.6g}: the load slides the body (gross slip from "
                            f"load factor {slide:.6g}; friction cannot carry the tangential load)")
            err.load_factor = slide
            raise err from None
        if law.tips_open and not np.any(st.active):
            raise ReferenceSolverError(f"step 2, load factor {lam:.6g}: the load tips the body over "
                                       f"(every contact row is open)")
        arr = law.arrays([st], co(lam)[None])
        return arr["gap"][0], arr["force"][0], arr["closed"][0]
    return state_at, law


def section_onset(system, sol: Solution, groups: list[np.ndarray], *, base: Mapping[str, float] | None = None,
                  ramp: Mapping[str, float] | None = None, tol: float | None = None) -> tuple[float | None, int | None]:
    """The whole-section onset of :func:`reference_solver.onset.section_onset` along ``sol``: (lambda, group
    index), each state the end of a one-increment path with ``sol``'s method, k-factor and algorithm
    (``base``/``ramp`` as given to :func:`solve_path`, defaults the same). A path-dependent law (friction,
    ``sol.path_states`` kept): each state is one increment from the converged state at the largest load
    factor below it among ``sol``'s increments (the bracket's lower end) instead of from lambda = 0.
    ``tol`` on lambda; None: 1e-9, and for a path-dependent law the first-node onset's resolution
    ``law.onset_floor`` x the path's largest load factor (friction: SLIDE_TOL = 1e-4; each search point is a
    friction increment, and its state is defined to that resolution only: a finer search cost ~25 restarts)."""
    if sol.path_states:
        state_at, law = _restarted_state_at(system, sol, base, ramp)
        if tol is None:
            tol = max(SECTION_TOL, law.onset_floor * float(np.max(np.abs(sol.load_factor))))
        return _section_onset(system, sol, groups, state_at, tol, bisect=True)
    tol = SECTION_TOL if tol is None else tol

    def state_at(lam: float):
        s = solve_path(system, sol.method, sol.k_factor or 1.0, base=base, ramp=ramp, lambda_max=lam, increments=1,
                       algorithm=sol.algorithm, onset="off", recover=False)
        return s.gap[-1], s.force[-1], s.closed[-1]
    return _section_onset(system, sol, groups, state_at, tol)
