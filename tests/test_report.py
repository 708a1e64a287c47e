"""The report: four files written whole, a self-contained HTML that headless Chromium opens without
script errors, with every embedded PNG decoded and the sigma_N figure drawn (not blank), global
results read from reference folders, and file-borne text escaped."""

import base64
import io
import json
import re
import shutil
import subprocess
import tempfile

import numpy as np
import pandas as pd
import pytest
from PIL import Image

from deckbridge.compare import compare_tables
from deckbridge.readers.reference import global_metrics, read_source
from deckbridge.report import write_report
from deckbridge.results import COLUMNS, REQUIRED, conform

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run", "--window-size=1200,2000"]


def table(method, scale, n_theta=24, lams=(0.5, 1.0)):
    """Step 1 + step 2 on a ring: sigma = scale * (-10 + 16 lam cos theta) MPa."""
    th = 360.0 * np.arange(n_theta) / n_theta
    rows = []
    for step, inc, lam in [(1, 1, 0.0)] + [(2, k, l) for k, l in enumerate(lams, 1)]:
        s = scale * 1e6 * (-10 + 16 * lam * np.cos(np.radians(th)))
        rows += [("reference", method, step, inc, lam, j + 1, "table", th[j], 0.0, 1.5, s[j], 0.0,
                  "open" if s[j] > 0 else "closed") for j in range(n_theta)]
    return conform(pd.DataFrame(rows, columns=REQUIRED))


def _write_vtu(path, model):
    """result.vtu on the model's mesh: base ring u_z = 1 mm cos(theta), von Mises 100 MPa (1 - cos(theta)) / 2."""
    import meshio
    from deckbridge.mesh import build_mesh
    mesh = build_mesh(model)
    th = np.arctan2(mesh.nodes[:, 1], mesh.nodes[:, 0])
    u = np.zeros_like(mesh.nodes)
    u[:, 2] = np.where(mesh.nodes[:, 2] == 0.0, 1e-3 * np.cos(th), 0.0)
    vm = 1e8 * (1 - np.cos(th)) / 2
    meshio.write(path, meshio.Mesh(mesh.nodes, [("hexahedron", mesh.hexes)],
                                   point_data={"displacement": u, "von_mises": vm}))


@pytest.fixture
def report(tmp_path, small_model):
    """Two reference folders (one with global results in summary.json), compared and reported."""
    pen, lag = tmp_path / "pen", tmp_path / "lag"
    for folder, method, scale in ((pen, "penalty", 1.0), (lag, "lagrange<script>", 0.8)):
        folder.mkdir()
        table(method, scale).to_csv(folder / "contact.csv", index=False)
    (pen / "summary.json").write_text(json.dumps({"method": "penalty", "max_von_mises_pa": 1.25e8,
                                                  "max_displacement_m": 2.5e-3}))
    (lag / "summary.json").write_text("{}")
    _write_vtu(pen / "result.vtu", small_model)
    res = compare_tables([read_source(pen), read_source(lag)])
    out = tmp_path / "out"
    paths = write_report(res, out, model=small_model)
    return res, out, paths


def test_report_files_and_their_content(report):
    res, out, paths = report
    assert [p.name for p in paths] == ["report.html", "sigma_n.png", "discrepancy.csv", "summary.json"]
    assert sorted(p.name for p in out.iterdir()) == sorted(p.name for p in paths)   # no staging left over
    text = (out / "report.html").read_text()
    # self-contained: no resource fetched from anywhere
    assert not re.search(r"""(src|href)\s*=\s*["']?(https?:|//|file:)""", text)
    pngs = re.findall(r'src="data:image/png;base64,([A-Za-z0-9+/=]+)"', text)
    n_path = 2 + 2 * len(res.points)             # load path, status map; centred and through-wall per point
    assert len(pngs) == len(res.points) + 2 + n_path   # headline + one per load factor + load path + global
    assert text.count('<img class="path"') == n_path
    for b64 in re.findall(r'<img class="figure"[^>]*src="data:image/png;base64,([A-Za-z0-9+/=]+)"', text):
        assert Image.open(io.BytesIO(base64.b64decode(b64))).size == (990, 528)
    assert text.count('<img class="global"') == 1
    assert (out / "sigma_n.png").read_bytes() == base64.b64decode(pngs[0])
    # file-borne text is escaped, never markup
    assert "lagrange<script>" not in text and "lagrange&lt;script&gt;" in text
    # global level: from the penalty folder's summary.json; the other has none
    s = json.loads((out / "summary.json").read_text())
    assert s["global"]["reference/penalty"] == {"max_von_mises_pa": 1.25e8, "max_displacement_m": 2.5e-3,
                                                "from": "summary.json"}
    assert s["global"]["reference/lagrange<script>"] is None
    assert "125.000" in text and "not available for this source" in text
    assert s["model"]["mesh"]["n_theta"] == 16
    # liftoff: -10 + 16 lam cos(0) = 0 at lam = 0.625, interpolated between the increments 0.5 and 1
    onset = s["sources"]["reference/penalty"]["onset_first_node"]
    assert onset["interpolated"] == pytest.approx(0.625) and onset["bracket"] == [0.5, 1.0] and onset["exact"] is None


def test_global_metrics_from_a_result_vtu(tmp_path):
    """Without numbers in summary.json, max von Mises and max |u| come from result.vtu, at its last step
    (fields named per step as the reference solver writes them; step 1 deliberately larger)."""
    import meshio
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    u2 = np.array([[0, 0, 0], [3e-3, 4e-3, 0], [0, 0, -1e-3], [0, 0, 0]], float)
    meshio.write(tmp_path / "result.vtu", meshio.Mesh(
        pts, [("tetra", np.array([[0, 1, 2, 3]]))],
        point_data={"displacement_step1_m": 10 * u2, "displacement_step2_m": u2},
        cell_data={"von_mises_step1_pa": [np.array([9e8])], "von_mises_step2_pa": [np.array([2e8])]}))
    (tmp_path / "summary.json").write_text(json.dumps({"method": "penalty", "n_iterations": 7}))
    g = global_metrics(tmp_path / "contact.csv", "penalty")
    assert g == {"max_von_mises_pa": 2e8, "max_displacement_m": pytest.approx(5e-3), "from": "result.vtu"}
    assert global_metrics(tmp_path / "elsewhere" / "x.dat") == {}


def _chromium(*args, timeout=60):
    with tempfile.TemporaryDirectory() as profile:
        return subprocess.run([CHROMIUM, *FLAGS, f"--user-data-dir={profile}", *args],
                              capture_output=True, text=True, timeout=timeout)


@pytest.mark.skipif(CHROMIUM is None, reason="chromium not installed (scripts/bootstrap.sh installs it)")
def test_report_opens_in_headless_chromium_and_shows_the_figure(report, tmp_path):
    res, out, _ = report
    url = (out / "report.html").resolve().as_uri()
    dom = _chromium("--dump-dom", url)
    assert dom.returncode == 0, dom.stderr[-2000:]
    body = re.search(r"<body([^>]*)>", dom.stdout).group(1)
    attrs = dict(re.findall(r'data-([a-z-]+)="([^"]*)"', body))
    n_img = len(res.points) + 2 + 2 + 2 * len(res.points)
    assert attrs["images"] == f"{n_img}/{n_img}"            # every <img> loaded and decoded
    assert attrs["errors"] == "0"                           # no script error on the page
    assert dom.stdout.count('src="data:image/png;base64,') == n_img
    x, y, w, h = (int(v) for v in attrs["figure-rect"].split(","))
    assert w > 500 and h > 250 and y + h <= 2000

    shot = tmp_path / "shot.png"
    r = _chromium(f"--screenshot={shot}", url)
    assert r.returncode == 0 and shot.is_file(), r.stderr[-2000:]
    img = np.asarray(Image.open(shot).convert("RGB"), dtype=int)
    fig = img[y:y + h, x:x + w]
    ink = (fig.min(axis=2) < 235).mean()
    assert ink > 0.05                                       # drawn, not blank
    # the penalty curve's colour (tab blue #1f77b4) is on screen inside the figure
    blue = (np.abs(fig - np.array([0x1f, 0x77, 0xb4])).max(axis=2) < 40).sum()
    assert blue > 200
    outside = img[y + h + 5:y + h + 60, x:x + w]            # below the figure: the tables, mostly white
    assert (outside.min(axis=2) < 235).mean() < ink
