"""One name per fact: every key of a reference summary (``summary.json`` of ``solve`` / ``run``, a sweep
case, the ``liftoff`` study) defined once, with its unit and meaning.

The console lines, the ``summary.json`` files, the report and the Python API (:mod:`deckbridge.api`) use
these names; ``tests/test_summary_keys.py`` checks that every key written is defined here and that the
retired duplicates (:data:`RETIRED`) appear nowhere in the package, the tests or the README.

A :class:`Key` is a ``str`` (usable directly as a dict key, written to JSON as its name) that also carries
``unit`` and ``meaning``. Signs: sigma_n < 0 compression, > 0 tension; theta [deg] CCW from +x in [0, 360);
load factor lambda [-] multiplies (T, M) in step 2.
"""

from __future__ import annotations


class Key(str):
    """A summary key: the string itself, plus ``unit`` and ``meaning``."""
    unit: str
    meaning: str

    def __new__(cls, name: str, unit: str, meaning: str) -> "Key":
        obj = super().__new__(cls, name)
        obj.unit, obj.meaning = unit, meaning
        return obj

    def __reduce__(self):               # pickled (a Dask worker's summary) and copied as the plain name
        return (str, (str(self),))


KEYS: dict[str, Key] = {}


def _key(name: str, unit: str, meaning: str) -> Key:
    if name in KEYS:
        raise ValueError(f"summary key {name!r} defined twice")
    KEYS[name] = k = Key(name, unit, meaning)
    return k


# --- identity of the run -----------------------------------------------------------------------------------
SOURCE = _key("source", "-", "who computed it: 'reference' for the reference solver")
METHOD = _key("method", "-", "contact method: penalty | lagrange | augmented (deckbridge/methods.py)")
ALGORITHM = _key("algorithm", "-", "contact algorithm of the method (active-set, gauss-seidel, penalty)")
MODEL = _key("model", "-", "the model's name")
LOAD_INTRODUCTION = _key("load_introduction", "-", "top coupling: distributing | kinematic")
TANGENTIAL = _key("tangential", "-", "tangential contact: springs | friction")
# --- size --------------------------------------------------------------------------------------------------
DOFS = _key("dofs", "-", "3 x the mesh's node count")
REDUCED_DOFS = _key("reduced_dofs", "-", "dofs after the supports and the coupling are eliminated")
CONDENSED_DOFS = _key("condensed_dofs", "-", "dofs kept by the static condensation (contact rows, springs)")
CONTACT_ROWS = _key("contact_rows", "-", "contact rows: table nodes, then radial-stop nodes")
# --- onsets and anchors -----------------------------------------------------------------------------------
LIFTOFF_LOAD_FACTOR = _key("liftoff_load_factor", "-",
                           "first-node liftoff onset: smallest lambda at which a table node opens (bisected); "
                           "None when nothing lifts up to steps.lambda_max")
LIFTOFF_THETA_DEG = _key("liftoff_theta_deg", "deg", "azimuth of the first table node to lift")
SECTION_LIFTOFF_LOAD_FACTOR = _key("section_liftoff_load_factor", "-",
                                   "whole-section liftoff onset: smallest lambda at which every node through "
                                   "the wall at one azimuth is open (exact, reference solver)")
SECTION_LIFTOFF_THETA_DEG = _key("section_liftoff_theta_deg", "deg", "azimuth of the first whole section to lift")
DUAL_BASIS_LIFTOFF_LOAD_FACTOR = _key("dual_basis_liftoff_load_factor", "-",
                                      "8-/6-node table faces, lagrange: the first-node onset of the same law in "
                                      "CalculiX's dual multiplier basis (deckbridge/onset_basis.py); None: no lift")
DUAL_BASIS_SECTION_LIFTOFF_LOAD_FACTOR = _key("dual_basis_section_liftoff_load_factor", "-",
                                              "8-/6-node table faces, lagrange: the whole-section onset in CalculiX's "
                                              "dual multiplier basis (deckbridge/onset_basis.py); None: no lift")
BEAM_THEORY_LIFTOFF_LOAD_FACTOR = _key("beam_theory_liftoff_load_factor", "-",
                                       "thin ring, rigid section: lambda_c = N R / (2 (M + T H)); None when "
                                       "M + T H <= 0")
GROSS_SLIP_LOAD_FACTOR = _key("gross_slip_load_factor", "-", "friction: lambda at which the whole base slides")
# --- results -----------------------------------------------------------------------------------------------
MIN_SIGMA_N_PA = _key("min_sigma_n_pa", "Pa", "most compressive node sigma_n of the whole path (< 0 compression)")
MAX_SIGMA_N_PA = _key("max_sigma_n_pa", "Pa", "largest node sigma_n of the whole path (0 when nothing carries tension)")
REACTION_FORCE_N = _key("reaction_force_n", "N", "resultant contact + spring reaction on the body at the end "
                        "of step '1' and '2' (x, y, z)")
REACTION_MOMENT_NM = _key("reaction_moment_nm", "N m", "its moment about the top reference point, per step")
PENALTY_K = _key("penalty_k", "N/m", "methods with a penalty (penalty; augmented: its epsilon): k_factor, alpha "
                 "used, k_open_ratio and the stiffness statistics per surface (min, max, mean, count)")
AUGMENTED = _key("augmented", "-", "augmented Lagrangian only: augmentations (total, augmentations_max per "
                 "increment), final penetration penetration_m and its tolerance penetration_tol_m [m]")
K_TANGENT = _key("k_tangent", "N/m", "circumferential spring stiffness statistics (min, max, mean, count)")
FRICTION = _key("friction", "-", "friction only: the Coulomb check of the solution (stick / slip counts, "
                "largest |tau| / (mu |sigma_n|))")
K_TANGENT_FOLLOWS_K = _key("k_tangent_follows_k", "-", "whether the circumferential stiffness k_t is scaled "
                           "with the penalty factor (contact.penalty.k_tangent_follows)")
K_TANGENT_RIGID = _key("k_tangent_rigid", "-", "sweep's Lagrange reference: springs taken rigid (k -> infinity)")
OPEN_STIFFNESS = _key("open_stiffness", "-", "sweep: open-gap stiffness scaled with k or fixed")
K_OPEN_RATIO_USED = _key("k_open_ratio_used", "-", "sweep: open-gap stiffness over the closed one")
ONSET_REL_DIFF = _key("onset_rel_diff", "-", "sweep and verdict, per penalty case: first-node liftoff onset "
                      "|lambda(penalty) - lambda(Lagrange)| / lambda(Lagrange); 0 when neither lifts, inf (console "
                      "'one lifts') when only one does")
REPRODUCES = _key("reproduces", "-", "sweep and verdict, per penalty case: reproduces Lagrange, sigma_N within tol x "
                  "the Lagrange peak at every compared load factor and onset_rel_diff within the onset tolerance "
                  "(deckbridge/studies/recommend.py)")
CAVEATS = _key("caveats", "-", "what the numbers of this reference run do not show (run job)")
# --- the comparison (summary.json of run / compare) ------------------------------------------------------
RING_LINE_FORCE_MAX_DIFF = _key("ring_line_force_max_diff", "1",
                                "ccx/f2f vs reference/f2f on 8-/6-node faces: largest difference of the contact "
                                "force on an azimuth line of the deck's master ring over the largest line force, "
                                "worst state with lift/R <= 0.01 (deckbridge/quantities.py ring_line_force_n; exact "
                                "on both sides, unlike their nodal sigma_N)")
# --- cost --------------------------------------------------------------------------------------------------
SOLVER = _key("solver", "-", "sparse factorisation, contact algorithm, increments, iterations")
TIMINGS_S = _key("timings_s", "s", "seconds per phase (condensation, load path)")
WALL_TIME_S = _key("wall_time_s", "s", "seconds of the whole solve")
# --- the liftoff study (deckbridge liftoff) ---------------------------------------------------------------
TOL = _key("tol", "-", "liftoff: tolerance on lambda_c (absolute)")
METHODS = _key("methods", "-", "liftoff: the methods searched")
BASE_MOMENT_NM_AT_LAMBDA_1 = _key("base_moment_nm_at_lambda_1", "N m", "liftoff: M_b = M + T H at lambda = 1")
DIFFERENCE = _key("difference", "-", "liftoff: lambda_c(penalty) - lambda_c(lagrange), and over lambda_c(lagrange)")

# Old names of the same facts, removed (one name per fact); the test greps that none is left.
RETIRED: dict[str, Key] = {
    "section_onset_load_factor": SECTION_LIFTOFF_LOAD_FACTOR,
    "section_onset_theta_deg": SECTION_LIFTOFF_THETA_DEG,
    "liftoff_load_factor_beam_theory": BEAM_THEORY_LIFTOFF_LOAD_FACTOR,
    "beam_theory_lambda_c": BEAM_THEORY_LIFTOFF_LOAD_FACTOR,
    "k_tangent_follows_alpha": K_TANGENT_FOLLOWS_K,
}


def describe(name: str) -> str:
    """'name [unit]: meaning' of a defined key (KeyError for an undefined one)."""
    k = KEYS[name]
    return f"{k} [{k.unit}]: {k.meaning}"
