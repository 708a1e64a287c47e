"""The import graph of deckbridge and reference_solver, read with ``ast`` (function-level imports too).

Edges: ``import a.b`` and ``from a import b`` (to the module ``a.b`` when it is one, else to ``a``),
relative imports resolved; a package's ``__init__`` is the node of the package (its re-exports are
edges from the package). Imports by name at run time (``importlib.import_module``, the dialect table's
``"module:attr"`` strings) are not edges: that is how registries stay leaves.
"""

from __future__ import annotations

import ast
import functools
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("deckbridge", "reference_solver")


def modules() -> dict[str, Path]:
    """Module name -> source file, for every module of the two packages."""
    out = {}
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            parts = list(path.relative_to(ROOT).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            out[".".join(parts)] = path
    return out


def _known(name: str, mods: dict) -> str | None:
    """``name`` or its nearest enclosing module that exists."""
    while name and name not in mods:
        name = name.rpartition(".")[0]
    return name or None


@functools.lru_cache(maxsize=1)
def edges() -> frozenset[tuple[str, str]]:
    mods = modules()
    out = set()
    for name, path in mods.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            targets = []
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")[:len(package.split(".")) - (node.level - 1)]
                    target = ".".join(base + ([node.module] if node.module else []))
                else:
                    target = node.module or ""
                targets = [f"{target}.{a.name}" if f"{target}.{a.name}" in mods else target for a in node.names]
            for t in targets:
                k = _known(t, mods)
                if k and k != name:
                    out.add((name, k))
    return frozenset(out)


def cycles(graph_edges: set[tuple[str, str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan), each sorted."""
    succ: dict[str, list[str]] = {}
    for a, b in graph_edges:
        succ.setdefault(a, []).append(b)
        succ.setdefault(b, [])
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(succ[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(succ):
        if v not in index:
            visit(v)
    return out


def test_graph_sees_function_level_and_relative_imports():
    e = edges()
    assert ("deckbridge.dialects.calculix.render", "deckbridge.numbering.inp") in e  # module level, relative
    assert ("deckbridge.job", "deckbridge.errors") in e                             # inside a function
    assert ("deckbridge.render", "deckbridge.dialects") in e                        # a package's __init__
    # a two-module cycle is found
    assert cycles({("a", "b"), ("b", "a"), ("b", "c")}) == [["a", "b"]]


def test_no_import_cycle_between_modules_of_deckbridge():
    assert cycles(edges()) == []


def test_readers_never_import_render():
    bad = sorted((a, b) for a, b in edges()
                 if a.startswith("deckbridge.readers") and b.startswith("deckbridge.render"))
    assert bad == []


def test_reference_solver_imports_nothing_from_deckbridge():
    bad = sorted((a, b) for a, b in edges() if a.startswith("reference_solver") and b.startswith("deckbridge"))
    assert bad == []


def test_registry_and_records_are_leaves():
    """The registry imports only the record types; each dialect's record only them (its parts by name)."""
    from deckbridge.dialects import NAMES
    e = edges()
    assert sorted(b for a, b in e if a == "deckbridge.dialects._record") == []
    for node in ["deckbridge.dialects"] + [f"deckbridge.dialects.{n}" for n in NAMES]:
        assert sorted(b for a, b in e if a == node) == ["deckbridge.dialects._record"], node


@pytest.mark.parametrize("pkg", ["deckbridge.render", "deckbridge.readers"])
def test_registered_modules_do_not_import_their_package_back(pkg):
    assert sorted(a for a, b in edges() if b == pkg and a.startswith(pkg + ".")) == []


# --- folders: one layer order, no back-arrows -------------------------------------------------------
# A folder is a package of deckbridge (deckbridge/render/, deckbridge/dialects/calculix/, ...); a module at
# the top of deckbridge/ (model.py, job.py, ...) counts as its own folder. Bottom to top: a folder imports
# folders of its own layer or below, never above, and no two folders import each other (directly or round
# a loop). Every dialect folder deckbridge/dialects/<name>/ is in the "dialects" layer; the registry
# deckbridge/dialects/ (its __init__ and the record types) is a leaf at the bottom.
LAYERS = {
    "base": ["errors", "azimuth", "jsonable", "textsafe", "units", "safe_yaml", "results", "quantities",
             "mesh_data", "supports", "friction_table", "tangent_springs", "dialects", "summary_keys", "base_wall",
             "api_callable", "methods", "deck_elements", "face_areas"],
    "model": ["model_fields", "overrides", "outdir", "importers", "model", "mesh", "mesh_order", "numbering",
              "imported_model"],
    "outputs": ["render", "readers", "paraview", "wall_stress", "solve", "reference_f2f", "reference_dual", "onset_basis", "limits",
                "compare", "report"],
    "dialects": ["dialects.*"],
    "jobs": ["job", "studies", "model_reference"],
    "entry": ["cli", "deckbridge", "api", "api_results", "api_studies", "contact_results"],        # the command line and the package's public face
}


def folder_of(module: str, mods: dict) -> str | None:
    """The folder (layer unit) of a deckbridge module, without the ``deckbridge.`` prefix."""
    if not module.startswith("deckbridge"):
        return None
    pkg = module if mods[module].name == "__init__.py" else module.rpartition(".")[0]
    unit = module if pkg == "deckbridge" else pkg
    return "deckbridge" if unit == "deckbridge" else unit[len("deckbridge."):]


def layer_of(folder: str) -> int:
    for i, members in enumerate(LAYERS.values()):
        if folder in members or (folder.startswith("dialects.") and "dialects.*" in members):
            return i
    raise AssertionError(f"folder {folder!r} is in no layer of tests/test_import_graph.py LAYERS: place it")


def folder_edges() -> set[tuple[str, str]]:
    mods = modules()
    out = set()
    for a, b in edges():
        fa, fb = folder_of(a, mods), folder_of(b, mods)
        if fa and fb and fa != fb:
            out.add((fa, fb))
    return out


def test_folders_import_only_their_layer_or_below():
    names = list(LAYERS)
    up = sorted(f"{a} ({names[layer_of(a)]}) -> {b} ({names[layer_of(b)]})"
                for a, b in folder_edges() if layer_of(b) > layer_of(a))
    assert up == []


def test_no_two_folders_import_each_other():
    assert cycles(folder_edges()) == []


def test_every_folder_has_a_layer():
    mods = modules()
    for m in mods:
        if m.startswith("deckbridge"):
            layer_of(folder_of(m, mods))


def test_layer_check_sees_a_back_arrow():
    assert layer_of("cli") > layer_of("readers") > layer_of("model") > layer_of("errors")
    assert layer_of("dialects.calculix") > layer_of("render") and layer_of("dialects") == 0
    assert cycles({("report", "studies"), ("studies", "report")}) == [["report", "studies"]]


MAX_LINES = 400


def test_no_module_exceeds_400_lines():
    long = sorted(f"{p.relative_to(ROOT)}: {n}" for p in modules().values()
                  if (n := len(p.read_text().splitlines())) > MAX_LINES)
    assert long == []


def test_every_import_of_a_module_of_the_two_packages_names_one_that_exists():
    """``from .x import y`` inside the packages names a module x that exists (a moved module leaves none
    behind: the graph above would otherwise count the edge to the enclosing package and see nothing)."""
    mods = modules()
    bad = []
    for name, path in mods.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.ImportFrom) and node.module:
                if node.level:
                    base = package.split(".")[:len(package.split(".")) - (node.level - 1)]
                    target = ".".join(base + [node.module])
                else:
                    target = node.module
                if target.split(".")[0] in PACKAGES and target not in mods:
                    bad.append(f"{name}: from {'.' * node.level}{node.module}")
    assert bad == []
