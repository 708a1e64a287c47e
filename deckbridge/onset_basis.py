"""The face-weighted Lagrange's liftoff onsets checked in a second multiplier basis (issue 23, "where does the
base lift off, at what load").

On 8-/6-node table faces the reference Lagrange puts its sign condition on the multipliers of the non-negative hat
basis (reference_solver/face_law.py); its onsets are where one multiplier reaches 0. The same condensed system
solved in CalculiX's dual basis (``contact_weighting='face-dual'``, :func:`deckbridge.reference_dual.dual_system`)
is a second discretisation of the same law: on meshes fine enough for the onset the two agree (first node within
0.15 % on hex20 48 x 8 x 1, 0.3 % wedge15 48 x 12 x 1, 0.14 % on the Gmsh C3D20 + C3D15 skirt 96 x 6 x 1,
~1 % tet10 48 x 8 x 1 at t/R 0.03; the dual's onset is the later one, its multiplier a weighted mean reaching
inward of the outer fibre: +0.4 / +0.65 % of the thick ring where the hat one is within 0.1 / 0.3 %; the default
72 x 30 x 2 mesh with the default loads, first node: hex20r 0.6 %, hex20 0.6 %, wedge15 1.8 %, tet10 2.0 %). On tall
cells the base traction of the discrete model scatters under N alone and the hat basis amplifies that on
6-node faces: the Gmsh mixed skirt 48 x 3 x 1 (0.67 m cells) opens 22 inner-edge mid-side rows under N alone
(first node lambda 0, whole section 0.361), where the dual basis (as ccx's mortar) gives 0.631 / 0.651 and
the thick ring 0.67056 / 0.6796 (parametric wedge15 48 x 3 x 1: 0.608 / 0.660 first node, 7.9 % apart; the
mixed skirt with the default loads 0.324 / 0.346 first node, 0.387 / 0.423 whole section, 8.6 % apart). :func:`basis_check` records the dual onsets in the Lagrange summary and returns
a warning line when either onset differs by more than :data:`DISAGREE` of the larger: then the onset is the
mesh's, not the structure's (refine ``mesh.n_z``; docs/elements.md).
"""

from __future__ import annotations

from . import summary_keys as K
from .errors import DeckbridgeError
from .methods import LAGRANGE

DISAGREE = 0.05          # relative difference of the two bases' onsets that warns (module doc: <= 2.0 % measured
                         # where the mesh is fit for the onset, 6-100 % where it is not)


def dual_basis_onsets(model, mesh, system, solve_dual=None) -> tuple[float | None, float | None]:
    """(first-node, whole-section) liftoff load factors of the model's Lagrange path in ccx's dual basis on the
    condensed ``system`` (no re-condensing; None where nothing lifts up to steps.lambda_max). ``solve_dual()``:
    the job's one solve of that path (:func:`deckbridge.reference_dual.dual_lagrange`, shared with ccx/mortar's
    partner), else solved here."""
    from .reference_dual import dual_lagrange
    from .wall_stress import reference_section_onset
    dual, _, _, sol = solve_dual() if solve_dual is not None else dual_lagrange(model, mesh, system)
    return sol.liftoff_load_factor, reference_section_onset(dual, mesh, sol)[0]


def _differ(a: float | None, b: float | None) -> bool:
    if a is None or b is None:
        return (a is None) != (b is None)
    return abs(a - b) > DISAGREE * max(abs(a), abs(b), 1e-12)


def basis_check(model, mesh, system, summary: dict, solve_dual=None) -> str | None:
    """Add the dual-basis onsets to a face-weighted Lagrange ``summary`` (its liftoff_load_factor and
    section_liftoff_load_factor are the hat basis's) and return a one-line warning where they disagree by more
    than DISAGREE, else None. Nothing (None) for a nodal problem (4-/3-node faces) or another method.
    ``solve_dual``: as :func:`dual_basis_onsets`."""
    if system.problem.contact_weighting != "face" or summary.get("method") != LAGRANGE:
        return None
    try:
        first, section = dual_basis_onsets(model, mesh, system, solve_dual)
    except DeckbridgeError as exc:              # a check only: the job's own solutions stand
        return f"  note: the onset check in ccx's dual basis did not run ({str(exc).splitlines()[0]})"
    summary[K.DUAL_BASIS_LIFTOFF_LOAD_FACTOR], summary[K.DUAL_BASIS_SECTION_LIFTOFF_LOAD_FACTOR] = first, section
    hat_first, hat_section = summary.get(K.LIFTOFF_LOAD_FACTOR), summary.get(K.SECTION_LIFTOFF_LOAD_FACTOR)
    if not (_differ(hat_first, first) or _differ(hat_section, section)):
        return None
    fmt = lambda v: "none" if v is None else f"{v:.4g}"     # noqa: E731
    return (f"  warning: reference lagrange liftoff onset (first node / whole section) lambda {fmt(hat_first)} / "
            f"{fmt(hat_section)} in the hat multiplier basis, {fmt(first)} / {fmt(section)} in ccx's dual basis: "
            f"more than {DISAGREE:.0%} apart: the onset is the mesh's here (tall quadratic cells? refine along the "
            "wall, mesh.n_z; docs/elements.md)")
