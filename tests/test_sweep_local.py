"""The sweep's local executor (deckbridge/studies/local.py): cases on forked worker processes.

Checked against the other executors, which share none of its code for running or storing a case:
file for file against a Dask split sweep (whose client reads every case back from the store), and
against the in-process sweep with field recovery for strategy 'mesh'; a killed local sweep stops its
workers and resumes to the same files; option conflicts end in one line."""

import json
import multiprocessing

import pytest
from click.testing import CliRunner

from deckbridge.cli import main
from deckbridge.model import load
from deckbridge.studies import CaseStore, run_sweep
from deckbridge.studies.local import LocalExecutor
from test_studies import Killed, kill_after

TINY = ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1", "steps.increments=5"]
KS = [0.1, 1.0, 10.0]
FILES = ("summary.json", "sweep.csv", "quantities.csv")


def _sweep_cli(out, *extra):
    args = ["sweep", *[x for s in TINY for x in ("--set", s)], "--k-factors", "10,0.1,1", "--workers", "2",
            *extra, "-o", str(out)]
    res = CliRunner().invoke(main, args)
    assert res.exit_code == 0, res.output + res.stderr
    return json.loads((out / "run.json").read_text())


def test_local_sweep_writes_what_a_dask_split_sweep_writes(tmp_path):
    local = _sweep_cli(tmp_path / "local")                        # auto: one condensation -> local
    dask = _sweep_cli(tmp_path / "dask", "--executor", "dask")
    assert local["executor"] == "local (2 processes, strategy split)" and dask["executor"].startswith("dask (")
    assert len(local["computed"]) == len(dask["computed"]) == 4
    assert len({v["solved_on"] for v in local["case_timings_s"].values()}) == 2       # both workers solved
    for name in FILES:
        assert (tmp_path / "local" / name).read_bytes() == (tmp_path / "dask" / name).read_bytes(), name
    for cid in local["computed"]:                                 # the stored tables, byte for byte
        assert (tmp_path / "local" / "cases" / f"{cid}.csv").read_bytes() == \
            (tmp_path / "dask" / "cases" / f"{cid}.csv").read_bytes(), cid
    html = (tmp_path / "local" / "report.html").read_text()
    assert html.count("data:image/png;base64,") == (tmp_path / "dask" / "report.html").read_text().count(
        "data:image/png;base64,") >= 2


def test_local_strategy_mesh_recovers_the_wall_as_the_in_process_sweep(tmp_path):
    model = load(None, TINY)
    run_sweep(model, KS, tmp_path / "ref", progress=False, report=False)                # in process, factor kept
    with LocalExecutor(2) as ex:
        got = run_sweep(model, KS, tmp_path / "mesh", client=ex, strategy="mesh", progress=False, report=False)
    assert got["run"]["executor"] == "local (2 processes, strategy mesh)"
    assert "szz_inner_pa" in got["summary"]["claims"][0]["claim2"]                      # base-wall sigma_zz judged
    for name in FILES:
        assert (tmp_path / "mesh" / name).read_bytes() == (tmp_path / "ref" / name).read_bytes(), name


def test_killed_local_sweep_stops_its_workers_and_resumes_to_the_same_files(tmp_path):
    model = load(None, TINY)
    with LocalExecutor(2) as ex:
        whole = run_sweep(model, KS, tmp_path / "whole", client=ex, progress=False, report=False)

    seen, kill_after_two = kill_after(2)

    out = tmp_path / "sweep"
    with pytest.raises(Killed):
        with LocalExecutor(2) as ex:
            run_sweep(model, KS, out, client=ex, progress=False, report=False, on_case_stored=kill_after_two)
    assert not multiprocessing.active_children()                  # no worker left behind
    assert not (out / "summary.json").exists()
    with LocalExecutor(2) as ex:
        again = run_sweep(model, KS, out, client=ex, progress=False, report=False)
    assert sorted(again["run"]["reused"]) == sorted(seen) and len(again["run"]["computed"]) == 2
    for name in FILES:
        assert (out / name).read_bytes() == (tmp_path / "whole" / name).read_bytes(), name
    assert sorted(r["case_id"] for r in CaseStore(out).log()) == sorted(whole["run"]["computed"])


def test_local_executor_with_a_scheduler_is_one_line_and_writes_nothing(tmp_path):
    out = tmp_path / "never"
    res = CliRunner().invoke(main, ["sweep", "--executor", "local", "--scheduler", "tcp://127.0.0.1:9", "-o", str(out)])
    assert res.exit_code == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("deckbridge: error:"), res.stderr
    assert "--executor local and --scheduler" in lines[0] and not out.exists()


def test_workers_forked_after_a_factorisation_in_this_process_do_not_hang(tmp_path):
    """GNU OpenMP (CHOLMOD) is not fork-safe: a child forked from a thread that ran a parallel region
    hung in its own factorisation. In a fresh interpreter (its own OpenMP state), under a time limit."""
    import subprocess
    import sys

    code = ("from deckbridge.model import load\n"
            "from deckbridge.studies.tasks import condense_variant\n"
            "from deckbridge.studies.local import LocalExecutor\n"
            f"md = load(None, {TINY!r}).to_dict()\n"
            "ref = condense_variant(md, light=True)\n"          # CHOLMOD in this process first
            "with LocalExecutor(2) as ex:\n"
            "    cond = ex.condense(md, True, meanwhile=lambda: None)\n"
            "    out = dict(ex.solve(cond, [(md, 'lagrange', None, 'scaled'), (md, 'penalty', 1.0, 'scaled')],\n"
            "                        ['lagrange', 'penalty k=1']))\n"
            "assert (cond.system.S == ref.system.S).all()\n"
            "assert all(not isinstance(r, Exception) and len(r[0]) > 0 for r in out.values())\n"
            "print('ok')\n")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert res.returncode == 0 and res.stdout.strip() == "ok", res.stderr[-2000:]


def test_a_worker_that_dies_ends_the_sweep_in_one_line_and_the_rest_resumes(tmp_path, monkeypatch):
    """A worker killed (out of memory, say) mid-sweep: exit 1 with one line, the cases stored before it
    stay, and the same command resumes (the workers inherit this process's modules: the patch reaches them)."""
    import os

    import deckbridge.studies.tasks as tasks

    real = tasks.solve_or_error

    def dies_on_k1(cond, model_dict, method, k_factor, open_stiffness="scaled"):
        if k_factor == 1.0:
            os._exit(9)
        return real(cond, model_dict, method, k_factor, open_stiffness)

    monkeypatch.setattr(tasks, "solve_or_error", dies_on_k1)
    args = ["sweep", *[x for s in TINY for x in ("--set", s)], "--k-factors", "10,0.1,1", "--workers", "2",
            "-o", str(tmp_path / "s")]
    res = CliRunner().invoke(main, args)
    err = res.stderr.split("\r")[-1].strip()            # after the progress bar's redraws
    assert res.exit_code == 1 and res.stderr.count("deckbridge: error:") == 1, res.stderr
    assert err.startswith("deckbridge: error: a local worker process ended abruptly") and "\n" not in err
    assert not multiprocessing.active_children() and not (tmp_path / "s" / "summary.json").exists()
    monkeypatch.setattr(tasks, "solve_or_error", real)
    res = CliRunner().invoke(main, args)
    assert res.exit_code == 0, res.stderr
    run = json.loads((tmp_path / "s" / "run.json").read_text())
    assert len(run["computed"]) + len(run["reused"]) == 4 and len(run["computed"]) >= 1


def _children(pid: int) -> list[int]:
    """Child pids of ``pid`` (every thread's, /proc)."""
    from pathlib import Path
    kids = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        try:
            kids += [int(x) for x in (task / "children").read_text().split()]
        except (FileNotFoundError, ProcessLookupError):     # the thread ended since the listing
            continue
    return kids


def _running(pid: int) -> bool:
    """``pid`` exists and is not a zombie."""
    from pathlib import Path
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


@pytest.mark.skipif(not __import__("sys").platform.startswith("linux"), reason="/proc and fork: Linux")
def test_sigkilled_sweep_takes_its_workers_along_and_the_rerun_is_not_blocked(tmp_path):
    """Issue 26: ``sweep ... -o out & kill -KILL $!`` left both forked workers alive (re-parented) holding the
    folder's lock: the re-run failed with "another sweep (pid <dead parent>) is writing here". A real SIGKILL of
    the real command: its workers end within seconds, and the same command then runs to the end."""
    import os
    import signal
    import subprocess
    import sys
    import time
    from pathlib import Path

    exe = Path(sys.executable).parent / "deckbridge"
    out = tmp_path / "study"
    args = [str(exe), "sweep", *[x for s in TINY for x in ("--set", s)], "--set", "steps.increments=30",
            "--k-factors", "0.1,0.3,1,3,10,30,100", "--workers", "2", "--executor", "local", "-o", str(out)]
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    try:
        t0 = time.monotonic()
        while len(workers := _children(proc.pid)) < 2:
            assert proc.poll() is None and time.monotonic() - t0 < 90, "the sweep never forked its workers"
            time.sleep(0.05)
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=10)
    finally:
        if proc.poll() is None:
            proc.kill()
    t0 = time.monotonic()
    while [w for w in workers if _running(w)] and time.monotonic() - t0 < 10:
        time.sleep(0.1)
    left = [w for w in workers if _running(w)]
    for w in left:                                # do not leave them behind if the test fails
        os.kill(w, signal.SIGKILL)
    assert not left, f"workers {left} outlived their killed client"
    again = subprocess.run(args, capture_output=True, text=True, env=env, timeout=300)
    assert again.returncode == 0, again.stderr[-2000:]
    assert json.loads((out / "run.json").read_text())["computed"] is not None
