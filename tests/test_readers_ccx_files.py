"""Every reader error names the file it was reading (issue 26: an error on a .dat named its sibling .frd).

A ccx job is read from three files (the deck .inp for the slave table, the .dat, the .frd), whichever of them
is given. Real CalculiX 2.20 output of the project's penalty deck (16 x 4 x 1), one file spoiled at a time:
the error names the spoiled file whichever one was given, and a node row with a value too many is an error
at its line (before, it silently ended the block and the nodes after it read as open)."""

import shutil

import pytest

from deckbridge.errors import DeckbridgeError
from deckbridge.model import load
from deckbridge.readers import read
from ccx_job import ccx_penalty_job

pytestmark = pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX ccx not installed")
STEM = "JAR_ccx_penalty"


@pytest.fixture(scope="module")
def job(tmp_path_factory):
    model = load(None, ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1"])
    return ccx_penalty_job(model, tmp_path_factory.mktemp("ccx_files")).parent


def _spoil(job, tmp_path, suffix, find, replace, nth=0):
    """Copy the job; in its ``suffix`` file replace ``find`` by ``replace`` on the nth line holding it.
    Returns the copied folder and the spoiled line's number (1-based)."""
    dest = tmp_path / "job"
    shutil.copytree(job, dest)
    f = dest / f"{STEM}{suffix}"
    lines = f.read_text().splitlines(keepends=True)
    hits = [i for i, line in enumerate(lines) if find in line]
    i = hits[nth]
    lines[i] = lines[i].replace(find, replace, 1)
    f.write_text("".join(lines))
    return dest, i + 1


def _error(path) -> str:
    with pytest.raises(DeckbridgeError) as err:
        read(path)
    msg = str(err.value)
    assert "\n" not in msg
    return msg


def test_unspoiled_job_reads_from_each_file(job):
    for suffix in (".inp", ".dat", ".frd"):
        assert len(read(job / f"{STEM}{suffix}"))


def test_bad_deck_line_names_the_deck(job, tmp_path):
    text = (job / f"{STEM}.inp").read_text()
    area = next(line.split()[-1] for line in text.splitlines() if line.startswith("** deckbridge-n2f ") and
                "node" not in line)
    dest, _ = _spoil(job, tmp_path, ".inp", area, "abc")
    for given in (".dat", ".frd"):
        msg = _error(dest / f"{STEM}{given}")
        assert msg.startswith(f"{str(dest / (STEM + '.inp'))!r}: unreadable (ValueError")


def test_bad_frd_time_names_the_frd(job, tmp_path):
    dest, _ = _spoil(job, tmp_path, ".frd", " 1.200000000", " 1.2000x0000")
    msg = _error(dest / f"{STEM}.dat")
    assert msg.startswith(f"{str(dest / (STEM + '.frd'))!r}: unreadable (ValueError")


def test_bad_frd_value_names_the_frd_line(job, tmp_path):
    dest, line = _spoil(job, tmp_path, ".frd", "E-", "Q-", nth=200)
    msg = _error(dest / f"{STEM}.dat")
    assert msg.startswith(f"{str(dest / (STEM + '.frd'))!r}: line {line}: unreadable")


def test_a_row_with_a_value_too_many_is_an_error_at_its_line(job, tmp_path):
    text = (job / f"{STEM}.dat").read_text().splitlines()
    head = next(i for i, line in enumerate(text) if line.lstrip().startswith("contact stress"))
    row = text[head + 3]
    dest, line = _spoil(job, tmp_path, ".dat", row, row + "  1.000000E+00")
    assert line == head + 4
    for given in (".dat", ".frd", ".inp"):
        msg = _error(dest / f"{STEM}{given}")
        assert msg.startswith(f"{str(dest / (STEM + '.dat'))!r}: line {line}: 4 values where the block has 3")
