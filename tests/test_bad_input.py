"""Regression tests of issue 13: every reproduction ends in one line, a non-zero exit and nothing
half-written, within a bounded time (an alarm turns a hang into a failure).

In-process through click's CliRunner where possible; subprocesses only where a signal or a real exit
code is the point.
"""

from __future__ import annotations

import re
import json
import os
import signal
import socket
import subprocess
import sys
import threading
import time
import tracemalloc
from pathlib import Path

import pytest
from click.testing import CliRunner

from deckbridge import limits, outdir
from deckbridge.cli import main
from deckbridge.errors import DeckbridgeError, InputError, ModelError, RunError
from deckbridge.model import Model, load, loads_model

SMALL = ["--set", "mesh.n_theta=16", "--set", "mesh.n_z=4", "--set", "mesh.n_r=1", "--set", "steps.increments=4"]
BOMB = ('title: &a ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]\n'
        "b: &b [*a,*a,*a,*a,*a,*a,*a,*a,*a]\nc: &c [*b,*b,*b,*b,*b,*b,*b,*b,*b]\n"
        "d: &d [*c,*c,*c,*c,*c,*c,*c,*c,*c]\ne: &e [*d,*d,*d,*d,*d,*d,*d,*d,*d]\n")


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


# --- 1. output blow-up --------------------------------------------------------------------------------
def test_alias_bomb_in_a_model_file_is_refused_at_once(tmp_path):
    p = tmp_path / "bomb.yaml"
    p.write_text(BOMB)
    t0 = time.perf_counter()
    one_error_line(cli(["decks", p, "-o", tmp_path / "o"]), 2, "anchors (&name) are not allowed")
    assert time.perf_counter() - t0 < 5
    assert not (tmp_path / "o").exists()


def test_alias_bomb_through_set_is_refused():
    one_error_line(cli(["decks", "--set", "title=[&a [1,2,3], *a, *a]", "-o", "o"]), 2, "title")


def test_a_huge_value_is_shown_shortened(tmp_path):
    p = tmp_path / "big.yaml"
    p.write_text("title: " + "x" * 900_000 + "\n")
    line = one_error_line(cli(["decks", p, "-o", tmp_path / "o"]), 2, "big.yaml: title = 'xxxx")
    assert "..." in line
    line = one_error_line(cli(["decks", "--set", "title=" + "y" * 20_000_000, "-o", tmp_path / "o"]), 2, "--set")
    huge = tmp_path / "huge.yaml"
    with open(huge, "w") as fh:
        fh.write("title: " + "z" * 20_000_000 + "\n")
    one_error_line(cli(["decks", huge, "-o", tmp_path / "o"]), 2, "a model file is at most")


def test_escape_and_shorten_any_value():
    err = ModelError("geometry.k\x1b[31m\nx", ["a" * 10_000] * 10_000, "unknown key")
    text = str(err)
    assert "\x1b" not in text and "\n" not in text and len(text) < 800
    assert text.startswith("geometry.k\\x1b[31m\\nx = ")


# --- 2. unbounded work ------------------------------------------------------------------------------------
def test_memory_estimate_refuses_a_million_azimuths_without_allocating(monkeypatch):
    monkeypatch.delenv(limits.ALLOW_ENV, raising=False)
    tracemalloc.start()
    t0 = time.perf_counter()
    res = cli(["decks", "--set", "mesh.n_theta=1000000", "-o", "never"])
    elapsed = time.perf_counter() - t0
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    one_error_line(res, 2, "279,000,000 dofs need about")
    assert elapsed < 1.0 and peak < 20e6
    assert "--allow-large" in res.stderr


def test_memory_estimate_matches_the_measured_points():
    """README: 0.25 GB at 20k dof, 0.96 GB at 100k, 3.8 GB at 400k, 10.5 GB at 1M: the estimate is above
    each measured peak and within 50 % of it."""
    for n, gb in ((20e3, 0.25), (100e3, 0.96), (400e3, 3.8), (1e6, 10.5)):
        est = limits.estimate_bytes(n) / 1e9
        assert gb <= est <= 1.5 * gb, (n, est)


def test_allow_large_passes_the_estimate(monkeypatch):
    monkeypatch.setattr(limits, "available_bytes", lambda: 1e6)
    m = load(None, ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1"])
    with pytest.raises(InputError, match="GB available"):
        limits.check_memory(m)
    assert limits.check_memory(m, allow_large=True) > 1e6
    monkeypatch.setenv(limits.ALLOW_ENV, "1")
    assert limits.check_memory(m) > 1e6


@pytest.mark.parametrize("args, needle", [
    (["decks", "/dev/zero", "-o", "o"], "not a regular file"),
    (["decks", "--set", "steps.increments=10000000", "-o", "o"], "steps.increments = 10000000: must be <= 10000"),
    (["sweep", "--k-factors", ",".join(str(k + 1) for k in range(10_000)), "-o", "o"], "10000 k-factors, at most 100"),
    (["sweep", "--mesh", "n_theta=" + ",".join(str(16 + k) for k in range(1000)), "-o", "o"], "mesh variants"),
    (["sweep", "--workers", "1000000", "-o", "o"], "--workers = 1000000: at most"),
    (["sweep", "--workers", "0", "-o", "o"], "--workers = 0"),
    (["liftoff", "--tol", "1e-17", *SMALL], "--tol = 1e-17: must be at least 1e-09"),
])
def test_unbounded_work_is_refused_before_it_starts(tmp_path, args, needle):
    os.chdir(tmp_path)
    t0 = time.perf_counter()
    one_error_line(cli(args), 2, needle)
    assert time.perf_counter() - t0 < 5
    assert not (tmp_path / "o").exists()


# --- 4. silently wrong answers ----------------------------------------------------------------------------
@pytest.mark.parametrize("text, needle", [
    ("", "the file holds no model"),
    ("# only a comment\n", "the file holds no model"),
    ("name: A\nname: B\n", "line 2: duplicate key 'name'"),
    ("mesh: {n_theta: 20}\nmesh: {n_z: 3}\n", "duplicate key 'mesh'"),
    ("mesh: {n_theta: 030}\n", "'030' is ambiguous"),
    ("loads: {azimuth: 1:00}\n", "'1:00' is ambiguous"),
    ("mesh: {n_theta: 0x18}\n", "'0x18' is ambiguous"),
    ("material: {nu: 0.499}\n", "material.nu = 0.499: must be < 0.49"),
    ('name: "JAR\\n"\n', "name = 'JAR\\n'"),
    ("geometry: {thickness: 1.0e-300}\n", "geometry.thickness = 1e-300"),
    ("material: {E: 1" + "0" * 400 + "}\n", "material.E = 1000"),
    ("mesh: {n_theta: 1.0e+300}\n", "mesh.n_theta = 1e+300: must be an integer"),
    ("a:\n" + "".join("  " * (k + 1) + "a:\n" for k in range(200)), "nested deeper than"),
    ("[" * 5000 + "]" * 5000, "nested deeper than"),
])
def test_model_files_that_used_to_mean_something_else(tmp_path, text, needle):
    p = tmp_path / "m.yaml"
    p.write_text(text)
    line = one_error_line(cli(["decks", p, "-o", tmp_path / "o"]), 2, needle)
    assert "m.yaml" in line                                   # value errors name the file
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("setting, needle", [
    ("mesh.n_theta=030", "'030' is ambiguous"), ("loads.M=1:00", "'1:00' is ambiguous"),
    ("mesh.n_theta=0x18", "'0x18' is ambiguous"), ("material.nu=0.4999", "must be < 0.49"),
])
def test_set_values_that_used_to_mean_something_else(setting, needle):
    one_error_line(cli(["decks", "--set", setting, "-o", "o"]), 2, needle)


def test_yaml_12_numbers_are_read_as_written():
    m = loads_model("material: {E: 2.1e11, nu: 0.3}\nmesh: {n_theta: 30}\nloads: {N: 1e6}\n")
    assert m.material.E == 2.1e11 and m.mesh.n_theta == 30 and m.loads.N == 1e6


def test_latin1_model_file_is_one_line(tmp_path):
    p = tmp_path / "latin.yaml"
    p.write_bytes("title: café\n".encode("latin-1"))
    one_error_line(cli(["decks", p, "-o", tmp_path / "o"]), 2, "not UTF-8 text (byte 0xe9 on line 1)")


# --- 5. data loss -------------------------------------------------------------------------------------------
@pytest.fixture
def two_reference_folders(tmp_path):
    for method in ("penalty", "lagrange"):
        res = cli(["solve", "--method", method, *SMALL, "--set", "outputs.vtu=false", "-o", tmp_path / method[:3]])
        assert res.exit_code == 0, res.output
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


# --- 7./9. tracebacks and message shape ----------------------------------------------------------------------
def test_disk_full_is_one_line_and_a_run_error(tmp_path, monkeypatch):
    import errno

    import deckbridge.render as render

    def full(*a, **k):
        raise OSError(errno.ENOSPC, "No space left on device", str(tmp_path / "o" / "x.bdf"))
    monkeypatch.setattr(render, "staged", full)
    one_error_line(cli(["decks", *SMALL, "-o", tmp_path / "o"]), 1, "No space left on device")
    assert not (tmp_path / "o").exists()


def test_a_library_calling_sys_exit_is_one_line(tmp_path, monkeypatch):
    import deckbridge.cli.compare_cmd as cmd

    def bail(*a, **k):
        sys.exit(1)
    monkeypatch.setattr(cmd, "detect", bail)
    one_error_line(cli(["compare", tmp_path / "src", "-o", tmp_path / "o"]), 1, "a library ended the command")


def test_unexpected_errors_are_one_line_and_debug_shows_the_traceback(tmp_path, monkeypatch):
    import deckbridge.cli.compare_cmd as cmd

    def boom(*a, **k):
        raise ValueError("bad\nthing\x1b[2J")
    monkeypatch.setattr(cmd, "detect", boom)
    line = one_error_line(cli(["compare", tmp_path / "src", "-o", tmp_path / "o"]), 1, "ValueError: bad")
    assert "--debug" in line
    res = cli(["--debug", "compare", tmp_path / "src", "-o", tmp_path / "o"])
    assert res.exit_code == 1 and "Traceback" in res.stderr


def test_control_characters_in_keys_are_escaped(tmp_path):
    line = one_error_line(cli(["decks", "--set", "geometry.a\x1b[2Jb\nc=1", "-o", tmp_path / "o"]), 2)
    assert "\\x1b[2J" in line and "\\n" in line


def test_warnings_do_not_precede_the_error_line(tmp_path, monkeypatch):
    import warnings

    import deckbridge.cli.compare_cmd as cmd

    def warn_then_fail(*a, **k):
        warnings.warn("invalid value encountered in divide", RuntimeWarning)
        raise DeckbridgeError("x: failed")
    monkeypatch.setattr(cmd, "detect", warn_then_fail)
    one_error_line(cli(["compare", tmp_path / "src", "-o", tmp_path / "o"]), 2, "x: failed")


def test_help_documents_the_exit_codes():
    out = cli(["--help"]).output
    assert "2 usage, model or input-file error" in out and "1 the run failed" in out


def test_name_with_newline_is_refused():
    with pytest.raises(ModelError, match="name"):
        Model(name="JAR\n")


# --- 8. dead ends ------------------------------------------------------------------------------------------------
def test_run_with_friction_skips_the_calculix_decks_with_a_note(tmp_path):
    res = cli(["run", *SMALL, "--set", "contact.friction=0.2", "--set", "outputs.vtu=false", "-o", tmp_path / "r"])
    assert res.exit_code == 0, res.output
    assert "note: calculix deck: contact.friction" in res.output and "left out" in res.output
    decks = sorted(p.name for p in (tmp_path / "r" / "decks").iterdir())
    assert decks and not any("ccx" in d for d in decks)
    assert "FRICTION" in (tmp_path / "r" / "decks" / "JAR_lagrange.inp").read_text().upper()


def test_sigterm_stops_ccx_and_removes_its_scratch_files(tmp_path):
    """A stand-in ccx (DECKBRIDGE_CCX) writes scratch files and sleeps; SIGTERM to deckbridge must stop it."""
    fake = tmp_path / "fake_ccx"
    pidfile = tmp_path / "ccx.pid"
    fake.write_text(f"#!/bin/sh\necho $$ > {pidfile}\ntouch \"$2.12d\" spooles.out\necho 'increment 1 attempt 1'\n"
                    "exec sleep 60\n")
    fake.chmod(0o755)
    env = dict(os.environ, DECKBRIDGE_CCX=str(fake))
    exe = Path(sys.executable).parent / "deckbridge"
    proc = subprocess.Popen([str(exe), "run", *SMALL, "--set", "outputs.vtu=false", "--with-ccx",
                             "-o", str(tmp_path / "r")], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    try:
        t0 = time.monotonic()
        while not pidfile.exists() or not pidfile.read_text().strip():
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() - t0 < 40, "fake ccx never started"
            time.sleep(0.1)
        time.sleep(0.3)
        ccx_pid = int(pidfile.read_text())
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=15)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode != 0
    assert "Traceback" not in err
    with pytest.raises(ProcessLookupError):
        os.kill(ccx_pid, 0)
    ccx_dir = tmp_path / "r" / "ccx"
    assert not list(ccx_dir.glob("*.12d")) and not (ccx_dir / "spooles.out").exists()


# --- readers: unfinished and corrupt ccx jobs (real ccx output) ----------------------------------------------------
@pytest.fixture(scope="module")
def ccx_job(tmp_path_factory):
    import shutil
    if shutil.which("ccx") is None:
        pytest.skip("ccx not installed")
    from deckbridge.dialects.calculix import runner as ccx_run
    from deckbridge.render import render_all
    model = load(None, ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1", "steps.increments=4"])
    folder = tmp_path_factory.mktemp("ccx13")
    deck = [p for p in render_all(model, folder, ["calculix"]) if "penalty" in p.name][0]
    run = ccx_run.run(deck, timeout_s=60)
    return model, run


def _copy_job(run, dest: Path) -> Path:
    dest.mkdir()
    for p in (run.deck, run.dat, run.frd):
        (dest / p.name).write_bytes(p.read_bytes())
    return dest / run.deck.name


@pytest.mark.ccx
def test_ccx_results_that_used_to_read_silently_wrong(ccx_job, tmp_path):
    from deckbridge.readers import read
    model, run = ccx_job
    ok = read(run.frd, model=model)
    assert ok["load_factor"].max() == pytest.approx(1.0)

    deck = _copy_job(run, tmp_path / "nan")                      # one nan in a force print
    lines = deck.with_suffix(".dat").read_text().splitlines()
    k = next(i for i, ln in enumerate(lines) if i > 110 and len(ln.split()) == 4 and ln.split()[0].isdigit())
    lines[k] = lines[k].split()[0].rjust(10) + "  nan  0.0  0.0"
    deck.with_suffix(".dat").write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"line \d+: non-finite value 'nan'"):
        read(deck.with_suffix(".dat"), model=model)

    deck = _copy_job(run, tmp_path / "half")                     # both files cut in half
    for ext in (".dat", ".frd"):
        text = deck.with_suffix(ext).read_text()
        deck.with_suffix(ext).write_text(text[: len(text) // 2])
    with pytest.raises(InputError, match="truncated"):
        read(deck.with_suffix(".frd"), model=model)

    deck = _copy_job(run, tmp_path / "step1")                    # the job stopped after step 1
    dat = deck.with_suffix(".dat").read_text()
    first_step2 = next(m.start() for m in re.finditer(r"and time\s+(\S+)", dat) if float(m.group(1)) > 1.0)
    deck.with_suffix(".dat").write_text(dat[:first_step2].rsplit("\n", 1)[0] + "\n")
    deck.with_suffix(".frd").unlink()
    with pytest.raises(InputError, match="results end at load factor 0, before steps.lambda_max = 1"):
        read(deck.with_suffix(".dat"), model=model)
    from deckbridge.readers._checks import compare_up_to
    with compare_up_to(0.0):                                   # --load-factor 0 asks for no more
        assert read(deck.with_suffix(".dat"), model=model)["step"].max() == 1

    deck = _copy_job(run, tmp_path / "text")                     # text in the time field
    dat = deck.with_suffix(".dat").read_text().replace("and time  0.1500000E+01", "and time  0.15abc00E+01", 1)
    deck.with_suffix(".dat").write_text(dat)
    res = cli(["compare", deck.with_suffix(".dat"), "-o", tmp_path / "cmp"])
    one_error_line(res, 2, "is not a number")
    assert not (tmp_path / "cmp").exists()


# --- issue 21.11 / 26: penalty factors out of range -------------------------------------------------------------
@pytest.mark.parametrize("args, needle", [
    (["solve", "--method", "penalty", "--k-factor", "1e300"], "--k-factor = 1e+300: puts the penalty stiffness"),
    (["solve", "--method", "penalty", "--k-factor", "1e-300"], "--k-factor = 1e-300: puts the penalty stiffness"),
    (["solve", "--method", "penalty", "--alpha", "1e300"], "--alpha = 1e+300: puts the penalty stiffness"),
    (["solve", "--method", "penalty", "--alpha", "1e-300"], "--alpha = 1e-300: puts the penalty stiffness"),
    (["liftoff", "--method", "penalty", "--k-factor", "1e300"], "--k-factor = 1e+300: puts the penalty stiffness"),
    (["solve", "--method", "penalty", "--set", "contact.penalty.k_normal=1e30"],
     "contact.penalty.k_normal = 1e+30: puts the penalty stiffness"),
])
def test_penalty_factor_out_of_range_names_the_option(tmp_path, args, needle):
    """--k-factor 1e300 ended in "ValueError: array must not contain infs or NaNs", 1e-300 in LinAlgError:
    refused before any work in one line naming the option (the library names k_factor / alpha or the
    model key; the CLI shows the flag)."""
    os.chdir(tmp_path)
    one_error_line(cli([*args, *SMALL, *(["-o", "o"] if args[0] == "solve" else [])]), 2, needle)
    assert not (tmp_path / "o").exists()


def test_penalty_at_the_ends_of_its_range_still_balances_and_converges():
    """The bounds of solve.PENALTY_RATIO (rho = alpha k K / E) are where the answer is still right: at
    the upper end the penalty node forces equal Lagrange's to 1 % of the largest (independent method),
    at both ends the contact and spring reactions balance N and T lambda (force balance)."""
    import numpy as np

    from deckbridge.solve import PENALTY_RATIO, condense_model, penalty_factor, reactions, solve_system

    m = load(None, ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1", "contact.penalty.k_tangent=3.0e7"])
    mesh, system = condense_model(m)
    unit = m.contact.penalty.alpha * m.material.bulk_modulus / m.material.E       # rho at k_factor 1
    _, _, lag = solve_system(m, mesh, system, "lagrange")
    for rho in PENALTY_RATIO:
        kf = penalty_factor(m, rho / unit * (1 - 1e-12 if rho == PENALTY_RATIO[1] else 1 + 1e-12))   # the ends
        _, _, sol = solve_system(m, mesh, system, "penalty", kf)
        F, _ = reactions(system.problem, sol, -1)
        np.testing.assert_allclose(F, [m.loads.T * sol.load_factor[-1], 0.0, m.loads.N], rtol=0, atol=1e-6 * m.loads.N)
        if rho == PENALTY_RATIO[1]:
            assert np.abs(sol.force[-1] - lag.force[-1]).max() < 0.01 * lag.force[-1].max()
    with pytest.raises(ModelError, match="^k_factor = "):
        penalty_factor(m, PENALTY_RATIO[1] / unit * 1.01)


def test_run_refuses_a_model_penalty_out_of_range_before_any_work(tmp_path):
    """run with contact.penalty.alpha = 1e6 (rho = 8.3e5) stopped after writing the decks: checked first now."""
    os.chdir(tmp_path)
    one_error_line(cli(["run", "--set", "contact.penalty.alpha=1e6", *SMALL, "-o", "o"]), 2,
                   "contact.penalty.alpha = 1000000.0: puts the penalty stiffness")
    assert not (tmp_path / "o").exists()
