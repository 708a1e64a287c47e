"""Load the default model, override keys, and read derived quantities (all SI).

The beam-theory liftoff of a rigid ring is lambda_c = N R / (2 M_b) with M_b = M + T H.
"""

from deckbridge.model import load

model = load(None)                                    # the embedded default JAR
stiff = model.with_overrides({"contact.penalty.alpha": 1.0, "mesh.n_theta": 48})
print(f"alpha {model.contact.penalty.alpha:g} -> {stiff.contact.penalty.alpha:g}, "
      f"n_theta {model.mesh.n_theta} -> {stiff.mesh.n_theta}")

g, ld = model.geometry, model.loads
m_b = ld.M + ld.T * g.height                          # [N m], opens the side at loads.azimuth
print(f"M_b = {model.base_moment:.6g} N m, beam-theory liftoff lambda = {model.beam_theory_liftoff():.4f}")
assert model.base_moment == m_b
assert abs(model.beam_theory_liftoff() - ld.N * g.radius / (2 * m_b)) < 1e-12
assert abs(model.beam_theory_liftoff() - 0.5956) < 1e-4
