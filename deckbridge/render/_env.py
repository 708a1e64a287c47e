"""The jinja2 environment shared by every deck dialect, and text sanitising for decks.

Templates are package data: the repository's top-level ``templates/`` folder is installed as the
package ``deckbridge.templates`` (``[tool.setuptools.package-dir]`` in ``pyproject.toml``; an editable
install maps the same name to the folder), and read through :mod:`importlib.resources`, so a wheel
renders the same decks as a checkout. ``templates/<dialect>/`` holds a dialect's templates;
``templates/_shared/`` the blocks several dialects include or extend (named ``_shared/...``).
"""

from __future__ import annotations

import re
from functools import lru_cache
from importlib.resources import files
from importlib.resources.abc import Traversable
from pathlib import Path

import jinja2

from ..outdir import safe_filename

TEMPLATE_PACKAGE = "deckbridge.templates"

_UNSAFE = re.compile(r"[^A-Za-z0-9 _.,:;()/+=-]")


def safe_comment(text: str, max_len: int = 60) -> str:
    """Model text made safe for a deck comment: one line, no '*', '$', control or odd characters."""
    one = " ".join(str(text).split())
    return _UNSAFE.sub("_", one)[:max_len]


def template_root() -> Traversable:
    """The installed templates folder (a Traversable of the package ``deckbridge.templates``)."""
    return files(TEMPLATE_PACKAGE)


@lru_cache(maxsize=None)
def environment(dialect: str) -> jinja2.Environment:
    """A strict environment loading ``templates/<dialect>/`` (or the absolute folder ``dialect``) then ``templates/``
    (undefined variables raise)."""
    root = template_root()
    folder = Path(dialect) if Path(dialect).is_absolute() else root / dialect   # absolute: a dialect outside the package
    if not folder.is_dir():
        raise FileNotFoundError(f"template folder {dialect!r} is missing from {TEMPLATE_PACKAGE}")

    def load(name: str) -> str | None:
        parts = name.split("/")
        for base in (folder, root):
            source = base.joinpath(*parts)
            if source.is_file():
                return source.read_bytes().decode("utf-8")
        return None

    env = jinja2.Environment(loader=jinja2.FunctionLoader(load), undefined=jinja2.StrictUndefined,
                             autoescape=False, keep_trailing_newline=True, trim_blocks=True,
                             lstrip_blocks=True)
    env.filters["safe_comment"] = safe_comment
    return env


def render(dialect: str, template: str, **context) -> str:
    return environment(dialect).get_template(template).render(**context)


def deck_paths(dialect, model_name: str, outdir: str | Path) -> list[Path]:
    """Paths in ``outdir`` of the decks of the dialect record ``dialect`` for the model ``model_name`` (names checked)."""
    return [Path(outdir) / safe_filename(n) for n in dialect.deck_names(model_name)]
