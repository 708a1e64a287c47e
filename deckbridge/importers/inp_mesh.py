"""Nodes and elements of an Abaqus/CalculiX deck read back (checks of the rendered inp decks, imports)."""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from ..errors import DeckbridgeError, read_text

_COUNTED = re.compile(r"^(?:DC3D|C3D|CPS|CPE|CAX|M3D|S|T3D)(\d+)")
_FIXED = {"B31": 2, "B32": 3, "GAPUNI": 2, "SPRING1": 1, "SPRING2": 2, "SPRINGA": 2, "DASHPOTA": 2, "MASS": 1}


def node_count(etype: str) -> int | None:
    """Nodes per element of an Abaqus/CalculiX element type (C3D8I: 8, C3D10: 10, S4R: 4, T3D2: 2), None
    for a type this reader does not know (its lines then end where a line does not end with ',')."""
    t = etype.upper()
    if t in _FIXED:
        return _FIXED[t]
    m = _COUNTED.match(t)
    return int(m.group(1)) if m else None


@dataclass(frozen=True)
class InpMesh:
    """Nodes and elements read back from an Abaqus-style deck."""
    node_ids: np.ndarray
    nodes: np.ndarray
    elements: dict          # element type -> (ids (m,), connectivity (m, k) of node ids)
    elsets: dict = field(default_factory=dict)   # ELSET= of *ELEMENT cards: name -> element ids


def read_inp_mesh(path) -> InpMesh:
    """Read ``*NODE`` and ``*ELEMENT`` blocks of an Abaqus/CalculiX deck; every other card is skipped.

    Element data as CalculiX reads them (``elements.f``): an element of a type with n nodes
    (:func:`node_count`) takes its id and n node ids, continuing on the next lines until it has n
    (C3D10 written 8 + 3, C3D20 as 16 + 5); ids past the n-th on a line and a ',' ending a complete line
    are ignored. A type of unknown node count continues while its lines end with ','. An element left
    incomplete by the next keyword is an error naming it. meshio 5.3 cannot read the decks: it keeps only
    the last ``*NODE`` block and stops at element types it does not know (SPRING1, GAPUNI).
    """
    ids, xyz, elems, elsets = [], [], {}, {}
    mode, etype, need, pending, elset = None, None, None, [], None
    for lineno, raw in enumerate(read_text(path).splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("**"):
            continue
        if line.startswith("*"):
            if pending:
                raise DeckbridgeError(f"{str(path)!r}: line {lineno}: element {pending[0]} of type {etype} is "
                                      f"incomplete ({len(pending) - 1} of {need or '?'} node ids before this card)")
            head = [p.strip().upper() for p in line[1:].split(",")]
            mode = head[0] if head[0] in ("NODE", "ELEMENT") else None
            if mode == "ELEMENT":
                etype = next((p.split("=", 1)[1].strip() for p in head[1:] if p.replace(" ", "").startswith("TYPE=")),
                             None)
                if etype is None:
                    raise DeckbridgeError(f"{str(path)!r}: line {lineno}: *ELEMENT without TYPE")
                need = node_count(etype)
                elset = next((p.split("=", 1)[1].strip() for p in line[1:].split(",")[1:]
                              if p.replace(" ", "").upper().startswith("ELSET=")), None)
            continue
        if mode is None:
            continue
        try:
            fields = line.split(",")
            if mode == "NODE":
                ids.append(int(fields[0]))
                xyz.append([float(v) for v in fields[1:4]])
                continue
            pending += [int(f) for f in fields if f.strip()]
            if need is None and line.endswith(","):
                continue
            if need is not None and len(pending) < need + 1:
                continue
            e_ids, conn = elems.setdefault(etype, ([], []))
            e_ids.append(pending[0])
            if elset:
                elsets.setdefault(elset, []).append(pending[0])
            conn.append(pending[1:] if need is None else pending[1:need + 1])
            pending = []
        except (ValueError, IndexError):
            raise DeckbridgeError(f"{str(path)!r}: line {lineno}: unreadable {mode} data {line[:60]!r}") from None
    if pending:
        raise DeckbridgeError(f"{str(path)!r}: element {pending[0]} of type {etype} is incomplete at the end of "
                              f"the file ({len(pending) - 1} of {need or '?'} node ids)")
    out = {}
    for t, (i, c) in elems.items():
        sizes = {len(row) for row in c}
        if len(sizes) > 1:
            raise DeckbridgeError(f"{str(path)!r}: elements of type {t} have {min(sizes)} to {max(sizes)} node "
                                  "ids (one count per type)")
        out[t] = (np.array(i, dtype=np.int64), np.array(c, dtype=np.int64).reshape(len(i), -1))
    return InpMesh(node_ids=np.array(ids, dtype=np.int64), nodes=np.array(xyz, float).reshape(-1, 3), elements=out,
                   elsets={k: np.array(v, np.int64) for k, v in elsets.items()})


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
