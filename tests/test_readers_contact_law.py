"""A sign that contradicts the contact law is a read error naming the file and line (issue 26).

Real CalculiX 2.20 output of the project's decks (16 x 4 x 1 mesh, default loads) with one value's sign
flipped: the node-to-surface penalty job's ``*CONTACT PRINT`` pressure of a pressed table node at the end
of step 1 (its ``.dat`` gap says it penetrates: tension there is impossible), and the mortar job's
``*NODE PRINT`` RF of a table node (closed at gap 0: a Lagrange-type contact never pulls there). Unaltered,
both read; on main the flipped penalty file was read and gave the onset "lambda in [0, 0]".
"""

import re
import shutil

import numpy as np
import pytest

from deckbridge.errors import InputError
from deckbridge.dialects.calculix.runner import run
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.readers import read
from deckbridge.dialects.calculix import render as calculix

pytestmark = pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX ccx not installed")


@pytest.fixture(scope="module")
def jobs(tmp_path_factory):
    model = load(None, ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1"])
    folder = tmp_path_factory.mktemp("ccx_law")
    for p in calculix.write(model, build_mesh(model), folder):
        run(p, timeout_s=120)
    return model, folder


def _copy(folder, stem, dest):
    dest.mkdir()
    for suffix in (".inp", ".dat", ".frd"):
        shutil.copyfile(folder / f"{stem}{suffix}", dest / f"{stem}{suffix}")
    return dest / f"{stem}.dat"


def _flip_first(dat, head: str, node: int, col: int = 1) -> int:
    """Flip the sign of value ``col`` (1 = the first after the node id) on ``node``'s row in the first block
    whose head contains ``head``; return the 1-based line number changed."""
    lines = dat.read_text().splitlines(keepends=True)
    start = next(i for i, line in enumerate(lines) if head in line)
    for i in range(start + 1, len(lines)):
        parts = lines[i].split()
        if parts and parts[0] == str(node):
            value = parts[col]
            assert float(value) != 0.0
            flipped = value[1:] if value.startswith("-") else "-" + value
            head_, tail = lines[i].split(parts[col - 1], 1)
            tail = tail.replace(" " + value, (" " if value.startswith("-") else "") + flipped, 1)
            lines[i] = head_ + parts[col - 1] + tail
            assert float(lines[i].split()[col]) == -float(value)
            dat.write_text("".join(lines))
            return i + 1
    raise AssertionError(f"node {node} not in the block {head!r}")


def test_real_files_read_clean(jobs):
    _, folder = jobs
    df = read(folder)
    assert set(df["method"]) == {"penalty", "mortar", "f2f"}
    assert "origin" not in df.columns


def test_flipped_penalty_pressure_is_named_by_its_line(jobs, tmp_path):
    model, folder = jobs
    dat = _copy(folder, "JAR_ccx_penalty", tmp_path / "job")
    before = read(dat)
    s1 = before[(before["step"] == 1) & (before["surface"] == "table") & (before["node"] == 17)]
    assert (s1["sigma_n_pa"] < 0).all() and (s1["gap_m"] < 0).all()       # pressed and penetrating
    line = _flip_first(dat, "contact stress (slave node,press", 17)
    for m in (None, model):
        with pytest.raises(InputError) as err:
            read(dat, model=m)
        msg = str(err.value)
        assert "\n" not in msg
        assert f"{str(dat)!r}: line {line}:" in msg
        assert "node 17" in msg and "tension in a closed contact" in msg


def test_flipped_mortar_force_is_named_by_its_line(jobs, tmp_path):
    _, folder = jobs
    dat = _copy(folder, "JAR_ccx_lagrange", tmp_path / "job")
    line = _flip_first(dat, "forces (fx,fy,fz) for set NTABLE", 9, col=3)      # fz
    with pytest.raises(InputError) as err:
        read(dat.parent)
    msg = str(err.value)
    assert re.search(rf"'[^']*JAR_ccx_lagrange\.dat': line {line}: sigma_n = [0-9.e+]+ Pa", msg)
    assert "node 9, surface table: tension in a closed contact" in msg


def test_compression_in_an_open_contact_is_refused(jobs, tmp_path):
    """A lifted mortar table node (gap > 1 mm at lambda = 1) given the RF of the most pressed one."""
    _, folder = jobs
    dat = _copy(folder, "JAR_ccx_lagrange", tmp_path / "job")
    df = read(dat.parent)
    last = df[(df["step"] == 2) & (df["increment"] == df["increment"].max()) & (df["surface"] == "table")]
    node = int(last.loc[last["gap_m"].idxmax(), "node"])
    assert last["gap_m"].max() > 1e-3
    text = dat.read_text().splitlines(keepends=True)
    head = [i for i, line in enumerate(text) if "forces (fx,fy,fz) for set NTABLE" in line][-1]
    block = range(head + 2, head + 2 + len(last))
    fz = {int(text[i].split()[0]): text[i].split()[3] for i in block}
    row = next(i for i in block if int(text[i].split()[0]) == node)
    most = max(fz.values(), key=lambda v: abs(float(v)))
    text[row] = text[row].replace(fz[node], most)
    dat.write_text("".join(text))
    with pytest.raises(InputError, match=rf"JAR_ccx_lagrange.dat': line {row + 1}: .*node {node}, surface table: "
                                         "compression in an open contact"):
        read(dat.parent)


def test_abaqus_dat_flipped_cpress_is_named_by_its_line(tmp_path, small_model):
    """The Abaqus .dat contact print sample (test_readers_misc): node 17 pressed at COPEN -1.19e-6 m in step 1;
    its CPRESS given the other sign is tension in a closed contact, at the line of that row."""
    from test_readers_misc import ABAQUS_DAT
    p = tmp_path / "jar_abaqus.dat"
    lines = ABAQUS_DAT.splitlines(keepends=True)
    i = next(k for k, line in enumerate(lines) if line.split()[:2] == ["17", "1.0700E+07"])
    lines[i] = lines[i].replace(" 1.0700E+07", "-1.0700E+07", 1)
    p.write_text("".join(lines))
    with pytest.raises(InputError, match=re.escape(f"{str(p)!r}: line {i + 1}: sigma_n = 1.07e+07 Pa with gap "
                                                   "-1.19e-06 m") + ".*node 17, surface table: tension in a closed"):
        read(p, model=small_model)


def test_nastran_gap_force_of_the_other_sign_is_named_by_its_record():
    """MSC's v10601s.op2 (REFERENCE data): gap 101 closed (u = 1.1494e-4 > U0 = 0) with compX = 33333 N.
    Read as stored it passes; with that force's sign flipped it is tension in a closed gap, named by its OP2
    record; cc188b's open gap carrying its PGAP preload F0 = 3.6e5 N still reads (F0 is subtracted)."""
    from pathlib import Path

    from deckbridge.readers._contact_law import check_contact_law
    from deckbridge.dialects.nastran.reader import deck_contact_map, read_gap_forces, tidy
    data = Path(__file__).resolve().parents[2] / "shared" / "data" / "msc_gap_examples"
    if not (data / "v10601s.op2").is_file():
        pytest.skip("../shared/data not present")
    op2 = data / "v10601s.op2"
    raw = read_gap_forces(op2)
    raw = raw[raw["table"] == "OEF1X"].reset_index(drop=True)
    cmap = deck_contact_map(data / "v10601s.bdf")
    assert len(check_contact_law(tidy(raw, cmap, op2, "nastran", "penalty", 1.0), op2)) == 2
    raw.loc[raw["element"] == 101, "force_n"] *= -1
    with pytest.raises(InputError, match=re.escape(f"{str(op2)!r}: OEF1X record of gap element 101, subcase 1, "
                                                   "increment 1: sigma_n = 33333.3 Pa") + ".*tension in a closed"):
        check_contact_law(tidy(raw, cmap, op2, "nastran", "penalty", 1.0), op2)
    assert len(read(data / "cc188b.op2"))
