"""Shared pieces of the command line: the group, model options and one-line error handling."""

from __future__ import annotations

import functools
import sys

import click

from ..errors import DeckbridgeError
from ..model import Model, ModelError, load


class _Group(click.Group):
    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except (ModelError, DeckbridgeError) as exc:
            click.echo(f"deckbridge: error: {exc}", err=True)
            sys.exit(2)


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="deckbridge")
def main():
    """deckbridge: one contact model, decks for penalty and Lagrange, a reference solver, a comparison."""


def model_options(func):
    """Add ``[MODEL]`` and ``--set key.sub=value`` and pass a validated ``model`` to the command."""

    @click.argument("model_path", metavar="[MODEL]", required=False,
                    type=click.Path(dir_okay=False))
    @click.option("--set", "overrides", multiple=True, metavar="KEY=VALUE",
                  help="Override a model value, e.g. --set mesh.n_theta=48 (repeatable).")
    @functools.wraps(func)
    def wrapper(model_path, overrides, **kwargs):
        model: Model = load(model_path, list(overrides))
        return func(model=model, **kwargs)

    return wrapper
