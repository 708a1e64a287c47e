"""Our own record reader of the Nastran OP2 contact result tables (no pyNastran).

Why our own: pyNastran 1.4.1 reads OQGCF1 and OSPDS1/OSPDSI1, but of **OBC1 it unpacks the records and
throws them away**: its result object holds zeros and it logs "no output for Contact Pressure and
Tractions" (``pyNastran/op2/tables/obc.py``, checked on the Simcenter file of
``../shared/data/nx_surface_contact``). So every contact table is read here, from the file's records.

The OP2 is a sequence of Fortran records ``[n][n bytes][n]`` (32-bit words, little- or big-endian,
told from the first record's length, which is 4). A data block ("table") is

    [2] [name, 8 chars] [-1] [7] [trailer, 7 words] [-2] [1] [0] [2] [name] [-3] [1] [0]
    then pairs  [n] [n words: IDENT] [-k] [1] [0]  [n] [n words: DATA] [-k-1] [1] [0] ...  until [0]

and the file ends with one more [0] after the last table's [0] (so the last three words are 0) (the same on the MSC and Simcenter
files in ../shared/data). A block of n words may be split over several records; they are joined.

IDENT (146 words; SORT1 real tables only): word 1 = approach code x 10 + device code, 2 = table code,
4 = subcase, 5 = load set (int; approach 1, statics) or time / load factor (float; approach 10,
nonlinear statics), 9 = format code (1 = real), 10 = words per entry. DATA entries, one per grid,
word 1 = grid id x 10 + device code:

- OQGCF1 (table code 63), 8 words: grid, grid type, t1, t2, t3, r1, r2, r3 (contact force on the grid,
  global system of the grid, force units);
- OBC1 (62), 5 words: grid, pressure, s1, s2, s3 (contact pressure, > 0 compressive in the Simcenter
  file: the nodes that carry force have positive pressure, and the total force of a contact region equals
  the sum of pressure x face share, see :mod:`.nastran_contact`; tractions in the global system);
- OSPDS1 / OSPDSI1 (65 / 64), 2 words: grid, separation (final / initial distance of a source grid to the
  target, < 0 = penetration).

Refused, one line naming the file and the byte: a file whose records do not chain (truncated: a record
runs past the end; garbled: its two length words differ), a contact table cut before its end, an OP2
with no end-of-file record (job unfinished or file cut), complex or SORT2 contact tables, and an OP2 with
none of the four tables.
"""

from __future__ import annotations

import mmap
import struct
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...errors import InputError

TABLES = {"OQGCF1": 8, "OBC1": 5, "OSPDS1": 2, "OSPDSI1": 2}     # name -> words per grid entry
COLUMNS = {"OQGCF1": ("fx", "fy", "fz", "mx", "my", "mz"), "OBC1": ("pressure", "s1", "s2", "s3"),
           "OSPDS1": ("separation",), "OSPDSI1": ("separation_initial",)}
APPROACH_STATICS, APPROACH_NONLINEAR = 1, 10


@dataclass
class Block:
    """One IDENT/DATA pair of a contact table: a subcase (and load step) of one table."""
    table: str
    subcase: int
    approach: int
    step: float            # load set id (statics) or time / load factor (nonlinear statics)
    grids: np.ndarray      # (n,) int64
    values: np.ndarray     # (n, k) float64, the table's :data:`COLUMNS`
    offset: int            # byte offset of the DATA record (for messages)


@dataclass
class ContactOP2:
    """The contact tables of one OP2: ``blocks[table]`` in file order."""
    path: Path
    blocks: dict[str, list[Block]] = field(default_factory=dict)


def _records(buf, path: Path) -> tuple[str, list[tuple[int, int]]]:
    """Endianness ('<' or '>') and (start, length) of every record's body; refuse what does not chain."""
    size = len(buf)
    if size < 12:
        raise InputError(f"{str(path)!r}: not an OP2 ({size} bytes)")
    end = next((e for e in "<>" if struct.unpack_from(e + "i", buf, 0)[0] == 4), None)
    if end is None:
        raise InputError(f"{str(path)!r}: not an OP2 (its first record is not a 4-byte word)")
    out, pos = [], 0
    while pos < size:
        if pos + 4 > size:
            raise InputError(f"{str(path)!r}: truncated at byte {pos} (a record's length word is cut): file cut")
        n = struct.unpack_from(end + "i", buf, pos)[0]
        if n < 0 or pos + 8 + n > size:
            raise InputError(f"{str(path)!r}: truncated at byte {pos}: a record of {n} bytes runs past the end "
                             f"of the file ({size} bytes): file cut or job unfinished")
        if struct.unpack_from(end + "i", buf, pos + 4 + n)[0] != n:
            raise InputError(f"{str(path)!r}: garbled at byte {pos}: a record's two length words differ "
                             "(not an OP2 of 32-bit words, or a damaged file)")
        out.append((pos + 4, n))
        pos += 8 + n
    return end, out


def read_tables(path: str | Path) -> ContactOP2:
    """The contact tables (:data:`TABLES`) of the OP2 at ``path``; InputError when it has none."""
    path = Path(path)
    try:
        fh = open(path, "rb")
    except FileNotFoundError:
        raise InputError(f"{str(path)!r}: no such file") from None
    with fh:
        if path.stat().st_size == 0:
            raise InputError(f"{str(path)!r}: not an OP2 (empty file)")
        with mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as buf:
            return _parse(buf, path)


def _parse(buf, path: Path) -> ContactOP2:
    end, recs = _records(buf, path)

    def word(i: int) -> int | None:
        s, n = recs[i] if i < len(recs) else (0, 0)
        return struct.unpack_from(end + "i", buf, s)[0] if n == 4 else None

    def name(i: int) -> str | None:
        s, n = recs[i] if i < len(recs) else (0, 0)
        return bytes(buf[s:s + 8]).decode("latin-1").strip() if n == 8 else None

    if any(word(len(recs) - k) != 0 for k in (1, 2, 3)):     # [-k] [1] [0] | [0] table end | [0] end of file
        raise InputError(f"{str(path)!r}: no end-of-file record (the OP2 does not end with a table's end and the "
                         "end-of-file zero word): "
                         "job unfinished or file cut")
    out = ContactOP2(path)
    for i in range(len(recs) - 4):
        if word(i) == 2 and word(i + 2) == -1 and word(i + 3) == 7 and name(i + 1) in TABLES:
            tab = name(i + 1)
            out.blocks[tab] = _table(buf, end, recs, i + 5, tab, path, word, name)
    if not out.blocks:
        raise InputError(f"{str(path)!r}: no contact result tables (OQGCF1, OBC1, OSPDS1, OSPDSI1) in the OP2: "
                         "not a surface-contact run, or BCRESULTS not requested")
    return out


def _table(buf, end: str, recs, i: int, tab: str, path: Path, word, name) -> list[Block]:
    """Blocks of the table whose header ends before record ``i`` (the record after the trailer)."""
    def expect(j: int, want, what: str):
        got = name(j) if isinstance(want, str) else word(j)
        if got != want:
            s = recs[j][0] - 4 if j < len(recs) else len(buf)
            raise InputError(f"{str(path)!r}: {tab} garbled or cut at byte {s}: expected {what}")
    for k, want in enumerate((-2, 1, 0, 2)):
        expect(i + k, want, "the table's header")
    expect(i + 4, tab, "the table's name")
    for k, want in enumerate((-3, 1, 0)):
        expect(i + 5 + k, want, "the table's header")
    j, marker, parts = i + 8, -4, []
    while True:
        n = word(j)
        if n is None or n < 0:
            expect(j, 0, "a block length or the table's end")
        if n == 0:
            break
        start, got, j = recs[j + 1][0] if j + 1 < len(recs) else len(buf), 0, j + 1
        chunks = []
        while got < 4 * n and j < len(recs):
            s, ln = recs[j]
            chunks.append(bytes(buf[s:s + ln]))
            got, j = got + ln, j + 1
        if got != 4 * n:
            raise InputError(f"{str(path)!r}: {tab} garbled or cut at byte {start}: a block of {n} words holds "
                             f"{got // 4}")
        parts.append((start, b"".join(chunks)))
        for k, want in enumerate((marker, 1, 0)):
            expect(j + k, want, "a block marker")
        j, marker = j + 3, marker - 1
    if len(parts) % 2:
        raise InputError(f"{str(path)!r}: {tab} has an identification record without its data (file cut?)")
    return [_block(tab, parts[k], parts[k + 1], end, path) for k in range(0, len(parts), 2)]


def _block(tab: str, ident: tuple[int, bytes], data: tuple[int, bytes], end: str, path: Path) -> Block:
    w = np.frombuffer(ident[1], dtype=end + "i4")
    if w.size < 10:
        raise InputError(f"{str(path)!r}: {tab} identification record at byte {ident[0]} has {w.size} words")
    approach, tcode, subcase, fmt, nwide = int(w[0]) // 10, int(w[1]), int(w[3]), int(w[8]), int(w[9])
    if tcode >= 1000 or fmt != 1 or nwide != TABLES[tab]:
        raise InputError(f"{str(path)!r}: {tab} at byte {ident[0]}: table code {tcode}, format {fmt}, {nwide} words "
                         f"per grid: only SORT1 real tables of {TABLES[tab]} words are read")
    step = float(w[4:5].view(end + "f4")[0]) if approach == APPROACH_NONLINEAR else float(w[4])
    raw = np.frombuffer(data[1], dtype=end + "i4")
    if raw.size % nwide:
        raise InputError(f"{str(path)!r}: {tab} data at byte {data[0]}: {raw.size} words, not a multiple of {nwide}")
    rows = raw.reshape(-1, nwide)
    vals = rows.view(end + "f4")[:, 2 if tab == "OQGCF1" else 1:].astype(np.float64)
    return Block(tab, subcase, approach, step, (rows[:, 0] // 10).astype(np.int64), vals, data[0])
