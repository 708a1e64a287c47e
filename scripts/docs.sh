#!/usr/bin/env bash
# Build the documentation site into site/ (offline; open site/index.html): MkDocs-Material, the API
# reference from docstrings (mkdocstrings), the model reference and the commands' help generated at
# build time (docs/hooks/deckbridge_docs.py). Installs what it needs through scripts/bootstrap.sh.
#   bash scripts/docs.sh            # -> site/
#   bash scripts/docs.sh -d DIR     # -> DIR (any option goes to `mkdocs build`)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# Material for MkDocs 9.x is maintained to May 2027 (its successor, Zensical, reads this mkdocs.yml): notice silenced
export NO_MKDOCS_2_WARNING=1
exec bash "$root/scripts/bootstrap.sh" python -m mkdocs build --strict --quiet -f "$root/mkdocs.yml" "$@"
