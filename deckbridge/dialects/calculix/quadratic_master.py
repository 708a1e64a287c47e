"""The CalculiX face-to-face deck's table master under quadratic slave faces (a wide fixed C3D8 ring).

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
            "master_elems": element_lines(rg.elem_ids, rg.conn), "table_master": face_lines(rg.elem_ids, rg.face)}

