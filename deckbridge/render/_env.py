"""The jinja2 environment shared by every deck dialect, and text sanitising for decks."""

from __future__ import annotations

import re
from functools import lru_cache
from pathlib import Path

import jinja2

TEMPLATE_ROOT = Path(__file__).resolve().parents[2] / "templates"

_UNSAFE = re.compile(r"[^A-Za-z0-9 _.,:;()/+=-]")


def safe_comment(text: str, max_len: int = 60) -> str:
    """Model text made safe for a deck comment: one line, no '*', '$', control or odd characters."""
    one = " ".join(str(text).split())
    return _UNSAFE.sub("_", one)[:max_len]


@lru_cache(maxsize=None)
def environment(dialect: str) -> jinja2.Environment:
    """A strict environment loading ``templates/<dialect>/`` (undefined variables raise)."""
    folder = TEMPLATE_ROOT / dialect
    if not folder.is_dir():
        raise FileNotFoundError(f"template folder {folder} is missing")
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(str(folder)), undefined=jinja2.StrictUndefined,
                             autoescape=False, keep_trailing_newline=True, trim_blocks=True,
                             lstrip_blocks=True)
    env.filters["safe_comment"] = safe_comment
    return env


def render(dialect: str, template: str, **context) -> str:
    return environment(dialect).get_template(template).render(**context)
