"""Shared test fixtures: small models and the path of ../shared beside the checkout; the order in which the two
pytest-xdist workers take the suite.

Scheduling (``--dist loadscope --no-loadscope-reorder``, pyproject addopts): each module's tests run on one
worker, so that a module's module-scoped fixtures and caches (a solve, a ccx job) are paid once (with
``--dist load`` both workers took tests of the same module and each paid them); the scenario matrix has a
class per case (tests/test_scenario_matrix.py), so its cases spread over the workers while each case's run is
shared by its invariants. (``--dist loadgroup`` with ``xdist_group`` marks would say the same, but it groups
nothing with pytest 9.2: pytest-xdist issue 1386.) The scopes are sent longest first (:data:`LONG_SCOPES`,
measured CPU seconds; the rest behind them, most tests first), so that the two workers finish together
rather than one waiting on a long module at the end. Only the order and the worker change; every test runs
as written.
"""

import os
from pathlib import Path

# Two xdist workers share the CI's two cores: each worker and the CalculiX jobs it starts get one OpenMP thread
# (unless the caller set one). Measured: the scenario matrix's TestCase06 ccx run took 566 s with ccx on two
# threads beside one busy core, 66 s on one thread (OpenMP threads spin-waiting on a descheduled partner).
if os.environ.get("PYTEST_XDIST_WORKER") and "OMP_NUM_THREADS" not in os.environ:
    os.environ["OMP_NUM_THREADS"] = "1"

import pytest

from deckbridge.model import load

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared"

# scopes that take longest on one core [CPU s, one process, OMP_NUM_THREADS=1]; sent first, longest first.
# A scope missing here (or an estimate gone stale) only changes the order, never what runs.
LONG_SCOPES = {
    "tests/test_friction_report.py": 100.0,
    "tests/test_scenario_matrix.py::": 60.0,      # each case's class (TestCaseNN), one scope each
}


@pytest.fixture
def small_model():
    """A light JAR variant for fast tests (16 x 4 x 1 hexahedra)."""
    return load(None, ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1"])


def _scope(nodeid: str) -> str:
    """xdist's loadscope unit of a test: its class, else its module (xdist.scheduler.loadscope)."""
    return nodeid.rsplit("::", 1)[0]


def _weight(scope: str) -> float:
    return max((w for prefix, w in LONG_SCOPES.items()
                if scope == prefix or (prefix.endswith("::") and scope.startswith(prefix))), default=0.0)


@pytest.hookimpl(trylast=True)
def pytest_collection_modifyitems(config, items):
    """On an xdist worker: the scopes of LONG_SCOPES first, longest first; then the rest by their number of
    tests, most first (xdist's own --loadscope-reorder rule), ties in file order; within a scope the file
    order (a stable sort). Every worker sorts the same collection the same way, as xdist requires."""
    if not hasattr(config, "workerinput"):      # -n 0: file order
        return
    count: dict[str, int] = {}
    for item in items:
        count[_scope(item.nodeid)] = count.get(_scope(item.nodeid), 0) + 1
    order = {s: (-_weight(s), -n, k) for k, (s, n) in enumerate(count.items())}
    items.sort(key=lambda item: order[_scope(item.nodeid)])
