"""Output folders (issue 26, issue 21 item 9): the user's files are never overwritten nor deleted, a failed run
leaves its folder as it was, a degenerate mesh still gets its report, files get a plain open()'s mode, a full disk
names the path, and a mesh no machine could hold is refused before numpy tries.

Every check here runs the real command (click's runner, in process) on a 16 x 4 x 1 mesh and looks at the files
left on disk afterwards: bytes, names, mode bits."""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from deckbridge import outdir
from deckbridge.cli import main

SMALL = ["--set", "mesh.n_theta=16", "--set", "mesh.n_z=4", "--set", "mesh.n_r=1", "--set", "steps.increments=4",
         "--set", "outputs.vtu=false"]
TIPS = ["--set", "loads.M=2.5e7"]           # the skirt tips over: the reference solver fails


def cli(args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    """``run SMALL`` once a module: the previous run the failed-run and rerun tests start from (each a copy)."""
    out = tmp_path_factory.mktemp("small_run") / "run"
    res = cli(["run", *SMALL, "-o", out])
    assert res.exit_code == 0, res.output
    return out


def snapshot(folder: Path) -> dict:
    """Every file and folder under ``folder`` (hidden ones included) -> sha256 of its bytes (None: a folder)."""
    out = {}
    for root, dirs, files in os.walk(folder):
        for d in dirs:
            out[os.path.relpath(os.path.join(root, d), folder)] = None
        for f in files:
            p = os.path.join(root, f)
            out[os.path.relpath(p, folder)] = hashlib.sha256(Path(p).read_bytes()).hexdigest()
    return out


def error_line(res, code: int) -> str:
    assert res.exit_code == code, (res.exit_code, res.output)
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("deckbridge: error: "), res.stderr
    return lines[0]


# --- a folder the project did not create and mark: refused unless --force, for every command ---------------------
ARGS = {"decks": [*SMALL], "solve": ["--method", "penalty", *SMALL], "run": [*SMALL], "sweep": [*SMALL, "--k-factors", "1"],
        "liftoff": [*SMALL], "compare": ["no-such-source"]}


def test_every_command_with_an_output_folder_is_checked_here():
    with_outdir = {name for name, cmd in main.commands.items() if any(p.name == "outdir" for p in cmd.params)}
    assert with_outdir == set(ARGS)


@pytest.mark.parametrize("command", sorted(ARGS))
def test_a_folder_of_the_users_files_is_refused(tmp_path, command):
    """Issue 26: ``run -o .`` in a folder holding the user's summary.json / report.html overwrote them."""
    (tmp_path / "summary.json").write_text('{"mine": true}')
    (tmp_path / "report.html").write_text("<p>my report</p>")
    before = snapshot(tmp_path)
    line = error_line(cli([command, *ARGS[command], "-o", tmp_path]), 2)
    assert "holds files deckbridge did not write (report.html, summary.json)" in line and "--force" in line
    assert snapshot(tmp_path) == before                       # not a byte written, no marker added


def test_run_into_the_current_folder_is_refused(tmp_path, monkeypatch):
    """``run -o .`` where the user keeps a summary.json of their own."""
    (tmp_path / "summary.json").write_text('{"mine": true}')
    monkeypatch.chdir(tmp_path)
    assert "-o = '.': holds files" in error_line(cli(["run", *SMALL, "-o", "."]), 2)
    assert sorted(os.listdir(tmp_path)) == ["summary.json"]


def test_force_writes_beside_the_users_files_and_a_rerun_needs_no_force(tmp_path):
    (tmp_path / "notes.txt").write_text("mine")
    assert cli(["decks", *SMALL, "-o", tmp_path, "--force"]).exit_code == 0
    assert (tmp_path / "notes.txt").read_text() == "mine" and outdir.owner_of(tmp_path) == "decks"
    assert cli(["decks", *SMALL, "-o", tmp_path]).exit_code == 0        # its own folder now


# --- failed runs: the folder as it was --------------------------------------------------------------------------
def test_a_run_that_tips_over_leaves_the_folder_as_it_was(tmp_path, small_run):
    """Issue 21.9: ``run --set loads.M=2.5e7 -o X`` left X/decks/; into an existing run's folder it left new
    decks beside the old results."""
    error_line(cli(["run", *SMALL, *TIPS, "-o", tmp_path / "new"]), 1)
    assert not (tmp_path / "new").exists()
    old = tmp_path / "old"
    shutil.copytree(small_run, old, symlinks=True)              # a successful run's folder
    before = snapshot(old)
    error_line(cli(["run", *SMALL, *TIPS, "--set", "mesh.n_theta=20", "-o", old]), 1)
    assert snapshot(old) == before
    empty = tmp_path / "empty"
    empty.mkdir()
    error_line(cli(["run", *SMALL, *TIPS, "-o", empty]), 1)
    assert list(empty.iterdir()) == []


def test_a_successful_rerun_replaces_the_previous_run_and_keeps_other_files(tmp_path, small_run):
    """A re-run removes what the previous run wrote and it does not (a stale ``ccx/``, recorded in the marker),
    and never a file the project did not write."""
    shutil.copytree(small_run, tmp_path, symlinks=True, dirs_exist_ok=True)    # a successful run's folder
    recorded = outdir.recorded(tmp_path)
    assert {"decks", "reference_penalty", "report.html", "summary.json"} <= set(recorded)
    (tmp_path / "ccx").mkdir()                                  # as a run --with-ccx leaves it
    (tmp_path / "ccx" / "JAR_ccx_penalty.frd").write_text("old result")
    (tmp_path / "mine.txt").write_text("mine")
    assert cli(["run", *SMALL, "--set", "mesh.n_theta=20", "-o", tmp_path]).exit_code == 0
    assert not (tmp_path / "ccx").exists() and (tmp_path / "mine.txt").read_text() == "mine"
    assert '"n_theta": 20' in (tmp_path / "summary.json").read_text()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".deckbridge-") and p.name not in outdir.CONTROL]


# --- the report of a degenerate point set (Qhull) -----------------------------------------------------------------
@pytest.mark.parametrize("extra", [[], ["--with-ccx", "--set", "steps.increments=30", "--set", "mesh.n_theta=12"]],
                         ids=["reference", "with-ccx"])
def test_a_one_row_mesh_gets_its_report(tmp_path, extra):
    """Issue 26 / 21.9: ``run --set mesh.n_z=1`` and ``run --with-ccx --set steps.increments=1500`` on a tiny
    mesh ended in "RuntimeError: Error in qhull Delaunay" (one row of von Mises points on the wall map) and
    left decks/ and reference_*/; the same with 30 increments, ccx included."""
    if extra and shutil.which("ccx") is None:
        pytest.skip("ccx not installed")
    res = cli(["run", *SMALL, "--set", "mesh.n_z=1", "--set", "outputs.vtu=true", *extra, "-o", tmp_path / "r"])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "r" / "report.html").stat().st_size > 0 and (tmp_path / "r" / "summary.json").is_file()
    assert (tmp_path / "r" / "ccx").is_dir() == bool(extra)


@pytest.mark.parametrize("zz", [np.zeros(12), np.r_[np.zeros(11), 1e-13]])
def test_wall_map_draws_collinear_points(zz):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from deckbridge.report.figures import _wall_map
    fig = Figure()
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    th = np.linspace(0.0, 330.0, 12)
    sc = _wall_map(ax, th, zz, np.linspace(1.0, 2.0, 12), 2.0)
    fig.canvas.draw()
    assert len(sc.get_array()) == 12


# --- modes, full disks, sizes no machine holds ------------------------------------------------------------------
def test_case_tables_get_the_mode_of_a_plain_open(tmp_path):
    """Issue 26: CSVs of sweep cases were written 0600 (mkstemp) where open() gives 0666 & ~umask."""
    from deckbridge.studies.store import CaseStore
    old = os.umask(0o022)
    try:
        store = CaseStore(tmp_path)
        store._write_csv(store.dir / "case.csv", "node,sigma_n_pa\n1,2\n")
        outdir.write_text(tmp_path / "plain.txt", "x")
    finally:
        os.umask(old)
    assert (store.dir / "case.csv").stat().st_mode & 0o777 == 0o644
    assert (tmp_path / "plain.txt").stat().st_mode & 0o777 == 0o644


@pytest.fixture
def full_disk(tmp_path):
    """A 256 kB tmpfs (root only); skipped where it cannot be mounted."""
    mnt = tmp_path / "full"
    mnt.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=256k", "tmpfs", str(mnt)],
                      capture_output=True).returncode != 0:
        pytest.skip("cannot mount a tmpfs here (not root)")
    try:
        yield mnt
    finally:
        subprocess.run(["umount", "-l", str(mnt)], capture_output=True)


def test_a_full_disk_names_the_path(full_disk):
    """Issue 26: "No space left on device" without the path. A real full disk (tmpfs), a real sweep."""
    out = full_disk / "study"
    res = cli(["sweep", *SMALL, "--set", "mesh.n_theta=48", "--k-factors", "1,10", "--workers", "1", "-o", out])
    assert res.exit_code == 1, res.output
    line = res.stderr.replace("\r", "\n").splitlines()[-1]          # after the progress bar's lines
    assert line.startswith("deckbridge: error: ") and "No space left on device" in line and str(out) in line, line


def test_a_file_size_limit_names_the_path(tmp_path):
    """The same without root: a real EFBIG (RLIMIT_FSIZE) while the decks are written, in a subprocess."""
    code = ("import resource, signal, sys; signal.signal(signal.SIGXFSZ, signal.SIG_IGN); "
            "resource.setrlimit(resource.RLIMIT_FSIZE, (20000, 20000)); "
            "from deckbridge.cli import main; sys.argv = ['deckbridge'] + sys.argv[1:]; main()")
    out = tmp_path / "decks"
    res = subprocess.run([sys.executable, "-c", code, "decks", *SMALL, "--set", "mesh.n_theta=64", "-o", str(out)],
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == 1, res.stderr
    assert res.stderr.startswith("deckbridge: error: ") and "File too large" in res.stderr and str(out) in res.stderr
    assert not out.exists()


def test_a_mesh_no_machine_holds_is_refused_naming_the_keys(tmp_path):
    """Issue 26: "Unable to allocate 3.07 EiB": with --allow-large, a mesh of 10^7 x 10^5 went to numpy."""
    res = cli(["sweep", "--allow-large", "--set", "mesh.n_theta=10000000", "--set", "mesh.n_z=100000",
               "--k-factors", "1", "-o", tmp_path / "s"])
    line = error_line(res, 2)
    assert "mesh.n_theta x mesh.n_z x mesh.n_r = 10000000 x 100000 x" in line and "memory and swap" in line
    assert "Unable to allocate" not in line and not (tmp_path / "s").exists()


def test_a_lock_whose_owner_was_killed_is_taken_over_though_its_children_live(tmp_path):
    """Issue 26: the folder's lock (flock) was inherited by forked children, so a SIGKILLed sweep's orphans kept
    it. A real process takes the lock, forks a child that lives on, and is SIGKILLed: the lock is free."""
    import signal
    import time

    code = ("import os, sys, time; from deckbridge import outdir\n"
            "with outdir.lock(sys.argv[1]):\n"
            "    pid = os.fork()\n"
            "    if pid == 0:\n"
            "        time.sleep(60); os._exit(0)\n"
            "    print(pid, flush=True); time.sleep(60)\n")
    proc = subprocess.Popen([sys.executable, "-c", code, str(tmp_path)], stdout=subprocess.PIPE, text=True)
    child = int(proc.stdout.readline())
    try:
        with pytest.raises(outdir.RunError, match=f"pid {proc.pid}"):
            with outdir.lock(tmp_path, "another sweep"):
                pass
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=10)
        time.sleep(0.2)
        assert Path(f"/proc/{child}").exists()              # the child still runs, holding the parent's fds
        with outdir.lock(tmp_path, "another sweep"):
            pass
    finally:
        proc.kill()
        os.kill(child, signal.SIGKILL)
