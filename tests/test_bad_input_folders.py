"""Regression tests of issue 13 (see tests/test_bad_input.py): data loss (compare into a source folder,
corrupt neighbours of a source, the user's dot files in a sweep folder) and Dask (a scheduler that is not
one, the local cluster's sockets)."""

from __future__ import annotations

import os
import shutil
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from bad_input_cli import SMALL, cli, one_error_line, time_limit  # noqa: F401 (time_limit: autouse fixture)
from deckbridge import outdir

# --- 5. data loss -------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def solved_once(tmp_path_factory):
    """The two reference solves, once a module (each test gets its own copy: the tests rename and spoil them)."""
    folder = tmp_path_factory.mktemp("solved")
    for method in ("penalty", "lagrange"):
        res = cli(["solve", "--method", method, *SMALL, "--set", "outputs.vtu=false", "-o", folder / method[:3]])
        assert res.exit_code == 0, res.output
    return folder


@pytest.fixture
def two_reference_folders(tmp_path, solved_once):
    for name in ("pen", "lag"):
        shutil.copytree(solved_once / name, tmp_path / name, symlinks=True)
    return tmp_path / "pen", tmp_path / "lag"


def test_compare_refuses_to_write_into_a_source_or_another_commands_folder(tmp_path, two_reference_folders):
    pen, lag = two_reference_folders
    before = (pen / "summary.json").read_bytes()
    one_error_line(cli(["compare", lag, pen, "-o", pen]), 2, "is the source folder")
    one_error_line(cli(["compare", lag, pen, "-o", pen / "cmp"]), 2, "inside the source folder")
    assert (pen / "summary.json").read_bytes() == before and not (pen / "cmp").exists()
    solved = tmp_path / "other"
    assert cli(["solve", "--method", "lagrange", *SMALL, "--set", "outputs.vtu=false", "-o", solved]).exit_code == 0
    one_error_line(cli(["compare", lag, pen, "-o", solved]), 2, "written by 'deckbridge solve'")
    res = cli(["compare", lag, pen, "-o", solved, "--force"])
    assert res.exit_code == 0, res.output
    assert outdir.owner_of(solved) == "compare"
    assert cli(["compare", lag, pen, "-o", solved]).exit_code == 0          # its own folder: rewritten


def test_corrupt_vtu_and_deep_json_beside_a_source_do_not_stop_the_comparison(tmp_path, two_reference_folders):
    """meshio prints and calls sys.exit(1) on a corrupt result.vtu; json recurses on deep nesting."""
    pen, lag = two_reference_folders
    (pen / "result.vtu").write_text("<VTKFile garbage")
    (lag / "summary.json").write_text("[" * 100_000 + "]" * 100_000)
    res = cli(["compare", pen, lag, "-o", tmp_path / "cmp"])
    assert res.exit_code == 0, res.output
    assert "Error" not in res.output and (tmp_path / "cmp" / "report.html").is_file()


@pytest.mark.parametrize("fmt", ["plain_csv", "abaqus_dat", "mystran_f06", "nastran_op2", "calculix", "reference"])
def test_a_device_as_a_source_is_refused_without_reading_it(tmp_path, fmt):
    one_error_line(cli(["compare", "--format", fmt, "/dev/zero", "-o", tmp_path / "o"]), 2, "'/dev/zero'")


def test_empty_output_path_is_refused(tmp_path):
    os.chdir(tmp_path)
    one_error_line(cli(["decks", *SMALL, "-o", ""]), 2, "-o = '': give an output folder")
    assert list(tmp_path.iterdir()) == []


def test_dollar_signs_in_source_names_do_not_break_the_figure(tmp_path, two_reference_folders):
    pen, lag = two_reference_folders
    a, b = tmp_path / "$\\alpha$_{x}$", tmp_path / "a$b"
    pen.rename(a)
    lag.rename(b)
    res = cli(["compare", a, b, "-o", tmp_path / "cmp"])
    if res.exit_code:
        one_error_line(res, res.exit_code)


# --- 6. Dask ----------------------------------------------------------------------------------------------------
def _fake_server(reply: bytes):
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(4)
    conns = []

    def serve():
        while True:
            try:
                c, _ = srv.accept()
            except OSError:
                return
            conns.append(c)
            if reply:
                c.sendall(reply)
    threading.Thread(target=serve, daemon=True).start()
    return srv, conns


@pytest.mark.parametrize("reply", [b"", b"\xff" * 64])
def test_scheduler_that_is_not_dask_ends_in_one_line_in_time(reply):
    """In a subprocess: a half-made Client must not keep the process (or a later test) waiting."""
    srv, conns = _fake_server(reply)
    code = ("from deckbridge.studies.cluster import open_client\n"
            "from deckbridge.errors import RunError\n"
            "try:\n"
            f"    with open_client('tcp://127.0.0.1:{srv.getsockname()[1]}', timeout_s=1.0): pass\n"
            "except RunError as exc:\n"
            "    print(exc)\n")
    t0 = time.perf_counter()
    try:
        res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=30)
    finally:
        srv.close()
        for c in conns:
            c.close()
    assert time.perf_counter() - t0 < 20
    assert res.returncode == 0 and res.stdout.startswith("`scheduler` = 'tcp://127.0.0.1:"), (res.stdout, res.stderr)
    assert "Traceback" not in res.stderr, res.stderr


def test_local_cluster_listens_on_loopback_only_and_has_no_dashboard():
    psutil = pytest.importorskip("psutil")
    from deckbridge.studies.cluster import open_client
    with open_client(workers=1, processes=False) as client:
        listening = [c.laddr for c in psutil.Process().net_connections("tcp") if c.status == "LISTEN"]
        assert client.scheduler_info()["address"].startswith("inproc://")
        assert all(a.port != 8787 for a in listening), listening


def test_two_sweeps_into_one_folder(tmp_path):
    with outdir.lock(tmp_path / "study", "another sweep"):
        res = cli(["sweep", *SMALL, "--k-factors", "1", "-o", tmp_path / "study"])
        one_error_line(res, 1, "another sweep (pid")
    with outdir.lock(tmp_path / "study"):                      # released: the next writer gets it
        pass


def test_stale_temporaries_are_removed(tmp_path):
    """Only the project's own temporaries (``.deckbridge-`` names) go, and only in a folder it marked."""
    cases = tmp_path / "cases"
    cases.mkdir(parents=True)
    (tmp_path / ".deckbridge-staging-abc12345").mkdir()
    (tmp_path / ".deckbridge-staging-abc12345" / "half.csv").write_text("1,2")
    (cases / ".deckbridge-tmp-x1_lagrange.csv.k2j3h4l5").write_text("node,sigma\n1,")
    (cases / "x1_lagrange.csv").write_text("kept")
    assert outdir.remove_stale(tmp_path) == []                 # not marked: nothing is the project's
    outdir.mark(tmp_path, "sweep")
    removed = outdir.remove_stale(tmp_path)
    assert len(removed) == 2 and sorted(p.name for p in cases.iterdir()) == ["x1_lagrange.csv"]
    assert sorted(p.name for p in tmp_path.iterdir()) == [".deckbridge-output", "cases"]


USER_FILES = {".staging-notes/todo.txt": "call Bob", ".env.backup1": "KEY=1", ".notes.swp123": "swap",
              "cases/.mine.csv.backup1": "1,2"}


def _user_files(folder: Path) -> dict:
    for name, text in USER_FILES.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_text(text)
    return {name: (folder / name).read_text() for name in USER_FILES}


def test_sweep_keeps_the_users_dot_files(tmp_path):
    """Issue 26: a sweep (forced into the user's folder, then resumed) deleted .staging-notes/todo.txt,
    .env.backup1 and .notes.swp123 as "stale temporaries"; it removes only its own ``.deckbridge-`` ones."""
    out = tmp_path / "study"
    out.mkdir()
    want = _user_files(out)
    one_error_line(cli(["sweep", *SMALL, "--k-factors", "1", "--workers", "1", "-o", out]), 2,
                   "holds files deckbridge did not write")
    res = cli(["sweep", *SMALL, "--k-factors", "1", "--workers", "1", "-o", out, "--force"])
    assert res.exit_code == 0, res.output
    (out / "cases" / ".deckbridge-tmp-x.csv.ab12cd34").write_text("half")     # a killed writer's temporary
    res = cli(["sweep", *SMALL, "--k-factors", "1", "--workers", "1", "-o", out])    # resumed: its folder now
    assert res.exit_code == 0, res.output
    assert {name: (out / name).read_text() for name in USER_FILES} == want
    assert not (out / "cases" / ".deckbridge-tmp-x.csv.ab12cd34").exists()
