"""Interrupts (issue 21 item 9): Ctrl-C (SIGINT) or SIGTERM while CalculiX runs under ``deckbridge run
--with-ccx`` ends in the project's one error line (not click's "Aborted!"), stops ccx, and leaves the output
folder byte for byte as it was (no partial ``decks/``, ``reference_*/`` or ``ccx/``).

Real signals to a real ``deckbridge`` process running the real ccx on a 16 x 4 x 1 mesh."""

from __future__ import annotations

import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from test_output_folders import SMALL, snapshot

pytestmark = pytest.mark.skipif(shutil.which("ccx") is None, reason="ccx not installed")
EXE = Path(sys.executable).parent / "deckbridge"


def _ccx_children(pid: int) -> list[int]:
    kids = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        kids += [int(x) for x in (task / "children").read_text().split()]
    return [k for k in kids if Path(f"/proc/{k}/comm").is_file() and Path(f"/proc/{k}/comm").read_text().strip() == "ccx"]


def _running(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.fixture(scope="module")
def previous_run(tmp_path_factory):
    """A real ``deckbridge run`` (its own process) once a module: the folder each signal test starts from (a copy)."""
    out = tmp_path_factory.mktemp("previous") / "run"
    first = subprocess.run([str(EXE), "run", *SMALL, "-o", str(out)], capture_output=True, text=True, timeout=300)
    assert first.returncode == 0, first.stderr
    return out


@pytest.mark.parametrize("sig, said", [(signal.SIGINT, "interrupted (SIGINT"), (signal.SIGTERM, "terminated (SIGTERM)")])
def test_a_signal_during_ccx_is_one_line_and_leaves_the_folder_as_it_was(tmp_path, previous_run, sig, said):
    out = tmp_path / "run"
    shutil.copytree(previous_run, out, symlinks=True)
    before = snapshot(out)
    proc = subprocess.Popen([str(EXE), "run", *SMALL, "--set", "steps.increments=40", "--with-ccx", "-o", str(out)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))   # as a terminal gives it
    try:
        t0 = time.monotonic()
        while not (ccx := _ccx_children(proc.pid)):
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() - t0 < 120, "ccx never started"
            time.sleep(0.05)
        time.sleep(0.5)
        proc.send_signal(sig)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert proc.returncode == 1, err
    assert len(lines) == 1 and lines[0].startswith(f"deckbridge: error: {said}"), err
    assert "Aborted!" not in err and "Traceback" not in err
    assert not _running(ccx[0])
    assert snapshot(out) == before                      # the first run's files, and nothing else
