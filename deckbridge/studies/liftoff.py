"""Critical load factor of liftoff: the lambda on (T, M) in step 2 at which the first table node lifts.

``critical_load(model, methods, tol)`` condenses the model once and, per method, runs the load path
(step 1 N, step 2 N + lambda (T, M)) with the solver's bisection of the onset to ``tol`` in lambda
(absolute): ``lambda_c`` is the smallest load factor found lifted, the onset lies in
[lambda_c - tol, lambda_c]. When nothing lifts off up to ``steps.lambda_max`` the search goes on beyond it, doubling
the range up to ``EXPAND`` x lambda_max, and says so; when nothing lifts off there either, lambda_c is
None with the reason. Beam theory for a thin ring under M_b = lambda (M + T H): lambda_c = N R / (2 M_b(1)).
"""

from __future__ import annotations

import math

from .. import summary_keys as K
from ..errors import DeckbridgeError
from ..methods import LAGRANGE, METHODS as REGISTRY, NAMES, PENALTY
from ..model import Model
from ..solve import condense_model, contact_row_theta, penalty_factor, solve_path
from .tasks import one_blas_thread

EXPAND = 100.0          # search up to this many times steps.lambda_max
METHODS = (PENALTY, LAGRANGE)      # the default pair ('both'); any of deckbridge.methods.NAMES is accepted


def _one(model: Model, mesh, system, method: str, tol: float, k_factor: float) -> dict:
    lam_max = model.steps.lambda_max
    top = EXPAND * lam_max
    hi = lam_max
    tried = []
    while True:
        sol = solve_path(model, system, method, k_factor, lambda_max=hi, liftoff_tol=tol / hi, recover=False)
        tried.append(hi)
        if sol.liftoff_load_factor is not None or hi >= top:
            break
        hi = min(2.0 * hi, top)
    lam = sol.liftoff_load_factor
    out = {"method": method, "k_factor": k_factor if REGISTRY[method].uses_k else None,
           "lambda_c": lam, "theta_deg": None if lam is None else contact_row_theta(mesh, sol.liftoff_row),
           "bracket": None if lam is None else [max(0.0, lam - tol), lam],
           "tol": tol, "searched_up_to": hi, "expanded": hi > lam_max, "lambda_max": lam_max,
           "base_moment_at_lambda_c_nm": None if lam is None else lam * model.base_moment}
    if lam is None:
        out["message"] = (f"no liftoff up to lambda = {hi:g} ({EXPAND:g} x steps.lambda_max = {lam_max:g})"
                          + ("; M + T H = 0: step 2 does not bend the skirt" if model.base_moment == 0 else ""))
    elif out["expanded"]:
        out["message"] = (f"no liftoff up to steps.lambda_max = {lam_max:g}: searched beyond it, "
                          f"found at lambda = {lam:.6g}")
    else:
        out["message"] = None
    return out


def critical_load(model: Model, methods: tuple[str, ...] | list[str] = METHODS, tol: float = 1e-3,
                  k_factor: float = 1.0) -> dict:
    """lambda_c and its azimuth per method (one condensation for all); with two methods, the difference."""
    if not (isinstance(tol, (int, float)) and math.isfinite(tol) and tol > 0):
        raise DeckbridgeError(f"`tol` = {tol!r}: must be a positive number (absolute, in load factor)")
    if tol >= model.steps.lambda_max:
        raise DeckbridgeError(f"`tol` = {tol!r}: must be smaller than steps.lambda_max = {model.steps.lambda_max:g}")
    for m in methods:
        if m not in NAMES:
            raise DeckbridgeError(f"`methods` = {m!r}: must be one of {', '.join(NAMES)}")
    kf = penalty_factor(model, k_factor)
    mesh, system = condense_model(model)
    with one_blas_thread():
        res = {m: _one(model, mesh, system, m, tol, kf) for m in methods}
    follows = model.contact.penalty.k_tangent_follows and model.contact.tangential == "springs"
    out = {"model": model.name, "load_introduction": model.load_introduction, "tol": tol,
           K.K_TANGENT_FOLLOWS_K: follows,
           K.BEAM_THEORY_LIFTOFF_LOAD_FACTOR: model.beam_theory_liftoff(),
           "base_moment_nm_at_lambda_1": model.base_moment, "methods": list(methods), **res}
    if PENALTY in res and LAGRANGE in res:
        a, b = (res[m]["lambda_c"] for m in METHODS)
        out["difference"] = None if a is None or b is None else {
            "penalty_minus_lagrange": a - b, "relative_to_lagrange": (a - b) / b if b else None}
    return out


def format_table(result: dict) -> str:
    """The result as a plain-text table (one line per method), then notes."""
    lines = [f"{'method':<18} {'lambda_c':>10} {'theta [deg]':>12} {'M_b [N m]':>12}  note"]
    for m in result["methods"]:
        r = result[m]
        lam = "none" if r["lambda_c"] is None else f"{r['lambda_c']:.5f}"
        th = "-" if r["theta_deg"] is None else f"{r['theta_deg']:.1f}"
        mb = "-" if r["base_moment_at_lambda_c_nm"] is None else f"{r['base_moment_at_lambda_c_nm']:.4g}"
        name = m if r["k_factor"] is None else f"{m} (k x {r['k_factor']:g})"
        lines.append(f"{name:<18} {lam:>10} {th:>12} {mb:>12}  {r['message'] or ''}".rstrip())
    d = result.get("difference")
    if d is not None:
        rel = "" if d["relative_to_lagrange"] is None else f" ({d['relative_to_lagrange'] * 100:+.2f} % of Lagrange)"
        lines.append(f"difference penalty - lagrange: {d['penalty_minus_lagrange']:+.5f}{rel}")
    if result.get(K.K_TANGENT_FOLLOWS_K):
        lines.append("note: contact.penalty.k_tangent follows alpha: the circumferential springs are k_c(alpha) "
                     "(x the k-factor for penalty), so both onsets depend on alpha, Lagrange's too; "
                     "set k_tangent to a number [N/m] to compare methods at a fixed restraint")
    bt = result[K.BEAM_THEORY_LIFTOFF_LOAD_FACTOR]
    lines.append(f"beam theory (thin ring, rigid section) N R / (2 (M + T H)): "
                 + ("none (M + T H = 0)" if bt is None else f"{bt:.5f}")
                 + f"; tolerance {result['tol']:g} in lambda")
    return "\n".join(lines)
