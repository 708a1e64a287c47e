"""mesh.file and the files it names follow issue 13's rules for the model file (issue 15 on main):
relative to the model file, a regular non-empty file of bounded size, no control characters in the
name; node-id list files and .bdf INCLUDEs stay in the mesh file's folder; the memory check counts the
imported mesh's nodes. Each refusal is one line naming the key and the value."""

import os

import numpy as np
import pytest

from deckbridge import limits
from deckbridge.errors import InputError
from deckbridge.importers import spec
from deckbridge.mesh import build_mesh
from deckbridge.model import ModelError, load
from gmsh_skirt import write_bdf, write_inp
from test_import_checks import N, _ring

SETS = "mesh.sets={base: BASE, top: TOP}"


def _inp(path):
    ids, xyz, eids, conn = _ring()
    return write_inp(path, ids, xyz, eids, conn, {"BASE": ids[: 2 * N], "TOP": ids[2 * N:]})


def _refused(args, pattern, path=None):
    with pytest.raises(ModelError, match=pattern) as err:
        load(path, args)
    assert "\n" not in str(err.value)
    return err.value


def test_mesh_file_is_relative_to_the_model_file_not_the_working_folder(tmp_path, monkeypatch):
    (tmp_path / "models").mkdir()
    _inp(tmp_path / "models" / "ring.inp")
    model_file = tmp_path / "models" / "ring.yaml"
    model_file.write_text("mesh:\n  file: ring.inp\n  sets: {base: BASE, top: TOP}\n")
    monkeypatch.chdir(tmp_path)                       # ring.inp is not in the working folder
    m = load(model_file)
    assert m.mesh.file == str(tmp_path / "models" / "ring.inp")
    assert build_mesh(m).table.nodes.size == 2 * N


def test_mesh_file_must_be_a_regular_non_empty_bounded_file(tmp_path, monkeypatch):
    (tmp_path / "folder.inp").mkdir()
    _refused([f"mesh.file={tmp_path / 'folder.inp'}", SETS], r"mesh.file = .*folder.inp.*is a folder")
    os.mkfifo(tmp_path / "pipe.inp")
    _refused([f"mesh.file={tmp_path / 'pipe.inp'}", SETS], r"mesh.file = .*not a regular file")
    (tmp_path / "empty.inp").write_text("")
    _refused([f"mesh.file={tmp_path / 'empty.inp'}", SETS], r"mesh.file = .*is empty")
    _refused([f"mesh.file={tmp_path / 'none.inp'}", SETS], r"mesh.file = .*cannot read file")
    f = _inp(tmp_path / "ring.inp")
    monkeypatch.setattr(spec, "MAX_MESH_BYTES", os.path.getsize(f) - 1)
    _refused([f"mesh.file={f}", SETS], rf"{os.path.getsize(f)} bytes: at most {os.path.getsize(f) - 1} bytes")


def test_mesh_file_name_with_a_control_character_is_refused(tmp_path):
    e = _refused({"mesh.file": str(tmp_path / "a\nb.inp"), "mesh.sets": {"base": "B", "top": "T"}},
                 "without control characters")
    assert "\\n" in str(e)


def test_node_list_files_and_includes_stay_in_the_mesh_folder(tmp_path):
    ids, xyz, eids, conn = _ring()
    (tmp_path / "sub").mkdir()
    f = write_bdf(tmp_path / "sub" / "ring.bdf", ids, xyz, eids, conn, {})
    (tmp_path / "sub" / "base.txt").write_text(" ".join(str(i) for i in ids[: 2 * N]))
    (tmp_path / "sub" / "top.txt").write_text("\n".join(str(i) for i in ids[2 * N:]))
    (tmp_path / "top_outside.txt").write_text("\n".join(str(i) for i in ids[2 * N:]))
    ok = build_mesh(load(None, [f"mesh.file={f}", "mesh.sets={base: base.txt, top: top.txt}"]))
    assert ok.table.nodes.size == 2 * N
    with pytest.raises(ModelError, match=r"mesh.sets.top = '../top_outside.txt': must be a file in the mesh"):
        build_mesh(load(None, [f"mesh.file={f}", "mesh.sets={base: base.txt, top: ../top_outside.txt}"]))
    (tmp_path / "sub" / "bad.txt").write_text("1 2 x3")
    with pytest.raises(ModelError, match=r"mesh.sets.top = 'bad.txt': a node-id list file holds integers"):
        build_mesh(load(None, [f"mesh.file={f}", "mesh.sets={base: base.txt, top: bad.txt}"]))
    text = f.read_text()
    f.write_text(text.replace("BEGIN BULK", "BEGIN BULK\nINCLUDE '../outside.bdf'", 1))
    (tmp_path / "outside.bdf").write_text("$ nothing\n")
    with pytest.raises(ModelError, match=r"mesh.file = '../outside.bdf': must be a file in the mesh"):
        build_mesh(load(None, [f"mesh.file={f}", "mesh.sets={base: base.txt, top: top.txt}"]))


def test_memory_check_counts_the_imported_nodes(tmp_path, monkeypatch):
    m = load(None, [f"mesh.file={_inp(tmp_path / 'ring.inp')}", SETS])
    monkeypatch.delenv(limits.ALLOW_ENV, raising=False)
    need = limits.check_memory(m)
    assert need == pytest.approx(limits.quick_estimate(m, 3 * 4 * N))   # 4 N nodes, 3 dof each
    monkeypatch.setattr(limits, "available_bytes", lambda: 1e6)
    with pytest.raises(InputError, match=rf"mesh .*ring.inp: {3 * 4 * N} dofs need about"):
        limits.check_memory(m)
