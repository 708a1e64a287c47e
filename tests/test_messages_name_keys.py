"""Library code speaks in model keys and parameter names, the command line in flags (issue 22).

Every error a module outside ``deckbridge/cli/`` raises names a function parameter in backquotes
(`workers`), never a flag (--workers); ``cli._common.as_flags`` writes the flag the user typed.
"""

import ast
import re
from pathlib import Path

import pytest

from deckbridge import limits
from deckbridge.cli._common import PARAMETER_FLAGS, as_flags
from deckbridge.errors import DeckbridgeError

ROOT = Path(__file__).resolve().parents[1] / "deckbridge"
FLAG = re.compile(r"(?<![\w-])--[a-z][a-z-]+")


def _raised_strings(path: Path):
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Raise) and node.exc is not None:
            for sub in ast.walk(node.exc):
                if isinstance(sub, ast.Constant) and isinstance(sub.value, str):
                    yield node.lineno, sub.value


def test_no_library_error_names_a_flag():
    found = [f"{p.relative_to(ROOT.parent)}:{line}: {text!r}" for p in sorted(ROOT.rglob("*.py"))
             if "cli" not in p.relative_to(ROOT).parts[:1]
             for line, text in _raised_strings(p) if FLAG.search(text)]
    assert found == []


def test_the_scan_sees_a_flag():
    assert FLAG.search("use --workers") and not FLAG.search("a well-known key") and not FLAG.search("-o = x")


def test_the_cli_writes_the_flag_of_a_named_parameter():
    with pytest.raises(DeckbridgeError) as err:
        limits.check_workers(0)
    assert str(err.value) == "`workers` = 0: must be a positive integer"
    assert as_flags(str(err.value)) == "--workers = 0: must be a positive integer"
    assert as_flags("`executor` local and `scheduler` = 'x'") == "--executor local and --scheduler = 'x'"
    assert as_flags("`not_a_parameter` stays") == "`not_a_parameter` stays"
    assert all(f.startswith("-") for f in PARAMETER_FLAGS.values())
