"""``deckbridge import MESH --like model.yaml`` (issue 25): the imported mesh's model takes material, loads,
contact, steps and analysis of another model; before, it silently took steel and the default JAR loads.

Off the default path: a Gmsh-written tube (R = 1.2 m, t = 0.03 m, H = 1.5 m, 24 x 4 x 1, tests/gmsh_skirt.py)
and a model with aluminium E, other loads, Coulomb friction and kinematic coupling. Checked against
independent truths: the step-1 contact forces balance the like model's N (not the JAR's 2.7 MN); beam
theory N R / (2 (M + T H)) with the like loads and the measured R; the penalty stiffness k_c = alpha A^2 K / V
is proportional to E (K = E / (3 (1 - 2 nu))), so the imported models with and without --like differ by
E_like / E_steel.
"""

import json

import numpy as np
import pytest
import yaml
from click.testing import CliRunner

from deckbridge import load
from deckbridge.cli import main
from gmsh_skirt import gmsh_skirt

R, T, H = 1.2, 0.03, 1.5
LIKE = {"name": "ALU", "material": {"name": "aluminium", "E": 70.0e9, "nu": 0.33},
        "contact": {"tangential": "friction", "friction": 0.25, "penalty": {"alpha": 0.5}},
        "load_introduction": "kinematic",
        "loads": {"N": 1.1e6, "T": 5.0e4, "M": 6.0e5, "azimuth": 30.0},
        "steps": {"lambda_max": 0.8, "increments": 4},
        "geometry": {"radius": 9.0, "height": 9.0, "thickness": 0.5},     # not carried: the mesh is the geometry
        "mesh": {"n_theta": 8, "n_z": 2, "n_r": 1}}


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("like")
    g = gmsh_skirt(tmp / "mesh", R=R, t=T, H=H, n_theta=24, n_z=4, n_r=1)
    like = tmp / "alu.yaml"
    like.write_text(yaml.safe_dump(LIKE))
    out = {}
    for tag, extra in (("like", ["--like", str(like)]), ("plain", [])):
        path = tmp / f"{tag}.yaml"
        r = CliRunner().invoke(main, ["import", str(g["msh"]), "-o", str(path), "--base", "BASE", "--top", "TOP",
                                      *extra])
        assert r.exit_code == 0, r.output
        out[tag] = path
    return out, like


def test_like_carries_material_loads_contact_steps_not_geometry(imported):
    paths, like = imported
    m, src = load(paths["like"]), load(like)
    for key in ("material", "contact", "loads", "steps", "analysis", "load_introduction"):
        assert getattr(m, key) == getattr(src, key), key
    assert m.geometry.radius == pytest.approx(R, rel=1e-9) and m.geometry.thickness == pytest.approx(T, rel=1e-9)
    assert (m.mesh.n_theta, m.mesh.n_z) == (24, 4)
    assert "(--like)" in paths["like"].read_text()
    plain = load(paths["plain"])
    assert plain.material.E == 210e9 and plain.loads.N == 2.7e6      # without --like: the JAR's, as before


def test_like_model_solves_with_its_own_loads_and_stiffness(imported, tmp_path):
    paths, _ = imported
    summ = {}
    for tag in ("like", "plain"):
        r = CliRunner().invoke(main, ["solve", str(paths[tag]), "--method", "penalty", "--set", "outputs.vtu=false",
                                      "--set", "steps.lambda_max=0.8",   # the JAR loads tip this tube at 0.994
                                      "-o", str(tmp_path / tag)])
        assert r.exit_code == 0, r.output
        summ[tag] = json.loads((tmp_path / tag / "summary.json").read_text())
    s = summ["like"]
    fz1 = s["reaction_force_n"]["1"][2]
    assert fz1 == pytest.approx(1.1e6, rel=1e-6)                       # force balance with the like N
    assert s["beam_theory_liftoff_load_factor"] == pytest.approx(1.1e6 * R / (2 * (6.0e5 + 5.0e4 * H)), rel=1e-9)
    assert s["tangential"] == "friction" and s["friction"] is not None
    assert s["load_introduction"] == "kinematic"
    # k_c = alpha A^2 K / V: alpha 0.5 vs 0.1 and K(E=70e9, nu=0.33) vs K(E=210e9, nu=0.3)
    K = lambda E, nu: E / (3 * (1 - 2 * nu))  # noqa: E731
    ratio = s["penalty_k"]["table"]["mean"] / summ["plain"]["penalty_k"]["table"]["mean"]
    assert ratio == pytest.approx(0.5 / 0.1 * K(70e9, 0.33) / K(210e9, 0.3), rel=1e-9)
    assert np.isclose(summ["plain"]["reaction_force_n"]["1"][2], 2.7e6, rtol=1e-6)
