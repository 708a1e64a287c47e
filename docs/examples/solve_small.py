"""Solve the default skirt on a small mesh with both contact methods and check the table reactions.

At the end of step 1 only N acts: the normal forces of the table nodes add up to N (force balance),
whatever the contact method. The Lagrange liftoff lies near the beam-theory estimate N R / (2 M_b).
"""

from deckbridge.model import load
from deckbridge.solve import solve_model

model = load(None, ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1"])
for method in ("lagrange", "penalty"):
    table, summary = solve_model(model, method)
    step1 = table[(table["step"] == 1) & (table["surface"] == "table")]
    step1 = step1[step1["increment"] == step1["increment"].max()]
    total = step1["force_n"].sum()                       # > 0 compressive [N]
    print(f"{method:8s}: sum of table forces at the end of step 1 = {total:.6g} N (N = {model.loads.N:g} N), "
          f"liftoff at lambda = {summary['liftoff_load_factor']:.4f}, theta = {summary['liftoff_theta_deg']:.1f} deg")
    assert abs(total - model.loads.N) < 1e-6 * model.loads.N

print(f"beam theory: lambda_c = N R / (2 M_b) = {model.beam_theory_liftoff():.4f}")
