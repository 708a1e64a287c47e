"""The sweep report read back as HTML: one cell per header cell in every table, and the first liftoff it
names is the one of summary.json (issue 21.8)."""

import json
from html import escape
from html.parser import HTMLParser

import pytest

from deckbridge.model import load
from deckbridge.studies import run_sweep

# a fixed k_t: the Lagrange reference keeps finite springs, and its sigma_N is not linear in lambda
# between the states around its onset: an estimate from the states is not the solver's onset
TINY = ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1", "steps.increments=5", "contact.penalty.k_tangent=2e8"]


class _Tables(HTMLParser):
    """Every <table> of a page as a list of rows, each row a list of (tag, text) cells; and the <h3> texts."""

    def __init__(self):
        super().__init__()
        self.tables, self.h3, self._cell, self._in_h3 = [], [], None, False

    def handle_starttag(self, tag, attrs):
        if tag == "table":
            self.tables.append([])
        elif tag == "tr":
            self.tables[-1].append([])
        elif tag in ("td", "th"):
            self._cell = [tag, ""]
        elif tag == "h3":
            self._in_h3 = True
            self.h3.append("")

    def handle_endtag(self, tag):
        if tag in ("td", "th"):
            self.tables[-1][-1].append(tuple(self._cell))
            self._cell = None
        elif tag == "h3":
            self._in_h3 = False

    def handle_data(self, data):
        if self._cell is not None:
            self._cell[1] += data
        if self._in_h3:
            self.h3[-1] += data


def test_sweep_report_tables_have_one_cell_per_header_and_the_first_liftoff_of_summary_json(tmp_path):
    """Issue 21.8: the per-lambda tables had 6 header cells over 10 cells per row, and the first liftoff
    of their headings (here 0.5476, the comparator's estimate from the states) was not summary.json's
    (0.5195, the solver's)."""
    out = tmp_path / "s"
    run_sweep(load(None, TINY), [1.0, 100.0], out, progress=False, report=True)
    html = (out / "report.html").read_text(encoding="utf-8")
    page = _Tables()
    page.feed(html)
    assert len(page.tables) >= 5
    for t in page.tables:
        head, *rows = t
        assert {tag for tag, _ in head} == {"th"} and rows, head
        assert all(len(r) == len(head) for r in rows), ([c for _, c in head], [len(r) for r in rows])
    summary = json.loads((out / "summary.json").read_text())
    ref = summary["lagrange_reference"]                 # what summary.json says the reference is, in the report
    assert "same circumferential springs, k_t = 2e+08 N/m" in ref and f"Lagrange reference: {escape(ref)}." in html
    m = summary["meshes"][0]
    first = min([m["lagrange"]["liftoff_load_factor"]] + [d["liftoff_load_factor"] for d in m["penalty"]])
    lifts = [h for h in page.h3 if "first liftoff" in h]
    assert len(lifts) == 1 and lifts[0].endswith(f"(lambda = {first:.4g})"), (lifts, first)
    # the same onsets, under the same name, in the mesh table
    mesh_table = next(t for t in page.tables if t[0][0][1] == "case" and len(t[0]) == 12
                      and t[0][8][1] == "onset: first node λ")
    got = {r[0][1]: float(r[8][1]) for r in mesh_table[1:]}
    assert got["Lagrange"] == pytest.approx(m["lagrange"]["liftoff_load_factor"], abs=5e-5)
    for d in m["penalty"]:
        assert got[f"penalty k = {d['k_factor']:g}"] == pytest.approx(d["liftoff_load_factor"], abs=5e-5)
