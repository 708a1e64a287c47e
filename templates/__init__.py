"""Deck templates (jinja2), one folder per dialect and ``_shared/`` for blocks several dialects use.

This file makes the folder the package ``deckbridge.templates`` of the wheel (see ``pyproject.toml``),
read by :mod:`deckbridge.render._env` through :mod:`importlib.resources`. It holds no code.
"""
