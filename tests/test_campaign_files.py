"""Property-based campaign, files (issue 26 acceptance): output folders, compare inputs, real solver files,
imported meshes, interrupts.

Same properties as tests/test_campaign_inputs.py (tests/campaign.py): success writing only into its output,
or one ``deckbridge: error:`` line naming the file or option at fault, exit 2 or 1, never "unexpected", no
traceback, the sandbox unchanged. Every generated compare input carries at least one defect, so that no
case draws a report (a report costs seconds).
"""

from __future__ import annotations

import shutil

import pytest
from hypothesis import given
from hypothesis import strategies as st

from campaign import CAMPAIGN, outcome, refused, run, small_set
from deckbridge.model import load
from deckbridge.readers._nodemap import slave_nodes

# --- output folders -----------------------------------------------------------------------------------------
@pytest.mark.parametrize("target", ["f.txt/sub", "", "f.txt"])
def test_output_path_that_cannot_be_a_folder(tmp_path, target):
    (tmp_path / "f.txt").write_text("the user's\n")
    res, before, after = run(["decks", "--dialect", "mystran", "-o", target] + small_set(), tmp_path)
    refused(res, before, after, repr(target) if target else "-o", "output", code=2)


@pytest.mark.parametrize("names", [("JAR_mystran.bdf",), ("summary.json", "report.html"),
                                   (".env.backup1", ".staging-notes/todo.txt", ".notes.swp123")])
def test_user_folder_is_not_written_without_force(tmp_path_factory, names):
    """Fixed cases, not generated: a failing hypothesis test shrinks for a minute."""
    box = tmp_path_factory.mktemp("userdir")
    for n in names:
        (box / "mine" / n).parent.mkdir(parents=True, exist_ok=True)
        (box / "mine" / n).write_text("the user's own file\n")
    res, before, after = run(["decks", "--dialect", "mystran", "-o", "mine"] + small_set(), box)
    refused(res, before, after, "mine", "--force")


# --- compare inputs ------------------------------------------------------------------------------------------
DEFECTS = ["duplicate", "fraction", "far_theta", "nan", "no_stress", "unit", "empty", "binary", "flip_open"]


def _csv_with(defects: list[str], nodes) -> bytes:
    head = "node,CPRESS [MPa],COPEN [mm]"
    rows = [f"{n},{10 + i % 3},-0.01" for i, n in enumerate(nodes[:8])]
    for d in defects:
        if d == "duplicate":
            rows.append(rows[1])
        elif d == "fraction":
            rows[2] = f"{nodes[2]}.5,10,-0.01"
        elif d == "far_theta":
            head, rows = "theta [deg],CPRESS [MPa]", [f"{30 * i},{10 + i}" for i in range(8)] + ["1e300,5"]
        elif d == "nan":
            rows[3] = f"{nodes[3]},nan,-0.01"
        elif d == "no_stress":
            head = "node,value,COPEN [mm]"
        elif d == "unit":
            head = "node,CPRESS [ksi],COPEN [mm]"
        elif d == "flip_open":
            rows[4] = f"{nodes[4]},10,2.0"            # pressed at an open gap of 2 mm
        elif d == "empty":
            return b""
        elif d == "binary":
            return b"\x00\xff\xfe\x89PNG\r\n"
    return ("\n".join([head] + rows) + "\n").encode()


@CAMPAIGN
@given(st.lists(st.sampled_from(DEFECTS), min_size=1, max_size=3, unique=True), st.booleans())
def test_compare_inputs_with_a_defect(tmp_path_factory, defects, first):
    box = tmp_path_factory.mktemp("cmp")
    nodes = slave_nodes(load(None, [])).index.to_numpy()
    (box / "bad.csv").write_bytes(_csv_with(defects, nodes))
    (box / "good.csv").write_bytes(_csv_with([], nodes))
    pair = ["bad.csv", "good.csv"] if first else ["good.csv", "bad.csv"]
    res, before, after = run(["compare", *pair, "-o", "out"], box)
    refused(res, before, after, "bad.csv", code=2)


# --- real solver files ------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def ccx_folder(tmp_path_factory):
    if shutil.which("ccx") is None:
        pytest.skip("CalculiX ccx not installed")
    from ccx_job import ccx_penalty_job
    return ccx_penalty_job(load(None, SMALL_CCX), tmp_path_factory.mktemp("real")).parent


SMALL_CCX = ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1"]


def _spoil_dat(text: str, how: str, k: int) -> str:
    """One defect in a real ccx penalty .dat: the k-th row of the first contact-stress block (end of step 1,
    every table node pressed and penetrating) flipped, given a value too many, or made nan; or the file cut."""
    lines = text.splitlines(keepends=True)
    head = next(i for i, line in enumerate(lines) if line.lstrip().startswith("contact stress"))
    i = head + 2 + k
    parts = lines[i].split()
    if how == "flip":
        lines[i] = lines[i].replace(parts[1], "-" + parts[1], 1)
    elif how == "extra":
        lines[i] = lines[i].rstrip("\n") + "  1.000000E+00\n"
    elif how == "nan":
        lines[i] = lines[i].replace(parts[1], "nan", 1)
    else:
        return "".join(lines)[: len(text) * (k + 1) // 40]
    return "".join(lines)


@CAMPAIGN
@given(st.sampled_from(["flip", "extra", "nan", "cut"]), st.integers(min_value=0, max_value=15))
def test_real_ccx_file_with_a_defect(ccx_folder, tmp_path_factory, how, k):
    box = tmp_path_factory.mktemp("ccx")
    shutil.copytree(ccx_folder, box / "job")
    dat = box / "job" / "JAR_ccx_penalty.dat"
    dat.write_text(_spoil_dat(dat.read_text(), how, k))
    res, before, after = run(["compare", "job/JAR_ccx_penalty.dat", "-o", "out"] + small_set()[:0], box)
    line = refused(res, before, after, "JAR_ccx_penalty.dat", code=2)
    if how == "flip":
        assert "line " in line and "tension in a closed contact" in line, line


# --- imported meshes --------------------------------------------------------------------------------------------
MESH_EDITS = ["nan_coord", "huge_coord", "drop_line", "repeat_line", "trailing_comma", "junk", "cut", "unknown_set"]


def _spoil_inp(text: str, how: str, k: int) -> str:
    lines = text.splitlines(keepends=True)
    data = [i for i, line in enumerate(lines) if line.strip() and not line.startswith("*")]
    i = data[k % len(data)]
    if how == "nan_coord":
        lines[i] = lines[i].rsplit(",", 1)[0] + ", nan\n"
    elif how == "huge_coord":
        lines[i] = lines[i].rsplit(",", 1)[0] + ", 1e300\n"
    elif how == "drop_line":
        del lines[i]
    elif how == "repeat_line":
        lines.insert(i, lines[i])
    elif how == "trailing_comma":
        lines[i] = lines[i].rstrip("\n") + ",\n"
    elif how == "junk":
        lines.insert(i, "\x00\xff junk ;;\n")
    elif how == "cut":
        return "".join(lines)[: len(text) * (k % 20 + 1) // 21]
    return "".join(lines)


@CAMPAIGN
@given(st.sampled_from(MESH_EDITS), st.integers(min_value=0, max_value=400))
def test_imported_mesh_with_a_defect(tmp_path_factory, how, k):
    from test_import_cli import _tube
    box = tmp_path_factory.mktemp("imp")
    mesh = _tube(box)
    mesh.write_text(_spoil_inp(mesh.read_text(), how, k))
    base = "NOPE" if how == "unknown_set" else "FLOOR"
    res, before, after = run(["import", mesh.name, "-o", "m.yaml", "--base", base, "--top", "LID"], box)
    outcome(res, before, after, "m.yaml", "tube.inp", "NOPE")


# --- interrupts ----------------------------------------------------------------------------------------------
STAGES = {"decks": ("deckbridge.render.render_all", ["decks", "-o", "out"]),
          "solve": ("deckbridge.solve.solve_bound", ["solve", "--method", "penalty", "-o", "out"])}


@pytest.mark.parametrize("stage", sorted(STAGES))
def test_interrupt_leaves_no_partial_folder(tmp_path, monkeypatch, stage):
    """Ctrl-C (KeyboardInterrupt) in the middle of a command: exit non-zero and no partial output folder."""
    target, args = STAGES[stage]
    module, name = target.rsplit(".", 1)

    def interrupted(*a, **kw):
        raise KeyboardInterrupt

    monkeypatch.setattr(f"{module}.{name}", interrupted)
    res, before, after = run(args + small_set(), tmp_path)
    assert res.exit_code != 0
    assert after == before, sorted(set(after) - set(before))


def test_interrupt_is_one_error_line(tmp_path, monkeypatch):
    def interrupted(*a, **kw):
        raise KeyboardInterrupt

    monkeypatch.setattr("deckbridge.solve.solve_bound", interrupted)
    res, before, after = run(["solve", "--method", "penalty", "-o", "out"] + small_set(), tmp_path)
    refused(res, before, after)
