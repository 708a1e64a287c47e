"""The scenario matrix of issue 21: the model's options combined pairwise (tests/scenarios.py generates the
covering array), each case run once (decks, reference solver penalty and Lagrange, ccx penalty and mortar on a
16 x 4 x n_r mesh) and checked by every invariant of tests/scenario_checks.py; the refused combinations are
asserted as one-line refusals before any work.

A (case, invariant) that fails on main because of an item of issue 21 another branch fixes is marked
``xfail(strict=True)`` by :data:`KNOWN` (a rule on the case's levels, not a list of cases), so that it
XPASS-fails once the fix lands and the mark is removed. The first matching rule names the test's reason; a
test broken by two items stays XFAIL until both land: ``bench/scenario_matrix.py --n-theta 16 --n-z 4
--increments 5 --seed 21`` prints this matrix's every (case, invariant) without marks. The larger matrix:
bench/scenario_matrix.py with its defaults.
"""

import shutil

import pytest

from scenario_checks import CHECKS, refused_before_work
from scenarios import check_params, REFUSED, Case, covering_array, run_case

CASES = [Case(levels) for levels in covering_array()]

# (rule on the levels, invariants it breaks (None: all), reason); the first rule that matches marks the test.
# Every item the matrix found in issue 21 (items 1, 2, 4, 5, 6, 16), the pads' EBASE set, the mortar friction
# increments and false gross slip are fixed on main; the mortar deck on cones is compared through the wall
# (scenario_checks.ccx_vs_reference, docs/mortar_stop.md); what is left are open bugs, each named here:
ALL_BUT_DECKS = tuple(c for c in CHECKS if c != "decks_command")


def _mortar_stalls(v: dict) -> bool:
    return v["nlgeom"] and v["pads"] == "pads" and v["stop"] == "outer" and v["t_over_r"] == 0.005


# The stalling case only has to show the stall: its mortar deck's minimum increment (2e-6 of step 2) is
# raised to this, so that ccx says 'increment size smaller than minimum' at lambda 0.57205 after 22 s of CPU
# instead of at 0.57225 after 75 s (the same increments and attempts up to there, compared in the .sta;
# one run of ccx 2.20). A fix that lets ccx through lambda 0.572 still XPASSes.
STALL_MIN_INCREMENT = 1e-4

KNOWN = [
    (lambda v: v["mesh"] == "bdf" and v["tangential"] == "friction" and v["top"] == "kinematic",
     ("no_free_penetration", "ccx_vs_reference"),
     "open: ccx's node-to-surface search drops the interior through-wall table nodes with friction on these "
     "Gmsh .bdf skirts (3.6-3.8 mm into the table with no force from lambda 0.6; SMALL SLIDING delays it to 0.8, "
     "master extent/faceting do not cure it, small increments diverge at 0.44: docs/mortar_stop.md)"),
    (_mortar_stalls, ALL_BUT_DECKS,
     "open: ccx's mortar deck with NLGEOM, pads and an outer stop stalls at lambda 0.572 on t/R 0.005 "
     "('increment size smaller than minimum'; tipping at 1.194; without NLGEOM or the stop it runs; not the "
     "GAPUNI stiffness (x 1e-4) nor the residual controls (ccx defaults): docs/mortar_stop.md; here with the "
     f"minimum increment raised to {STALL_MIN_INCREMENT:g}, see STALL_MIN_INCREMENT)"),
]


def _params(case: Case) -> list:
    return check_params(case, CHECKS, KNOWN)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """One run per case, shared by its invariants."""
    cache = {}

    def get(case: Case):
        if case.name not in cache:
            cap = STALL_MIN_INCREMENT if _mortar_stalls(case.levels) else None
            cache[case.name] = run_case(case, tmp_path_factory.mktemp(f"case{len(cache):02d}"), cap)
        return cache[case.name]
    return get


def test_covering_array_covers_every_allowed_pair_and_no_forbidden_one():
    """The generator's output against a brute-force enumeration of the pairs."""
    import itertools

    from scenarios import FACTORS, _pairs, forbidden
    cases = covering_array()
    covered = set().union(*(_pairs(c) for c in cases))
    for a, b in itertools.combinations(sorted(FACTORS), 2):
        for va in FACTORS[a]:
            for vb in FACTORS[b]:
                pair = ((a, va), (b, vb))
                assert (pair in covered) != bool(forbidden({a: va, b: vb})), pair
    assert covering_array() == cases                             # deterministic
    assert len(cases) < len(list(itertools.product(*FACTORS.values()))) / 100


def _case_class(k: int, case: Case) -> type:
    """``TestCase<k>``: the case's invariants, one test each. A class per case so that pytest-xdist's
    ``--dist loadscope`` (pyproject addopts) keeps a case's invariants on the worker that ran the case."""
    @pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX ccx not installed")
    @pytest.mark.parametrize("check", _params(case))
    def test_scenario(self, runs, check):
        CHECKS[check](runs(case))
    return type(f"TestCase{k:02d}", (), {"__doc__": case.name, "test_scenario": test_scenario})


for _k, _case in enumerate(CASES):
    globals()[f"TestCase{_k:02d}"] = _case_class(_k, _case)


@pytest.mark.parametrize("overrides,dialect,key", REFUSED, ids=[r[2] + "-" + r[1] for r in REFUSED])
def test_unsupported_combination_refused_before_any_work(tmp_path, overrides, dialect, key):
    refused_before_work(overrides, dialect, key, tmp_path)
