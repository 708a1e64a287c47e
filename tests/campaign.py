"""Test helper of the property-based campaign (tests/test_campaign_*.py): run the CLI in-process in a sandbox
folder and check what every refusal must be.

A refusal is: exit 2 (input) or 1 (run), exactly one stderr line ``deckbridge: error: ...`` naming what is
at fault, never "unexpected", no traceback, no control characters; nothing created or changed in the
sandbox (no partial output folder, no stray file beside it, the user's files intact). A success writes
only into its output folder.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
from pathlib import Path

from click.testing import CliRunner
from hypothesis import HealthCheck, settings

from deckbridge.cli import main

# bounded: derandomized, few examples, no deadline (the machine is shared); each family < ~10 s on one core
CAMPAIGN = settings(max_examples=12, deadline=None, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
SMALL = ["mesh.n_theta=16", "mesh.n_z=2", "mesh.n_r=1", "steps.increments=2"]


def small_set() -> list[str]:
    return [a for s in SMALL for a in ("--set", s)]


def snapshot(root: Path) -> dict[str, str]:
    """Relative path -> content hash (files) or 'dir' of everything under ``root``."""
    out = {}
    for dirpath, dirs, files in os.walk(root):
        for d in dirs:
            out[os.path.relpath(os.path.join(dirpath, d), root)] = "dir"
        for f in files:
            p = os.path.join(dirpath, f)
            try:
                with open(p, "rb") as fh:
                    out[os.path.relpath(p, root)] = hashlib.sha1(fh.read()).hexdigest()
            except OSError:
                out[os.path.relpath(p, root)] = "unreadable"
    return out


def run(args, sandbox: Path, **kw):
    """Invoke ``deckbridge args`` in-process with the working folder ``sandbox``; returns (result, before, after)."""
    before = snapshot(sandbox)
    with contextlib.chdir(sandbox):
        res = CliRunner().invoke(main, [str(a) for a in args], **kw)
    return res, before, snapshot(sandbox)


def error_line(res) -> str:
    """The one error line of a refused command (asserting the refusal's form)."""
    assert res.exit_code in (1, 2), (res.exit_code, res.output[-2000:])
    assert res.exception is None or isinstance(res.exception, SystemExit), repr(res.exception)
    # a progress bar redraws its line with carriage returns: what stays on the terminal is the last redraw
    lines = [ln.split("\r")[-1] for ln in res.stderr.split("\n") if ln.split("\r")[-1].strip()]
    assert len(lines) == 1 and lines[0].startswith("deckbridge: error: "), res.stderr[-2000:]
    line = lines[0]
    assert "unexpected" not in line and "Traceback" not in res.output, line
    assert "\x1b" not in line and "\r" not in line and len(line) < 2000, repr(line[:300])
    return line


def refused(res, before, after, *needles: str, code: int | None = None) -> str:
    """A clean refusal that changed nothing in the sandbox and names one of ``needles`` (if any)."""
    line = error_line(res)
    if code is not None:
        assert res.exit_code == code, (res.exit_code, line)
    assert after == before, ("the sandbox changed", sorted(set(after.items()) ^ set(before.items()))[:10])
    if needles:
        assert any(n in line for n in needles), (needles, line)
    return line


def outcome(res, before, after, out: str, *needles: str) -> str | None:
    """Success writing only under ``out`` (None), or a clean refusal (its line)."""
    if res.exit_code == 0:
        new = {k for k in set(after) - set(before)}
        assert all(k == out or k.startswith(out + os.sep) for k in new), sorted(new)[:10]
        assert all(after.get(k) == v for k, v in before.items() if not k.startswith(out + os.sep)), \
            "a file outside the output folder changed"
        return None
    return refused(res, before, after, *needles)
