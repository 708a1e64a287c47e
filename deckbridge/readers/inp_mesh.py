"""Nodes and elements of an Abaqus/CalculiX deck read back (checks of the rendered inp decks)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import DeckbridgeError
from ._files import read_text


@dataclass(frozen=True)
class InpMesh:
    """Nodes and elements read back from an Abaqus-style deck."""
    node_ids: np.ndarray
    nodes: np.ndarray
    elements: dict          # element type -> (ids (m,), connectivity (m, k) of node ids)


def read_inp_mesh(path) -> InpMesh:
    """Read ``*NODE`` and ``*ELEMENT`` blocks of an Abaqus/CalculiX deck; every other card is skipped.

    meshio 5.3 cannot read the decks: it keeps only the last ``*NODE`` block and stops at element types
    it does not know (SPRING1, GAPUNI). Element data lines ending with ',' continue on the next line.
    """
    ids, xyz, elems = [], [], {}
    mode, etype, pending = None, None, []
    for lineno, raw in enumerate(read_text(path).splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("**"):
            continue
        if line.startswith("*"):
            head = [p.strip().upper() for p in line[1:].split(",")]
            mode = head[0] if head[0] in ("NODE", "ELEMENT") else None
            if mode == "ELEMENT":
                etype = next((p.split("=", 1)[1].strip() for p in head[1:] if p.startswith("TYPE=")), None)
                if etype is None:
                    raise DeckbridgeError(f"{str(path)!r}: line {lineno}: *ELEMENT without TYPE")
            pending = []
            continue
        if mode is None:
            continue
        try:
            fields = [f for f in line.split(",")]
            if mode == "NODE":
                ids.append(int(fields[0]))
                xyz.append([float(v) for v in fields[1:4]])
            else:
                pending += [int(f) for f in fields if f.strip()]
                if line.endswith(","):
                    continue
                e_ids, conn = elems.setdefault(etype, ([], []))
                e_ids.append(pending[0])
                conn.append(pending[1:])
                pending = []
        except (ValueError, IndexError):
            raise DeckbridgeError(f"{str(path)!r}: line {lineno}: unreadable {mode} data {line[:60]!r}") from None
    return InpMesh(node_ids=np.array(ids, dtype=np.int64), nodes=np.array(xyz, float).reshape(-1, 3),
                   elements={t: (np.array(i, dtype=np.int64), np.array(c, dtype=np.int64)) for t, (i, c) in
                             elems.items()})


def keyword_blocks(text: str):
    """``(keyword, options, data lines)`` of every card of an Abaqus/CalculiX deck, in order: keyword upper
    case without ``*``, options {NAME upper: value ('' for a flag)}, data lines stripped (comments dropped)."""
    blocks: list = []
    for raw in text.splitlines():
        line = raw.strip()
        if not line or line.startswith("**"):
            continue
        if line.startswith("*"):
            head = [p.strip() for p in line[1:].split(",")]
            opts = {p.split("=", 1)[0].strip().upper(): (p.split("=", 1)[1].strip() if "=" in p else "")
                    for p in head[1:] if p}
            blocks.append((head[0].upper(), opts, []))
        elif blocks:
            blocks[-1][2].append(line)
    return blocks


def contact_friction(path) -> list[tuple[str, str, float]]:
    """``(slave surface, master surface, friction coefficient of the interaction)`` of every ``*CONTACT PAIR``
    line of a deck, read back (0 where the interaction has no ``*FRICTION``)."""
    mu: dict[str, float] = {}
    pairs: list[tuple[str, str, str]] = []
    current = None
    for key, opts, data in keyword_blocks(read_text(path)):
        if key == "SURFACE INTERACTION":
            current = opts.get("NAME", "").upper()
            mu[current] = 0.0
        elif key == "FRICTION" and current is not None:
            mu[current] = float(data[0].split(",")[0]) if data else 0.0
        elif key != "SURFACE BEHAVIOR":
            current = None
        if key == "CONTACT PAIR":
            pairs += [(*(f.strip().upper() for f in d.split(",")[:2]), opts.get("INTERACTION", "").upper())
                      for d in data]
    return [(slave, master, mu.get(inter, 0.0)) for slave, master, inter in pairs]
