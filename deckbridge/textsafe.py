"""Printable, bounded text for messages: every value a message shows goes through :func:`show`.

A value echoed into an error line is shortened ``reprlib``-style (strings, sequences, mappings and
nesting all bounded, so a YAML alias bomb costs microseconds, not minutes and 351 MB of stderr) and
its control characters are escaped (a newline or an ESC in a key never reaches the terminal raw).
"""

from __future__ import annotations

import reprlib

MAX_TEXT = 80            # characters of a string value shown
MAX_LINE = 600           # characters of a whole message line

_repr = reprlib.Repr()
_repr.maxstring = MAX_TEXT
_repr.maxother = MAX_TEXT
_repr.maxlong = 40
_repr.maxlevel = 3
_repr.maxlist = _repr.maxtuple = _repr.maxdict = _repr.maxset = _repr.maxfrozenset = 6
_repr.maxarray = 6


def escape(text: str) -> str:
    """``text`` with control characters (C0, DEL, C1, line/paragraph separators) escaped."""
    out = []
    for ch in text:
        o = ord(ch)
        if o < 0x20 or 0x7F <= o < 0xA0 or o in (0x2028, 0x2029):
            out.append({"\n": "\\n", "\r": "\\r", "\t": "\\t"}.get(ch, f"\\x{o:02x}" if o < 0x100 else f"\\u{o:04x}"))
        else:
            out.append(ch)
    return "".join(out)


def shorten(text: str, limit: int = MAX_LINE) -> str:
    """``text`` cut to ``limit`` characters, marking the cut with '...'."""
    return text if len(text) <= limit else text[: limit - 3] + "..."


def show(value) -> str:
    """The ``repr`` of ``value`` for a message: bounded in size and depth, control characters escaped."""
    try:
        text = _repr.repr(value)
    except Exception:  # noqa: BLE001  (a value whose repr fails still gets a line)
        text = f"<{type(value).__name__}>"
    return escape(shorten(text, 4 * MAX_TEXT))


def one_line(text) -> str:
    """``str(text)`` as one printable line of at most :data:`MAX_LINE` characters."""
    s = str(text)
    if len(s) > 4 * MAX_LINE:
        s = s[: 4 * MAX_LINE]
    return shorten(escape(s))
