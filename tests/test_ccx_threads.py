"""ccx's thread count when the caller sets none: the idle cores (deckbridge/dialects/calculix/runner.py)."""

from __future__ import annotations

import subprocess

import pytest

from deckbridge.dialects.calculix import runner

BLOCK = """*NODE
1,0,0,0
2,1,0,0
3,1,1,0
4,0,1,0
5,0,0,1
6,1,0,1
7,1,1,1
8,0,1,1
*ELEMENT,TYPE=C3D8,ELSET=E
1,1,2,3,4,5,6,7,8
*MATERIAL,NAME=M
*ELASTIC
2.1e11,0.3
*SOLID SECTION,ELSET=E,MATERIAL=M
*NSET,NSET=TOP
5,6,7,8
*BOUNDARY
1,1,3
2,2,3
3,3,3
4,1,1
4,3,3
*STEP
*STATIC
1.,1.
*CLOAD
5,3,-1000.
6,3,-1000.
7,3,-1000.
8,3,-1000.
*NODE PRINT,NSET=TOP
U
*END STEP
"""


def test_idle_cores_from_two_samples():
    samples = iter([(100.0, 1000.0), (150.0, 1100.0)])      # 50 of 100 jiffies idle on 2 CPUs: 1 core idle
    assert runner.idle_cores(0.0, times=lambda: next(samples), n_cpu=2) == pytest.approx(1.0)
    assert runner.idle_cores(0.0, times=lambda: None, n_cpu=2) is None


def test_proc_stat_is_read():
    t = runner._cpu_times()
    if t is None:
        pytest.skip("no /proc/stat on this system")
    idle, total = t
    assert 0 <= idle <= total


@pytest.mark.parametrize("free, expected", [(0.2, 1), (0.6, 1), (1.6, 2), (7.0, 2), (None, 2)])
def test_threads_follow_idle_cores(free, expected):
    assert runner.default_threads({}, idle=lambda: free, n_cpu=2) == expected


@pytest.mark.parametrize("var", runner.THREAD_VARS)
def test_callers_setting_wins(var):
    assert runner.default_threads({var: "4"}, idle=lambda: 0.1, n_cpu=2) is None


def test_run_passes_idle_cores_to_ccx(tmp_path, monkeypatch):
    for var in runner.THREAD_VARS:
        monkeypatch.delenv(var, raising=False)
    monkeypatch.setattr(runner, "idle_cores", lambda: 0.3)
    seen = {}
    real = subprocess.Popen

    def spy(*args, **kw):
        seen.update(kw["env"])
        return real(*args, **kw)

    monkeypatch.setattr(runner.subprocess, "Popen", spy)
    deck = tmp_path / "block.inp"
    deck.write_text(BLOCK)
    job = runner.run(deck, timeout_s=60)
    assert all(seen[v] == "1" for v in runner.THREAD_VARS)
    # the tip moves by the uniaxial closed form: u_z = -F L / (E A) with F = 4 kN on a 1 m cube
    rows = [ln.split() for ln in job.dat.read_text().splitlines()]
    uz = [float(r[3]) for r in rows if len(r) == 4 and r[0] in "5678"]
    assert len(uz) == 4 and uz == pytest.approx([-4000.0 / 2.1e11] * 4, rel=1e-6)
