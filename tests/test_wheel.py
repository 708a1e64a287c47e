"""The wheel: built from the tree, installed non-editable into a fresh venv outside the checkout, it renders
the same decks and solves to the same liftoff as the checkout (templates and reference_solver ship).

Offline and quick (~10 s): ``pip wheel --no-build-isolation`` with the project venv's setuptools (the
``test`` extra), a venv without pip whose dependencies come from the project venv's site-packages (a
``.pth`` path line), ``pip --python`` to install the wheel into it with ``--no-deps``.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
import sysconfig
import tomllib
from pathlib import Path

import pytest

from deckbridge.model import load
from deckbridge.render import render_all

ROOT = Path(__file__).resolve().parents[1]
SMALL = ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1"]


def _sha(folder: Path) -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir())
            if not p.name.startswith(".")}     # not the output marker (.deckbridge-output)


def test_pyproject_lists_every_package_of_the_tree():
    listed = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    tree = {".".join(p.parent.relative_to(ROOT).parts) for pkg in ("deckbridge", "reference_solver")
            for p in (ROOT / pkg).rglob("__init__.py")}
    assert tree | {"deckbridge.data", "deckbridge.templates"} == listed


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """(bin folder of a fresh venv holding the installed wheel, a work folder outside the checkout)."""
    tmp = tmp_path_factory.mktemp("wheel")
    src = tmp / "src"
    src.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, src / name)
    for pkg in ("deckbridge", "reference_solver", "templates"):
        shutil.copytree(ROOT / pkg, src / pkg, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    pip = [sys.executable, "-m", "pip", "-q", "--disable-pip-version-check"]
    subprocess.run(pip + ["wheel", "--no-deps", "--no-build-isolation", "--no-index", "-w", str(tmp / "dist"),
                          str(src)], check=True, cwd=tmp, env=env, capture_output=True)
    (wheel,) = (tmp / "dist").glob("deckbridge-*.whl")
    venv = tmp / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True, env=env)
    py = venv / "bin" / "python"
    site = subprocess.run([py, "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"], check=True,
                          capture_output=True, text=True).stdout.strip()
    Path(site, "project_deps.pth").write_text(sysconfig.get_path("purelib") + "\n")
    subprocess.run(pip + ["--python", str(py), "install", "--no-deps", "--no-index", str(wheel)], check=True,
                   env=env, capture_output=True)
    work = tmp / "work"
    work.mkdir()
    return venv / "bin", work, env


def test_installed_package_is_the_wheel_not_the_checkout(installed):
    bindir, work, env = installed
    where = subprocess.run([bindir / "python", "-c", "import deckbridge, reference_solver, deckbridge.templates as t;"
                            "print(deckbridge.__file__); print(reference_solver.__file__); print(t.__file__)"],
                           cwd=work, env=env, check=True, capture_output=True, text=True).stdout.split()
    assert all(str(bindir.parent) in w and str(ROOT) not in w for w in where)


def test_wheel_renders_the_decks_of_the_checkout(installed, tmp_path):
    bindir, work, env = installed
    sets = [a for s in SMALL for a in ("--set", s)]
    subprocess.run([bindir / "deckbridge", "decks", *sets, "-o", "decks"], cwd=work, env=env, check=True,
                   capture_output=True)
    render_all(load(None, SMALL), tmp_path / "decks")
    assert len(_sha(work / "decks")) == 9     # 8 decks (Abaqus: Lagrange, augmented; ccx: penalty, mortar, face-to-face) and the model VTU
    assert _sha(work / "decks") == _sha(tmp_path / "decks")


def test_wheel_solves_to_the_liftoff_of_the_checkout(installed, tmp_path):
    """Both in fresh processes (an earlier test in this process may have changed BLAS threading, which
    moves the last digits)."""
    bindir, work, env = installed
    sets = [a for s in SMALL for a in ("--set", s)]
    summaries = []
    for exe, out in ((bindir / "deckbridge", work / "solved"), (Path(sys.executable).parent / "deckbridge",
                                                               tmp_path / "solved")):
        subprocess.run([exe, "solve", *sets, "--method", "penalty", "-o", out], cwd=out.parent, env=env,
                       check=True, capture_output=True)
        summaries.append(json.loads((out / "summary.json").read_text()))
    assert summaries[0]["liftoff_load_factor"] is not None
    assert summaries[0]["liftoff_load_factor"] == summaries[1]["liftoff_load_factor"]
    assert summaries[0]["min_sigma_n_pa"] == summaries[1]["min_sigma_n_pa"]
