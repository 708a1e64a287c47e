"""A penalty sweep on a small mesh: the gap to Lagrange closes as k grows, and the recommendation is the
smallest k-factor whose sigma_N and liftoff onset both reproduce Lagrange within tol (2 %), given as
k-factor, alpha and KA per node [N/m]. About 10 s.
"""

import tempfile

from deckbridge.model import load
from deckbridge.studies.sweep import run_sweep

model = load(None, ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1", "steps.increments=5"])
with tempfile.TemporaryDirectory() as out:
    res = run_sweep(model, [1, 10, 100, 1000, 10000], out, progress=False, report=False)
s = res["summary"]
mesh = s["meshes"][0]
for d in mesh["penalty"]:
    print(f"k-factor {d['k_factor']:>7g}: worst |dsigma_N| / peak = {100 * d['max_rel_diff']:6.3f} %, "
          f"onset {100 * d['onset_rel_diff']:6.3f} % off, reproduces Lagrange: {d['reproduces']}")
print("recommended:", mesh["recommended"]["text"])
rel = [d["max_rel_diff"] for d in mesh["penalty"]]
assert all(b < a for a, b in zip(rel, rel[1:]))                  # converges as k grows
k = s["recommended_k_factor"]
assert k is not None and k > 1                                    # alpha = 0.1 is not enough here
assert s["recommended"]["alpha"] == [0.1 * k]
