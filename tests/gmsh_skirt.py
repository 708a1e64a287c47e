"""An independent skirt mesh made with the Gmsh Python API (structured, transfinite hexahedra), written
to .msh (Gmsh), .inp and .bdf (plain writers here, Gmsh's numbering kept) with node sets BASE and TOP."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np


def gmsh_skirt(outdir: Path, R=1.5, t=0.02, H=2.0, n_theta=48, n_z=6, n_r=1):
    """Mesh the tube R -+ t/2, 0 <= z <= H [m] with Gmsh: a transfinite, recombined (r, z) rectangle
    revolved about z in four 90 deg quarters with n_theta/4 layers each, duplicates merged. Returns the
    paths {'msh', 'inp', 'bdf'} and Gmsh's arrays (node ids, xyz, element ids, hexahedra, sets).

    Gmsh runs in a child process: its shared library (OpenGL, OpenMP) loaded into the test process made
    the interpreter crash at exit (segmentation fault after every test had passed)."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    args = json.dumps({"outdir": str(outdir), "R": R, "t": t, "H": H, "n_theta": n_theta, "n_z": n_z, "n_r": n_r})
    subprocess.run([sys.executable, __file__, args], check=True, timeout=300)
    a = np.load(outdir / "gmsh_arrays.npz")
    tags, xyz, conn, eids = a["tags"], a["xyz"], a["conn"], a["eids"]
    sets = {"BASE": a["BASE"], "TOP": a["TOP"]}
    msh = outdir / "skirt.msh"
    nids = np.asarray(tags, np.int64)
    xyz = np.asarray(xyz, float).reshape(-1, 3)
    used = np.unique(conn)
    keep = np.isin(nids, used)
    return {"msh": msh, "inp": write_inp(outdir / "skirt.inp", nids[keep], xyz[keep], eids, conn, sets),
            "bdf": write_bdf(outdir / "skirt.bdf", nids[keep], xyz[keep], eids, conn, sets),
            "node_ids": nids[keep], "xyz": xyz[keep], "elem_ids": eids, "conn": conn, "sets": sets}


def _skirt_model(gmsh, R, t, H, n_theta, n_z, n_r, top_radius=None, scale=1.0, recombine=True,
                 recombine_section=None) -> dict:
    """The Gmsh model of :func:`gmsh_skirt` (geometry, transfinite meshing constraints, physical groups
    SKIRT (volumes), BASE and TOP (faces)), not yet meshed: R, t, H [m], ``top_radius`` the mid-wall radius at the
    top (a cone: the revolved section is a parallelogram; None: R), coordinates times ``scale`` (1000: mm).
    ``recombine`` False: the section is meshed in triangles and revolved into tetrahedra (Gmsh splits each
    extruded prism into three); ``recombine_section`` (default: ``recombine``) False with ``recombine`` True:
    triangles revolved into prisms. Returns the physical group tags {'BASE': tag, 'TOP': tag}."""
    s, rt = scale, (R if top_radius is None else top_radius)
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("skirt")
    geo = gmsh.model.geo
    p = [geo.addPoint(s * (R - t / 2), 0, 0), geo.addPoint(s * (R + t / 2), 0, 0),
         geo.addPoint(s * (rt + t / 2), 0, s * H), geo.addPoint(s * (rt - t / 2), 0, s * H)]
    lines = [geo.addLine(p[i], p[(i + 1) % 4]) for i in range(4)]
    loop = geo.addCurveLoop(lines)
    surf = geo.addPlaneSurface([loop])
    for ln, n in zip(lines, (n_r, n_z, n_r, n_z)):
        geo.mesh.setTransfiniteCurve(ln, n + 1)
    geo.mesh.setTransfiniteSurface(surf)
    if recombine if recombine_section is None else recombine_section:
        geo.mesh.setRecombine(2, surf)
    vols, bottoms, tops = [], [], []
    cur = (2, surf)
    for q in range(4):   # revolve in 4 quarters (one revolution of 360 deg is not allowed)
        out = geo.revolve([cur], 0, 0, 0, 0, 0, 1, np.pi / 2, numElements=[n_theta // 4], recombine=recombine)
        vols.append(out[1][1])
        # the lateral surfaces from lines[0] (bottom) and lines[2] (top)
        bottoms.append(out[2][1])
        tops.append(out[4][1])
        cur = out[0]
    geo.synchronize()
    gmsh.model.geo.removeAllDuplicates()
    geo.synchronize()
    gmsh.model.addPhysicalGroup(3, vols, name="SKIRT")
    return {name: gmsh.model.addPhysicalGroup(2, faces, name=name) for name, faces in (("BASE", bottoms),
                                                                                        ("TOP", tops))}


def _mesh_in_this_process(outdir: Path, R, t, H, n_theta, n_z, n_r, written=False) -> None:
    """The Gmsh part of :func:`gmsh_skirt`: writes skirt.msh and gmsh_arrays.npz into ``outdir``; with
    ``written`` (:func:`gmsh_written`) also the other files of :data:`GMSH_FILES`."""
    import gmsh
    gmsh.initialize(["-noenv"])
    try:
        _skirt_model(gmsh, R, t, H, n_theta, n_z, n_r)
        gmsh.model.mesh.generate(3)
        gmsh.model.mesh.removeDuplicateNodes()
        if written:
            gmsh.option.setNumber("Mesh.SaveGroupsOfNodes", 1)
            gmsh.option.setNumber("Mesh.MshFileVersion", 2.2)
            gmsh.write(str(outdir / GMSH_FILES["msh22"]))
            gmsh.write(str(outdir / GMSH_FILES["inp"]))
            gmsh.option.setNumber("Mesh.SaveElementTagType", 2)   # .bdf: property id = physical group tag
            gmsh.write(str(outdir / GMSH_FILES["bdf"]))
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        msh = outdir / "skirt.msh"
        gmsh.write(str(msh))
        tags, xyz, _ = gmsh.model.mesh.getNodes()
        etypes, etags, enodes = gmsh.model.mesh.getElements(3)
        assert list(etypes) == [5], etypes        # 5 = 8-node hexahedron
        conn = np.asarray(enodes[0], np.int64).reshape(-1, 8)
        eids = np.asarray(etags[0], np.int64)
        sets = {}
        for name in ("BASE", "TOP"):
            tag = [t for d, t in gmsh.model.getPhysicalGroups(2) if gmsh.model.getPhysicalName(2, t) == name][0]
            sets[name] = np.asarray(gmsh.model.mesh.getNodesForPhysicalGroup(2, tag)[0], np.int64)
    finally:
        gmsh.finalize()
    np.savez(Path(outdir) / "gmsh_arrays.npz", tags=np.asarray(tags, np.int64), xyz=np.asarray(xyz, float),
             conn=conn, eids=eids, BASE=sets["BASE"], TOP=sets["TOP"])


def write_inp(path, nids, xyz, eids, conn, sets, etype="C3D8"):
    lines = ["*NODE"] + [f"{i}, {x!r}, {y!r}, {z!r}" for i, (x, y, z) in zip(nids, xyz)]
    lines += [f"*ELEMENT, TYPE={etype}, ELSET=SKIRT"] + [", ".join(map(str, [e, *c])) for e, c in zip(eids, conn)]
    for name, ids in sets.items():
        lines.append(f"*NSET, NSET={name}")
        lines += [", ".join(map(str, ids[k:k + 16])) for k in range(0, len(ids), 16)]
    Path(path).write_text("\n".join(lines) + "\n")
    return Path(path)


def write_bdf(path, nids, xyz, eids, conn, sets):
    """Free-field Nastran: GRID (large-field via ',' free format), CHEXA, SET1 (ids 1, 2 for BASE, TOP)."""
    lines = ["SOL 101", "CEND", "BEGIN BULK"]
    lines += [f"GRID*,{i},,{x!r},{y!r}\n*,{z!r}" for i, (x, y, z) in zip(nids, xyz)]
    lines += [f"CHEXA,{e},1,{','.join(map(str, c[:6]))}\n,{c[6]},{c[7]}" for e, c in zip(eids, conn)]
    lines += ["PSOLID,1,1", "MAT1,1,2.1e11,,0.3"]
    for sid, (name, ids) in enumerate(sets.items(), start=1):
        ids = [str(i) for i in ids]
        lines.append(f"SET1,{sid}," + ",".join(ids[:7]))
        lines += ["," + ",".join(ids[k:k + 8]) for k in range(7, len(ids), 8)]
    lines.append("ENDDATA")
    Path(path).write_text("\n".join(lines) + "\n")
    return Path(path)


GMSH_FILES = {"msh": "skirt.msh", "msh22": "skirt22.msh", "inp": "skirt.inp", "bdf": "skirt.bdf"}


def gmsh_written(outdir: Path, R=1.5, t=0.02, H=2.0, n_theta=24, n_z=6, n_r=1, scale=1.0) -> dict:
    """The skirt of :func:`gmsh_skirt` with every coordinate multiplied by ``scale`` (1000: a mesh in mm),
    written by Gmsh itself (``gmsh.write``) as an analyst exports it: ``.msh`` 4.1 and 2.2, ``.inp`` and
    ``.bdf``, each with what Gmsh writes for the physical groups (the volumes SKIRT, the skin faces BASE
    and TOP as 2D elements; node sets *NSET in the .inp through ``Mesh.SaveGroupsOfNodes``; in the .bdf
    the skin CQUAD4 carry their group's tag as property id, BASE = 2, TOP = 3, with no PSHELL). Returns
    the paths by format (:data:`GMSH_FILES`) and Gmsh's arrays (node ids, xyz, hexahedra, sets)."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    args = json.dumps({"outdir": str(outdir), "R": R * scale, "t": t * scale, "H": H * scale, "n_theta": n_theta,
                       "n_z": n_z, "n_r": n_r, "written": True})
    subprocess.run([sys.executable, __file__, args], check=True, timeout=300)
    a = np.load(outdir / "gmsh_arrays.npz")
    out = {k: outdir / v for k, v in GMSH_FILES.items()}
    out.update(node_ids=a["tags"], xyz=a["xyz"].reshape(-1, 3), conn=a["conn"], elem_ids=a["eids"],
               sets={"BASE": a["BASE"], "TOP": a["TOP"]})
    return out


def gmsh_files(outdir: Path, R=1.5, t=0.02, H=2.0, n_theta=16, n_z=4, n_r=1, top_radius=None,
               unit="m", order: int = 1) -> dict:
    """The skirt as *Gmsh itself writes it*: ``skirt.msh`` (4.1), ``skirt.inp`` and ``skirt.bdf`` from
    ``gmsh.write`` (skin elements of the physical surfaces BASE and TOP included, Gmsh's numbering, node sets
    ``*NSET`` BASE / TOP in the .inp), plus ``base.txt`` / ``top.txt`` (the sets' node ids, one a line, for the
    .bdf, which carries no sets). Geometry [m] as :func:`gmsh_skirt`, ``top_radius`` the mid-wall radius at
    the top (a cone: the revolved section is a parallelogram), coordinates written in ``unit`` ('m' or
    'mm'). ``order`` 2: second-order elements (``Mesh.ElementOrder`` 2, ``Mesh.SecondOrderIncomplete`` 1: 20-node
    hexahedra). Returns {'msh', 'inp', 'bdf': path, 'sets': {fmt: the model's mesh.sets value}}."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    args = json.dumps({"files": True, "outdir": str(outdir), "R": R, "t": t, "H": H, "n_theta": n_theta,
                       "n_z": n_z, "n_r": n_r, "top_radius": top_radius, "unit": unit, "order": order})
    subprocess.run([sys.executable, __file__, args], check=True, timeout=300)
    sets = {"msh": "{base: BASE, top: TOP}", "inp": "{base: BASE, top: TOP}",
            "bdf": "{base: base.txt, top: top.txt}"}
    return {**{f: outdir / f"skirt.{f}" for f in ("msh", "inp", "bdf")}, "sets": sets}


def _files_in_this_process(outdir: Path, R, t, H, n_theta, n_z, n_r, top_radius, unit, order=1) -> None:
    """The Gmsh part of :func:`gmsh_files` (child process)."""
    import gmsh
    gmsh.initialize(["-noenv"])
    try:
        groups = _skirt_model(gmsh, R, t, H, n_theta, n_z, n_r, top_radius, {"m": 1.0, "mm": 1000.0}[unit])
        if order != 1:
            gmsh.option.setNumber("Mesh.ElementOrder", order)
            gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 1)
        gmsh.model.mesh.generate(3)
        gmsh.model.mesh.removeDuplicateNodes()
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.SaveGroupsOfNodes", 1)
        for fmt in ("msh", "inp", "bdf"):
            gmsh.write(str(outdir / f"skirt.{fmt}"))
        for name, tag in groups.items():
            ids = gmsh.model.mesh.getNodesForPhysicalGroup(2, tag)[0]
            (outdir / f"{name.lower()}.txt").write_text("\n".join(str(int(i)) for i in ids) + "\n")
    finally:
        gmsh.finalize()


QUADRATIC_KINDS = ("hex20", "hex27", "tet10", "wedge15")


def gmsh_quadratic(outdir: Path, kind: str = "hex20", R=1.5, t=0.02, H=2.0, n_theta=48, n_z=6, n_r=2,
                   unstructured: bool = False, size: float | None = None) -> dict:
    """A second-order skirt meshed as an analyst does it with the Gmsh API: mesh the tube first order,
    then ``gmsh.model.mesh.setOrder(2)``; ``kind`` 'hex20' (recombined, ``Mesh.SecondOrderIncomplete`` 1),
    'hex27' (recombined, the option left at its default 0: 27-node hexahedra), 'tet10' (the revolved
    section not recombined: tetrahedra, in through-wall rows), 'wedge15' (triangles revolved into recombined
    prisms, ``Mesh.SecondOrderIncomplete`` 1); ``unstructured``: Gmsh's own tetrahedra of
    the OpenCASCADE tube, largest size ``size``, default t). Mid-side nodes lie on the true cylinder. Written by ``gmsh.write``
    as ``skirt.msh`` (4.1), ``skirt.inp`` (``Mesh.SaveGroupsOfNodes``: *NSET BASE / TOP) and ``skirt.bdf``, plus
    ``base.txt`` / ``top.txt`` (the .bdf carries no sets), and ``skirt_large.bdf`` (``Mesh.BdfFieldFormat`` 2:
    large-field cards). Returns {'msh', 'inp', 'bdf', 'bdf_large': path, 'sets': {fmt:
    the model's mesh.sets value}, 'n_elements': int, 'nodes_per_element': int}."""
    assert kind in QUADRATIC_KINDS, kind
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    args = json.dumps({"quadratic": kind, "outdir": str(outdir), "R": R, "t": t, "H": H, "n_theta": n_theta,
                       "n_z": n_z, "n_r": n_r, "unstructured": unstructured, "size": size})
    subprocess.run([sys.executable, __file__, args], check=True, timeout=300)
    info = json.loads((outdir / "gmsh_info.json").read_text())
    sets = {"msh": "{base: BASE, top: TOP}", "inp": "{base: BASE, top: TOP}",
            "bdf": "{base: base.txt, top: top.txt}"}
    sets["bdf_large"] = sets["bdf"]
    return {**{f: outdir / f"skirt.{f}" for f in ("msh", "inp", "bdf")}, "bdf_large": outdir / "skirt_large.bdf",
            "sets": sets, **info}


def _quadratic_in_this_process(outdir: Path, kind, R, t, H, n_theta, n_z, n_r, unstructured, size=None) -> None:
    """The Gmsh part of :func:`gmsh_quadratic` (child process)."""
    import gmsh
    gmsh.initialize(["-noenv"])
    try:
        if unstructured:
            groups = _occ_tube(gmsh, R, t, H, size or t)
        else:
            groups = _skirt_model(gmsh, R, t, H, n_theta, n_z, n_r, recombine=kind != "tet10",
                                  recombine_section=kind not in ("tet10", "wedge15"))
        gmsh.model.mesh.generate(3)
        gmsh.model.mesh.removeDuplicateNodes()
        if kind in ("hex20", "wedge15"):
            gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 1)
        gmsh.model.mesh.setOrder(2)
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.SaveGroupsOfNodes", 1)
        for fmt in ("msh", "inp", "bdf"):
            gmsh.write(str(outdir / f"skirt.{fmt}"))
        gmsh.option.setNumber("Mesh.BdfFieldFormat", 2)          # large-field GRID* cards (16 characters)
        gmsh.write(str(outdir / "skirt_large.bdf"))
        for name, tag in groups.items():
            ids = gmsh.model.mesh.getNodesForPhysicalGroup(2, tag)[0]
            (outdir / f"{name.lower()}.txt").write_text("\n".join(str(int(i)) for i in ids) + "\n")
        etypes, etags, enodes = gmsh.model.mesh.getElements(3)
        info = {"n_elements": int(sum(len(e) for e in etags)),
                "nodes_per_element": int(len(enodes[0]) // len(etags[0]))}
    finally:
        gmsh.finalize()
    (outdir / "gmsh_info.json").write_text(json.dumps(info))


def _occ_tube(gmsh, R, t, H, size) -> dict:
    """The tube R -+ t/2, 0 <= z <= H as an OpenCASCADE solid, Gmsh's default tetrahedra of size ``size``;
    physical groups SKIRT, BASE (the face at z = 0), TOP (z = H)."""
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("tube")
    occ = gmsh.model.occ
    outer = occ.addCylinder(0, 0, 0, 0, 0, H, R + t / 2)
    inner = occ.addCylinder(0, 0, 0, 0, 0, H, R - t / 2)
    vol, _ = occ.cut([(3, outer)], [(3, inner)])
    occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.option.setNumber("Mesh.MeshSizeMin", size / 2)
    faces = {"BASE": [], "TOP": []}
    for dim, tag in gmsh.model.getBoundary(vol, oriented=False):
        z = gmsh.model.occ.getCenterOfMass(dim, tag)[2]
        if abs(z) < 1e-9 * H:
            faces["BASE"].append(tag)
        elif abs(z - H) < 1e-9 * H:
            faces["TOP"].append(tag)
    gmsh.model.addPhysicalGroup(3, [v for _, v in vol], name="SKIRT")
    return {name: gmsh.model.addPhysicalGroup(2, f, name=name) for name, f in faces.items()}


def gmsh_mixed(outdir: Path, order: int = 1, R=1.5, t=0.02, H=2.0, n_theta=48, n_z=6, n_r=2,
               tri_quarters=(1, 3), tet_layers: int = 0) -> dict:
    """A mixed skirt as an analyst meshes it with the Gmsh API: the base annulus (four 90-degree quarters,
    transfinite) meshed quad-dominant -- quarters ``tri_quarters`` (0: 0-90 deg, ...) in triangles, the others
    recombined into quadrilaterals -- and extruded along z in ``n_z`` recombined layers: hexahedra over the
    quadrilaterals, prisms (wedges) over the triangles, a base of quad and triangle faces. ``order`` 2:
    ``Mesh.ElementOrder`` 2 with ``Mesh.SecondOrderIncomplete`` 1 (20-node hexahedra, 15-node wedges, mid-side
    nodes on the true circles). Written by ``gmsh.write`` as ``skirt.msh`` (4.1), ``skirt.inp`` (*NSET BASE / TOP
    through ``Mesh.SaveGroupsOfNodes``) and ``skirt.bdf`` (``Mesh.BdfFieldFormat`` 2), plus ``base.txt`` /
    ``top.txt``. ``tet_layers`` > 0: every quarter in triangles, the lowest ``n_z - tet_layers`` layers extruded
    recombined (prisms: a wedge layer at the base) and the top ``tet_layers`` layers not recombined (Gmsh cuts each
    prism into three tetrahedra), of height H tet_layers / n_z; the two volumes meet on triangles. Returns
    {'msh', 'inp', 'bdf': path, 'sets': {fmt: mesh.sets value}, 'counts': {Gmsh element type name: count}}."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    args = json.dumps({"mixed": order, "outdir": str(outdir), "R": R, "t": t, "H": H, "n_theta": n_theta,
                       "n_z": n_z, "n_r": n_r, "tri_quarters": list(range(4)) if tet_layers else list(tri_quarters),
                       "tet_layers": tet_layers})
    subprocess.run([sys.executable, __file__, args], check=True, timeout=300)
    info = json.loads((outdir / "gmsh_info.json").read_text())
    sets = {"msh": "{base: BASE, top: TOP}", "inp": "{base: BASE, top: TOP}",
            "bdf": "{base: base.txt, top: top.txt}"}
    return {**{f: outdir / f"skirt.{f}" for f in ("msh", "inp", "bdf")}, "sets": sets, **info}


def _mixed_in_this_process(outdir: Path, order, R, t, H, n_theta, n_z, n_r, tri_quarters, tet_layers=0) -> None:
    """The Gmsh part of :func:`gmsh_mixed` (child process)."""
    import gmsh
    gmsh.initialize(["-noenv"])
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("mixed")
        geo = gmsh.model.geo
        c = geo.addPoint(0, 0, 0)
        ang = np.radians([0, 90, 180, 270])
        pin = [geo.addPoint((R - t / 2) * np.cos(a), (R - t / 2) * np.sin(a), 0) for a in ang]
        pout = [geo.addPoint((R + t / 2) * np.cos(a), (R + t / 2) * np.sin(a), 0) for a in ang]
        radial = [geo.addLine(pin[q], pout[q]) for q in range(4)]
        arc_in = [geo.addCircleArc(pin[q], c, pin[(q + 1) % 4]) for q in range(4)]
        arc_out = [geo.addCircleArc(pout[q], c, pout[(q + 1) % 4]) for q in range(4)]
        surfs = []
        for q in range(4):
            loop = geo.addCurveLoop([radial[q], arc_out[q], -radial[(q + 1) % 4], -arc_in[q]])
            surfs.append(geo.addPlaneSurface([loop]))
        for ln in radial:
            geo.mesh.setTransfiniteCurve(ln, n_r + 1)
        for ln in arc_in + arc_out:
            geo.mesh.setTransfiniteCurve(ln, n_theta // 4 + 1)
        for q, s in enumerate(surfs):
            geo.mesh.setTransfiniteSurface(s)
            if q not in tri_quarters:
                geo.mesh.setRecombine(2, s)
        vols, tops = [], []
        low = n_z - tet_layers
        for s in surfs:
            out = geo.extrude([(2, s)], 0, 0, H * low / n_z, numElements=[low], recombine=True)
            vols.append(out[1][1])
            if tet_layers:
                out = geo.extrude([out[0]], 0, 0, H * tet_layers / n_z, numElements=[tet_layers], recombine=False)
                vols.append(out[1][1])
            tops.append(out[0][1])
        geo.synchronize()
        gmsh.model.addPhysicalGroup(3, vols, name="SKIRT")
        groups = {name: gmsh.model.addPhysicalGroup(2, f, name=name) for name, f in (("BASE", surfs), ("TOP", tops))}
        gmsh.model.mesh.generate(3)
        if order == 2:
            gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 1)
            gmsh.model.mesh.setOrder(2)
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.SaveGroupsOfNodes", 1)
        gmsh.option.setNumber("Mesh.BdfFieldFormat", 2)
        for fmt in ("msh", "inp", "bdf"):
            gmsh.write(str(outdir / f"skirt.{fmt}"))
        for name, tag in groups.items():
            ids = gmsh.model.mesh.getNodesForPhysicalGroup(2, tag)[0]
            (outdir / f"{name.lower()}.txt").write_text("\n".join(str(int(i)) for i in ids) + "\n")
        etypes, etags, _ = gmsh.model.mesh.getElements(3)
        counts = {gmsh.model.mesh.getElementProperties(e)[0]: len(g) for e, g in zip(etypes, etags)}
    finally:
        gmsh.finalize()
    (outdir / "gmsh_info.json").write_text(json.dumps({"counts": counts}))


if __name__ == "__main__":
    kw = json.loads(sys.argv[1])
    if "mixed" in kw:
        _mixed_in_this_process(Path(kw.pop("outdir")), kw.pop("mixed"), **kw)
    elif "quadratic" in kw:
        _quadratic_in_this_process(Path(kw.pop("outdir")), kw.pop("quadratic"), **kw)
    elif kw.pop("files", False):
        _files_in_this_process(Path(kw.pop("outdir")), **kw)
    else:
        _mesh_in_this_process(Path(kw.pop("outdir")), **kw)
