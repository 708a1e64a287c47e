"""``deckbridge init PATH``: write the default model as a commented YAML file."""

from pathlib import Path

import click

from ..errors import DeckbridgeError
from ..model import default_text
from ..outdir import prepare, write_text
from ._common import main


@main.command("init")
@click.argument("path", type=click.Path(dir_okay=False))
@click.option("--force", is_flag=True, help="Overwrite an existing file.")
def init_cmd(path, force):
    """Write the embedded default JAR model to PATH as commented YAML."""
    p = Path(path)
    if p.exists() and not force:
        raise DeckbridgeError(f"{str(p)!r}: exists (use --force to overwrite)")
    prepare(p.parent if str(p.parent) else ".")
    write_text(p, default_text())
    click.echo(f"wrote {p}")
