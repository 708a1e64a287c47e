"""The CalculiX face-to-face deck's table master under quadratic slave faces (a wide fixed C3D8 ring), and one
master surface per contact pair on any faces (:func:`pair_masters`).

Lives with the CalculiX dialect: it writes element and face cards (``deckbridge.render.inp_cards``) on the
``.inp`` numbering (``deckbridge.numbering.inp``), which the base-layer ``deck_elements`` may not import.
"""

from __future__ import annotations

import numpy as np

from ...numbering.inp import FACE_TOP, ring
from ...render.inp_cards import element_lines, face_lines


def f2f_ring(model, mesh, first_node: int, first_elem: int) -> dict:
    """The face-to-face deck's table under quadratic slave faces: a fixed C3D8 ring (top faces S2 at z = 0, one
    per azimuth interval, t deep) whose straight-edged faces cover the curved slave faces: radial margin
    max(t, 2 r_out (1 / cos(pi / n_theta) - 1)) beyond the wall. ccx 2.20 reads a master face between its corner
    nodes: on a matching quadratic master (C3D20 under each C3D20R face, 24 x 3 x 1, R 1.5, t 0.02) the chords
    left half the slave face uncovered (base settled 1.13 mm against p / K = 0.546 mm; 48 azimuths: 3.4 %
    more), on this ring 0.5457 mm. Returns the node groups (name, ids, xyz) ``top`` and ``bottom``, the
    ``master_elems`` lines and the ``table_master`` surface lines."""
    t = model.geometry.thickness
    r_in, r_out = model.geometry.radius - t / 2, model.geometry.radius + t / 2
    margin = max(t, 2.0 * r_out * (1.0 / np.cos(np.pi / mesh.n_theta) - 1.0))
    rg = ring([r_in - margin, r_out + margin], [-t, 0.0], mesh.n_theta, first_node, first_elem, FACE_TOP)
    top = rg.nodes[:, 2] == 0.0
    return {"top": ("NMTOP", rg.node_ids[top], rg.nodes[top]), "bottom": ("NMBOT", rg.node_ids[~top], rg.nodes[~top]),
            "master_elems": element_lines(rg.elem_ids, rg.conn), "table_master": face_lines(rg.elem_ids, rg.face),
            "elems": rg.elem_ids}


def pair_masters(model, mesh, master: dict, same: list, quad: bool) -> tuple[list, tuple, str]:
    """One master surface per contact pair of the face-to-face deck, none shared: ccx 2.20 integrates a
    ``SURFACE TO SURFACE`` pair wrong where its master faces are another pair's too (measured, hex8i 32 x 3 x 2,
    k_normal 1e8 N/m, two pairs on MASTER_TABLE: the base penetrated 16 % more than N / Sum k and the reference,
    the inner/middle/outer forces off by 14 / 5 / 4 %; with disjoint masters both to 1e-6; tet10 48 x 3 x 1: 11 %
    and 8 % off N, 3e-5 with a ring per pair). ``same``: a face mask (base-face order) per group of equal slopes.
    One group: MASTER_TABLE, nothing added. Several: the matching 4-node master is split (each group gets the
    master faces under its slave faces; nodes may be shared, faces not); the quadratic ring, whose faces lie
    under several groups' faces, is written once more per further group (coincident nodes NMCOPY, fixed).
    Returns per group (master surface name, its face lines or "" for MASTER_TABLE), the NMCOPY node group
    (name, ids, xyz) and the extra master element lines."""
    names = [("MASTER_TABLE", "")] if len(same) == 1 else []
    copies, lines = [], []
    if len(same) > 1 and not quad:
        names = [(f"MASTER_TABLE{g + 1}", face_lines(master["elems"][m], FACE_TOP)) for g, m in enumerate(same)]
    elif len(same) > 1:
        top, bottom = master["top"][1], master["bottom"][1]
        nn, ne = top.size + bottom.size, master["elems"].size
        first = (int(min(top.min(), bottom.min())), int(master["elems"].min()))
        names.append(("MASTER_TABLE", ""))
        for g in range(1, len(same)):
            rg = f2f_ring(model, mesh, first[0] + g * nn, first[1] + g * ne)
            names.append((f"MASTER_TABLE{g + 1}", rg["table_master"]))
            copies.append(rg)
            lines.append(rg["master_elems"])
    ids = [np.r_[c["bottom"][1], c["top"][1]] for c in copies]
    xyz = [np.r_[c["bottom"][2], c["top"][2]] for c in copies]
    order = np.argsort(np.concatenate(ids)) if ids else np.zeros(0, int)
    node_group = ("NMCOPY", np.concatenate(ids)[order] if ids else np.zeros(0, int),
                  np.concatenate(xyz)[order] if xyz else np.zeros((0, 3)))
    return names, node_group, "\n".join(lines)

