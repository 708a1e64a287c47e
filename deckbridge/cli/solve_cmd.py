"""``deckbridge solve``: run the reference solver on a model with one contact method (deckbridge.methods)."""

import click
from tqdm import tqdm

from ..errors import DeckbridgeError
from ..methods import K_METHODS, METHODS, NAMES
from ._common import MESH_META, main, model_options


@main.command("solve")
@model_options
@click.option("--method", type=click.Choice(NAMES), required=True,
              help="Contact method: penalty (gap springs, CGAP/PGAP semantics), lagrange (exact) or augmented "
                   "(augmented Lagrangian: penalty plus multiplier updates, the exact answer at any k).")
@click.option("--alpha", type=float, default=None,
              help="Penalty, augmented: k_c = ALPHA A^2 K / V instead of the model's contact.penalty.alpha.")
@click.option("--k-factor", "k_factor", type=float, default=None,
              help="Penalty, augmented: multiply the model's normal contact stiffness by F.")
@click.option("--algorithm", type=click.Choice(["active-set", "gauss-seidel"]), default=None,
              help="Lagrange: exact active set (default) or the paper's projected Gauss-Seidel (slow past liftoff).")
@click.option("-o", "--out", "outdir", required=True, type=click.Path(),
              help="Output folder: contact.csv, summary.json, result.vtu, result.pvd + result_NNN.vtu "
                   "(ParaView series, one VTU per increment); written whole or not at all.")
def solve_cmd(model, method, alpha, k_factor, algorithm, outdir):
    """Solve MODEL with the reference solver and write the contact table, a summary and a VTU file."""
    from .. import summary_keys as K
    from ..api import solve                   # the solver: imported by the commands that solve
    from ..solve import penalty_factor

    if alpha is not None and k_factor is not None:
        raise DeckbridgeError(f"--alpha = {alpha!r} and --k-factor = {k_factor!r}: give one or the other")
    if method not in K_METHODS and (alpha is not None or k_factor is not None):
        raise DeckbridgeError(f"--alpha/--k-factor: only for --method {' or '.join(K_METHODS)} "
                              "(Lagrange has no penalty stiffness)")
    if algorithm is not None and algorithm not in METHODS[method].algorithms:
        raise DeckbridgeError(f"--algorithm = {algorithm!r}: only for --method lagrange")
    k_factor = 1.0 if k_factor is None else k_factor
    if method in K_METHODS:
        penalty_factor(model, k_factor, alpha)          # its range, before any work
    with tqdm(total=model.steps.increments + 2, desc=f"{method} increments", unit="inc", leave=False) as bar:
        def progress(step, inc, lam):
            bar.set_postfix_str(f"step {step} lambda {lam:.3g}")
            bar.update(1)
        result = solve(model, method, k_factor=k_factor, alpha=alpha, algorithm=algorithm, on_increment=progress,
                       mesh=click.get_current_context().meta.get(MESH_META),     # the guard's, when it built one
                       release=True)             # the factor and dense blocks go before the VTUs are written
    paths, summary = result.write(outdir), result.summary
    series = [p for p in paths if p.suffix == ".vtu" and p.name != "result.vtu"]   # listed in result.pvd
    for p in paths:
        if p not in series:
            click.echo(f"wrote {p}" + (f" (+ {len(series)} VTUs, one per increment)" if p.suffix == ".pvd" else ""))
    lf, lfs = summary[K.LIFTOFF_LOAD_FACTOR], summary[K.SECTION_LIFTOFF_LOAD_FACTOR]
    click.echo(f"{method}: liftoff " + ("none" if lf is None else
               f"at load factor {lf:.4f}, theta {summary[K.LIFTOFF_THETA_DEG]:.1f} deg")
               + ("" if lfs is None else f" (whole section {lfs:.4f})")
               + f"; sigma_n in [{summary[K.MIN_SIGMA_N_PA] / 1e6:.4g}, {summary[K.MAX_SIGMA_N_PA] / 1e6:.4g}] MPa;"
               f" {summary[K.DOFS]} dofs in {summary[K.WALL_TIME_S]:.2f} s")
    if summary.get(K.AUGMENTED):
        au = summary[K.AUGMENTED]
        click.echo(f"augmented: {au['augmentations']} augmentations (at most {au['augmentations_max']} per "
                   f"increment); penetration {au['penetration_m']:.3g} m (tolerance {au['penetration_tol_m']:.3g} m)")
