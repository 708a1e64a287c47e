"""No new method-name literals in deckbridge: a decision about a contact method reads the registry
(deckbridge/methods.py: PENALTY, LAGRANGE, AUGMENTED, the Method records), not a string written out again.

The package is read with ``ast``: every string constant equal to a method name ('penalty', 'lagrange',
'augmented') counts, outside methods.py and summary_keys.py (the registry and the keys' meanings), docstrings
and the CLI's ``help=`` text. What remains is in :data:`ALLOWED`, each with its reason; a file may hold
fewer (a literal replaced), never more.
"""

from __future__ import annotations

import ast
from collections import Counter
from pathlib import Path

from deckbridge.methods import NAMES

PKG = Path(__file__).resolve().parents[1] / "deckbridge"
EXEMPT_FILES = {"methods.py", "summary_keys.py"}

# (file under deckbridge/, literal): (at most this many, why it stays)
ALLOWED: dict[tuple[str, str], tuple[int, str]] = {
    ("dialects/calculix/reader.py", "lagrange"): (1, "data: a user's ccx job file named *lagrange* is a mortar run"),
    ("dialects/calculix/reader.py", "penalty"): (1, "data: a user's ccx job file named *penalty* is a penalty run"),
    # owned by other helpers in round 3 (r3-ccxquad, r3-decks): to be replaced by PENALTY / LAGRANGE there
    ("dialects/calculix/render.py", "penalty"): (5, "the CalculiX deck kinds (DECKS) and their numbering calls"),
    ("dialects/abaqus/reader.py", "lagrange"): (1, "the method column of the Abaqus surface-contact table"),
    ("dialects/abaqus/render.py", "augmented"): (1, "the template flag `augmented` (templates/abaqus/lagrange.inp.j2)"),
    ("dialects/nastran_surface/reader.py", "penalty"): (1, "the method column of the Nastran surface-contact table"),
}


def _docstrings(tree: ast.AST) -> set[int]:
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) and isinstance(first.value.value, str):
                out.add(id(first.value))
    return out


def _help_texts(tree: ast.AST) -> set[int]:
    """String constants inside a ``help=`` keyword (the CLI's option and command help)."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.keyword) and node.arg == "help":
            out |= {id(n) for n in ast.walk(node.value) if isinstance(n, ast.Constant)}
    return out


def method_literals(path: Path) -> list[tuple[int, str]]:
    """(line, literal) of every string constant of ``path`` equal to a method name, docstrings and help text aside."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    skip = _docstrings(tree) | _help_texts(tree)
    return [(n.lineno, n.value) for n in ast.walk(tree)
            if isinstance(n, ast.Constant) and isinstance(n.value, str) and n.value in NAMES and id(n) not in skip]


def test_no_new_method_name_literals_in_deckbridge():
    found: dict[tuple[str, str], list[int]] = {}
    for path in sorted(PKG.rglob("*.py")):
        rel = path.relative_to(PKG).as_posix()
        if rel in EXEMPT_FILES:
            continue
        for line, lit in method_literals(path):
            found.setdefault((rel, lit), []).append(line)
    over = {k: v for k, v in found.items() if len(v) > ALLOWED.get(k, (0, ""))[0]}
    assert not over, ("method-name literals: use deckbridge.methods (PENALTY, LAGRANGE, AUGMENTED, METHODS[...]) "
                      f"or add a data use to ALLOWED with its reason: {over}")


def test_the_scan_sees_literals_and_skips_docstrings_and_help(tmp_path):
    src = tmp_path / "probe.py"
    src.write_text('"""Module doc: \'penalty\'."""\nimport click\n\n\ndef f(m):\n    """\'lagrange\'"""\n'
                   '    return m == "penalty" or m in ("lagrange", "mortar")\n\n\n'
                   '@click.option("--x", help="penalty")\ndef g():\n    return {"augmented": 1}\n')
    assert sorted(method_literals(src)) == [(7, "lagrange"), (7, "penalty"), (12, "augmented")]
    assert Counter(lit for _, lit in method_literals(src)) == Counter(NAMES)
