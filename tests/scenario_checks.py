"""The invariants of the scenario matrix (:mod:`scenarios`), one function each; each raises AssertionError with
the case's numbers, or returns a short note of what it checked.

Every check compares against something outside the number checked: the applied loads (a force balance of
the contact forces read back from each solver's own output), the contact law (no penetration without force),
the same deck in SI and in mm run by ccx, the reference solver against ccx on the same analysis, and the
job's printed warnings against the data they claim.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from deckbridge.readers.reference import read_friction
from deckbridge.quantities import PENETRATION_FLOOR, PENETRATION_WARN, RESIDUAL_WARN, TENSION_WARN
from deckbridge.quantities import nodal_force, pressure_force
from deckbridge.readers import read
from deckbridge.importers.inp_mesh import read_inp_mesh
from deckbridge.report.caveats import SMALL_STRAIN

from ccx_f2f_resultant import ring_line_pairs, ring_resultant
from scenario_units import TOL_CCX_FILES, TOL_UNITS, paraview_si_equals_mm, si_equals_mm  # noqa: F401 (CHECKS, tests)
from scenarios import Run, table_state

TOL_FORCE = 1e-3        # equilibrium: relative to N (forces) and N R (moments)
TOL_CCX = 0.02          # ccx against the reference: fraction of the peak |sigma_N| of the state


def ran(run: Run) -> str:
    """No traceback: the job finished."""
    assert run.error is None, run.error
    return "finished"


def decks_read_back(run: Run) -> str:
    """Every deck read back by its parser: pyNastran ``read_bdf`` (cross-referenced) for .bdf, the project's
    inp reader for .inp; each deck carries every node of the mesh."""
    from pyNastran.bdf.bdf import BDF
    ran(run)
    n_mesh = len(read(run.out / "reference_penalty", model=run.model).node.unique())   # slaves only: a floor
    decks = sorted((run.out / "decks").glob("*"))
    for deck in decks:
        if deck.suffix == ".bdf":
            bdf = BDF(debug=None)
            bdf.read_bdf(str(deck), xref=True)
            assert len(bdf.nodes) >= n_mesh, deck.name
        elif deck.suffix == ".inp":
            assert read_inp_mesh(deck).node_ids.size >= n_mesh, deck.name
    return f"{len(decks)} decks"


def decks_command(run: Run) -> str:
    """``deckbridge decks`` (in-process, the case's --set options) exits 0 and writes the job's decks (their
    names; the job may have left out a dialect with a note: it must not, decks being the same model)."""
    from click.testing import CliRunner

    from deckbridge.cli import main
    out = run.out.parent / "decks_cli"
    args = ["decks", "-o", str(out)] + [a for o in run.overrides for a in ("--set", o)]
    res = CliRunner().invoke(main, args)
    assert res.exit_code == 0, f"exit {res.exit_code}: {res.output.strip().splitlines()[-1:]} {res.exception!r}"
    got = sorted(p.name for p in out.iterdir() if not p.name.startswith("."))
    if (run.out / "decks").is_dir():
        want = sorted(p.name for p in (run.out / "decks").iterdir() if not p.name.startswith("."))
        assert got == want, f"decks wrote {got}, the job {want}"
    return f"{len(got)} files"


def ccx_finished(run: Run) -> str:
    """The ccx jobs (nodal penalty but on 8-/6-node faces, mortar; face-to-face without NLGEOM) ran every state."""
    ran(run)
    want = _factors(run.tables["reference/penalty"])
    for label in (() if run.quadratic else ("ccx/penalty",)) + ("ccx/mortar",) + ((), ("ccx/f2f",))[not run.model.analysis.nlgeom]:
        assert label in run.tables, f"{label} missing"
        got = _factors(run.tables[label])
        assert got == want, f"{label}: load factors {sorted(got)}, the reference has {sorted(want)}"
    return f"{len(want)} load factors"


def _factors(df) -> set:
    """The distinct load factors of a contact table (rounded to 1e-9)."""
    return set(np.round(df["load_factor"].to_numpy(float), 9).tolist())


def _interactions(text: str) -> dict[str, list[str]]:
    """{interaction name: its option lines} of an inp deck: the lines from ``*SURFACE INTERACTION, NAME=X``
    to the next keyword that is not one of its options."""
    out, name = {}, None
    for line in text.splitlines():
        up = line.strip().upper()
        if not up or up.startswith("**"):
            continue
        m = re.match(r"\*SURFACE INTERACTION\s*,\s*NAME\s*=\s*(\S+)", up)
        if m:
            name = m.group(1)
            out[name] = []
        elif up.startswith("*") and not up.startswith(("*SURFACE BEHAVIOR", "*FRICTION")):
            name = None
        elif name is not None:
            out[name].append(up)
    return out


def stop_frictionless(run: Run) -> str:
    """The radial stop is frictionless in every deck as in the reference solver (docs/friction.md): no
    friction or tangential stiffness on the stop's PGAPs (pyNastran), no *FRICTION with mu > 0 in a STOP
    interaction of an inp deck."""
    from pyNastran.bdf.bdf import BDF

    from deckbridge.mesh import build_mesh
    from deckbridge.numbering.nastran import gap_layout
    ran(run)
    if run.model.contact.stop.side == "none" or run.model.contact.friction <= 0:
        return "skipped: no stop or no friction"
    gaps = gap_layout(build_mesh(run.model))
    stop_ids = gaps.eid[gaps.surface == "stop"]
    bdf = BDF(debug=None)
    bdf.read_bdf(str(run.out / "decks" / f"{run.model.name}_penalty.bdf"), xref=False)
    for pid in stop_ids:
        p = bdf.properties[int(pid)]
        assert not (p.mu1 or p.mu2 or p.kt), f"stop PGAP {pid}: MU1 {p.mu1}, MU2 {p.mu2}, KT {p.kt}"
    n = 0
    for deck in sorted((run.out / "decks").glob("*.inp")):
        for name, lines in _interactions(deck.read_text()).items():
            if "STOP" not in name:
                continue
            n += 1
            fr = [lines[i + 1] for i, ln in enumerate(lines[:-1]) if ln.startswith("*FRICTION")]
            mu = [float(f.split(",")[0]) for f in fr]
            assert not any(mu), f"{deck.name} {name}: *FRICTION mu {mu}"
    return f"{stop_ids.size} stop PGAPs, {n} stop interactions"


def analysis_as_asked(run: Run) -> str:
    """Every ccx deck runs the model's analysis: NLGEOM in its *STEP lines exactly when analysis.nlgeom
    (report.caveats.deck_options reads the deck as the report does)."""
    from deckbridge.report.caveats import deck_options
    ran(run)
    decks = sorted((run.out / "ccx").glob("*.inp"))
    for deck in decks:
        got = deck_options(deck)["nlgeom"]
        assert got == run.model.analysis.nlgeom, f"{deck.name}: NLGEOM {got}, analysis.nlgeom {run.model.analysis.nlgeom}"
    return f"{len(decks)} decks"


def _applied(run: Run, lam: float) -> tuple[np.ndarray, np.ndarray]:
    """Applied force and moment about the base centre (0, 0, 0) at load factor ``lam``."""
    lv = run.model.load_vectors()
    f = np.asarray(lv["N_force"], float) + lam * np.asarray(lv["T_force"], float)
    ref = np.array([0.0, 0.0, run.model.geometry.height])
    return f, lam * np.asarray(lv["M_moment"], float) + np.cross(ref, f)


def _nlgeom(run: Run, label: str) -> bool:
    """Whether the analysis of source ``label`` ('ccx/penalty', 'reference/lagrange', ...) is NLGEOM."""
    source = label.split("/")[0]
    return source == "ccx" and bool(run.model.analysis.nlgeom)


def equilibrium(run: Run) -> str:
    """Global equilibrium of N and M (vertical contact forces of every source, every state) against the
    applied loads (moments of NLGEOM decks to the small-strain rotation bound); of T (horizontal) where the output carries every horizontal force: the reference's
    friction forces and stop forces every state (friction cases), the reference reactions at step ends
    (spring cases: the springs' forces are not in contact.csv). force_n: each solver's nodal force (exact in sum and
    moment); ccx f2f on 8-/6-node faces prints none (NaN): its master ring's reaction (ccx_f2f_resultant)."""
    ran(run)
    n = abs(run.model.loads.N)
    scale_m = n * run.model.geometry.radius
    worst = 0.0
    for label, df in run.tables.items():
        # an NLGEOM deck balances its loads on the deformed shape: undeformed arms hold to the rotation
        # (P-delta), bounded in the small-strain range by SMALL_STRAIN['rotation_rad']
        tol_m = SMALL_STRAIN["rotation_rad"] if _nlgeom(run, label) else TOL_FORCE
        fric = read_friction(run.out / f"reference_{label.split('/')[1]}") if label.startswith("ref") else None
        master = ring_resultant(run.out / "ccx", label, df, run.model.steps.lambda_max)
        for step, inc, lam, g in table_state(df):
            f_app, m_app = _applied(run, lam)
            tab = g[g.surface == "table"]
            th = np.radians(tab.theta_deg.to_numpy(float))
            fz = nodal_force(tab)               # the solver's nodal forces: exact in sum and moment
            x, y = tab.r.to_numpy(float) * np.cos(th), tab.r.to_numpy(float) * np.sin(th)
            fm = (fz.sum(), (y * fz).sum(), -(x * fz).sum()) if master is None else master[lam]
            err = {"N": abs(fm[0] + f_app[2]) / n, "Mx": abs(fm[1] + m_app[0]) / scale_m,
                   "My": abs(fm[2] + m_app[1]) / scale_m}
            if fric is not None:
                fr = fric[(fric.step == step) & (fric.increment == inc)]
                st = g[g.surface == "stop"]
                ts = np.radians(st.theta_deg.to_numpy(float))
                sign = 1.0 if run.model.contact.stop.side == "inner" else -1.0
                fh = np.array([fr.ft_x_n.sum(), fr.ft_y_n.sum()]) + sign * np.array(
                    [(st.force_n * np.cos(ts)).sum(), (st.force_n * np.sin(ts)).sum()])
                err["T"] = float(np.abs(fh + f_app[:2]).max()) / n
            bad = {k: v for k, v in err.items() if v > (tol_m if k[0] == "M" else TOL_FORCE)}
            assert not bad, f"{label} step {step} increment {inc} (lambda {lam:g}): residual / N {bad}"
            worst = max(worst, *err.values())
    for method, s in run.summaries.items():
        for step, force in s["reaction_force_n"].items():
            lam = 0.0 if step == "1" else run.model.steps.lambda_max
            res = np.abs(np.asarray(force) + _applied(run, lam)[0]).max() / n
            assert res <= TOL_FORCE, f"reference/{method} step {step}: reaction + applied = {res:.3g} N"
    return f"worst residual {worst:.2g} of N"


def no_free_penetration(run: Run) -> str:
    """No table node penetrates without force (the contact law; quantities.free_penetration_m's thresholds), on the
    gap the row's law constrains (gap_m, quantities.law_gaps): the face-weighted Lagrange's projected gap
    (D g) / D 1 on 8-/6-node faces (reference lagrange and mortar, ccx mortar), whose nodal gap may be < 0 at a
    force-free row (the constraint is weak: -1.7 um hex20r / -6.7 um tet10 at lambda 1)."""
    ran(run)
    r_max = run.model.geometry.radius + run.model.geometry.thickness
    for label, df in run.tables.items():
        for step, inc, lam, g in table_state(df):
            tab = g[g.surface == "table"]
            pen = -tab.gap_m.to_numpy(float)
            free = pressure_force(tab) <= 0             # no pressure (8-node corners pull: force_n < 0 there)
            loaded = pen[~free].max(initial=0.0)
            worst = pen[free].max(initial=0.0)
            assert worst <= max(PENETRATION_FLOOR * r_max, PENETRATION_WARN * loaded), (
                f"{label} lambda {lam:g}: node(s) {tab.node[free & (pen == worst)].tolist()} penetrate "
                f"{worst * 1e3:.3g} mm with no force (loaded nodes: {loaded * 1e3:.3g} mm)")
    return "ok"


def _lift_over_r(df, lam: float, radius: float) -> float:
    g = df[(df.load_factor == lam) & (df.surface == "table")]
    return float(np.maximum(g.gap_m.to_numpy(float), 0).max() / radius)


def _through_wall(g, side: str) -> np.ndarray:
    """Through-wall sigma_N per azimuth [Pa] of joined table rows: Sum sigma_N x area / Sum area (quantities)."""
    w = g.assign(sa=g[f"sigma_n_pa{side}"] * g[f"area_m2{side}"])
    a = w.groupby(np.round(g[f"theta_deg{side}"].to_numpy(float), 6))[["sa", f"area_m2{side}"]].sum()
    return (a["sa"] / a[f"area_m2{side}"]).to_numpy(float)


def ccx_vs_reference(run: Run) -> str:
    """ccx against the reference to 2 % of the peak at every state where the analysis is the same (no
    NLGEOM in the deck: analysis.nlgeom false) and the small-
    strain caveat does not apply (lift/R <= report.caveats.SMALL_STRAIN of the reference).

    Penalty deck vs reference penalty node by node (one nodal law); mortar vs reference Lagrange through the
    wall (sum F / sum A per azimuth), on 8-/6-node faces vs the job's reference/mortar (the Lagrange in ccx's own
    multiplier basis, deckbridge/reference_dual.py; the hat basis differs at the contact edge, docs/mortar_stop.md): mortar's node force integrates N_i p over the faces, spreading a through-
    wall pressure gradient (a cone's, already under N) unlike the nodal law: 1.1-2.1 % node by node, <= 0.83 %
    through the wall (docs/mortar_stop.md). An area-weighted mean never fails where the node values pass.
    Frictionless: ccx f2f vs the reference face-integrated penalty through the wall (docs/ccx_f2f.md); on 8-/6-node
    faces, where ccx's sigma_N is CPRESS (extrapolated) and the reference's the hat-basis projection, two readings
    of one field that differ by up to 25 % of the peak at the contact edge, by the exact contact force on each
    azimuth line of the deck's master ring (ccx's RF, the reference's point forces on the ring's shape functions)
    against the largest line force."""
    ran(run)
    if run.model.analysis.nlgeom:
        return "skipped: NLGEOM decks against the small-strain reference"
    out = []
    mortar = "mortar" if "reference/mortar" in run.tables else "lagrange"   # ccx/mortar's partner in ccx's basis
    pairs = ([] if run.quadratic else [("penalty", "penalty", False)]) + [(mortar, "mortar", True)]
    if "reference/f2f" in run.tables and run.quadratic:      # exact on both sides: the master ring's line forces
        worst, n = 0.0, 0
        for lam, ref, ccx in ring_line_pairs(run):
            lift = _lift_over_r(run.tables["reference/f2f"], lam, run.model.geometry.radius)
            if lift > SMALL_STRAIN["lift_over_radius"]:
                continue
            e = float(np.abs(ref - ccx).max() / np.abs(ref).max())
            assert e <= TOL_CCX, f"ccx/f2f vs reference/f2f at lambda {lam:g}: max |d F| (ring line) / peak = {e:.3%}"
            worst, n = max(worst, e), n + 1
        out.append(f"f2f ring lines {n} states, worst {worst:.3%}")
    elif "reference/f2f" in run.tables:         # face-to-face penalty vs the face-integrated reference penalty
        pairs.append(("f2f", "f2f", True))
    for ref, ccx, wall in pairs:
        r, c = run.tables[f"reference/{ref}"], run.tables[f"ccx/{ccx}"]
        j = r[r.surface == "table"].merge(c[c.surface == "table"], on=["step", "increment", "node"],
                                          suffixes=("_r", "_c"))
        assert len(j) == (c.surface == "table").sum(), f"ccx/{ccx}: table nodes or states do not match the reference"
        worst, n = 0.0, 0
        for (_, _), g in j.groupby(["step", "increment"]):
            lam = float(g.load_factor_r.iloc[0])
            if _lift_over_r(r, lam, run.model.geometry.radius) > SMALL_STRAIN["lift_over_radius"]:
                continue
            d = _through_wall(g, "_r") - _through_wall(g, "_c") if wall else g.sigma_n_pa_r - g.sigma_n_pa_c
            e = float(np.abs(d).max() / np.abs(g.sigma_n_pa_r).max())
            assert e <= TOL_CCX, (f"ccx/{ccx} vs reference/{ref} at lambda {lam:g}: max |d sigma_N| "
                                  f"({'through-wall' if wall else 'node'}) / peak = {e:.3%}")
            worst, n = max(worst, e), n + 1
        out.append(f"{ccx} {n} states, worst {worst:.2%}")
    return "; ".join(out)


def _base_area(run: Run, n_theta: int) -> float:
    """Area of the meshed base: the annulus R -+ t/2 between two regular n_theta-gons (the mesh's facets)."""
    g = run.model.geometry
    return 0.5 * n_theta * np.sin(2 * np.pi / n_theta) * ((g.radius + g.thickness / 2) ** 2
                                                          - (g.radius - g.thickness / 2) ** 2)


_WARN = re.compile(r"warning: lambda = ([-+0-9.eE]+): (.*)")


def warnings_true(run: Run) -> str:
    """Every warning the job prints is true, re-checked from the data: an equilibrium residual against the
    applied N (the base-wall sigma_zz resultant over the whole ring), open-gap tension and force-free
    penetration against the contact table. The sigma_zz resultant is the through-wall mean over every azimuth
    times the area of the meshed base (a regular polygon annulus), against the applied N; on cells with mid-side
    nodes (the wall rows hold the corners only, the faces are curved) the wall table's section force, Sum
    axial_force_n (int sigma_zz dA over every base-face node)."""
    ran(run)
    label, count = None, 0
    n = abs(run.model.loads.N)
    for line in run.lines:
        if not line.startswith(" ") and ": onset" in line:
            label = line.split(":")[0]
            continue
        m = _WARN.search(line)
        if not m:
            continue
        count += 1
        lam, text = float(m.group(1)), m.group(2)
        df = run.tables[label]
        rows = df[np.isclose(df.load_factor, lam, rtol=1e-3, atol=1e-9) & (df.surface == "table")]
        if "sigma_zz equilibrium" in text:
            wall = run.walls.get(label)
            assert wall is not None, f"{label}: warned without a wall table: {line}"
            at = wall[np.isclose(wall.load_factor, lam, rtol=1e-3, atol=1e-9)]
            w = at.groupby("theta_deg").szz_mean_pa.mean()
            if "axial_force_n" in at and np.isfinite(at.axial_force_n).all():
                res = abs(at.groupby("theta_deg").axial_force_n.mean().sum() + n) / n
            else:
                res = abs(w.mean() * _base_area(run, w.size) + n) / n
            assert res > RESIDUAL_WARN, (f"{label}: '{line.strip()}' but the wall's sigma_zz resultant balances "
                                         f"the applied N to {res:.2%}")
        elif "tension" in text:
            s = rows.sigma_n_pa.to_numpy(float)
            ratio = s[rows.status == "open"].max(initial=0.0) / abs(s.min())
            assert ratio > TENSION_WARN, f"{label}: '{line.strip()}' but open tension / peak = {ratio:.2%}"
        elif "penetrate" in text:
            nodes = [int(x) for x in re.findall(r"\d+", text.split("node(s)")[1].split("penetrate")[0])]
            g = rows[rows.node.isin(nodes)]
            assert len(g) and ((g.gap_m < 0) & (g.sigma_n_pa >= 0)).all(), f"{label}: '{line.strip()}' not in the data"
    return f"{count} warnings"


CHECKS = {f.__name__: f for f in (ran, decks_command, decks_read_back, ccx_finished, analysis_as_asked, equilibrium,
                                   no_free_penetration, stop_frictionless, ccx_vs_reference, si_equals_mm, paraview_si_equals_mm,
                                   warnings_true)}


def refused_before_work(overrides: list[str], dialect: str, key: str, folder: Path) -> str:
    """A combination that cannot be supported: the dialect refuses with one line naming ``key`` and no file
    is written; for CalculiX, ``run --with-ccx`` refuses it the same way before any work (no output folder)."""
    from deckbridge.errors import DeckUnsupported
    from deckbridge.job import run_job
    from deckbridge.model import load
    from deckbridge.render import render_all
    model = load(None, ["mesh.n_theta=16", "mesh.n_z=2", "mesh.n_r=1"] + overrides)
    jobs = [lambda: render_all(model, folder / "decks", names=[dialect])]
    if dialect == "calculix":
        jobs.append(lambda: run_job(model, folder / "run", with_ccx=True, echo=lambda s: None))
    for job in jobs:
        try:
            job()
        except DeckUnsupported as exc:
            msg = str(exc)
            assert "\n" not in msg and key in msg, msg
            written = [p for p in folder.rglob("*") if p.is_file()]
            assert not written and not (folder / "run").exists(), f"written before the refusal: {written}"
            continue
        raise AssertionError(f"{dialect}: {overrides} accepted")
    return msg
