"""Property-based campaign, model inputs (issue 26 acceptance): YAML model files, ``--set``, injection through
names, resources, friction / pads / grids.

For every generated bad or hostile input: success (writing only into the output folder), or one line
``deckbridge: error: ...`` naming the key or file at fault, exit 2 or 1, never "unexpected", no traceback,
nothing written (no partial output folder). In-process (click's CliRunner), bounded examples
(tests/campaign.py: CAMPAIGN), small meshes.
"""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from campaign import CAMPAIGN, outcome, refused, run, small_set

KEYS = ["name", "title", "geometry.radius", "geometry.height", "geometry.thickness", "geometry.top_radius",
        "material.E", "material.nu", "contact.stop.side", "contact.stop.radius", "contact.penalty.alpha",
        "contact.penalty.open_ratio", "contact.friction", "contact.tangential", "load_introduction", "loads.N",
        "loads.T", "loads.M", "loads.azimuth", "steps.lambda_max", "analysis.nlgeom", "units"]
HOSTILE = ["nan", ".nan", "-.inf", "1e999", "-1e999", "1e-320", "0", "-0", "-1", "1" * 300, "abc", "", "~",
           "[1, [2, [3]]]", "{a: 1}", "!!python/object:os.system ''", "&a 1", "*a", "\x1b[31m", "0x10", "1_0",
           "yes", "'1.5'", "[]", "{}", "1e308", "-2.5", "inf"]
values = st.one_of(st.sampled_from(HOSTILE), st.text(max_size=12))


def _decks(extra, sandbox, model=None):
    args = ["decks", "--dialect", "mystran", "-o", "out"] + small_set() + list(extra)
    return run(args + ([model] if model else []), sandbox)


# --- YAML model files --------------------------------------------------------------------------------------
documents = st.one_of(
    st.builds(lambda k, v: "\n".join(f"{'  ' * i}{p}:" for i, p in enumerate(k.split(".")[:-1]))
              + ("\n" if "." in k else "") + "  " * k.count(".") + f"{k.split('.')[-1]}: {v}\n",
              st.sampled_from(KEYS), st.sampled_from(HOSTILE)),
    st.sampled_from(["- a\n- b\n", "just text\n", "a: &x [1]\nb: *x\n", "geometry: {radius: 1, radius: 2}\n",
                     "mesh:\n\tn_theta: 4\n", "!!python/object/apply:os.system ['true']\n", "[" * 200 + "\n",
                     "\ufeffgeometry: {radius: 1.5}\n", "geometry:\n  colour: red\n", "loads: 5\n",
                     "%YAML 9.9\n---\na: 1\n"]),
    st.binary(max_size=40).map(lambda b: b.decode("latin-1")))


@CAMPAIGN
@given(documents)
def test_yaml_model_file(tmp_path_factory, text):
    box = tmp_path_factory.mktemp("yaml")
    (box / "m.yaml").write_text(text, encoding="utf-8", errors="surrogateescape")
    res, before, after = _decks([], box, "m.yaml")
    outcome(res, before, after, "out", "m.yaml")


# --- --set ----------------------------------------------------------------------------------------------------
@CAMPAIGN
@given(st.sampled_from(KEYS + ["mesh", "geometry.colour", "", ".", "a..b", "contact.pads.count"]), values)
def test_set_value(tmp_path_factory, key, value):
    box = tmp_path_factory.mktemp("set")
    res, before, after = _decks(["--set", f"{key}={value}"], box)
    outcome(res, before, after, "out", key or "--set", "--set")


# --- injection through names -----------------------------------------------------------------------------------
CARDS = ["\n*STEP", "\nBEGIN BULK", "\nENDDATA", "\r*END STEP", "$\n", "**\n*NODE", ",\n1, 2, 3", "\u2028*STEP",
         "\x00", "\x85*STEP", "\n\n*STEP"]


@CAMPAIGN
@given(st.sampled_from(["name", "title"]), st.sampled_from(["x", "", "*", "$"]), st.sampled_from(CARDS),
       st.text(max_size=6))
def test_names_inject_no_card(tmp_path_factory, key, head, card, tail):
    """Every deck line that holds the name's marker QZ is a comment (Nastran '$', inp '**'), Nastran's
    ``TITLE =`` or an inp ``*HEADING`` text line: never a keyword line of its own."""
    box = tmp_path_factory.mktemp("inject")
    res, before, after = run(["decks", "-o", "out", "--dialect", "calculix", "--dialect", "nastran"] + small_set()
                             + ["--set", f"{key}={head}{card}QZ{tail}"], box)
    if outcome(res, before, after, "out", key) is None:
        for deck in (box / "out").iterdir():
            for line in deck.read_text(errors="replace").splitlines():
                text = line.lstrip()
                if "QZ" in text:
                    ok = text.startswith(("$", "TITLE =")) if deck.suffix == ".bdf" else not (
                        text.startswith("*") and not text.startswith("**"))
                    assert ok, (deck.name, line)


# --- resources ------------------------------------------------------------------------------------------------
@CAMPAIGN
@given(st.sampled_from(["mesh.n_theta", "mesh.n_z", "mesh.n_r", "steps.increments"]),
       st.sampled_from([10**6, 10**9, 10**30, 2**31, 2**63, 0, -1]))
def test_resources_are_refused_before_work(tmp_path_factory, monkeypatch, key, n):
    monkeypatch.delenv("DECKBRIDGE_ALLOW_LARGE", raising=False)
    box = tmp_path_factory.mktemp("res")
    res, before, after = run(["decks", "-o", "out"] + small_set() + ["--set", f"{key}={n}"], box)
    refused(res, before, after, key, "--allow-large", "dofs")


@pytest.mark.parametrize("k", ["1e-300", "1e300", "nan", "-1", "0", "inf"])
def test_k_factor_range(tmp_path, k):
    res, before, after = run(["solve", "--method", "penalty", "--k-factor", k, "-o", "out"] + small_set(), tmp_path)
    refused(res, before, after, "--k-factor", "k_factor", k)


@pytest.mark.parametrize("nu", ["-0.99999999", "0.5", "-1", "0.7"])
def test_poisson_ratio_range(tmp_path, nu):
    res, before, after = _decks(["--set", f"material.nu={nu}"], tmp_path)
    refused(res, before, after, "material.nu")


# --- friction, pads, grids ------------------------------------------------------------------------------------------
pads = st.fixed_dictionaries({}, optional={"count": st.sampled_from(["0", "-1", "1e9", "2.5", "nan", "x", "4"]),
                                           "width_deg": st.sampled_from(["0", "-5", "400", "nan", "1e300", "30"]),
                                           "first_deg": st.sampled_from(["nan", "1e300", "-720", "7.5", "0"]),
                                           "colour": st.just("red")})


@CAMPAIGN
@given(st.sampled_from(["contact.friction", "contact.tangential", "contact.penalty.k_tangent"]),
       st.sampled_from(["-0.1", "nan", "1e300", "friction", "springs", "glue", "-1e6", "follow", "0"]))
def test_friction_settings(tmp_path_factory, key, value):
    box = tmp_path_factory.mktemp("fric")
    res, before, after = _decks(["--set", f"{key}={value}"], box)
    outcome(res, before, after, "out", key, "contact.")


@CAMPAIGN
@given(pads)
def test_pads(tmp_path_factory, spec):
    box = tmp_path_factory.mktemp("pads")
    text = "{" + ", ".join(f"{k}: {v}" for k, v in spec.items()) + "}"
    res, before, after = _decks(["--set", f"contact.pads={text}"], box)
    outcome(res, before, after, "out", "contact.pads")


@CAMPAIGN
@given(st.sampled_from(["contact.penalty.open_ratio", "mesh.n_theta", "geometry.colour", "loads.N", "", "a..b"]),
       st.lists(st.sampled_from(["1e-3", "nan", "", "-1", "x", "1e300", "12", "2.5"]), min_size=0, max_size=3))
def test_sweep_grid(tmp_path_factory, key, vals):
    box = tmp_path_factory.mktemp("grid")
    spec = f"{key}={','.join(vals)}"
    if "nan" not in vals and "x" not in vals and "" not in vals and "-1" not in vals and key in (
            "contact.penalty.open_ratio", "loads.N") and vals:
        vals.append("nan")                            # keep every case a bad one: a good grid would run a sweep
        spec = f"{key}={','.join(vals)}"
    res, before, after = run(["sweep", "--k-factors", "1,10", "--grid", spec, "-o", "out"] + small_set(), box)
    refused(res, before, after, key or "--grid", "--grid")
