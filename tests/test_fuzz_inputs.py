"""Property-based checks (hypothesis) of every way input comes in: the model loader, ``--set`` and
every reader (ccx .dat/.frd, Nastran OP2, MYSTRAN F06, Abaqus .dat, plain CSV, reference folder).

Property: every generated input ends in success or in one clean line (a DeckbridgeError, or exit 2
with one ``deckbridge: error:`` line through the CLI), never a traceback, and a table that is read
holds no NaN or infinite sigma_n / load factor. Inputs are real files mutated (truncated, numbers
replaced by nan/inf/huge/text, lines dropped or repeated, bytes inserted). Bounded: derandomized,
a fixed number of examples per property, about 30-40 s in all on a 2-core machine.
"""

from __future__ import annotations

import math
import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest
import yaml
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from deckbridge.cli import main
from deckbridge.errors import DeckbridgeError, ModelError
from deckbridge.model import Model, load, loads_model
from deckbridge.readers import read
from deckbridge.results import ResultsError

from conftest import SHARED

FUZZ = settings(max_examples=100, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
SMALL = ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1", "steps.increments=2"]
MODEL_KEYS = ["name", "title", "geometry.radius", "geometry.height", "geometry.thickness", "geometry.top_radius",
              "mesh.n_theta", "mesh.n_z", "mesh.n_r", "material.name", "material.E", "material.nu",
              "contact.stop.side", "contact.stop.radius", "contact.penalty.alpha", "contact.penalty.k_normal",
              "contact.penalty.open_ratio", "contact.friction", "load_introduction", "loads.N", "loads.T",
              "loads.M", "loads.azimuth", "steps.lambda_max", "steps.increments", "outputs.vtu"]
NASTY = ["nan", "NaN", ".nan", "inf", "-inf", ".inf", "1e999", "-1e999", "1" * 400, "0x18", "030", "1:00",
         "1_000", "abc", "", "\x1b[31m", "\n", "&a 1", "*a", "[1, [2, [3]]]", "{a: 1}", "!!python/none ''",
         "1e-320", "-0", "2.5e-5", "12", "yes", "~"]


def _one_line(text: str) -> None:
    assert "\n" not in text and "\x1b" not in text and "\r" not in text, repr(text[:300])
    assert len(text) < 2000


def _table_ok(df, allow_nan_lambda=False) -> None:
    assert len(df) > 0
    assert np.isfinite(df["sigma_n_pa"].to_numpy(float)).all()
    lam = df["load_factor"].to_numpy(float)
    assert (np.isfinite(lam) | (allow_nan_lambda & np.isnan(lam))).all()
    assert not np.isinf(df["gap_m"].to_numpy(float)).any()


# --- the model loader and --set -------------------------------------------------------------------
scalars = st.one_of(st.none(), st.booleans(), st.integers(min_value=-10**30, max_value=10**400),
                    st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=30),
                    st.sampled_from(NASTY))
values = st.recursive(scalars, lambda inner: st.lists(inner, max_size=4) | st.dictionaries(
    st.text(max_size=8), inner, max_size=4), max_leaves=12)


@st.composite
def model_docs(draw):
    """A YAML model: known sections with values of any kind, sometimes unknown keys or raw text."""
    doc: dict = {}
    for key in draw(st.lists(st.sampled_from(MODEL_KEYS), max_size=6)):
        parts = key.split(".")
        node = doc
        for p in parts[:-1]:
            node = node.setdefault(p, {}) if isinstance(node.get(p, {}), dict) else {}
        node[parts[-1]] = draw(values)
    if draw(st.booleans()):
        doc[draw(st.text(max_size=10))] = draw(values)
    text = yaml.safe_dump(doc, allow_unicode=True) if doc else ""
    if draw(st.integers(0, 4)) == 0:
        text = draw(st.text(max_size=200))
    return text


@FUZZ
@given(model_docs())
def test_model_loader_ends_in_a_model_or_one_line(text):
    try:
        m = loads_model(text, "fuzz.yaml")
    except ModelError as exc:
        _one_line(str(exc))
        assert str(exc).startswith("fuzz.yaml: ")
        return
    assert isinstance(m, Model)
    assert all(math.isfinite(v) for v in (m.geometry.radius, m.material.E, m.loads.N, m.steps.lambda_max))


@FUZZ
@given(st.sampled_from(MODEL_KEYS + ["mesh", "geometry.colour", "", ".", "a..b"]),
       st.one_of(st.sampled_from(NASTY), st.text(max_size=40)), st.sampled_from(["=", "", "=="]))
def test_set_parser_ends_in_a_model_or_one_line(key, value, sep):
    try:
        m = load(None, [f"{key}{sep}{value}"])
    except ModelError as exc:
        _one_line(str(exc))
        return
    assert isinstance(m, Model)


@settings(FUZZ, max_examples=20)
@given(st.sampled_from([k for k in MODEL_KEYS if not k.startswith("mesh.")]),
       st.one_of(st.sampled_from(NASTY), st.text(max_size=20)))
def test_cli_set_ends_in_success_or_one_line(key, value):
    """Through the command line: exit 0, or exit 1/2 with exactly one error line, never a traceback."""
    with tempfile.TemporaryDirectory() as tmp:
        args = ["decks", "--dialect", "mystran", "-o", str(Path(tmp) / "out")]
        for s in SMALL + [f"{key}={value}"]:
            args += ["--set", s]
        res = CliRunner().invoke(main, args)
    assert res.exit_code in (0, 1, 2), res.output
    assert res.exception is None or isinstance(res.exception, SystemExit), repr(res.exception)
    if res.exit_code:
        lines = res.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("deckbridge: error: "), res.stderr
        _one_line(lines[0])


# --- readers ----------------------------------------------------------------------------------------
BAD_NUMBERS = ["nan", "NaN", "inf", "-inf", "1e999", "abc", "1" * 400, "", "-", "1.0.0"]
where = st.floats(min_value=0, max_value=1)
edit = st.one_of(
    st.tuples(st.just("number"), where, st.sampled_from(BAD_NUMBERS)),        # a value of a data line
    st.tuples(st.just("number"), where, st.sampled_from(BAD_NUMBERS)),        # (twice: the likeliest harm)
    st.tuples(st.just("truncate"), st.floats(min_value=0.05, max_value=0.999), st.just("")),
    st.tuples(st.sampled_from(["drop", "repeat"]), where, st.just("")),
    st.tuples(st.just("insert"), where, st.sampled_from(NASTY) | st.text(max_size=12)))
edits = st.lists(edit, min_size=1, max_size=3)


def _mutate(data: bytes, plan) -> bytes:
    text = data.decode("latin-1")
    for kind, where, payload in plan:
        lines = text.splitlines(keepends=True) or [""]
        i = min(int(where * len(lines)), len(lines) - 1)
        if kind == "truncate":
            text = text[: int(where * len(text))]
        elif kind == "drop":
            del lines[i]
            text = "".join(lines)
        elif kind == "repeat":
            lines.insert(i, lines[i])
            text = "".join(lines)
        elif kind == "insert":
            pos = int(where * len(text))
            text = text[:pos] + payload + text[pos:]
        else:                               # replace one number of a line holding numbers by the payload
            rows = [k for k, ln in enumerate(lines) if sum(c.isdigit() for c in ln) > 6] or [i]
            k = rows[min(int(where * len(rows)), len(rows) - 1)]
            toks = lines[k].replace(",", " ").split()
            nums = [t for t in toks if any(c.isdigit() for c in t)]
            if nums:
                lines[k] = lines[k].replace(nums[int(where * 7919) % len(nums)], payload, 1)
            text = "".join(lines)
    return text.encode("latin-1", errors="replace")


def _check_read(files: dict[str, bytes], target: str, fmt: str, model, plan, allow_nan_lambda=False):
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for name, data in files.items():
            (folder / name).parent.mkdir(parents=True, exist_ok=True)
            (folder / name).write_bytes(_mutate(data, plan) if name == target else data)
        try:
            df = read(folder / target.split("/")[0], fmt=fmt, model=model)
        except (DeckbridgeError, ResultsError) as exc:
            _one_line(str(exc))
            return "refused"
        _table_ok(df, allow_nan_lambda)
        return "read"


@pytest.fixture(scope="module")
def small():
    return load(None, SMALL)


@pytest.fixture(scope="module")
def ccx_job(small, tmp_path_factory):
    if shutil.which("ccx") is None:
        pytest.skip("ccx not installed")
    from deckbridge.dialects.calculix import runner as ccx_run
    from deckbridge.render import render_all
    folder = tmp_path_factory.mktemp("fuzz_ccx")
    deck = [p for p in render_all(small, folder, ["calculix"]) if "penalty" in p.name][0]
    run = ccx_run.run(deck, timeout_s=60)
    return {p.name: p.read_bytes() for p in (deck, run.dat, run.frd)}


@FUZZ
@given(edits, st.sampled_from([".dat", ".frd"]), st.booleans())
def test_ccx_reader_on_mutated_files(ccx_job, small, plan, suffix, with_model):
    target = next(n for n in ccx_job if n.endswith(suffix))
    _check_read(ccx_job, target, "calculix", small if with_model else None, plan)


@pytest.fixture(scope="module")
def reference_folder(small, tmp_path_factory):
    folder = tmp_path_factory.mktemp("fuzz_ref") / "ref"
    res = CliRunner().invoke(main, ["solve", "--method", "lagrange", *sum((["--set", s] for s in SMALL), []),
                                    "--set", "outputs.vtu=false", "-o", str(folder)])
    assert res.exit_code == 0, res.output
    return {f"ref/{p.name}": p.read_bytes() for p in folder.iterdir() if not p.name.startswith(".")}


@FUZZ
@given(edits, st.booleans())
def test_reference_reader_on_mutated_files(reference_folder, small, plan, with_model):
    _check_read(reference_folder, "ref/contact.csv", "reference", small if with_model else None, plan)


@FUZZ
@given(edits)
def test_abaqus_dat_reader_on_mutated_files(small, plan):
    from test_readers_misc import ABAQUS_DAT
    _check_read({"jar_abaqus.dat": ABAQUS_DAT.encode()}, "jar_abaqus.dat", "abaqus_dat", small, plan)


PLAIN_CSV = "theta_deg,CPRESS [MPa],load_factor\n" + "".join(
    f"{22.5 * j},{10 + j},{lam}\n" for lam in (0.5, 1.0) for j in range(16))


@FUZZ
@given(edits, st.booleans())
def test_plain_csv_reader_on_mutated_files(small, plan, with_model):
    _check_read({"export.csv": PLAIN_CSV.encode()}, "export.csv", "plain_csv", small if with_model else None, plan)


OP2 = SHARED / "data" / "msc_gap_examples" / "cc188b.op2"


@settings(FUZZ, max_examples=25)
@given(edits)
def test_op2_reader_on_mutated_files(plan):
    if not OP2.is_file():
        pytest.skip(f"shared MSC OP2 example absent ({OP2})")
    files = {OP2.name: OP2.read_bytes(), OP2.with_suffix(".bdf").name: OP2.with_suffix(".bdf").read_bytes()}
    _check_read(files, OP2.name, "nastran_op2", None, plan)


@pytest.fixture(scope="module")
def f06_job(small, tmp_path_factory):
    from deckbridge.dialects.mystran import runner as mystran_run
    from deckbridge.mesh import build_mesh
    from deckbridge.dialects.mystran.render import write
    folder = tmp_path_factory.mktemp("fuzz_f06")
    model = load(None, SMALL + ["steps.lambda_max=0.5", "contact.stop.side=none"])
    try:
        f06 = mystran_run.run(write(model, build_mesh(model), folder)[0], timeout_s=60)
    except DeckbridgeError as exc:
        pytest.skip(f"MYSTRAN not available ({exc})")
    return model, {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()}, f06.name


@FUZZ
@given(edits, st.booleans())
def test_f06_reader_on_mutated_files(f06_job, plan, with_model):
    model, files, f06 = f06_job
    _check_read(files, f06, "mystran_f06", model if with_model else None, plan, allow_nan_lambda=not with_model)
