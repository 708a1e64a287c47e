"""The skirt on quadratic elements through the face-weighted Lagrange law (issue 23; reference_solver/face_law.py).

96 x 6 x 2 skirt (n_theta, n_z, n_r), default loads, lambda = 0.3 (below the beam-theory liftoff 0.53, full
contact): the through-wall mean of the solver's sigma_N (the pressure field's nodal values) at every corner
azimuth against thin-ring beam theory, as a fraction of the peak (trapezoid through the wall: the field of the
hat multiplier basis is linear between the nodes of an edge). Measured: hex8i 0.0007, hex20r 0.0034, tet10
0.0019 (modified basis, Simpson: hex20r 0.0010, hex20 0.0008, tet10 0.0040, wedge15 0.0010); on the coarse
24 x 3 x 2 skirt 0.05-0.22 (modified basis; step 1, N alone: the HRZ
top weights' self-equilibrated load pattern has not decayed over the short, 0.39 m wide cells). The table
reactions add up to N (1e-9).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.integrate import trapezoid

from deckbridge.errors import ModelError
from deckbridge.model import load
from deckbridge.quantities import beam_theory_sigma
from deckbridge.solve import build_problem, condense_model, solve_model, solve_path


def _model(element, *extra):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load(None, [f"mesh.element={element}", "mesh.n_theta=96", "mesh.n_z=6", "mesh.n_r=2",
                           "steps.lambda_max=0.3", "steps.increments=1", "outputs.vtu=false", *extra])


def _wall_error(element):
    m = _model(element)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _, system = condense_model(m)
        sol = solve_path(m, system, "lagrange")
    p = system.problem
    tab = p.contact_surface == "table"
    xyz = p.nodes[p.contact_nodes[tab]]
    th = np.round(np.degrees(np.arctan2(xyz[:, 1], xyz[:, 0])) % 360, 6)
    r = np.hypot(xyz[:, 0], xyz[:, 1])
    s, lam = sol.sigma_n[-1][tab], sol.load_factor[-1]
    R, t = m.geometry.radius, m.geometry.thickness
    peak = abs(beam_theory_sigma(m.loads.N, lam * m.base_moment, R, t, 180.0))
    errs = []
    for a in np.unique(th):
        i = np.flatnonzero(th == a)
        i = i[np.argsort(r[i])]
        if element == "hex8i" or i.size == 5:        # quadratic: a corner azimuth, 2 n_r + 1 nodes through the wall
            wall = trapezoid(s[i], x=r[i]) / t
        else:
            continue
        errs.append(abs(wall - beam_theory_sigma(m.loads.N, lam * m.base_moment, R, t, a - m.loads.azimuth)) / peak)
    assert lam == pytest.approx(0.3) and sol.closed[-1][tab].all()
    assert sol.force[-1][tab].sum() == pytest.approx(m.loads.N, rel=1e-9)       # force balance
    return max(errs), len(errs)


@pytest.mark.parametrize("element", ["hex20r", "tet10"])
def test_quadratic_skirt_full_contact_against_beam_theory(element):
    err, n = _wall_error(element)
    assert n >= 96
    assert err < 0.005
    assert err < _wall_error("hex8i")[0] + 0.005      # within 0.5 % of hex8i on the same mesh (0.0007)


def test_friction_refused_on_quadratic_faces_with_the_stop():
    """Friction with the radial stop (the default) on 8-/6-node faces (penalty on quadratic faces is the face-integrated penalty law: tests/test_face_penalty_skirt.py; the
    reference solver's face-weighted friction law: tests/test_friction_quadratic*.py)"""
    f = load(None, ["mesh.element=tet10", "mesh.n_theta=24", "mesh.n_z=3", "mesh.n_r=1",
                    "contact.tangential=friction", "contact.friction=0.3"])
    with pytest.raises(ModelError, match=r"^contact.stop.side = 'inner'.*radial stop.*mesh.element=tet10"):
        build_problem(f)


def test_solve_model_writes_the_projected_pressure_on_quadratic_faces():
    """The contact table of a tet10 skirt: sigma_n_pa is the law's pressure (-D^-T r), force_n the nodal force r the
    solver applies (quantities.DEFINITIONS), both adding up to the reaction N (1e-9), the nodal forces' moment
    balancing the applied one (1e-9 of N R; the pressure x hat area about the nodes does not: a 6-node face's
    corner force is not its share); every table node closed under N alone."""
    m = load(None, ["mesh.element=tet10", "mesh.n_theta=24", "mesh.n_z=3", "mesh.n_r=1", "steps.lambda_max=0.2",
                    "steps.increments=1", "outputs.vtu=false"])
    df, summary = solve_model(m, "lagrange")
    d = df[(df.surface == "table") & (df.step == 1)]
    assert (d.status == "closed").all()
    assert (d.sigma_n_pa * d.area_m2).sum() == pytest.approx(-m.loads.N, rel=1e-9)
    assert d.force_n.sum() == pytest.approx(m.loads.N, rel=1e-9)
    s2 = df[(df.surface == "table") & (df.step == 2)]
    s2 = s2[s2.increment == s2.increment.max()]
    lv, lam = m.load_vectors(), float(s2.load_factor.iloc[0])
    f_app = np.asarray(lv["N_force"], float) + lam * np.asarray(lv["T_force"], float)
    m_app = lam * np.asarray(lv["M_moment"], float) + np.cross([0.0, 0.0, m.geometry.height], f_app)
    x = s2.r * np.cos(np.radians(s2.theta_deg))
    scale = m.loads.N * m.geometry.radius
    assert abs(-(x * s2.force_n).sum() + m_app[1]) <= 1e-9 * scale
    assert abs(-(x * -s2.sigma_n_pa * s2.area_m2).sum() + m_app[1]) > 1e-6 * scale      # the pressure's share
    assert summary["reaction_force_n"]["1"][2] == pytest.approx(m.loads.N, rel=1e-9)
    exact = -m.loads.N / (2 * np.pi * m.geometry.radius * m.geometry.thickness)
    assert np.abs(d.sigma_n_pa / exact - 1).max() < 0.05            # coarse mesh: 0.98-1.02 measured on 24 x 3 x 2
