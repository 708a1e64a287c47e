"""One ``--set key.sub=value`` override: its text parsed into a dotted key and a YAML value (applied to a model
by :func:`deckbridge.model.apply_overrides`)."""

from __future__ import annotations

from typing import Any

import yaml

from . import safe_yaml
from .errors import ModelError


def parse_override(text: str) -> tuple[str, Any]:
    """Parse ``key.sub=value``; the value is read as YAML (numbers, null, strings)."""
    if "=" not in text:
        raise ModelError("`overrides`", text, "expected key.sub=value")
    key, raw = text.split("=", 1)
    key = key.strip()
    if not key:
        raise ModelError("`overrides`", text, "empty key")
    if len(text) > 4096:
        raise ModelError("`overrides`", text, "longer than 4096 characters")
    try:
        value = safe_yaml.load(raw) if raw.strip() else None
    except safe_yaml.StrictYAMLError as exc:
        raise ModelError(key, raw, str(exc).removeprefix("line 1: ")) from None
    except yaml.YAMLError:
        value = raw
    return key, value
