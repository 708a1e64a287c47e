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
