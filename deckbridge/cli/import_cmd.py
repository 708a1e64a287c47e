"""``deckbridge import MESH -o model.yaml``: write a model for an existing hexahedral mesh, after checking it."""

from pathlib import Path

import click

from ..errors import DeckbridgeError
from ..outdir import prepare, write_text
from ._common import main


@main.command("import")
@click.argument("mesh", type=click.Path(dir_okay=False))
@click.option("-o", "--out", "out", required=True, type=click.Path(dir_okay=False), help="Model YAML to write.")
@click.option("--base", required=True, help="Node set of the slave nodes on the table (base plane).")
@click.option("--top", required=True, help="Node set of the loaded top (the reference node goes to its centre).")
@click.option("--stop", default=None, help="Node set of the radial-stop face (default: the base's inner edge).")
@click.option("--units", type=click.Choice(["m", "mm"]), default="m", help="Length unit of the mesh file.")
@click.option("--name", default=None, help="Model name (default: the mesh file's stem).")
@click.option("--set", "overrides", multiple=True, metavar="KEY=VALUE", help="Override a model value (repeatable).")
@click.option("--like", "like", default=None, type=click.Path(dir_okay=False), metavar="MODEL.yaml",
              help="Take material, loads, contact, steps and analysis from this model (all but its mesh and "
                   "geometry) instead of the default JAR's.")
@click.option("--force", is_flag=True, help="Overwrite an existing model file.")
def import_cmd(mesh, out, base, top, stop, units, name, overrides, like, force):
    """Read MESH (.inp, .msh, .bdf), check it, and write a model that uses it."""
    from ..imported_model import model_for_mesh
    from ..model import load
    p = Path(out)
    if p.exists() and not force:
        raise DeckbridgeError(f"{str(p)!r}: exists (use --force to overwrite)")
    like_model = None if like is None else load(like)
    model, text = model_for_mesh(mesh, p, base, top, stop, units, name=name, overrides=list(overrides),
                                 like=like_model)
    prepare(p.parent if str(p.parent) else ".")
    write_text(p, text)
    g = model.geometry
    click.echo(f"wrote {p}: R = {g.radius:.6g} m, t = {g.thickness:.6g} m, H = {g.height:.6g} m"
               + ("" if like is None else f"; material, loads and contact of {like}"))
    from ..dialects import DIALECTS
    from ..mesh import build_mesh
    mesh = build_mesh(model)
    from ..deck_elements import element_problem
    for d in DIALECTS.values():
        if element_problem(d.name, model, mesh):   # no decks of this dialect for these cells (run and decks say so)
            continue
        why = d.id_problem(mesh)
        if why:
            click.echo(f"note: {d.name} decks cannot carry this mesh's ids: {why}")
