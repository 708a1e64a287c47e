"""MkDocs hook of the deckbridge site: fills generated parts of pages at build time, so that they
cannot drift from the code.

- ``<!-- model-reference -->``: the model reference (:func:`deckbridge.model_reference.reference_markdown`,
  from the model's own defaults, default-file comments and validators);
- ``<!-- cli-help: NAME -->``: ``deckbridge NAME --help`` as click prints it;
- ``<!-- notebook: PATH -->``: the notebook at PATH (relative to docs/) as Markdown and code cells, or a
  note while it is not there.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

_CLI = re.compile(r"<!-- cli-help: ([a-z_-]+) -->")
_NB = re.compile(r"<!-- notebook: ([A-Za-z0-9_./-]+) -->")


def cli_help(name: str) -> str:
    import click

    from deckbridge.cli import main

    cmd = main.commands[name]
    text = cmd.get_help(click.Context(cmd, info_name=f"deckbridge {name}", terminal_width=100, max_content_width=100))
    return "```text\n" + text + "\n```"


def notebook_markdown(path: Path) -> str:
    if not path.is_file():
        return (f"!!! note\n    The notebook `docs/{path.name}` is not in this checkout yet; this page shows it "
                "once it is.")
    nb = json.loads(path.read_text(encoding="utf-8"))
    lang = nb.get("metadata", {}).get("kernelspec", {}).get("language", "python")
    out = [f"Source: `docs/notebooks/{path.name}` (run by the tests).", ""]
    for cell in nb.get("cells", []):
        src = "".join(cell.get("source", []))
        if cell.get("cell_type") == "markdown":
            out += [src, ""]
        elif cell.get("cell_type") == "code" and src.strip():
            out += [f"```{lang}", src, "```", ""]
            for o in cell.get("outputs", []):
                text = "".join(o.get("text", [])) or "".join(o.get("data", {}).get("text/plain", []))
                if text.strip():
                    out += ["```text", text.rstrip(), "```", ""]
    return "\n".join(out)


def on_page_markdown(markdown: str, page, config, files) -> str:
    if "<!-- model-reference -->" in markdown:
        from deckbridge.model_reference import reference_markdown

        markdown = markdown.replace("<!-- model-reference -->", reference_markdown())
    markdown = _CLI.sub(lambda m: cli_help(m.group(1)), markdown)
    docs = Path(config["docs_dir"])
    return _NB.sub(lambda m: notebook_markdown(docs / m.group(1)), markdown)
