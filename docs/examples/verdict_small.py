"""The report's penalty verdict on a small mesh: the model's alpha = 0.1 is not converged against
Lagrange; the verdict names the k-factor, alpha and KA per node that are, and written as the model's own
penalty (alpha) that KA reproduces Lagrange within the tolerance. About 10 s.
"""

from deckbridge.model import load
from deckbridge.studies.verdict import penalty_verdict

model = load(None, ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1", "steps.increments=5"])
v = penalty_verdict(model, tol=0.02)
mp = v["model_penalty"]
print(f"alpha = 0.1: converged {mp['converged']}, worst |dsigma_N| / peak {100 * mp['max_rel_diff']:.2f} %, "
      f"onset {100 * mp['onset_rel_diff']:.2f} % off, penetration {100 * mp['penetration_over_t']:.2f} % of t")
print("write in the deck:", v["recommended_text"])
print("check it:", v["command"])
assert not mp["converged"] and mp["max_rel_diff"] > 0.02

# the recommended alpha as the model's own penalty (k-factor 1): it reproduces Lagrange
rec = v["recommended"]
again = penalty_verdict(model.with_overrides({"contact.penalty.alpha": rec["alpha"]}), tol=0.02)
print(f"alpha = {rec['alpha']:g}: worst {100 * again['model_penalty']['max_rel_diff']:.3f} %, "
      f"onset {100 * again['model_penalty']['onset_rel_diff']:.3f} % off")
assert again["model_penalty"]["converged"]
