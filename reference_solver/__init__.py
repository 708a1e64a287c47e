"""reference_solver: small-strain solid elasticity with penalty and Lagrange contact on rigid masters.

Stand-alone (imports nothing from deckbridge): arrays in, arrays out. SI units; contact normals
point from the master into the body, gaps > 0 are open, contact forces > 0 are compressive and
sigma_n = -force / area < 0 is compression.

API
---
``Problem(nodes, hexes, E, nu, contact_*, spring_*, ref_point, coupling_nodes, coupling_weights, loads, ...)``
    Frozen dataclass of arrays, validated on construction (see :class:`reference_solver.problem.Problem`).
    ``loads`` maps load-case names to (Fx, Fy, Fz, Mx, My, Mz) at ``ref_point``; ``coupling`` is
    'distributing' (RBE3-like) or 'kinematic' (rigid top); ``element`` 'c3d8i' (default), 'c3d8', 'c3d20',
    'c3d20r', 'c3d10', 'c3d15' or 'c3d4' (aliases 'hex8i', 'hex20r', 'tet10', ...), or ``blocks`` (one
    ``ElementBlock(element, cells)`` per element type: a mixed mesh).
``element_type(name)``, ``ELEMENT_TYPES``
    The element interface (:mod:`reference_solver.element_base`): shape functions, quadrature, face rule,
    Gauss-to-node extrapolation, stiffness and strain operators, vectorised over a block of elements.
``face_weights``: ``surface_faces``, ``face_matrix`` (M = int N_a N_b dA, or lumped), ``project_pressure``
    The building blocks of a face-weighted contact law (sigma_N = -M^-1 r).
``condense(problem, cases=None, factorize=None, schur='auto', threads=None) -> CondensedSystem``
    Assembles K (vectorised hexahedra, incompatible modes condensed per element, summed by 3x3 node
    blocks), rotates contact and spring nodes into local frames, applies the coupling (distributing:
    on the node blocks, trailing.py), factors once and builds the dense
    condensed operator on the contact dofs and the condensed loads of every basic load case. The
    result does not depend on the method or on the penalty stiffness: re-use it for k sweeps. With
    ``tangential='friction'`` a ``FrictionSystem`` (tangential dofs retained too; system.py).
    ``factorize(K) -> solve(B)`` is injectable (:func:`cholmod_factorize` default, :func:`splu_factorize`).
``solve_path(system, method='penalty'|'lagrange'|'augmented', k_factor=1.0, base={'N': 1}, ramp={'T': 1, 'M': 1},
             lambda_max=1.0, increments=10, targets=None, algorithm=None, liftoff_surface=None, ...) -> Solution``
    The one load-path driver (path.py): step 1 applies ``base``; step 2 ``base + lambda * ramp`` through
    ``targets`` (default [lambda_max]), ``increments`` per leg, each increment one call of the contact law
    ``METHODS`` names (laws.py: ``LAWS``, ``make_law``, ``register``). Penalty: bilinear gap springs
    (k_factor * contact_k closed, k_open_ratio times that open). Lagrange: exact primal-dual active set
    (default) or the paper's projected Gauss-Seidel (``algorithm='gauss-seidel'``). Augmented: the
    augmented Lagrangian with epsilon = k_factor * contact_k (augmented.py), the Lagrange answer at any
    epsilon. The liftoff onset (first ``liftoff_surface`` row that opens; None: any row) is bracketed by
    the increments and located exactly by following the piecewise-linear path, else bisected (onset.py,
    which also holds the whole-section onset ``section_onset``). The fields at the end of both steps are
    recovered with one solve into ``Solution.fields``.
``Solution``
    Per increment (rows) and contact row (columns): ``u``, ``gap`` [m] (> 0 open), ``force`` [N]
    (> 0 compressive), ``sigma_n`` [Pa] (< 0 compression), ``closed``; per spring ``spring_u``,
    ``spring_force``; ``liftoff_load_factor``, ``liftoff_row``; ``friction_check(problem, mu)``.
``element_von_mises(problem, u)``, ``distributing_forces(...)``, ``hex8_stiffness(...)``, ``assemble_stiffness(...)``
    Building blocks, also used by the tests.
``Problem(..., tangential='friction', friction=mu, contact_kt=...)``: Coulomb friction instead of springs;
    ``condense`` then returns a ``FrictionSystem`` (normal and tangential dofs retained) and ``solve_path``
    follows the path-dependent stick/slip with the friction law (friction_law.py: penalty return mapping,
    exact semi-smooth Newton, or augmented-Lagrangian multiplier updates), with
    ``targets=[...]`` (load factors visited in order) and ``on_gross_slip='raise'|'stop'``. ``GrossSlip``
    (a ``ReferenceSolverError``): the load slides the body.
``estimate_peak_bytes(n_nodes, n_hex, n_contact, n_spring, factor_entries)``, ``factor_entries(hexes, n_nodes)``
    Peak resident memory of condense + solve_path estimated from the mesh before any work [bytes]
    (measured peaks 0.6-0.92 of it from 20k to 3M dofs on the JAR skirt).
``threads=`` on ``condense`` and ``solve_path``; ``blas_threads(n)``, ``blas_info()``, ``default_threads()``
    BLAS thread pools limited with threadpoolctl (default 1, or REFERENCE_SOLVER_THREADS).
``ReferenceSolverError``
    Raised with a one-line message for a mechanism, no possible contact, a load that tips the body
    over, or non-finite numbers.
"""

from .assembly import assemble_stiffness
from .condense import CondensedSystem, check_mechanism
from .contact import lcp_active_set, lcp_pgs, penalty_solve
from .elements import ELEMENT_TYPES, element_type, hex8_stiffness
from .errors import ReferenceSolverError
from .estimate import estimate_peak_bytes, factor_entries
from .fields import element_stress, element_von_mises
from .friction import FrictionSystem, GrossSlip, condense_friction
from .laws import LAWS, ContactLaw, make_law, register
from . import augmented  # noqa: F401  (registers the 'augmented' law)
from . import face_penalty  # noqa: F401  (registers the face-integrated penalty: contact_weighting 'face')
from .linalg import HAVE_CHOLMOD, cholmod_factorize, default_factorize, splu_factorize
from .loads import distributing_forces
from .path import Increment, Solution, section_onset, solve_path
from .problem import ElementBlock, Problem
from .system import condense
from .threads import blas_info, blas_threads, default_threads

METHODS = tuple(LAWS)      # the contact methods, in registry order: penalty, lagrange, augmented

__all__ = [
    "Problem", "CondensedSystem", "Solution", "ReferenceSolverError", "condense", "solve_path",
    "check_mechanism", "assemble_stiffness", "hex8_stiffness", "distributing_forces",
    "element_stress", "element_von_mises", "penalty_solve", "lcp_active_set", "lcp_pgs",
    "cholmod_factorize", "splu_factorize", "default_factorize", "HAVE_CHOLMOD",
    "FrictionSystem", "GrossSlip", "condense_friction", "METHODS", "LAWS", "ContactLaw", "make_law", "register",
    "Increment", "section_onset",
    "blas_info", "blas_threads", "default_threads", "estimate_peak_bytes", "factor_entries",
    "ELEMENT_TYPES", "ElementBlock", "element_type",
]
