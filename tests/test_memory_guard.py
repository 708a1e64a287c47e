"""The memory guard (deckbridge.limits): the estimate from the mesh's symbolic factorisation grows with the
factor's fill and every other size, the quick arithmetic bound lets a small model through without building
anything, and a model above the memory available is refused with one line naming the mesh keys."""

import numpy as np
import pytest

from deckbridge import limits
from deckbridge.errors import InputError
from deckbridge.model import load

SMALL = ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1"]


def test_estimate_is_monotone_in_fill_and_sizes():
    base = dict(n_nodes=30_000, n_hex=20_000, n_retained=1_000, factor_entries=30_000_000, states=12)
    ref = limits.solve_estimate(**base).bytes
    for key in base:
        for vtu in (True, False):
            lo = limits.solve_estimate(**{**base, "vtu": vtu}).bytes
            hi = limits.solve_estimate(**{**base, key: 4 * base[key], "vtu": vtu}).bytes
            assert hi >= lo, key
    # the load path holds the factor: strictly increasing in the fill once it is the peak; at a small fill the
    # split or the VTU stage (the factor released by then) may be the peak
    fills = [limits.solve_estimate(**{**base, "factor_entries": f}, vtu=False).bytes for f in np.geomspace(1e8, 1e10, 7)]
    assert np.all(np.diff(fills) > 0)
    fills = [limits.solve_estimate(**{**base, "factor_entries": f}).bytes for f in np.geomspace(1e6, 1e9, 7)]
    assert np.all(np.diff(fills) >= 0) and fills[-1] > fills[0]
    # 8 bytes per factor entry at least: doubling the fill adds at least its bytes
    assert limits.solve_estimate(**{**base, "factor_entries": 2 * base["factor_entries"]}).bytes - ref >= 8 * 30e6
    assert limits.solve_estimate(**base, vtu=False).bytes <= ref        # the VTU stage only adds


def test_symbolic_estimate_counts_the_mesh_and_its_factor():
    m = load(None, SMALL)
    e = limits.symbolic_estimate(m)
    assert e.dofs == limits.dofs(16, 4, 1) == limits.model_dofs(m)
    assert 0 < e.retained <= limits.retained_bound(m)
    # the factor holds at least the lower triangle of K's pattern (81 entries per dof row, halved) and at
    # most the dense triangle
    assert 0.5 * 27 * e.dofs <= e.factor_entries <= e.dofs * (e.dofs + 1) / 2
    assert e.bytes == pytest.approx(limits.ESTIMATE_MARGIN * max(e.parts.values()))
    assert set(e.parts) == {"split", "load_path", "vtu"}
    assert limits.symbolic_estimate(load(None, SMALL + ["outputs.vtu=false"])).parts.keys() == {"split", "load_path"}
    assert limits.quick_estimate(m) >= e.bytes                       # the quick bound is above it


def test_quick_bound_passes_without_building_the_mesh(monkeypatch):
    monkeypatch.delenv(limits.ALLOW_ENV, raising=False)
    m = load(None, SMALL)
    monkeypatch.setattr(limits, "available_bytes", lambda: 1e12)
    monkeypatch.setattr(limits, "symbolic_estimate", lambda *a, **k: pytest.fail("symbolic analysis run"))
    assert limits.check_memory(m) == pytest.approx(limits.quick_estimate(m))


def test_a_model_over_the_bound_that_fits_is_not_refused(monkeypatch):
    monkeypatch.delenv(limits.ALLOW_ENV, raising=False)
    m = load(None, SMALL)
    sym, quick = limits.symbolic_estimate(m).bytes, limits.quick_estimate(m)
    assert sym < quick
    monkeypatch.setattr(limits, "available_bytes", lambda: 0.5 * (sym + quick))
    assert limits.check_memory(m) == pytest.approx(sym)              # decided by the symbolic estimate


def test_refused_above_the_memory_with_one_line_naming_the_keys(monkeypatch):
    monkeypatch.delenv(limits.ALLOW_ENV, raising=False)
    m = load(None, SMALL)
    sym = limits.symbolic_estimate(m).bytes
    monkeypatch.setattr(limits, "available_bytes", lambda: 0.9 * sym)
    with pytest.raises(InputError) as err:
        limits.check_memory(m)
    text = str(err.value)
    assert "\n" not in text
    assert text.startswith("mesh.n_theta x mesh.n_z x mesh.n_r = 16 x 4 x 1: ")
    assert f"{limits.dofs(16, 4, 1):,} dofs need about {sym / 1e9:.3g} GB (from its symbolic factorisation)" in text
    assert "`allow_large`" in text              # the CLI writes it as --allow-large (PARAMETER_FLAGS)
    assert limits.check_memory(m, allow_large=True) > 0              # --allow-large passes it


def test_gram_lower_is_exactly_symmetric_and_equals_l_lt():
    from reference_solver.linalg import gram_lower
    rng = np.random.default_rng(22)
    for m, block in ((0, 4), (1, 4), (9, 4), (64, 64), (130, 32)):
        L = np.tril(rng.normal(size=(m, m)))
        C = gram_lower(L, block=block)
        assert np.array_equal(C, C.T)
        np.testing.assert_allclose(C, L @ L.T, rtol=1e-13, atol=1e-12 * max(1, m))


def test_solve_command_builds_the_mesh_once_when_the_guard_needs_it(monkeypatch, tmp_path):
    """The guard's symbolic path builds the mesh; `deckbridge solve` reuses it (one build per command)."""
    from click.testing import CliRunner

    from deckbridge import mesh as mesh_mod
    from deckbridge import solve as solve_mod
    from deckbridge.cli import main

    monkeypatch.delenv(limits.ALLOW_ENV, raising=False)
    m = load(None, SMALL + ["outputs.vtu=false"])
    sym, quick = limits.symbolic_estimate(m).bytes, limits.quick_estimate(m)
    monkeypatch.setattr(limits, "available_bytes", lambda: 0.5 * (sym + quick))   # the symbolic path decides
    built = []
    real = mesh_mod.build_mesh

    def counting(model):
        built.append(model)
        return real(model)

    monkeypatch.setattr(mesh_mod, "build_mesh", counting)
    monkeypatch.setattr(solve_mod, "build_mesh", counting)
    sets = [a for s in SMALL + ["outputs.vtu=false"] for a in ("--set", s)]
    res = CliRunner().invoke(main, ["solve", "--method", "lagrange", *sets, "-o", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    assert len(built) == 1


def test_the_guard_knows_the_stress_recovery_chunk():
    from reference_solver.recover import STRESS_CHUNK, STRESS_THREADS
    assert limits.STRESS_CHUNK == STRESS_CHUNK and limits.STRESS_THREADS == STRESS_THREADS
    base = dict(n_nodes=300_000, n_retained=1_000, factor_entries=30_000_000, states=12)
    # past one chunk, more elements add their fields only, not their strain operator (9.2 kB each)
    extra = limits.solve_estimate(**base, n_hex=4 * STRESS_CHUNK).parts["vtu"] - \
        limits.solve_estimate(**base, n_hex=2 * STRESS_CHUNK).parts["vtu"]
    assert extra == (12 * 8 * limits.STATE_CELL_FLOATS + 130) * 2 * STRESS_CHUNK


@pytest.mark.parametrize("extra", [[], ["mesh.n_r=2"], ["mesh.element=hex20r"],
                                   ["contact.pads={count: 4, width_deg: 30, first_deg: 45}", "mesh.n_theta=48"],
                                   ["contact.pads={count: 3, width_deg: 20, first_deg: 10}", "mesh.n_theta=36"]])
def test_the_dense_block_floor_never_exceeds_the_built_problem(extra):
    """The floor that refuses without a symbolic analysis (limits.contact_rows_floor) is a lower bound of the
    contact rows of the problem the solver builds (with and without pads, linear and quadratic)."""
    from deckbridge.mesh import build_mesh
    from deckbridge.solve import build_problem
    m = load(None, SMALL + extra)
    floor = limits.contact_rows_floor(m)
    assert 0 < floor <= build_problem(m, build_mesh(m)).n_contacts


def test_a_ring_too_large_for_its_dense_block_is_refused_without_the_symbolic_analysis(monkeypatch):
    monkeypatch.delenv(limits.ALLOW_ENV, raising=False)
    m = load(None, ["mesh.n_theta=1000000", "mesh.n_z=2", "mesh.n_r=1"])
    monkeypatch.setattr(limits, "symbolic_estimate", lambda *a, **k: pytest.fail("symbolic analysis run"))
    monkeypatch.setattr(limits, "available_bytes", lambda: 64e9)
    with pytest.raises(InputError) as err:
        limits.check_memory(m)
    assert "18,000,000 dofs" in str(err.value) and "(its dense contact block alone)" in str(err.value)
    assert limits.contact_rows_floor(m) == 2 * 10**6         # 8 bytes x (2e6)^2 = 32 TB > 64 GB
