"""The neutral model: YAML round trip, overrides, validation messages and the CLI's bad-input behaviour."""

import math

import pytest
import yaml
from click.testing import CliRunner

from deckbridge.cli import main
from deckbridge.model import Model, ModelError, default_text, load, loads_model


def test_default_model_matches_the_embedded_yaml():
    m = load()
    raw = yaml.safe_load(default_text())
    assert m.geometry.radius == raw["geometry"]["radius"] == 1.5
    assert m.loads.N == pytest.approx(2.7e6)
    assert m.material.bulk_modulus == pytest.approx(2.1e11 / (3 * (1 - 0.6)))


def test_yaml_round_trip_is_identity():
    m = load(None, ["mesh.n_theta=48", "geometry.top_radius=1.4"])
    assert loads_model(m.to_yaml()) == m


def test_liftoff_happens_within_step_2_by_beam_theory():
    """The default loads are chosen so that M_b reaches N R / 2 inside step 2."""
    m = load()
    lam_c = (m.loads.N * m.geometry.radius / 2) / m.base_moment
    assert 0.0 < lam_c < m.steps.lambda_max


def test_load_vectors_open_the_azimuth_side():
    """M and T*H both lift the side at loads.azimuth: moment vector = z x (direction of azimuth) * (-M)."""
    m = load(None, ["loads.azimuth=90"])
    v = m.load_vectors()
    # lifting +y side: rotation about +x axis (right-hand rule takes +y up to +z)
    assert v["M_moment"][0] == pytest.approx(m.loads.M)
    assert abs(v["M_moment"][1]) < 1e-6 * m.loads.M
    # T points to azimuth 270 (-y); its moment about the base, r x F with r = (0, 0, H), is along +x
    tx, ty, _ = v["T_force"]
    h = m.geometry.height
    assert (-h * ty) == pytest.approx(m.loads.T * h) and abs(tx) < 1e-9


@pytest.mark.parametrize("override, key", [
    ("geometry.thickness=0", "geometry.thickness"),
    ("geometry.thickness=-0.01", "geometry.thickness"),
    ("material.nu=0.5", "material.nu"),
    ("mesh.n_theta=7", "mesh.n_theta"),
    ("material.E=abc", "material.E"),
    ("mesh.n_z=2.5", "mesh.n_z"),
    ("loads.azimuth=360", "loads.azimuth"),
    ("contact.stop.side=left", "contact.stop.side"),
    ("geometry.colour=red", "geometry.colour"),
    ("name=a b", "name"),
    ("name=../evil", "name"),
])
def test_bad_values_name_the_key_and_value(override, key):
    with pytest.raises(ModelError) as err:
        load(None, [override])
    msg = str(err.value)
    assert msg.startswith(f"{key} = ") and "\n" not in msg
    assert override.split("=", 1)[1].strip() in msg


def test_numbers_written_without_exponent_sign_are_numbers():
    """YAML 1.1 reads 2.1e11 as a string; the model accepts it as the number it is."""
    m = loads_model("material: {E: 2.1e11}")
    assert m.material.E == 2.1e11 and isinstance(m.material.E, float)


def test_yaml_is_loaded_safely():
    with pytest.raises(ModelError) as err:
        loads_model("name: !!python/object/apply:os.system ['echo pwned']")
    assert "not valid YAML" in str(err.value)


def test_unknown_top_level_key_in_file(tmp_path):
    p = tmp_path / "m.yaml"
    p.write_text("name: X\nmaterial: {E: 1.0e+9, nu: 0.3, density: 7800}\n")
    with pytest.raises(ModelError, match=r"m\.yaml: material\.density = 7800: unknown key$"):
        load(p)


def test_cone_radius_is_linear_in_height():
    m = load(None, ["geometry.top_radius=1.2"])
    assert m.geometry.r_top == 1.2
    assert math.isclose(Model().geometry.r_top, 1.5)


@pytest.mark.parametrize("args, needle", [
    (["--set", "geometry.thickness=0"], "geometry.thickness = 0"),
    (["--set", "material.nu=0.5"], "material.nu = 0.5"),
    (["--set", "mesh.n_theta=4"], "mesh.n_theta = 4"),
    (["--set", "loads.N=lots"], "loads.N = 'lots'"),
    (["--set", "mesh.colour=3"], "mesh.colour = 3: unknown key"),
])
def test_cli_bad_input_one_line_nonzero_exit_no_files(tmp_path, args, needle):
    out = tmp_path / "decks"
    res = CliRunner().invoke(main, ["decks", "-o", str(out), *args])
    assert res.exit_code != 0
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and needle in lines[0], res.output
    assert not out.exists() or not any(out.iterdir())


def test_cli_unwritable_output_folder(tmp_path):
    blocker = tmp_path / "afile"
    blocker.write_text("x")
    res = CliRunner().invoke(main, ["decks", "-o", str(blocker / "sub")])
    assert res.exit_code != 0
    assert "output folder" in res.output and str(blocker / "sub") in res.output
    assert len(res.output.strip().splitlines()) == 1


def test_init_writes_a_model_that_loads_back(tmp_path):
    p = tmp_path / "jar.yaml"
    res = CliRunner().invoke(main, ["init", str(p)])
    assert res.exit_code == 0, res.output
    assert load(p) == load()
    again = CliRunner().invoke(main, ["init", str(p)])
    assert again.exit_code != 0 and "exists" in again.output


def test_dotted_keys_reach_into_a_mapping_null_by_default():
    """Issue 21.15: ``--set contact.pads.count=4`` read "contact.pads = None: must be a mapping". Dotted keys
    build the null mapping: the model equals the one given as a whole mapping, a missing key without
    default is named in one line, an unknown one too."""
    whole = load(None, ["contact.pads={count: 4, width_deg: 30, first_deg: 45}"])
    dotted = load(None, ["contact.pads.count=4", "contact.pads.width_deg=30", "contact.pads.first_deg=45"])
    assert dotted == whole and dotted.contact.pads.count == 4 and dotted.contact.pads.width_deg == 30.0
    assert load(None, ["contact.pads.count=2", "contact.pads.width_deg=40"]).contact.pads.first_deg == 0.0
    band = load(None, ["contact.pads.count=2", "contact.pads.width_deg=40", "contact.pads.radial.inner=1.5"])
    assert band.contact.pads.inner == 1.5 and band.contact.pads.outer is None
    with pytest.raises(ModelError) as exc:
        load(None, ["contact.pads.count=4"])
    assert str(exc.value).startswith("contact.pads.width_deg = ") and "required" in str(exc.value)
    with pytest.raises(ModelError, match=r"^contact\.pads\.colour = .*unknown key"):
        load(None, ["contact.pads.count=4", "contact.pads.width_deg=30", "contact.pads.colour=1"])
    with pytest.raises(ModelError, match=r"^contact\.pdas\.count = .*unknown key"):
        load(None, ["contact.pdas.count=4"])


def test_poisson_ratio_near_minus_one_is_refused_and_the_bound_balances():
    """Issue 26: nu = -0.99999999 was accepted and the reactions missed T by 0.25 % (Fx 200,499 N for
    200,000 N). nu >= NU_MIN = -0.9 (G/K = 42, as K/G = 49.7 at NU_MAX): at the bound both methods'
    reactions balance N and T lambda to 1e-8 (force balance); below, one line names material.nu."""
    import numpy as np

    from deckbridge.model_fields import NU_MIN
    from deckbridge.solve import condense_model, reactions, solve_system

    for nu in (-0.99999999, -0.9000001):
        with pytest.raises(ModelError, match=r"^material\.nu = -0\.9.*must be >= -0\.9"):
            load(None, [f"material.nu={nu}"])
    m = load(None, ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1", f"material.nu={NU_MIN}"])
    mesh, system = condense_model(m)
    for method in ("penalty", "lagrange"):
        _, _, sol = solve_system(m, mesh, system, method)
        F, _ = reactions(system.problem, sol, -1)
        np.testing.assert_allclose(F, [m.loads.T * sol.load_factor[-1], 0.0, m.loads.N], rtol=0,
                                   atol=1e-8 * m.loads.N)
