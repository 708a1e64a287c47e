"""Shared pieces of the bad-input regression tests (tests/test_bad_input*.py, issue 13): the CLI run in-process
through click's CliRunner, the one-error-line check, and the 60 s alarm that turns a hang into a failure
(``time_limit``: an autouse fixture; a module imports it to use it)."""

from __future__ import annotations

import signal

import pytest
from click.testing import CliRunner

from deckbridge.cli import main

SMALL = ["--set", "mesh.n_theta=16", "--set", "mesh.n_z=4", "--set", "mesh.n_r=1", "--set", "steps.increments=4"]


class Hang(BaseException):
    """Raised by the alarm: a test that runs past its limit fails instead of hanging."""


@pytest.fixture(autouse=True)
def time_limit():
    def on_alarm(signum, frame):
        raise Hang("test ran past its 60 s limit")
    old = signal.signal(signal.SIGALRM, on_alarm)
    signal.alarm(60)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, old)


def cli(args, **kw):
    res = CliRunner().invoke(main, [str(a) for a in args], **kw)
    if isinstance(res.exception, Hang):
        raise res.exception
    return res


def one_error_line(res, code=2, needle=""):
    """Exit ``code``, exactly one stderr line ``deckbridge: error: ...`` holding ``needle``, no traceback."""
    assert res.exit_code == code, (res.exit_code, res.output)
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("deckbridge: error: "), res.stderr[:2000]
    assert "Traceback" not in res.output and "\x1b" not in res.stderr
    assert len(lines[0]) < 1000
    assert needle in lines[0], lines[0]
    return lines[0]
