"""The model reference, generated from the model itself: every key of :class:`deckbridge.model.Model`
with its default, its unit and meaning (the comment of that key in the embedded default model,
``data/default_jar.yaml``), the section's docstring, and the rules its validators enforce.

The rules are not written here: each key is set, one at a time, to a handful of probe values
(:data:`PROBES`) on the default model, and every distinct one-line :class:`~deckbridge.errors.ModelError`
reason that names that key is collected. A rule added to a validator therefore appears in the
reference without anyone copying it. ``deckbridge`` documentation builds call
:func:`reference_markdown` (``docs/hooks/deckbridge_docs.py``).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import yaml

from .errors import ModelError
from .model import Model, default_text

# numbers either side of the usual bounds, a string, a flag, a huge value, an integer above the mesh caps
PROBES = ("text", True, -1, 0, 0.5, 0.6, 1.5, 400.0, 10**8, 1e31)


@dataclass(frozen=True)
class KeyDoc:
    """One model key: dotted ``key``, its ``default`` (YAML text), the default file's ``comment`` (unit and
    meaning) and the validator ``rules`` (one-line reasons, in probe order)."""
    key: str
    default: str
    comment: str
    rules: tuple[str, ...]


def _comments() -> dict[str, str]:
    """{dotted key: the comment on its line and the comment-only lines right below it} of the default YAML."""
    text = default_text()
    lines = text.splitlines()
    out: dict[str, str] = {}

    def walk(node, prefix):
        if not isinstance(node, yaml.MappingNode):
            return
        for k, v in node.value:
            key = f"{prefix}{k.value}"
            row = k.start_mark.line
            parts = [lines[row].split("#", 1)[1].strip()] if "#" in lines[row] else []
            nxt = row + 1
            while nxt < len(lines) and lines[nxt].strip().startswith("#") and \
                    len(lines[nxt]) - len(lines[nxt].lstrip()) > len(lines[row]) - len(lines[row].lstrip()):
                parts.append(lines[nxt].strip().lstrip("#").strip())
                nxt += 1
            out[key] = " ".join(p for p in parts if p)
            walk(v, key + ".")

    walk(yaml.compose(text), "")
    return out


def _leaves(d: dict, prefix: str = ""):
    for k, v in d.items():
        if isinstance(v, dict):
            yield from _leaves(v, f"{prefix}{k}.")
        else:
            yield f"{prefix}{k}", v


def rules_of(key: str, base: Model | None = None) -> tuple[str, ...]:
    """The distinct reasons the validators give when ``key`` takes each of :data:`PROBES`."""
    base = base or Model()
    seen: list[str] = []
    for probe in PROBES:
        try:
            base.with_overrides({key: probe})
        except ModelError as exc:
            if exc.key == key and exc.reason not in seen:
                seen.append(exc.reason)
        except Exception:          # noqa: BLE001  (a probe of another type than the validator expects)
            continue
    return tuple(seen)


def key_docs() -> list[KeyDoc]:
    """Every leaf key of the default model, in the order of the default YAML."""
    comments = _comments()
    out = []
    for key, value in _leaves(Model().to_dict()):
        default = yaml.safe_dump(value, default_flow_style=True).strip().removesuffix("...").strip()
        out.append(KeyDoc(key, default, comments.get(key, ""), rules_of(key)))
    return out


def sections() -> dict[str, str]:
    """{section key: the docstring of its dataclass} ('' for the top-level keys)."""
    out = {"": (Model.__doc__ or "").strip()}
    for f in dataclasses.fields(Model):
        default = getattr(Model(), f.name)
        if dataclasses.is_dataclass(default):
            out[f.name] = " ".join((type(default).__doc__ or "").split())
            for g in dataclasses.fields(default):
                sub = getattr(default, g.name)
                if dataclasses.is_dataclass(sub):
                    out[f"{f.name}.{g.name}"] = " ".join((type(sub).__doc__ or "").split())
    return out


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ") or "–"


def reference_markdown() -> str:
    """The model reference as Markdown: one table per section, its docstring above it."""
    docs = key_docs()
    secs = sections()
    groups: dict[str, list[KeyDoc]] = {}
    for d in docs:
        sec = d.key.rsplit(".", 1)[0] if "." in d.key else ""
        parts = sec.split(".") if sec else []
        for i in range(len(parts)):                 # a section before its subsections (contact, contact.stop)
            groups.setdefault(".".join(parts[: i + 1]), [])
        groups.setdefault(sec, []).append(d)
    out = []
    for sec, items in groups.items():
        if not items:
            continue
        out.append(f"### `{sec}`" if sec else "### top-level keys")
        if secs.get(sec):
            out.append("")
            out.append(secs[sec])
        out += ["", "| key | default | unit and meaning | rules (from the validators) |", "|---|---|---|---|"]
        for d in items:
            rules = "; ".join(d.rules)
            out.append(f"| `{d.key}` | `{_cell(d.default)}` | {_cell(d.comment)} | {_cell(rules)} |")
        out.append("")
    return "\n".join(out)
