"""Regression tests of issue 13 (see tests/test_bad_input.py): dead ends (friction without ccx decks, SIGTERM
during ccx), unfinished and corrupt ccx jobs (real ccx output), penalty factors out of range (issue 21.11/26)."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from bad_input_cli import SMALL, cli, one_error_line, time_limit  # noqa: F401 (time_limit: autouse fixture)
from deckbridge.errors import InputError, ModelError
from deckbridge.model import load


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
