"""Strict YAML for model files and ``--set`` values: a SafeLoader with YAML 1.2 core-schema scalars.

Refused (one :class:`StrictYAMLError` line each, with the line number):

- aliases and anchors (``&a`` / ``*a``; a 299-byte alias bomb expands to gigabytes) and merge keys;
- duplicate keys in one mapping (YAML says they are an error; PyYAML keeps the last);
- nesting deeper than :data:`MAX_DEPTH`;
- numbers whose meaning differs between YAML 1.1 and 1.2 or that read as a mistake: leading-zero
  integers (``030``: 24 in YAML 1.1, 30 in 1.2), ``0x18``, ``0o17``, ``0b101``, digit separators
  (``1_000``) and sexagesimal (``1:00`` = 60 in YAML 1.1). Write the number in decimal.

Scalars resolve as YAML 1.2's core schema: ``true``/``false`` (not yes/no/on/off), ``null``/``~``,
decimal integers, decimal floats with or without exponent sign (``1.0e9`` is a float, a string in YAML 1.1),
``.inf``/``.nan`` (refused later as "must be finite"); everything else is a string (dates included).

:func:`read_model_text` reads a model file: a regular file of at most :data:`MAX_MODEL_BYTES`, UTF-8.
"""

from __future__ import annotations

import os
import re
import stat
from pathlib import Path

import yaml
from yaml.composer import ComposerError
from yaml.constructor import ConstructorError
from yaml.events import AliasEvent, MappingStartEvent, ScalarEvent, SequenceStartEvent

MAX_DEPTH = 20
MAX_MODEL_BYTES = 1 << 20          # 1 MiB: the default model is 3 kB

_INT = re.compile(r"[-+]?(0|[1-9][0-9]*)\Z")
_FLOAT = re.compile(r"[-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)?\Z")
_SPECIAL = re.compile(r"([-+]?\.(inf|Inf|INF)|\.(nan|NaN|NAN))\Z")
_AMBIGUOUS = re.compile(r"[-+]?(0[0-9_]+|0[xXoObB][0-9a-fA-F_]*|[0-9][0-9_]*(:[0-5]?[0-9])+(\.[0-9_]*)?"
                        r"|[0-9]+(_[0-9]*)+(\.[0-9_]*)?([eE][-+]?[0-9]+)?)\Z")
_BOOL = re.compile(r"(true|True|TRUE|false|False|FALSE)\Z")
_NULL = re.compile(r"(~|null|Null|NULL|)\Z")
_AMBIG_TAG = "tag:deckbridge,2026:ambiguous-number"


class StrictYAMLError(yaml.YAMLError):
    """A construct the strict loader refuses; ``str(err)`` is one line."""


class StrictLoader(yaml.SafeLoader):
    """SafeLoader without aliases, anchors, merge keys or duplicate keys; YAML 1.2 core scalars."""

    yaml_implicit_resolvers: dict = {}
    _depth = 0

    def compose_node(self, parent, index):
        event = self.peek_event()
        line = event.start_mark.line + 1
        if isinstance(event, AliasEvent):
            raise StrictYAMLError(f"line {line}: aliases (*name) are not allowed")
        if isinstance(event, (ScalarEvent, MappingStartEvent, SequenceStartEvent)) and event.anchor is not None:
            raise StrictYAMLError(f"line {line}: anchors (&name) are not allowed")
        self._depth += 1
        try:
            if self._depth > MAX_DEPTH:
                raise StrictYAMLError(f"line {line}: nested deeper than {MAX_DEPTH} levels")
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1

    def construct_mapping(self, node, deep=False):
        seen = set()
        for key_node, _ in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":
                raise StrictYAMLError(f"line {key_node.start_mark.line + 1}: merge keys (<<) are not allowed")
            key = self.construct_object(key_node, deep=True)
            try:
                dup = key in seen
            except TypeError:
                raise StrictYAMLError(f"line {key_node.start_mark.line + 1}: a key must be a plain value") from None
            if dup:
                raise StrictYAMLError(f"line {key_node.start_mark.line + 1}: duplicate key {str(key)[:60]!r}")
            seen.add(key)
        return super().construct_mapping(node, deep=deep)

    def flatten_mapping(self, node):   # no merge keys: nothing to flatten
        return None


def _construct_int(loader, node):
    value = loader.construct_scalar(node)
    if not _INT.fullmatch(value):
        raise StrictYAMLError(f"line {node.start_mark.line + 1}: {value[:40]!r} is not a decimal integer")
    return int(value)


def _construct_float(loader, node):
    value = loader.construct_scalar(node)
    if _SPECIAL.fullmatch(value):
        return float(value.replace(".", ""))
    if not _FLOAT.fullmatch(value):
        raise StrictYAMLError(f"line {node.start_mark.line + 1}: {value[:40]!r} is not a decimal number")
    return float(value)


def _construct_ambiguous(loader, node):
    value = loader.construct_scalar(node)
    raise StrictYAMLError(f"line {node.start_mark.line + 1}: {value[:40]!r} is ambiguous (YAML 1.1 and 1.2 read it "
                          "differently, or not as a decimal number): write the number in decimal")


def _construct_bool(loader, node):
    return loader.construct_scalar(node).lower() == "true"


StrictLoader.add_implicit_resolver("tag:yaml.org,2002:bool", _BOOL, list("tTfF"))
StrictLoader.add_implicit_resolver("tag:yaml.org,2002:null", _NULL, ["~", "n", "N", ""])
StrictLoader.add_implicit_resolver(_AMBIG_TAG, _AMBIGUOUS, list("-+0123456789"))
StrictLoader.add_implicit_resolver("tag:yaml.org,2002:int", _INT, list("-+0123456789"))
StrictLoader.add_implicit_resolver("tag:yaml.org,2002:float", _FLOAT, list("-+.0123456789"))
StrictLoader.add_implicit_resolver("tag:yaml.org,2002:float", _SPECIAL, list("-+."))
StrictLoader.add_constructor("tag:yaml.org,2002:int", _construct_int)
StrictLoader.add_constructor("tag:yaml.org,2002:float", _construct_float)
StrictLoader.add_constructor("tag:yaml.org,2002:bool", _construct_bool)
StrictLoader.add_constructor(_AMBIG_TAG, _construct_ambiguous)
for _tag in ("timestamp", "binary", "omap", "pairs", "set"):
    StrictLoader.add_constructor(f"tag:yaml.org,2002:{_tag}", None)  # unknown tag: refused as not valid YAML
del _tag


def load(text: str):
    """Parse one YAML document with :class:`StrictLoader`.

    Raises :class:`StrictYAMLError` for refused constructs, ``yaml.YAMLError`` for invalid YAML.
    """
    try:
        return yaml.load(text, Loader=StrictLoader)  # noqa: S506  (a SafeLoader subclass)
    except (ComposerError, ConstructorError) as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}: " if mark is not None else ""
        raise StrictYAMLError(f"{where}{exc.problem or exc.context or 'not valid YAML'}") from None
    except RecursionError:
        raise StrictYAMLError(f"nested deeper than {MAX_DEPTH} levels") from None


def _shorten(text: str) -> str:
    return text if len(text) <= 120 else text[:117] + "..."


def read_model_text(path: str | Path) -> str:
    """The text of a model file: must be a regular file, at most MAX_MODEL_BYTES, UTF-8, not empty.

    Raises ``ValueError`` with a one-line reason (the caller names the file).
    """
    p = Path(path)
    try:
        st = os.stat(p)
    except OSError as exc:
        raise ValueError(f"cannot read file ({exc.strerror})") from None
    if stat.S_ISDIR(st.st_mode):
        raise ValueError("is a folder, not a model file")
    if not stat.S_ISREG(st.st_mode):
        raise ValueError("not a regular file (device, pipe or socket)")
    if st.st_size > MAX_MODEL_BYTES:
        raise ValueError(f"{st.st_size} bytes: a model file is at most {MAX_MODEL_BYTES} bytes")
    try:
        with open(p, "rb") as fh:
            data = fh.read(MAX_MODEL_BYTES + 1)
    except OSError as exc:
        raise ValueError(f"cannot read file ({exc.strerror})") from None
    if len(data) > MAX_MODEL_BYTES:
        raise ValueError(f"more than {MAX_MODEL_BYTES} bytes: a model file is at most that")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise ValueError(f"not UTF-8 text (byte 0x{data[exc.start]:02x} on line {line}); save the file as UTF-8") from None
    if "\x00" in text:
        raise ValueError("contains NUL bytes: not a text file")
    return text
