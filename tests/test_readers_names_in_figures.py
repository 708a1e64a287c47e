"""User text reaches the report's figures as text, never as matplotlib mathtext (issue 26: a source or method
name holding ``$\\frac{`` in a CSV ended ``compare`` in "ValueError (unexpected)").

Through ``compare`` in-process: two plain CSV exports whose source and method columns hold mathtext
fragments, compared with each other. The report is written and the names appear in it (HTML-escaped)."""

import html
import json

import pytest
from click.testing import CliRunner

from deckbridge.cli import main

NAMES = [r"$\frac{", r"$x$\frac{1}{0}$", "a$b$c$", r"$\sqrt{$", "$$", r"\$"]


def _csv(path, source, method, scale):
    rows = "\n".join(f'{t},{-scale * (1 + (t % 180) / 90)},"{source}","{method}"' for t in range(0, 360, 30))
    path.write_text("theta [deg],sigma_n_pa,source,method\n" + rows + "\n")
    return path


@pytest.mark.parametrize("name", NAMES)
def test_compare_draws_mathtext_names_as_text(tmp_path, name):
    a = _csv(tmp_path / "a.csv", name, "m" + name, 1e6)
    b = _csv(tmp_path / "b.csv", "plain", name + "2", 2e6)
    out = tmp_path / "out"
    res = CliRunner().invoke(main, ["compare", str(a), str(b), "-o", str(out)])
    assert res.exit_code == 0, res.output
    assert res.exception is None or isinstance(res.exception, SystemExit)
    assert (out / "sigma_n.png").stat().st_size > 0
    page = (out / "report.html").read_text()
    assert html.escape(f"{name}/m{name}", quote=False) in page or html.escape(f"{name}/m{name}") in page
    assert f"{name}/m{name}" in json.loads((out / "summary.json").read_text())["global"]
