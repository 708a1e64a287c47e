"""The scenario matrix (issue 21): the model's options combined pairwise by a generated covering array, each
case run through the decks, the reference solver (both methods) and CalculiX, in-process.

:func:`covering_array` is a small deterministic greedy pairwise generator (seeded): every pair of levels of
every two factors appears in at least one case, except the pairs that :data:`CONSTRAINTS` forbids (known
refused combinations, asserted as refusals by :data:`REFUSED`). :func:`run_case` runs one case with the
project's own job (:func:`deckbridge.job.run_job`, report drawing left out: it is not under test here and
costs half the time; the whole-section onset runs as users get it, friction cases included) and returns what
the invariants of :mod:`scenario_checks` read.
"""

from __future__ import annotations

import contextlib
import itertools
import random
from dataclasses import dataclass
from pathlib import Path
from unittest import mock

import pandas as pd

import pytest

from deckbridge.job import run_job
from deckbridge.model import Model, load
from deckbridge.readers import read
from deckbridge.readers.reference import read_wall

FACTORS = {
    "mesh": ("parametric", "msh", "inp", "bdf"),      # parametric, or a Gmsh-built import as Gmsh writes it
    "stop": ("none", "inner", "outer"),
    "n_r": (1, 2, 3),
    "t_over_r": (0.005, 0.012, 0.03),
    "pads": ("ring", "pads"),
    "cone": ("cylinder", "cone"),
    "tangential": ("springs", "friction"),
    "units": ("SI", "mm"),
    "top": ("distributing", "kinematic"),
    "nlgeom": (False, True),
}

# Known-invalid combinations, kept out of the positive cases (each is asserted as a refusal in REFUSED):
# a partial case is forbidden when a constraint's every (factor, level) is in it.
CONSTRAINTS = [
    ({"tangential": "friction", "nlgeom": True},
     "the CalculiX penalty deck with NLGEOM is GAPUNI gaps, which have no friction"),
]

# The refusals: model overrides that must stop before any work with one line naming the option.
REFUSED = [
    (["contact.tangential=friction", "contact.friction=0.3", "analysis.nlgeom=true"], "calculix",
     "analysis.nlgeom"),
    (["contact.friction=0.3"], "calculix", "contact.friction"),                # friction with springs
    (["contact.tangential=friction", "contact.friction=0.3"], "mystran", "contact.tangential"),
]

# Quadratic skirts (issue 23; tests/test_quadratic_offpath_matrix.py): levels of FACTORS plus 'element'
# (mesh.element; an import case is Gmsh's second-order mesh, 20-node hexahedra). On 8-/6-node faces the
# node-based radial stop, pads and friction are refused (docs/elements.md), so these keep no stop, a ring and
# springs, and vary the rest.
QUADRATIC_CASES = [
    {"mesh": "parametric", "stop": "none", "n_r": 2, "t_over_r": 0.03, "pads": "ring", "cone": "cone",
     "tangential": "springs", "units": "mm", "top": "kinematic", "nlgeom": False, "element": "hex20r"},
    {"mesh": "msh", "stop": "none", "n_r": 1, "t_over_r": 0.012, "pads": "ring", "cone": "cylinder",
     "tangential": "springs", "units": "mm", "top": "distributing", "nlgeom": False, "element": "hex20"},
    {"mesh": "parametric", "stop": "none", "n_r": 1, "t_over_r": 0.005, "pads": "ring", "cone": "cylinder",
     "tangential": "springs", "units": "SI", "top": "kinematic", "nlgeom": True, "element": "tet10"},
]

R, H, MU = 1.5, 2.0, 0.3
CONE_TOP = 1.2                          # top mid-wall radius of the cone cases [m]
PADS = "{count: 4, width_deg: 45, first_deg: 0}"   # pad edges on the 22.5 deg element boundaries of n_theta 16


def forbidden(case: dict) -> str | None:
    """The reason a (partial) case is a known-invalid combination, or None."""
    for levels, why in CONSTRAINTS:
        if all(k in case and case[k] == v for k, v in levels.items()):
            return why
    return None


def _pairs(case: dict) -> set:
    items = sorted(case.items())
    return {(a, b) for a, b in itertools.combinations(items, 2)}


def covering_array(factors: dict = FACTORS, seed: int = 21, tries: int = 30) -> list[dict]:
    """A pairwise covering array of ``factors`` avoiding :data:`CONSTRAINTS`: greedy, deterministic for a
    ``seed``. Each new case starts from an uncovered pair, fills the other factors in a random order with the
    level covering most uncovered pairs (ties broken at random), and the best of ``tries`` candidates is kept."""
    rng = random.Random(seed)
    names = list(factors)
    uncovered = set()
    for a, b in itertools.combinations(sorted(names), 2):
        for va in factors[a]:
            for vb in factors[b]:
                if not forbidden({a: va, b: vb}):
                    uncovered.add(((a, va), (b, vb)))
    cases = []
    while uncovered:
        best, gain = None, -1
        pool = sorted(uncovered, key=repr)
        for _ in range(tries):
            (a, va), (b, vb) = rng.choice(pool)
            case = {a: va, b: vb}
            rest = [n for n in names if n not in case]
            rng.shuffle(rest)
            for n in rest:
                scored = []
                for v in factors[n]:
                    trial = {**case, n: v}
                    if forbidden(trial):
                        continue
                    new = sum(1 for p in _pairs(trial) if p in uncovered and (n, v) in p)
                    scored.append((new, rng.random(), v))
                case[n] = max(scored, key=lambda s: s[:2])[2]
            g = len(_pairs(case) & uncovered)
            if g > gain:
                best, gain = case, g
        uncovered -= _pairs(best)
        cases.append({n: best[n] for n in names})
    return cases


@dataclass(frozen=True)
class Case:
    """One scenario: its factor levels and the mesh size (n_theta x n_z; n_r is a factor)."""
    levels: dict
    n_theta: int = 16
    n_z: int = 4
    increments: int = 5

    @property
    def name(self) -> str:
        v = self.levels
        return "-".join([v["mesh"], f"stop_{v['stop']}", f"nr{v['n_r']}", f"tR{v['t_over_r']:g}", v["pads"],
                         v["cone"], v["tangential"], v["units"], v["top"], "nlgeom" if v["nlgeom"] else "linear"]
                        + ([v["element"]] if "element" in v else []))

    def overrides(self, mesh_files: dict | None = None) -> list[str]:
        """The model's ``--set`` overrides (``mesh_files``: :func:`gmsh_skirt.gmsh_files`'s answer for an import)."""
        v = self.levels
        t = v["t_over_r"] * R
        out = [f"geometry.radius={R}", f"geometry.height={H}", f"geometry.thickness={t!r}",
               f"mesh.n_theta={self.n_theta}", f"mesh.n_z={self.n_z}", f"mesh.n_r={v['n_r']}",
               f"contact.stop.side={v['stop']}", f"units={v['units']}", f"load_introduction={v['top']}",
               f"analysis.nlgeom={'true' if v['nlgeom'] else 'false'}", f"steps.increments={self.increments}",
               "outputs.vtu=false", "name=CASE"]
        if v["cone"] == "cone":
            out.append(f"geometry.top_radius={CONE_TOP}")
        if "element" in v and v["mesh"] == "parametric":
            out.append(f"mesh.element={v['element']}")
        if v["pads"] == "pads":
            out.append(f"contact.pads={PADS}")
        if v["tangential"] == "friction":
            out += ["contact.tangential=friction", f"contact.friction={MU}"]
        if v["mesh"] != "parametric":
            fmt = v["mesh"]
            out += [f"mesh.file={mesh_files[fmt]}", f"mesh.sets={mesh_files['sets'][fmt]}",
                    f"mesh.units={'mm' if v['units'] == 'mm' else 'm'}"]
        return out

    def mesh_files(self, folder: Path) -> dict | None:
        """Build the Gmsh files of an import case (None for a parametric mesh)."""
        v = self.levels
        if v["mesh"] == "parametric":
            return None
        from gmsh_skirt import gmsh_files
        return gmsh_files(folder / "gmsh", R=R, t=v["t_over_r"] * R, H=H, n_theta=self.n_theta, n_z=self.n_z,
                          n_r=v["n_r"], top_radius=CONE_TOP if v["cone"] == "cone" else None,
                          unit="mm" if v["units"] == "mm" else "m", order=2 if "element" in v else 1)


@dataclass
class Run:
    """What one case produced: the model, its folder, the job's console lines, the contact tables per
    source label ('reference/penalty', 'ccx/mortar', ...), the wall tables, the reference summaries, the
    error (one line) when the job stopped."""
    case: Case
    model: Model | None
    out: Path
    lines: list
    tables: dict
    walls: dict
    summaries: dict
    error: str | None = None
    overrides: tuple = ()
    si_twin: Path | None = None      # the SI twin's ccx penalty job of a mm case (scenario_checks, made once)

    @property
    def quadratic(self) -> bool:
        """8-/6-node contact faces: no node-based ccx penalty deck there (docs/elements.md)."""
        from deckbridge.mesh import build_mesh
        return bool(build_mesh(self.model).quadratic_faces)

    @property
    def penalty_deck(self) -> str:
        """The case's ccx penalty job: 'penalty' (node-to-surface), 'f2f' on 8-/6-node faces."""
        return "f2f" if self.quadratic else "penalty"


def with_min_increment(text: str, dt_min: float) -> str:
    """An inp deck's text with every ``*STATIC`` minimum increment (3rd field of its data line) raised to at
    least ``dt_min`` [step time]."""
    lines = text.split("\n")
    for k in range(1, len(lines)):
        if lines[k - 1].strip().upper().startswith("*STATIC") and not lines[k].lstrip().startswith("*"):
            f = lines[k].split(",")
            f[2] = f" {max(float(f[2]), dt_min):.12e}"
            lines[k] = ",".join(f)
    return "\n".join(lines)


def _mortar_min_increment(dt_min: float):
    """A stand-in for the ccx runner that raises the mortar deck's minimum increment to ``dt_min`` first."""
    from deckbridge.dialects.calculix import runner
    real = runner.run

    def run(deck, *args, **kwargs):
        if Path(deck).name.endswith("_ccx_lagrange.inp"):
            Path(deck).write_text(with_min_increment(Path(deck).read_text(), dt_min))
        return real(deck, *args, **kwargs)
    return mock.patch.object(runner, "run", run)


def run_case(case: Case, folder: Path, mortar_min_increment: float | None = None) -> Run:
    """Load the case's model and run the job with CalculiX into ``folder``/job (report drawing left out).
    ``mortar_min_increment``: raise the ccx mortar deck's minimum increment [step time] to it (a case known
    to stall in ccx then stops sooner at the same load factor; see tests/test_scenario_matrix.py)."""
    folder = Path(folder)
    lines: list[str] = []
    run = Run(case, None, folder / "job", lines, {}, {}, {})
    try:
        run.overrides = tuple(case.overrides(case.mesh_files(folder)))
        run.model = load(None, list(run.overrides))
        cap = _mortar_min_increment(mortar_min_increment) if mortar_min_increment else contextlib.nullcontext()
        with mock.patch("deckbridge.job.write_report_with_verdict", return_value=[]), cap:
            res = run_job(run.model, run.out, with_ccx=True, echo=lines.append)
    except Exception as exc:                     # the invariant "no traceback" reads it
        run.error = f"{type(exc).__name__}: {exc}".splitlines()[0]
        return run
    run.summaries = res["reference"]
    for method in ("penalty", "lagrange"):
        run.tables[f"reference/{method}"] = read(run.out / f"reference_{method}", model=run.model)
        run.walls[f"reference/{method}"] = read_wall(run.out / f"reference_{method}")
    ccx = read(run.out / "ccx", model=run.model)
    for method, g in ccx.groupby("method"):
        run.tables[f"ccx/{method}"] = g.reset_index(drop=True)
    f2f = res["comparison"].source("reference/f2f")   # ccx/f2f's partner, in memory only (deckbridge/reference_f2f.py)
    if f2f is not None:
        run.tables["reference/f2f"], run.walls["reference/f2f"] = f2f.table, f2f.wall
    mortar = res["comparison"].source("reference/mortar")   # ccx/mortar's partner (deckbridge/reference_dual.py)
    if mortar is not None:
        run.tables["reference/mortar"], run.walls["reference/mortar"] = mortar.table, mortar.wall
    return run


def table_state(df: pd.DataFrame):
    """(step, increment, load factor, rows) per state of a contact table, in order."""
    for (step, inc), g in df.groupby(["step", "increment"], sort=True):
        yield int(step), int(inc), float(g["load_factor"].iloc[0]), g


def check_params(case: Case, checks, known) -> list:
    """pytest params of ``case``'s invariants ``checks``, each a strict xfail with its reason where a ``known`` rule
    (levels -> bool, the checks it covers or None for all, why) names it."""
    out = []
    for check in checks:
        why = next((why for rule, covered, why in known
                    if rule(case.levels) and (covered is None or check in covered)), None)
        marks = [pytest.mark.xfail(strict=True, reason=why)] if why else []
        out.append(pytest.param(check, id=f"{case.name}-{check}", marks=marks))
    return out
